//! The `reconfcheck` command line: a thin layer over the library.
//!
//! Exit codes: 0 certified, 1 violations found, 2 unusable input,
//! 3 an output file could not be written.

mod cli;

use clap::{Parser, Subcommand};
use reconfcheck::algorithms;
use reconfcheck::certify::{self, Options, Report};
use reconfcheck::error::InputError;
use reconfcheck::scenario::Scenario;
use reconfcheck::schedule::Schedule;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// mimalloc rather than the system allocator: a certification allocates
/// per-step arrays that grow with the structure between long-lived small
/// allocations (the report), and glibc's heap kept every outgrown block —
/// one pass over the sandcastle reached 24 GB (cube-d5: 2.3 GB against
/// 0.12 GB with large blocks mapped apart).
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

const EXIT_VIOLATIONS: u8 = 1;
const EXIT_INPUT: u8 = 2;
const EXIT_OUTPUT: u8 = 3;

#[derive(Parser)]
#[command(
    name = "reconfcheck",
    version,
    about = "Certifies that a lattice modular robot's reconfiguration is physically feasible."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(clap::Args, Clone)]
struct ReportArgs {
    /// Write the JSON report to this file.
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
    /// Print the JSON report on standard output instead of the summary.
    #[arg(long)]
    print_json: bool,
    /// Never show a progress bar.
    #[arg(long)]
    no_progress: bool,
    /// Force exact sweeps everywhere (no compiled motion-rule tables).
    #[arg(long)]
    exact: bool,
    /// Collision tolerance, in units of the lattice spacing d.
    #[arg(long, default_value_t = reconfcheck::geometry::EPSILON)]
    epsilon: f64,
    /// Run the lattice checks only (occupancy, pivots, connectivity).
    #[arg(long)]
    lattice_only: bool,
    /// Physical model (TOML, see models/) for the gravity and connector-load
    /// check; overrides the schedule's own `model`.
    #[arg(long, value_name = "FILE")]
    model: Option<PathBuf>,
}

#[derive(Subcommand)]
enum Command {
    /// Certify a schedule file (exit 0 certified, 1 violations, 2 unusable input).
    Certify {
        schedule: PathBuf,
        #[command(flatten)]
        report: ReportArgs,
    },
    /// Generate the schedule of a scenario.
    Generate {
        scenario: PathBuf,
        /// Where to write the schedule (JSON).
        #[arg(short, long)]
        output: PathBuf,
    },
    /// Generate and certify a scenario (the bundled default without argument).
    Run {
        scenario: Option<PathBuf>,
        /// Also write the generated schedule to this file.
        #[arg(short, long)]
        output: Option<PathBuf>,
        #[command(flatten)]
        report: ReportArgs,
    },
    /// List the generators (algorithms) scenarios can name.
    Algorithms,
    /// Plot modules placed per time step (seed 000 Fig. 13–16) for the
    /// schedules of one or more scenarios, as PNG (or SVG).
    Plot {
        #[arg(required = true)]
        scenarios: Vec<PathBuf>,
        #[arg(short, long)]
        output: PathBuf,
        /// Chart title.
        #[arg(long, default_value = "scaffold assembly")]
        title: String,
    },
    /// Branch-length study: check every step of a shape family for a range
    /// of b; table on stdout, plot of utilisation and minimum pressure.
    BStudy {
        /// Shape family (see `study::b_study::FAMILIES`).
        #[arg(long, default_value = "branch")]
        family: String,
        /// Physical model (TOML).
        #[arg(long, value_name = "FILE", default_value = "models/catom-3.6mm.toml")]
        model: PathBuf,
        /// Shape size of scaffold families (pyramid: h; cube: tiles a side;
        /// default 2).
        #[arg(long)]
        size: Option<u32>,
        /// The CSG shape file of `--family csg` (e.g.
        /// models/shapes/sandcastle.csg).
        #[arg(long, value_name = "FILE")]
        shape: Option<PathBuf>,
        /// Smallest branch length (default: the family's, 1 or 4).
        #[arg(long)]
        b_min: Option<usize>,
        /// Largest branch length (default: the family's, 10 or 8).
        #[arg(long)]
        b_max: Option<usize>,
        /// Override the model's connector pressure (kPa).
        #[arg(long)]
        pressure: Option<f64>,
        /// Override the model's bending criterion (elastic | rigid-hinge).
        #[arg(long)]
        bending: Option<reconfcheck::mechanics::Bending>,
        /// Write the plot (PNG, or SVG by extension).
        #[arg(long, value_name = "FILE")]
        plot: Option<PathBuf>,
        /// Write the study as JSON.
        #[arg(long, value_name = "FILE")]
        json: Option<PathBuf>,
    },
    /// Draw the connector load map of a schedule's configuration at a step.
    Loadmap {
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
    },
    /// Seed 003 §V-B1: active subtraction on random configurations of
    /// several densities; prints a table and draws a box plot.
    DensityStudy {
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
        #[arg(short, long)]
        output: PathBuf,
    },
    /// Derive the FCC motion rules (cells blocking each of the 120 rotation
    /// links) from the catom geometry and print them as a table.
    Rules {
        /// Also write the rules as JSON to this file.
        #[arg(long, value_name = "FILE")]
        json: Option<PathBuf>,
    },
    /// Draw the catom geometry: the body, one sweep or one collision
    /// (PNG, or SVG if the file name ends in .svg).
    Render {
        #[arg(value_enum)]
        picture: PictureArg,
        #[arg(short, long)]
        output: PathBuf,
    },
}

/// The CLI's names for
/// [`reconfcheck::algorithms::active_subtraction::random::Growth`].
#[derive(Copy, Clone, Debug, clap::ValueEnum)]
enum GrowthArg {
    /// A random included module gains a random free neighbour (§V-B).
    Member,
    /// The module added last gains one, while it can.
    Chain,
}

/// The pictures `render` draws (the CLI's names for
/// [`reconfcheck::geometry::picture::Picture`], kept here so the library
/// does not depend on the argument parser).
#[derive(Copy, Clone, Debug, clap::ValueEnum)]
enum PictureArg {
    /// The catom body from three directions.
    Body,
    /// A 90° octagonal rotation with the cells that block it.
    Sweep,
    /// The deepest point of a collision, with its witness points.
    Collision,
}

impl From<PictureArg> for reconfcheck::geometry::picture::Picture {
    fn from(p: PictureArg) -> Self {
        use reconfcheck::geometry::picture::Picture;
        match p {
            PictureArg::Body => Picture::Body,
            PictureArg::Sweep => Picture::Sweep,
            PictureArg::Collision => Picture::Collision,
        }
    }
}

enum Failure {
    Input(InputError),
    Output(String),
}

impl From<InputError> for Failure {
    fn from(e: InputError) -> Self {
        Failure::Input(e)
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli.command) {
        Ok(code) => ExitCode::from(code),
        Err(Failure::Input(e)) => {
            eprintln!("error: {e}");
            ExitCode::from(EXIT_INPUT)
        }
        Err(Failure::Output(e)) => {
            eprintln!("error: {e}");
            ExitCode::from(EXIT_OUTPUT)
        }
    }
}

fn run(cmd: Command) -> Result<u8, Failure> {
    match cmd {
        Command::Certify { schedule, report } => {
            let s = Schedule::load(&schedule)?;
            certify_and_report(&s, &schedule, &report)
        }
        Command::Generate { scenario, output } => {
            let sc = Scenario::load(&scenario)?;
            let mut s = algorithms::generate(&sc)?;
            s.model = s.model.map(|m| sc.path_from(&m, &output));
            write(&output, &s.to_json())?;
            eprintln!(
                "wrote {} ({} modules, {} steps, {} moves)",
                output.display(),
                s.modules.len(),
                s.steps.len(),
                s.move_count()
            );
            Ok(0)
        }
        Command::Run {
            scenario,
            output,
            report,
        } => {
            let path = scenario.unwrap_or_else(Scenario::default_path);
            let sc = Scenario::load(&path)?;
            eprintln!("scenario {}: {}", sc.name, sc.description);
            let s = algorithms::generate(&sc)?;
            if let Some(out) = &output {
                let mut s = s.clone();
                s.model = s.model.map(|m| sc.path_from(&m, out));
                write(out, &s.to_json())?;
            }
            certify_and_report(&s, &path, &report)
        }
        Command::Rules { json } => {
            let t = reconfcheck::geometry::rules::table();
            print!("{}", t.to_text());
            if let Some(p) = json {
                write(&p, &t.to_json(reconfcheck::geometry::EPSILON))?;
            }
            Ok(0)
        }
        Command::Render { picture, output } => {
            let svg = reconfcheck::geometry::picture::svg(picture.into());
            reconfcheck::render::save(&svg, &output, 1.0).map_err(Failure::Output)?;
            eprintln!("wrote {}", output.display());
            Ok(0)
        }
        Command::DensityStudy {
            sizes,
            densities,
            samples,
            seed,
            repeats,
            growth,
            json,
            output,
        } => {
            use reconfcheck::algorithms::active_subtraction::{random::Growth, study};
            let cfg = study::StudyConfig {
                sizes,
                densities,
                samples,
                seed,
                growth: match growth {
                    GrowthArg::Member => Growth::Member,
                    GrowthArg::Chain => Growth::Chain,
                },
            };
            let bad = |m: String| Failure::Input(InputError::new(m));
            if cfg.samples == 0
                || cfg.sizes.iter().any(|&s| s < 2)
                || cfg.densities.iter().any(|&d| d == 0 || d >= 100)
            {
                return Err(bad(
                    "density-study needs samples ≥ 1, sizes ≥ 2 and densities in 1..99 %".into(),
                ));
            }
            // One bar over every sample: the study, then its repeats.
            let total = study::sample_count(&cfg) * (1 + repeats.filter(|&n| n >= 2).unwrap_or(0));
            let bar = reconfcheck::progress::bar(
                std::io::stderr().is_terminal(),
                total,
                "density study {bar:40} {pos}/{len} samples ({per_sec}, eta {eta})",
            );
            let samples = study::run_observed(&cfg, &bar).map_err(bad)?;
            let rows = study::summarise(&cfg, &samples);
            let spread = match repeats.filter(|&n| n >= 2) {
                Some(n) => study::spread_observed(&cfg, n, &bar).map_err(bad)?,
                None => Vec::new(),
            };
            bar.finish_and_clear();
            print!("{}", study::table(&rows));
            if let Some(n) = repeats.filter(|&n| n >= 2) {
                print!("\n{}", study::spread_table(&spread, n));
            }
            study::plot_with_spread(&cfg, &rows, &spread, &output).map_err(Failure::Output)?;
            eprintln!("wrote {}", output.display());
            if let Some(p) = &json {
                write(p, &study::to_json(&cfg, &samples, &rows, &spread))?;
                eprintln!("wrote {}", p.display());
            }
            Ok(0)
        }
        Command::BStudy {
            family,
            model,
            size,
            shape,
            b_min,
            b_max,
            pressure,
            bending,
            plot,
            json,
        } => {
            use reconfcheck::study::b_study;
            let mut m = reconfcheck::mechanics::Model::load(&model)?;
            if pressure.is_some() || bending.is_some() {
                m = m.with_connector(
                    pressure.map_or(m.connector.pressure, |k| k * 1e3),
                    bending.unwrap_or(m.connector.bending),
                );
            }
            let (lo, hi) = b_study::default_range(&family);
            let (b_min, b_max) = (b_min.unwrap_or(lo), b_max.unwrap_or(hi));
            if b_min == 0 || b_min > b_max {
                return Err(InputError::new(format!("bad range of b: {b_min}..={b_max}")).into());
            }
            let generate = b_study::family(&family, m.spacing * 1e3, size, shape.as_deref())?;
            let lengths: Vec<usize> = (b_min..=b_max).collect();
            let progress = std::io::stderr().is_terminal();
            let st = b_study::b_study(&family, &m, &lengths, generate, progress)?;
            print!("{}", st.table());
            if let Some(p) = &plot {
                st.plot(p).map_err(Failure::Output)?;
                eprintln!("wrote {}", p.display());
            }
            if let Some(p) = &json {
                write(
                    p,
                    &serde_json::to_string_pretty(&st).expect("study serialises"),
                )?;
            }
            Ok(0)
        }
        Command::Loadmap {
            schedule,
            step,
            model,
            output,
        } => {
            let s = Schedule::load(&schedule)?;
            let opts = Options {
                model,
                base_dir: schedule.parent().map(Path::to_path_buf),
                ..Default::default()
            };
            let path = certify::model_path(&s, &opts).ok_or_else(|| {
                InputError::new("no model: pass --model FILE or name one in the schedule")
                    .in_file(&schedule)
            })?;
            let m = reconfcheck::mechanics::Model::load(&path)?;
            let summary = reconfcheck::study::loadmap::render_step(&s, &m, step, &output).map_err(
                |e| match e {
                    reconfcheck::study::loadmap::Error::Input(e) => {
                        Failure::Input(e.in_file(&schedule))
                    }
                    reconfcheck::study::loadmap::Error::Output(e) => Failure::Output(e),
                },
            )?;
            println!("{summary}");
            Ok(0)
        }
        Command::Plot {
            scenarios,
            output,
            title,
        } => {
            let mut curves = Vec::new();
            for p in &scenarios {
                let sc = Scenario::load(p)?;
                let s = algorithms::generate(&sc)?;
                let v = algorithms::scaffold::plot::placed_per_step(&s);
                eprintln!(
                    "{}: {} modules placed in {} steps",
                    sc.name,
                    v.iter().sum::<usize>(),
                    v.len()
                );
                curves.push((sc.name.clone(), v));
            }
            algorithms::scaffold::plot::draw(&curves, &title, &output).map_err(Failure::Output)?;
            Ok(0)
        }
        Command::Algorithms => {
            for g in algorithms::registry() {
                println!("{:<20} {}", g.name(), g.about());
            }
            Ok(0)
        }
    }
}

fn certify_and_report(s: &Schedule, origin: &Path, args: &ReportArgs) -> Result<u8, Failure> {
    let opts = Options {
        name: origin.display().to_string(),
        progress: !args.no_progress && std::io::stderr().is_terminal(),
        exact: args.exact,
        epsilon: args.epsilon,
        lattice_only: args.lattice_only,
        model: args.model.clone(),
        base_dir: origin.parent().map(Path::to_path_buf),
        range_steps: None,
    };
    let report: Report = certify::certify(s, &opts).map_err(|e| e.in_file(origin))?;
    let json = report.to_json();
    if let Some(p) = &args.json {
        write(p, &json)?;
    }
    if args.print_json {
        println!("{json}");
    } else {
        print!("{}", report.summary());
    }
    Ok(if report.certified { 0 } else { EXIT_VIOLATIONS })
}

fn write(path: &Path, text: &str) -> Result<(), Failure> {
    std::fs::write(path, text)
        .map_err(|e| Failure::Output(format!("{}: cannot write: {e}", path.display())))
}
