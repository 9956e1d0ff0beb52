//! The `reconfcheck` command line: a thin layer over the library.
//!
//! Exit codes: 0 certified, 1 violations found, 2 unusable input,
//! 3 an output file could not be written.

use clap::{Parser, Subcommand};
use reconfcheck::algorithms;
use reconfcheck::certify::{self, Options, Report};
use reconfcheck::error::InputError;
use reconfcheck::scenario::Scenario;
use reconfcheck::schedule::Schedule;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

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
            let s = algorithms::generate(&sc)?;
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
                write(out, &s.to_json())?;
            }
            certify_and_report(&s, &path, &report)
        }
        Command::Plot { scenarios, output, title } => {
            let mut curves = Vec::new();
            for p in &scenarios {
                let sc = Scenario::load(p)?;
                let s = algorithms::generate(&sc)?;
                let v = algorithms::scaffold::plot::placed_per_step(&s);
                eprintln!("{}: {} modules placed in {} steps", sc.name, v.iter().sum::<usize>(), v.len());
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
