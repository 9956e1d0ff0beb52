//! `certify`, `generate` and `run`: schedules read, generated, certified.

use super::report::{ReportArgs, certify_and_report};
use reconfcheck::algorithms;
use reconfcheck::error::{Error, write_file};
use reconfcheck::scenario::Scenario;
use reconfcheck::schedule::Schedule;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct CertifyArgs {
    schedule: PathBuf,
    #[command(flatten)]
    report: ReportArgs,
}

#[derive(clap::Args)]
pub struct GenerateArgs {
    scenario: PathBuf,
    /// Where to write the schedule (JSON).
    #[arg(short, long)]
    output: PathBuf,
}

#[derive(clap::Args)]
pub struct RunArgs {
    scenario: Option<PathBuf>,
    /// Also write the generated schedule to this file.
    #[arg(short, long)]
    output: Option<PathBuf>,
    #[command(flatten)]
    report: ReportArgs,
}

pub fn certify(a: CertifyArgs) -> Result<u8, Error> {
    let s = Schedule::load(&a.schedule)?;
    certify_and_report(&s, &a.schedule, &a.report)
}

pub fn generate(a: GenerateArgs) -> Result<u8, Error> {
    let sc = Scenario::load(&a.scenario)?;
    let s = algorithms::generate(&sc)?;
    save(&sc, s.clone(), &a.output)?;
    eprintln!(
        "wrote {} ({} modules, {} steps, {} moves)",
        a.output.display(),
        s.modules.len(),
        s.steps.len(),
        s.move_count()
    );
    Ok(0)
}

pub fn run(a: RunArgs) -> Result<u8, Error> {
    let path = a.scenario.unwrap_or_else(Scenario::default_path);
    let sc = Scenario::load(&path)?;
    if super::parallel::is_root() {
        eprintln!("scenario {}: {}", sc.name, sc.description);
    }
    let s = algorithms::generate(&sc)?;
    if let Some(out) = &a.output {
        save(&sc, s.clone(), out)?;
    }
    certify_and_report(&s, &path, &a.report)
}

/// Writes a generated schedule to `out`, its model path made relative to
/// where the schedule is written.
fn save(sc: &Scenario, mut s: Schedule, out: &std::path::Path) -> Result<(), Error> {
    s.model = s.model.map(|m| sc.path_from(&m, out));
    write_file(out, s.to_json())
}
