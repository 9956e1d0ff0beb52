//! The subcommands that only draw: `render` (the catom geometry), `plot`
//! (modules placed per step) and `loadmap` (connector utilisation).

use reconfcheck::algorithms;
use reconfcheck::algorithms::scaffold::feed::Feed;
use reconfcheck::certify::{self, Options};
use reconfcheck::error::{Error, InputError};
use reconfcheck::mechanics::Model;
use reconfcheck::render::{self, Picture};
use reconfcheck::scenario::Scenario;
use reconfcheck::schedule::Schedule;
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct RenderArgs {
    #[arg(value_enum)]
    picture: PictureArg,
    #[arg(short, long)]
    output: PathBuf,
}

/// The pictures `render` draws (the CLI's names for [`Picture`], kept
/// here so the library does not depend on the argument parser).
#[derive(Copy, Clone, Debug, clap::ValueEnum)]
enum PictureArg {
    /// The catom body from three directions.
    Body,
    /// A 90° octagonal rotation with the cells that block it.
    Sweep,
    /// The deepest point of a collision, with its witness points.
    Collision,
}

pub fn render(a: RenderArgs) -> Result<u8, Error> {
    let picture = match a.picture {
        PictureArg::Body => Picture::Body,
        PictureArg::Sweep => Picture::Sweep,
        PictureArg::Collision => Picture::Collision,
    };
    render::save(&render::catom_svg(picture), &a.output, 1.0)?;
    eprintln!("wrote {}", a.output.display());
    Ok(0)
}

fn parse_feed(s: &str) -> Result<Feed, String> {
    Feed::parse(s).ok_or_else(|| format!("'{s}' is not a feed (known: just-in-time, eager)"))
}

#[derive(clap::Args)]
pub struct PlotArgs {
    /// Scenarios whose placement curves to draw (with `--figure 16`, the
    /// sandcastles to draw instead of the bundled two).
    #[arg(required_unless_present = "figure")]
    scenarios: Vec<PathBuf>,
    #[arg(short, long)]
    output: PathBuf,
    /// Chart title.
    #[arg(long, default_value = "scaffold assembly")]
    title: String,
    /// Draw seed 000's Fig. 11 to 16 (§5.4) instead, with the published
    /// numbers beside ours (table on stdout; see docs/scaffold.md).
    #[arg(long, value_name = "N")]
    figure: Option<u32>,
    /// Sizes for Figs. 11–13: `A..B` or `A,B,…`, within 2..9.
    #[arg(long, default_value = "2..9")]
    sizes: String,
    /// Folder of the authors' canonical targets.
    #[arg(long, value_name = "DIR")]
    shapes: Option<PathBuf>,
    /// When the sandbox releases modules, for Figs. 11–15 (Fig. 16 takes
    /// it from each scenario): `just-in-time` or `eager` (the authors'
    /// feeding; see docs/scaffold.md).
    #[arg(long, default_value = "just-in-time", value_parser = parse_feed)]
    feed: Feed,
    /// Never show a progress bar.
    #[arg(long)]
    no_progress: bool,
}

pub fn plot(a: PlotArgs) -> Result<u8, Error> {
    if let Some(number) = a.figure {
        return super::figures::draw(super::figures::Figure {
            number,
            sizes: super::figures::parse_sizes(&a.sizes)?,
            shapes: super::figures::shapes_dir(a.shapes.as_deref()),
            scenarios: a.scenarios,
            output: a.output,
            progress: !a.no_progress,
            feed: a.feed,
        });
    }
    let mut curves = Vec::new();
    for p in &a.scenarios {
        let sc = Scenario::load(p)?;
        let s = algorithms::generate(&sc)?;
        let v = reconfcheck::study::scaffold_figures::placed_per_step(&s);
        eprintln!(
            "{}: {} modules placed in {} steps",
            sc.name,
            v.iter().sum::<usize>(),
            v.len()
        );
        curves.push((sc.name.clone(), v));
    }
    render::placed_plot(&curves, &a.title, &[], &a.output)?;
    Ok(0)
}

#[derive(clap::Args)]
pub struct LoadmapArgs {
    schedule: PathBuf,
    /// Step (1-based; steps + 1 is the final configuration).
    #[arg(long, default_value_t = 1)]
    step: usize,
    /// Physical model (TOML); default: the schedule's own.
    #[arg(long, value_name = "FILE")]
    model: Option<PathBuf>,
    /// Output picture (PNG, or SVG by extension).
    #[arg(short, long)]
    output: PathBuf,
}

pub fn loadmap(a: LoadmapArgs) -> Result<u8, Error> {
    let s = Schedule::load(&a.schedule)?;
    let opts = Options {
        model: a.model,
        base_dir: a.schedule.parent().map(Path::to_path_buf),
        ..Default::default()
    };
    let path = certify::model_path(&s, &opts).ok_or_else(|| {
        InputError::new("no model: pass --model FILE or name one in the schedule")
            .in_file(&a.schedule)
    })?;
    let m = Model::load(&path)?;
    let summary = reconfcheck::render::loadmap(&s, &m, a.step, &a.output)
        .map_err(|e| e.in_file(&a.schedule))?;
    println!("{summary}");
    Ok(0)
}
