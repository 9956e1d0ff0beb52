//! `b-study`: the branch-length study over a range of b.

use super::parallel;
use reconfcheck::error::{Error, InputError, write_file};
use reconfcheck::mechanics::{Bending, Model};
use reconfcheck::number;
use reconfcheck::study::b_study;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
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
    /// Override the model's connector pressure (kPa, positive and finite).
    #[arg(long)]
    pressure: Option<f64>,
    /// Override the model's bending criterion (elastic | rigid-hinge).
    #[arg(long)]
    bending: Option<Bending>,
    /// Write the plot (PNG, or SVG by extension).
    #[cfg(feature = "render")]
    #[arg(long, value_name = "FILE")]
    plot: Option<PathBuf>,
    /// Write the study as JSON.
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
    /// Never show a progress bar.
    #[arg(long)]
    no_progress: bool,
    /// Write the study as a self-contained HTML page (curves and table).
    #[arg(long, value_name = "REPORT.html")]
    html: Option<PathBuf>,
    /// As `certify --load-factor-tolerance`: a failing structure's
    /// limit-analysis factor may read up to this fraction of itself high, in
    /// [0, 0.5); which b are safe stays exact. 0 is exact.
    #[arg(long, default_value_t = 0.0, value_name = "FRACTION")]
    load_factor_tolerance: f64,
    /// Limit-analyse only the steps that could be a row's worst: every
    /// step's elastic screen first, then the steps it could not clear,
    /// highest bound first, until no bound left exceeds the worst proved.
    /// Rows, verdicts and pressures are those of judging every step; only
    /// rank 0 judges the steps (its threads) when run under MPI.
    #[arg(long)]
    worst_only: bool,
    /// As --worst-only, but a row proved to fail is judged no further: the
    /// verdicts and the largest safe b are exact; a failing row's max util
    /// (marked ≥) is a lower bound, and so are its pressures where a step
    /// was left with no finite bound. For a large scaffold's b_max.
    #[arg(long)]
    until_verdict: bool,
}

impl Args {
    fn judging(&self) -> b_study::Judging {
        use b_study::Judging;
        match (self.until_verdict, self.worst_only) {
            (true, _) => Judging::UntilVerdict,
            (false, true) => Judging::WorstOnly,
            (false, false) => Judging::Every,
        }
    }
}

/// `--pressure` in kPa as the model's pressure in Pa: positive and finite
/// before and after the conversion (1e306 kPa overflows to an infinite
/// capacity, which would hold anything).
fn pressure_pa(kpa: f64) -> Result<f64, InputError> {
    number::positive(kpa)
        .and_then(|k| number::positive(k * 1e3))
        .map_err(|e| InputError::new(format!("--pressure (kPa): {e}")))
}

/// `RECONFCHECK_RANGE_TIMES`: one line per job of the study on standard
/// error as it ends, with the process id (where a parallel run's time
/// went).
fn print_job_time(job: usize, found: &Result<Vec<b_study::StepFinding>, InputError>, s: f64) {
    let steps = found
        .as_ref()
        .map_or(String::from("failed"), |f| match (f.first(), f.last()) {
            (Some(a), Some(b)) => format!("steps {}–{}", a.step(), b.step()),
            _ => String::from("no steps"),
        });
    eprintln!(
        "b-study job {job}: {steps}, {s:.3} s (pid {})",
        std::process::id()
    );
}

pub fn run(a: Args) -> Result<u8, Error> {
    let tolerance = super::report::load_factor_tolerance(a.load_factor_tolerance)?;
    let mut m = Model::load(&a.model)?;
    if a.pressure.is_some() || a.bending.is_some() {
        let pressure = match a.pressure {
            Some(kpa) => pressure_pa(kpa)?,
            None => m.connector.pressure,
        };
        m = m.with_connector(pressure, a.bending.unwrap_or(m.connector.bending));
    }
    if let Some(p) = &a.html {
        super::output::check_output("--html", p)?;
    }
    let (lo, hi) = b_study::default_range(&a.family);
    let (b_min, b_max) = (a.b_min.unwrap_or(lo), a.b_max.unwrap_or(hi));
    if b_min == 0 || b_min > b_max {
        return Err(InputError::new(format!("bad range of b: {b_min}..={b_max}")).into());
    }
    let generate = b_study::family(&a.family, m.spacing * 1e3, a.size, a.shape.as_deref())?;
    let lengths: Vec<usize> = (b_min..=b_max).collect();
    let progress = super::progress::reporter(!a.no_progress && parallel::is_root(), 1);
    let times = std::env::var_os("RECONFCHECK_RANGE_TIMES").is_some();
    let judging = a.judging();
    // The ranges of steps of every b are one pool of jobs for this
    // process's threads, or for every process under MPI; rank 0 folds the
    // rows from every part and alone writes.
    let Some((rows, unplanned, first_error)) = b_study::study_rows(
        &m,
        &lengths,
        &generate,
        &progress,
        tolerance,
        judging,
        &|order, job| {
            let timed = |t: usize| {
                let clock = std::time::Instant::now();
                let found = job(t);
                if times {
                    print_job_time(t, &found, clock.elapsed().as_secs_f64());
                }
                found
            };
            parallel::run_jobs(order, &timed, "jobs (ranges of steps and final structures)")
        },
    )?
    else {
        return Ok(0);
    };
    if rows.is_empty() {
        return Err(first_error
            .unwrap_or_else(|| {
                let why = unplanned
                    .first()
                    .map_or("no b given", |u| u.reason.as_str());
                InputError::new(format!("no branch length could be planned: {why}"))
            })
            .into());
    }
    let st = b_study::assemble(&a.family, &m, rows, unplanned, tolerance, judging);
    print!("{}", st.table());
    #[cfg(feature = "render")]
    if let Some(p) = &a.plot {
        reconfcheck::render::b_study_plot(&st, p)?;
        eprintln!("wrote {}", p.display());
    }
    if let Some(p) = &a.html {
        super::html::write_study(p, &st, &generate, &m, progress.clone())?;
    }
    if let Some(p) = &a.json {
        write_file(
            p,
            serde_json::to_string_pretty(&st).expect("study serialises"),
        )?;
    }
    Ok(0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pressure_that_is_not_a_positive_finite_number_of_pascals_is_refused() {
        for kpa in [f64::NAN, f64::INFINITY, 0.0, -5.0, 1e-320, 1e306] {
            let e = pressure_pa(kpa).unwrap_err();
            assert!(e.message.starts_with("--pressure (kPa): "), "{e}");
        }
        assert_eq!(pressure_pa(52.0).unwrap(), 52e3);
    }
}
