//! `density-study`: seed 003 §V-B1 over random configurations.

use reconfcheck::algorithms::active_subtraction::random::Growth;
use reconfcheck::error::{Error, InputError, write_file};
use reconfcheck::study::density as study;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Side lengths of the initial squares.
    #[arg(long, value_delimiter = ',', default_value = "10,20")]
    sizes: Vec<i32>,
    /// Densities of included modules, in percent.
    #[arg(long, value_delimiter = ',', default_value = "10,20,30,40,50,60,70")]
    densities: Vec<u32>,
    /// Random configurations per (size, density).
    #[arg(long, default_value_t = 80)]
    samples: usize,
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Also repeat the study with this many base seeds (seed, seed + 1,
    /// …), print how much each box's median moves between studies and
    /// draw the mean SAS median as a dashed line.
    #[arg(long)]
    repeats: Option<usize>,
    /// How the random configurations grow: `member` is §V-B as written;
    /// `chain` (grow from the module added last) measures how much the
    /// curve owes to the generator.
    #[arg(long, value_enum, default_value = "member")]
    growth: GrowthArg,
    /// Also write every sample, the box summaries and the spread as JSON.
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
    /// Box plot (PNG, or SVG by extension).
    #[cfg(feature = "render")]
    #[arg(short, long)]
    output: PathBuf,
    /// Never show a progress bar.
    #[arg(long)]
    no_progress: bool,
}

/// The CLI's names for [`Growth`].
#[derive(Copy, Clone, Debug, clap::ValueEnum)]
enum GrowthArg {
    /// A random included module gains a random free neighbour (§V-B).
    Member,
    /// The module added last gains one, while it can.
    Chain,
}

pub fn run(a: Args) -> Result<u8, Error> {
    let cfg = study::StudyConfig {
        sizes: a.sizes,
        densities: a.densities,
        samples: a.samples,
        seed: a.seed,
        growth: match a.growth {
            GrowthArg::Member => Growth::Member,
            GrowthArg::Chain => Growth::Chain,
        },
    };
    if cfg.samples == 0
        || cfg.sizes.iter().any(|&s| s < 2)
        || cfg.densities.iter().any(|&d| d == 0 || d >= 100)
    {
        return Err(InputError::new(
            "density-study needs samples ≥ 1, sizes ≥ 2 and densities in 1..99 %",
        )
        .into());
    }
    let repeats = a.repeats.filter(|&n| n >= 2);
    // One bar over every sample: the study, then its repeats.
    let progress = super::progress::reporter(!a.no_progress, 1);
    progress.start(
        "density study",
        (study::sample_count(&cfg) * (1 + repeats.unwrap_or(0))) as u64,
    );
    let samples = study::run_observed(&cfg, &progress)?;
    let rows = study::summarise(&cfg, &samples);
    let spread = match repeats {
        Some(n) => study::spread_observed(&cfg, n, &progress)?,
        None => Vec::new(),
    };
    progress.finish();
    print!("{}", study::table(&rows));
    if let Some(n) = repeats {
        print!("\n{}", study::spread_table(&spread, n));
    }
    #[cfg(feature = "render")]
    {
        reconfcheck::render::density::plot_with_spread(&cfg, &rows, &spread, &a.output)?;
        eprintln!("wrote {}", a.output.display());
    }
    if let Some(p) = &a.json {
        write_file(p, study::to_json(&cfg, &samples, &rows, &spread))?;
        eprintln!("wrote {}", p.display());
    }
    Ok(0)
}
