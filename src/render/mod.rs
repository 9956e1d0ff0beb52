//! Pictures: plots and drawings, written as PNG (or SVG).
//!
//! Charts are drawn with `plotters` into SVG, then rasterised by `resvg`
//! with the DejaVu Sans font shipped in `assets/fonts` (free licence) and
//! compiled in, so rendering needs no system fonts or C libraries on a
//! fresh machine. Draw with [`SvgCanvas`] and finish with [`save`].

use crate::error::Error;
use std::path::Path;
use std::sync::{Arc, OnceLock};

mod b_study;
mod catom;
pub mod comb_figures;
pub mod density;
pub mod docking_figures;
mod loadmap;
mod placed;
pub mod repost_figures;
pub mod scaffold_figures;

pub use b_study::plot as b_study_plot;
pub use catom::{Picture, svg as catom_svg};
pub use loadmap::{colour as utilisation_colour, draw as loadmap_svg, render_step as loadmap};
pub use placed::draw as placed_plot;

/// Why a picture could not be drawn (plotters' and resvg's errors, as text).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct DrawError(String);

/// Draws a chart's legend at `at`, on a light box with a black border
/// (every chart here uses the same).
pub(crate) fn legend<'a, DB, CT>(
    c: &mut plotters::chart::ChartContext<'a, DB, CT>,
    at: plotters::chart::SeriesLabelPosition,
) -> Result<(), DrawError>
where
    DB: plotters::prelude::DrawingBackend + 'a,
    CT: plotters::coord::CoordTranslate,
{
    use plotters::style::{BLACK, Color, WHITE};
    c.configure_series_labels()
        .position(at)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(draw_err)
}

/// Any drawing backend's error as a [`DrawError`], for `map_err`.
pub fn draw_err(e: impl std::fmt::Display) -> DrawError {
    DrawError(e.to_string())
}

/// Draws into a fresh SVG document with `draw`; a failure names `path`,
/// the picture it was meant for.
pub fn svg(
    path: &Path,
    draw: impl FnOnce(&mut String) -> Result<(), DrawError>,
) -> Result<String, Error> {
    let mut svg = String::new();
    draw(&mut svg).map_err(|e| Error::Render {
        path: path.to_path_buf(),
        message: e.0,
    })?;
    Ok(svg)
}

static FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

/// The plotters backend charts draw on: an in-memory SVG document.
pub type SvgCanvas<'a> = plotters::backend::SVGBackend<'a>;

/// Writes an SVG document to `path`: as SVG if the extension is `.svg`,
/// otherwise rasterised to PNG at the document's own size (× `scale`).
pub fn save(svg: &str, path: &Path, scale: f32) -> Result<(), Error> {
    let is_svg = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("svg"));
    if is_svg {
        return crate::error::write_file(path, svg);
    }
    let png = rasterise(svg, scale).map_err(|e| Error::Render {
        path: path.to_path_buf(),
        message: e.0,
    })?;
    crate::error::write_file(path, png)
}

/// Rasterises an SVG document to PNG bytes.
pub fn rasterise(svg: &str, scale: f32) -> Result<Vec<u8>, DrawError> {
    let opt = usvg_options();
    let tree =
        resvg::usvg::Tree::from_str(svg, opt).map_err(|e| draw_err(format!("bad SVG: {e}")))?;
    let size = tree
        .size()
        .to_int_size()
        .scale_by(scale)
        .ok_or_else(|| draw_err("empty picture"))?;
    let mut pixmap = resvg::tiny_skia::Pixmap::new(size.width(), size.height())
        .ok_or_else(|| draw_err("picture too large"))?;
    pixmap.fill(resvg::tiny_skia::Color::WHITE);
    resvg::render(
        &tree,
        resvg::tiny_skia::Transform::from_scale(scale, scale),
        &mut pixmap.as_mut(),
    );
    pixmap
        .encode_png()
        .map_err(|e| draw_err(format!("PNG encoding failed: {e}")))
}

fn usvg_options() -> &'static resvg::usvg::Options<'static> {
    static OPT: OnceLock<resvg::usvg::Options<'static>> = OnceLock::new();
    OPT.get_or_init(|| {
        let mut db = resvg::usvg::fontdb::Database::new();
        db.load_font_data(FONT.to_vec());
        db.set_sans_serif_family("DejaVu Sans");
        db.set_serif_family("DejaVu Sans");
        db.set_monospace_family("DejaVu Sans");
        let mut opt = resvg::usvg::Options {
            font_family: "DejaVu Sans".into(),
            ..Default::default()
        };
        opt.fontdb = Arc::new(db);
        opt
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use plotters::prelude::*;

    #[test]
    fn a_chart_with_text_renders_to_png() {
        let mut svg = String::new();
        {
            let root = SvgCanvas::with_string(&mut svg, (320, 240)).into_drawing_area();
            root.fill(&WHITE).unwrap();
            let mut chart = ChartBuilder::on(&root)
                .caption("a caption", ("sans-serif", 20))
                .x_label_area_size(30)
                .y_label_area_size(30)
                .build_cartesian_2d(0.0..1.0, 0.0..1.0)
                .unwrap();
            chart.configure_mesh().draw().unwrap();
            chart
                .draw_series(LineSeries::new([(0.0, 0.0), (1.0, 1.0)], &RED))
                .unwrap();
            root.present().unwrap();
        }
        assert!(svg.contains("a caption"));
        let png = rasterise(&svg, 1.0).unwrap();
        assert_eq!(&png[1..4], b"PNG");
        // Text was drawn: a picture with the caption differs from one without.
        let blank = rasterise(&svg.replace("a caption", ""), 1.0).unwrap();
        assert_ne!(png, blank);
    }
}
