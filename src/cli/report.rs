//! Certification and its report, shared by `certify` and `run`: the raw
//! flags, the validated options built from them, and the output.

use reconfcheck::certify::{self, Options};
use reconfcheck::error::{Error, InputError, write_file};
use reconfcheck::geometry::Tolerance;
use reconfcheck::schedule::Schedule;
use std::path::{Path, PathBuf};

/// Exit code of a schedule with violations.
pub const EXIT_VIOLATIONS: u8 = 1;

/// The flags of a certification, as typed.
#[derive(clap::Args, Clone)]
pub struct ReportArgs {
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
    /// Collision tolerance, in units of the lattice spacing d, in (0, 0.1].
    #[arg(long, default_value_t = reconfcheck::geometry::EPSILON)]
    epsilon: f64,
    /// Run the lattice checks only (occupancy, pivots, connectivity).
    #[arg(long)]
    lattice_only: bool,
    /// Certify a meta-module schedule (seed 004) at the meta-module level:
    /// the paper's SLIDE and k-TUNNEL preconditions, latches,
    /// connectivity and the in-place bound, without expanding it into
    /// atom operations (for moves with no derived atom sequence).
    #[arg(long)]
    meta_level: bool,
    /// Physical model (TOML, see models/) for the gravity and connector-load
    /// check; overrides the schedule's own `model`.
    #[arg(long, value_name = "FILE")]
    model: Option<PathBuf>,
    /// Also write the report as JUnit XML (one test case per check and
    /// step), for CI systems.
    #[arg(long, value_name = "FILE")]
    junit: Option<PathBuf>,
    /// Compare with an earlier JSON report of the same schedule: exit 1
    /// only for violations it did not have or for a utilisation that rose
    /// by more than --baseline-tolerance; fixed ones are listed.
    #[arg(long, value_name = "OLD.json")]
    baseline: Option<PathBuf>,
    /// The rise in utilisation (a fraction of capacity) a baseline
    /// comparison still accepts.
    #[arg(long, default_value_t = 1e-3, requires = "baseline")]
    baseline_tolerance: f64,
    /// Also write a self-contained HTML page: summary, tables, curves and
    /// a 3D replay of the schedule with its findings (no network needed).
    #[arg(long, value_name = "REPORT.html")]
    html: Option<std::path::PathBuf>,
    /// Let each step's reported limit-analysis load factor exceed the exact
    /// one by this fraction of itself, in [0, 0.5): poses whose factor is
    /// bounded from a solved neighbour are not solved. Verdicts stay exact.
    /// 0 is exact.
    #[arg(long, default_value_t = 0.0, value_name = "FRACTION")]
    load_factor_tolerance: f64,
    /// Steps per range of the mechanics, which ranges run in parallel
    /// (default: about 64 ranges of at least 16 steps). Shorter ranges
    /// spread a run of costly steps over more threads; each range starts
    /// its elastic solves afresh, so figures may differ from the default's
    /// in their last digits, never with the thread count.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
    range_steps: Option<u32>,
    /// Check only steps FIRST to LAST (numbered as in the report; `FIRST-`
    /// runs to the end, one number is one step). The steps before FIRST
    /// are replayed without checks, and the report keeps the schedule's
    /// step numbers: a minute for a window of a long schedule whose
    /// every step takes a quarter of an hour.
    #[arg(long, value_name = "FIRST-LAST", value_parser = certify::StepRequest::parse)]
    steps: Option<certify::StepRequest>,
}

impl ReportArgs {
    /// The validated options of certifying the schedule read from `origin`:
    /// every number checked before any library code runs.
    pub fn options(&self, origin: &Path) -> Result<Options, Error> {
        let epsilon =
            Tolerance::new(self.epsilon).map_err(|e| InputError::new(format!("--epsilon: {e}")))?;
        let t = load_factor_tolerance(self.load_factor_tolerance)?;
        Ok(Options {
            name: origin.display().to_string(),
            progress: super::progress::reporter(
                !self.no_progress && super::parallel::is_root(),
                50,
            ),
            exact: self.exact,
            epsilon,
            lattice_only: self.lattice_only,
            model: self.model.clone(),
            base_dir: origin.parent().map(Path::to_path_buf),
            range_steps: self.range_steps.map(|n| n as usize),
            range_done: std::env::var_os("RECONFCHECK_RANGE_TIMES")
                .is_some()
                .then_some(print_range_time),
            load_factor_tolerance: t,
            meta_level: self.meta_level,
            steps: self.steps,
        })
    }
}

/// `--load-factor-tolerance`, checked: a fraction in [0, 0.5) (NaN is
/// refused, not read as exact).
pub fn load_factor_tolerance(t: f64) -> Result<f64, InputError> {
    if (0.0..0.5).contains(&t) {
        Ok(t)
    } else {
        Err(InputError::new(format!(
            "--load-factor-tolerance: {t} is not a fraction in [0, 0.5)"
        )))
    }
}

/// `RECONFCHECK_RANGE_TIMES`: one line per range of steps on standard
/// error, with the process id (ranges of an MPI run come from many).
fn print_range_time(r: &certify::RangeDone) {
    eprintln!(
        "range {}: steps {}–{}, {:.3} s (pid {})",
        r.index,
        r.steps.0,
        r.steps.1,
        r.seconds,
        std::process::id()
    );
}

/// Certifies `s` (read from, or generated by, `origin`), writes and prints
/// the report; the exit code says whether it was certified.
pub fn certify_and_report(s: &Schedule, origin: &Path, args: &ReportArgs) -> Result<u8, Error> {
    let opts = args.options(origin)?;
    if let Some(p) = &args.html {
        super::output::check_output("--html", p)?;
    }
    let tolerance = reconfcheck::number::within(args.baseline_tolerance, 0.0, f64::MAX, "≥ 0")
        .map_err(|e| InputError::new(format!("--baseline-tolerance: {e}")))?;
    let report = certify::certify_by(s, &opts, super::parallel::runner().as_ref())
        .map_err(|e| e.in_file(origin))?;
    if !super::parallel::is_root() {
        // Another process gathered this one's part and writes the report.
        return Ok(0);
    }
    // Read the baseline before writing anything: an unusable one is the
    // input's error, and no half set of outputs is left behind.
    let baseline = match &args.baseline {
        Some(p) => Some(certify::load_baseline(
            p,
            &report,
            &origin.display().to_string(),
        )?),
        None => None,
    };
    let json = report.to_json();
    if let Some(p) = &args.json {
        write_file(p, &json)?;
    }
    if let Some(p) = &args.junit {
        write_file(p, certify::to_junit(&report))?;
    }
    if let Some(p) = &args.html {
        super::html::write_report(p, s, origin, &report, &opts)?;
    }
    if args.print_json {
        println!("{json}");
    } else {
        print!("{}", report.summary());
    }
    match baseline {
        Some(old) => {
            let c = certify::compare_with_baseline(&report, &old, tolerance);
            if !args.print_json {
                print!("{}", c.summary());
            }
            Ok(if c.regressed() { EXIT_VIOLATIONS } else { 0 })
        }
        None => Ok(if report.certified { 0 } else { EXIT_VIOLATIONS }),
    }
}
