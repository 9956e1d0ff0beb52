//! The `reconfcheck` command line: parses arguments and dispatches to
//! [`cli`], whose modules turn flags into validated library inputs.
//!
//! Exit codes: 0 certified, 1 violations found, 2 unusable input,
//! 3 an output file could not be written.

mod cli;

use clap::{Parser, Subcommand};
use reconfcheck::error::{Error, write_file};
use std::path::PathBuf;
use std::process::ExitCode;

/// mimalloc rather than the system allocator: a certification allocates
/// per-step arrays that grow with the structure between long-lived small
/// allocations (the report), and glibc's heap kept every outgrown block —
/// one pass over the sandcastle reached 24 GB (cube-d5: 2.3 GB against
/// 0.12 GB with large blocks mapped apart).
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

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

#[derive(Subcommand)]
enum Command {
    /// Certify a schedule file (exit 0 certified, 1 violations, 2 unusable input).
    Certify(cli::schedule::CertifyArgs),
    /// Generate the schedule of a scenario.
    Generate(cli::schedule::GenerateArgs),
    /// Generate and certify a scenario (the bundled default without argument).
    Run(cli::schedule::RunArgs),
    /// List the generators (algorithms) scenarios can name.
    Algorithms,
    /// Plot modules placed per time step (seed 000 Fig. 13–16) for the
    /// schedules of one or more scenarios, as PNG (or SVG).
    #[cfg(feature = "render")]
    Plot(cli::pictures::PlotArgs),
    /// Branch-length study: check every step of a shape family for a range
    /// of b; table on stdout, plot of utilisation and minimum pressure.
    BStudy(cli::b_study::Args),
    /// Draw the connector load map of a schedule's configuration at a step.
    #[cfg(feature = "render")]
    Loadmap(cli::pictures::LoadmapArgs),
    /// Seed 004: SLIDE costs derived by search, and the 2D combing's
    /// parallel steps and atom operations against n (log–log fits).
    CombStudy(cli::comb::Args),
    /// Seed 004: search the stored atom sequences again (the expanded
    /// model's SLIDE, about a minute) and write them to
    /// models/moves/, or check the stored ones (--check).
    DeriveMoves(cli::moves::Args),
    /// Seed 003 §V-B1: active subtraction on random configurations of
    /// several densities; prints a table and draws a box plot.
    DensityStudy(cli::density::Args),
    /// Seed 001: concurrent rotations and streamlines per time step
    /// (Fig. 9) of a RePoSt scenario, with a table per iteration.
    RepostStudy(cli::repost::Args),
    /// Seed 002: messages against modules (Fig. 10), available docking
    /// positions against percent built (Fig. 11) and the naive orders of
    /// Fig. 3, as tables.
    DockingStudy(cli::docking::Args),
    /// Derive the FCC motion rules (cells blocking each of the 120 rotation
    /// links) from the catom geometry and print them as a table.
    Rules {
        /// Also write the rules as JSON to this file.
        #[arg(long, value_name = "FILE")]
        json: Option<PathBuf>,
    },
    /// Read VisibleSim files as schedules: a configuration (config.xml) or
    /// a webots-visiblesim motion trace (CSV).
    #[command(subcommand)]
    Import(cli::interop::ImportCommand),
    /// Write a schedule's configuration at a step in another tool's format.
    #[command(subcommand)]
    Export(cli::interop::ExportCommand),
    /// Draw the catom geometry: the body, one sweep or one collision
    /// (PNG, or SVG if the file name ends in .svg).
    #[cfg(feature = "render")]
    Render(cli::pictures::RenderArgs),
}

fn main() -> ExitCode {
    let command = Cli::parse().command;
    match cli::parallel::run(|| dispatch(command)) {
        Ok(code) => ExitCode::from(code),
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}

fn dispatch(cmd: Command) -> Result<u8, Error> {
    match cmd {
        Command::Certify(a) => cli::schedule::certify(a),
        Command::Generate(a) => cli::schedule::generate(a),
        Command::Run(a) => cli::schedule::run(a),
        Command::Algorithms => {
            for g in reconfcheck::algorithms::registry() {
                println!("{:<20} {}", g.name(), g.about());
            }
            Ok(0)
        }
        #[cfg(feature = "render")]
        Command::Plot(a) => cli::pictures::plot(a),
        Command::BStudy(a) => cli::b_study::run(a),
        #[cfg(feature = "render")]
        Command::Loadmap(a) => cli::pictures::loadmap(a),
        Command::DensityStudy(a) => cli::density::run(a),
        Command::DockingStudy(a) => cli::docking::run(a),
        Command::RepostStudy(a) => cli::repost::run(a),
        Command::CombStudy(a) => cli::comb::run(a),
        Command::DeriveMoves(a) => cli::moves::run(a),
        Command::Rules { json } => {
            let t = reconfcheck::geometry::table();
            print!("{}", t.to_text());
            if let Some(p) = json {
                write_file(&p, t.to_json())?;
            }
            Ok(0)
        }
        Command::Import(a) => cli::interop::import(a),
        Command::Export(a) => cli::interop::export(a),
        #[cfg(feature = "render")]
        Command::Render(a) => cli::pictures::render(a),
    }
}
