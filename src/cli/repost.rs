//! `repost-study`: seed 001's Fig. 9 (concurrent rotations and streamlines
//! per time step) for one `repost` scenario, the bundled L → C by default,
//! or Fig. 10 (`--fig10`: the L → C at several sizes, with fits).

use reconfcheck::error::{Error, InputError, write_file};
use reconfcheck::scenario::Scenario;
use reconfcheck::study::repost as study;
use std::path::PathBuf;

/// The bundled Fig. 10 sizes.
const SIZES: [u32; 5] = [20, 28, 36, 44, 52];

#[derive(clap::Args)]
pub struct Args {
    /// Scenarios with `algorithm = "repost"`: one for Fig. 9 (default
    /// `scenarios/repost-l-to-c.toml`), or the sizes of Fig. 10 with
    /// `--fig10` (default the bundled `scenarios/repost-l-to-c-N.toml`,
    /// N = 20, 28, 36, 44, 52).
    scenarios: Vec<PathBuf>,
    /// Fig. 10 instead of Fig. 9: time steps against diameter and
    /// rotations against size, with least-squares fits.
    #[arg(long)]
    fig10: bool,
    /// Also write the data as JSON.
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
    /// Also draw the figure (PNG, or SVG by the extension).
    #[cfg(feature = "render")]
    #[arg(long, value_name = "FILE")]
    plot: Option<PathBuf>,
}

pub fn run(a: Args) -> Result<u8, Error> {
    if let Some(p) = &a.json {
        super::output::check_output("--json", p)?;
    }
    #[cfg(feature = "render")]
    if let Some(p) = &a.plot {
        super::output::check_output("--plot", p)?;
    }
    if a.fig10 {
        return fig10(a);
    }
    let path = match a.scenarios.as_slice() {
        [] => PathBuf::from("scenarios/repost-l-to-c.toml"),
        [one] => one.clone(),
        _ => {
            return Err(InputError::new(
                "repost-study draws Fig. 9 for one scenario; pass --fig10 to compare several sizes",
            )
            .into());
        }
    };
    let f = study::fig9(&Scenario::load(&path)?)?;
    print!("{}", study::table(&f));
    #[cfg(feature = "render")]
    let draw = reconfcheck::render::repost_figures::fig9;
    #[cfg(not(feature = "render"))]
    let draw = std::marker::PhantomData;
    outputs(&a, &f, draw)
}

fn fig10(a: Args) -> Result<u8, Error> {
    let paths: Vec<PathBuf> = if a.scenarios.is_empty() {
        SIZES
            .iter()
            .map(|n| PathBuf::from(format!("scenarios/repost-l-to-c-{n}.toml")))
            .collect()
    } else {
        a.scenarios.clone()
    };
    let scenarios = paths
        .iter()
        .map(|p| Scenario::load(p))
        .collect::<Result<Vec<_>, _>>()?;
    let f = study::fig10(&scenarios, &|name| eprintln!("planning {name}…"))?;
    print!("{}", study::fig10_table(&f));
    #[cfg(feature = "render")]
    let draw = reconfcheck::render::repost_figures::fig10;
    #[cfg(not(feature = "render"))]
    let draw = std::marker::PhantomData;
    outputs(&a, &f, draw)
}

/// How a figure is drawn to a file (nothing in a build without `render`).
#[cfg(feature = "render")]
type Draw<T> = fn(&T, &std::path::Path) -> Result<(), Error>;
#[cfg(not(feature = "render"))]
type Draw<T> = std::marker::PhantomData<T>;

/// Writes the study's data as JSON and draws its figure, where asked.
fn outputs<T: serde::Serialize>(a: &Args, data: &T, draw: Draw<T>) -> Result<u8, Error> {
    if let Some(p) = &a.json {
        write_file(p, serde_json::to_string_pretty(data).expect("serialises"))?;
    }
    #[cfg(feature = "render")]
    if let Some(p) = &a.plot {
        draw(data, p)?;
        eprintln!("wrote {}", p.display());
    }
    #[cfg(not(feature = "render"))]
    let _ = draw;
    Ok(0)
}
