//! One self-contained HTML page of a certification or a study: summary,
//! tables and curves, and a 3D replay of the schedule (three.js, inlined
//! from `assets/three/`, so that the page needs no network).
//!
//! The page is data plus a fixed viewer: everything the viewer shows is in
//! one JSON object inlined in the page ([`PageData`]), the schedule as
//! per-step deltas ([`replay::Replay`]). The viewer script is
//! `src/html/viewer.js`; it reads a URL hash `#step=K` (the step shown
//! first) and writes its state into `document.title` and the element
//! `#status` once drawn, which the browser test reads.

pub mod load_maps;
pub mod replay;

use crate::certify::{Report, Severity, Violation};
use crate::lattice::{Cell, LatticeKind};
use crate::schedule::Schedule;
use crate::study::b_study::Study;
use serde::Serialize;

/// three.js r160 (MIT), the pinned minified build from the npm registry.
const THREE_JS: &str = include_str!("../../assets/three/three.min.js");
const THREE_LICENSE: &str = include_str!("../../assets/three/LICENSE");
const VIEWER_JS: &str = include_str!("viewer.js");
const STYLE_CSS: &str = include_str!("style.css");

/// Findings listed one by one in the page; the rest are counted (a
/// sandcastle can warn hundreds of thousands of times).
const MAX_LISTED: usize = 5000;

/// Modules above which the body mesh is drawn coarser, so that a scene of
/// tens of thousands of catoms stays interactive on a software renderer.
const DETAILED_BELOW: usize = 4000;

/// What a page shows; every part is optional.
#[derive(Default)]
pub struct Page<'a> {
    pub title: String,
    pub report: Option<&'a Report>,
    pub schedule: Option<&'a Schedule>,
    /// Load maps of chosen steps (see [`load_map`]).
    pub load_maps: Vec<LoadMap>,
    pub study: Option<&'a Study>,
    /// A line shown above everything else (e.g. which b a study replays).
    pub note: Option<String>,
}

pub use load_maps::{LOAD_MAP_BUDGET, LoadMap, LoadMapData, load_map, load_maps};

/// Everything the viewer reads, inlined as JSON.
#[derive(Serialize)]
pub struct PageData<'a> {
    pub title: &'a str,
    pub generator: String,
    pub summary: Option<Summary>,
    pub violations: Vec<Finding>,
    pub warnings: Vec<Finding>,
    pub warnings_total: usize,
    pub warning_counts: Vec<(String, Severity, usize)>,
    pub violation_counts: Vec<(String, usize)>,
    /// Per metric: its value at each step (`null` where not measured).
    pub metrics: Vec<(String, Vec<Option<f64>>)>,
    pub replay: Option<Scene>,
    /// The load maps, packed (see [`LoadMapData`]); `load_maps_of` says
    /// how many steps have one.
    pub load_maps: Vec<LoadMapData>,
    pub load_maps_of: usize,
    pub study: Option<&'a Study>,
    pub note: Option<&'a str>,
}

/// The report's header and verdict.
#[derive(Serialize)]
pub struct Summary {
    pub certified: bool,
    pub schedule: String,
    pub lattice: String,
    pub modules: usize,
    pub final_modules: usize,
    pub steps: usize,
    pub moves: usize,
    pub checked: Vec<String>,
    pub not_checked: Vec<String>,
    pub stopped_at: Option<usize>,
    /// The steps checked, where only part of the schedule was (`--steps`):
    /// the replay opens at the first.
    pub window: Option<crate::certify::StepSpan>,
}

/// One violation or warning, placed in the scene.
#[derive(Serialize)]
pub struct Finding {
    pub step: usize,
    pub kind: String,
    pub severity: Severity,
    pub message: String,
    pub modules: Vec<u32>,
    /// Centres of the cells it names (units of d).
    pub cells: Vec<[f64; 3]>,
    /// Witness points (collision checks: on the mover and on the other;
    /// a structure that tips: where its weight acts at ground level).
    pub witness: Vec<[f64; 3]>,
}

/// The 3D scene: the body mesh and the replay.
#[derive(Serialize)]
pub struct Scene {
    pub lattice: LatticeKind,
    /// `[positions, normals, indices]` of one body, flattened.
    pub body: (Vec<f32>, Vec<f32>, Vec<u32>),
    /// Whether the body is the catom (else a cube of the lattice spacing).
    pub catom: bool,
    pub ground: Option<f64>,
    pub replay: replay::Replay,
}

fn finding(v: &Violation, lattice: LatticeKind) -> Finding {
    let centre = |c: &Cell| lattice.lattice().centre(*c).to_array();
    let witness = ["witness_mover", "witness_other", "weight_at_ground"]
        .iter()
        .filter_map(|k| v.detail.get(*k))
        .filter_map(|w| serde_json::from_value::<[f64; 3]>(w.clone()).ok())
        .collect();
    Finding {
        step: v.step,
        kind: v.kind.name(),
        severity: v.severity,
        message: v.message.clone(),
        modules: v.modules.clone(),
        cells: v.cells.iter().map(centre).collect(),
        witness,
    }
}

fn scene(s: &Schedule) -> Scene {
    let catom = s.lattice == LatticeKind::Fcc;
    let body = if catom {
        let detail = if s.modules.len() + s.final_module_count() < 2 * DETAILED_BELOW {
            3
        } else {
            2
        };
        let m = crate::geometry::catom().surface_mesh(detail);
        (
            m.positions.concat(),
            m.normals.concat(),
            m.triangles.concat(),
        )
    } else {
        (Vec::new(), Vec::new(), Vec::new())
    };
    let lattice = s.lattice.lattice();
    Scene {
        lattice: s.lattice,
        body,
        catom,
        ground: s
            .ground
            .map(|g| lattice.centre(Cell::new(0, 0, g.layer)).z - 0.5),
        replay: replay::encode(s),
    }
}

impl Page<'_> {
    /// The data the viewer reads.
    pub fn data(&self) -> PageData<'_> {
        let lattice = self
            .schedule
            .map(|s| s.lattice)
            .or(self.report.map(|r| r.lattice))
            .unwrap_or(LatticeKind::Fcc);
        let summary = self.report.map(|r| {
            let (checked, not_checked) = r.coverage();
            Summary {
                certified: r.certified,
                schedule: r.schedule.clone(),
                lattice: r.lattice.name().to_string(),
                modules: r.modules,
                final_modules: r.final_modules,
                steps: r.steps,
                moves: r.moves,
                checked,
                not_checked,
                stopped_at: r.stopped_at,
                window: r.window,
            }
        });
        let (violations, warnings, warnings_total) = match self.report {
            Some(r) => (
                r.violations
                    .iter()
                    .take(MAX_LISTED)
                    .map(|v| finding(v, lattice))
                    .collect(),
                r.warnings
                    .iter()
                    .take(MAX_LISTED)
                    .map(|v| finding(v, lattice))
                    .collect(),
                r.warnings.len(),
            ),
            None => (Vec::new(), Vec::new(), 0),
        };
        let warning_counts = self
            .report
            .map(|r| {
                r.warning_counts()
                    .into_iter()
                    .map(|((k, s), n)| (k.name(), s, n))
                    .collect()
            })
            .unwrap_or_default();
        let violation_counts = self
            .report
            .map(|r| {
                r.violation_counts()
                    .into_iter()
                    .map(|(k, n)| (k.name(), n))
                    .collect()
            })
            .unwrap_or_default();
        let mut metrics: Vec<(String, Vec<Option<f64>>)> = Vec::new();
        if let Some(r) = self.report {
            let mut names: Vec<&String> =
                r.per_step.iter().flat_map(|s| s.metrics.keys()).collect();
            names.sort();
            names.dedup();
            // Indexed by step number (the page reads value i as step i + 1):
            // a report of part of a schedule (`--steps`) starts later.
            let last = r.per_step.iter().map(|s| s.step).max().unwrap_or(0);
            for name in names {
                let mut values = vec![None; last];
                for s in &r.per_step {
                    if let Some(i) = s.step.checked_sub(1) {
                        values[i] = s.metrics.get(name).copied().filter(|v| v.is_finite());
                    }
                }
                metrics.push((name.clone(), values));
            }
        }
        PageData {
            title: &self.title,
            generator: format!("reconfcheck {}", env!("CARGO_PKG_VERSION")),
            summary,
            violations,
            warnings,
            warnings_total,
            warning_counts,
            violation_counts,
            metrics,
            replay: self.schedule.map(scene),
            load_maps: self.load_maps.iter().map(LoadMapData::of).collect(),
            load_maps_of: self.schedule.map_or(0, |s| s.steps.len() + 1),
            study: self.study,
            note: self.note.as_deref(),
        }
    }

    /// The page: one HTML document with three.js, the viewer, the style
    /// and the data inlined; it loads nothing from anywhere.
    pub fn html(&self) -> String {
        let data = serde_json::to_string(&self.data()).expect("page data serialises");
        let mut out = String::with_capacity(data.len() + THREE_JS.len() + 64 * 1024);
        out.push_str("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n");
        out.push_str(
            "<meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'; \
             script-src 'unsafe-inline'; style-src 'unsafe-inline'; img-src data: blob:\">\n",
        );
        out.push_str(&format!("<title>{}</title>\n", escape(&self.title)));
        // Before anything else runs: count console errors and uncaught
        // exceptions, so that the status line reports them.
        out.push_str(
            "<script>window.__errors=[];(function(){const e=console.error;\
             console.error=function(...a){window.__errors.push(a.join(' '));e.apply(console,a);};\
             addEventListener('error',ev=>window.__errors.push(String(ev.message)));})();</script>\n",
        );
        out.push_str("<style>\n");
        out.push_str(STYLE_CSS);
        out.push_str("</style>\n</head>\n<body>\n");
        out.push_str(&format!(
            "<header><h1>{}</h1><div id=\"status\">loading…</div></header>\n<main id=\"app\"></main>\n",
            escape(&self.title)
        ));
        out.push_str("<script type=\"application/json\" id=\"reconfcheck-data\">");
        out.push_str(&json_in_script(&data));
        out.push_str("</script>\n<script>\n/* three.js r160 — ");
        out.push_str(&THREE_LICENSE.replace("*/", "* /"));
        out.push_str(" */\n");
        out.push_str(&script_safe(THREE_JS));
        out.push_str("\n</script>\n<script>\n");
        out.push_str(VIEWER_JS);
        out.push_str("\n</script>\n</body>\n</html>\n");
        out
    }
}

/// Text for an HTML element.
fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// Text that cannot end the `<script>` element it is inlined in.
fn script_safe(s: &str) -> String {
    s.replace("</", "<\\/")
}

/// JSON that cannot end or alter the `<script>` element it is inlined in:
/// every `<` (only ever inside a string) written as `\u003c`, which any
/// JSON parser reads back as `<`.
fn json_in_script(s: &str) -> String {
    s.replace('<', "\\u003c")
}

#[cfg(test)]
mod tests;
