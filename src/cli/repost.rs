//! `repost-study`: seed 001's Fig. 9 (concurrent rotations and streamlines
//! per time step) for a `repost` scenario, the bundled L → C by default.

use reconfcheck::error::{Error, write_file};
use reconfcheck::scenario::Scenario;
use reconfcheck::study::repost as study;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// A scenario with `algorithm = "repost"`.
    #[arg(default_value = "scenarios/repost-l-to-c.toml")]
    scenario: PathBuf,
    /// Also write the curves and the iteration table as JSON.
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
    /// Also draw Fig. 9 (PNG, or SVG by the extension).
    #[cfg(feature = "render")]
    #[arg(long, value_name = "FILE")]
    plot: Option<PathBuf>,
}

pub fn run(a: Args) -> Result<u8, Error> {
    let sc = Scenario::load(&a.scenario)?;
    let f = study::fig9(&sc)?;
    print!("{}", study::table(&f));
    if let Some(p) = a.json {
        write_file(&p, serde_json::to_string_pretty(&f).expect("serialises"))?;
    }
    #[cfg(feature = "render")]
    if let Some(p) = a.plot {
        reconfcheck::render::repost_figures::fig9(&f, &p)?;
        eprintln!("wrote {}", p.display());
    }
    Ok(0)
}
