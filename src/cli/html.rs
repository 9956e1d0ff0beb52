//! `--html REPORT.html`: the self-contained report page of `certify`, `run`
//! and `b-study` (see `docs/report.md`).

use reconfcheck::certify::{self, Options, Report};
use reconfcheck::error::{Error, InputError, write_file};
use reconfcheck::html::{self, Page};
use reconfcheck::mechanics::Model;
use reconfcheck::progress::Reporter;
use reconfcheck::schedule::Schedule;
use reconfcheck::study::b_study::Study;
use std::path::Path;

/// Writes the page of a certification of `s` (read from `origin`): the
/// replay, the report, and where the mechanics ran the load maps
/// ([`html::load_maps`]: every step where they fit).
pub fn write_report(
    path: &Path,
    s: &Schedule,
    origin: &Path,
    report: &Report,
    opts: &Options,
) -> Result<(), Error> {
    let mut load_maps = Vec::new();
    if report.checks.iter().any(|c| c == "mechanics")
        && let Some(model_path) = certify::model_path(s, opts)
    {
        let model = reconfcheck::mechanics::Model::load(&model_path)?;
        load_maps = html::load_maps(s, &model, report, html::LOAD_MAP_BUDGET)
            .map_err(|e| e.in_file(origin))?;
    }
    let page = Page {
        title: format!("reconfcheck: {}", origin.display()),
        report: Some(report),
        schedule: Some(s),
        load_maps,
        study: None,
        note: None,
    };
    write_file(path, page.html())?;
    eprintln!("wrote {}", path.display());
    Ok(())
}

/// Writes the page of a b-study: its curves and table, and the replay of
/// one b ([`Study::replayed_b`]: the smallest that breaks, else the
/// largest), regenerated and certified again with every check under the
/// study's model — one more b's work, for the picture of the failure.
pub fn write_study(
    path: &Path,
    st: &Study,
    generate: &dyn Fn(usize) -> Result<Schedule, InputError>,
    model: &Model,
    progress: Reporter,
) -> Result<(), Error> {
    // The replayed b: its schedule, report and load maps (the mechanics
    // rescale `model` to the schedule's spacing themselves).
    let mut replayed = None;
    let mut load_maps = Vec::new();
    let mut note = None;
    if let Some((b, why)) = st.replayed_b() {
        let s = generate(b)?;
        let opts = Options {
            name: format!("{} at b = {b}", st.family),
            progress,
            ..Options::default()
        };
        let report = certify::certify_with_model(&s, &opts, model)?;
        load_maps = html::load_maps(&s, model, &report, html::LOAD_MAP_BUDGET)?;
        note = Some(format!(
            "The replay below is b = {b}, {why}: its schedule certified with every check."
        ));
        replayed = Some((s, report));
    }
    let page = Page {
        title: format!("reconfcheck b-study: {}", st.family),
        report: replayed.as_ref().map(|r| &r.1),
        schedule: replayed.as_ref().map(|r| &r.0),
        load_maps,
        study: Some(st),
        note,
    };
    write_file(path, page.html())?;
    eprintln!("wrote {}", path.display());
    Ok(())
}
