//! Shared builders for the integration tests.

use reconfcheck::certify::{self, Options, Report, ViolationKind};
use reconfcheck::lattice::Ground;
use reconfcheck::lattice::{Cell, LatticeKind};
use reconfcheck::schedule::{Event, Length, ModuleSpec, Schedule, Step};

/// A fixed 3 × 3 FCC platform in layer 0 (ids `x * 3 + y`) on the ground.
pub fn fcc_platform() -> Schedule {
    let mut s = Schedule::new(LatticeKind::Fcc, Length::mm(3.6));
    s.ground = Some(Ground { layer: 0 });
    for x in 0..3 {
        for y in 0..3 {
            s.modules.push(ModuleSpec {
                id: (x * 3 + y) as u32,
                cell: Cell::new(x, y, 0),
                fixed: true,
            });
        }
    }
    s
}

pub fn add(s: &mut Schedule, id: u32, cell: Cell) {
    s.modules.push(ModuleSpec {
        id,
        cell,
        fixed: false,
    });
}

pub fn step(s: &mut Schedule, events: Vec<Event>) {
    s.steps.push(Step { events });
}

pub fn rot(module: u32, pivot: u32, from: Cell, to: Cell) -> Event {
    Event::Rotate {
        module,
        pivot,
        from,
        to,
        route: reconfcheck::lattice::Route::Octagonal,
    }
}

/// Certifies with the lattice checks only (these tests are about them).
pub fn lattice_report(s: &Schedule) -> Report {
    let opts = Options::lattice_only();
    certify::certify(s, &opts).expect("usable input")
}

pub fn kinds(r: &Report) -> Vec<(ViolationKind, usize)> {
    r.violations.iter().map(|v| (v.kind, v.step)).collect()
}

/// The `reconfcheck` binary of this build.
pub fn bin() -> std::process::Command {
    std::process::Command::new(env!("CARGO_BIN_EXE_reconfcheck"))
}

/// Runs `cmd`, asserts exit 0 (showing both outputs otherwise) and
/// returns its standard output.
pub fn succeeds(cmd: &mut std::process::Command) -> String {
    let o = cmd.output().unwrap();
    let out = String::from_utf8_lossy(&o.stdout).into_owned();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{out}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    out
}

/// A path `name` in a scratch folder of this test process (`tag` keeps
/// test files apart).
pub fn scratch(tag: &str, name: &str) -> std::path::PathBuf {
    scratch_dir(tag).join(name)
}

/// The scratch folder `tag` of this test process, created.
pub fn scratch_dir(tag: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("reconfcheck-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The bundled walk's first step, written to `path`, plus a fixed module
/// 900: at (1, −1, 1), where the first rotation (0,0,1) → (1,0,1) about
/// (1,0,0) cuts it 0.28 d deep, or (`obstacle` false) out of the way at
/// (9, 9, 0), which keeps the module count.
pub fn walk_with_obstacle(path: &std::path::Path, obstacle: bool) {
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/walk-fcc.json"),
    )
    .unwrap();
    let mut s: serde_json::Value = serde_json::from_str(&text).unwrap();
    s["steps"].as_array_mut().unwrap().truncate(1);
    let cell = if obstacle { [1, -1, 1] } else { [9, 9, 0] };
    s["modules"]
        .as_array_mut()
        .unwrap()
        .push(serde_json::json!({"id": 900, "cell": cell, "fixed": true}));
    std::fs::write(path, s.to_string()).unwrap();
}

/// The page of `b-study --family branch --b-min LO --b-max HI --html`,
/// written to `page` (the run must succeed).
pub fn branch_study_page(page: &std::path::Path, lo: usize, hi: usize) {
    let o = bin()
        .args(["b-study", "--family", "branch", "--b-min"])
        .arg(lo.to_string())
        .arg("--b-max")
        .arg(hi.to_string())
        .args(["--no-progress", "--html"])
        .arg(page)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{o:?}");
}

/// Where every module of a schedule of rolling modules ends: the
/// initial cells, then each `enter` and rotation in order (any other
/// event is not expected there).
pub fn final_cells(s: &Schedule) -> std::collections::BTreeMap<u32, Cell> {
    let mut at: std::collections::BTreeMap<u32, Cell> =
        s.modules.iter().map(|m| (m.id, m.cell)).collect();
    for e in s.steps.iter().flat_map(|st| &st.events) {
        match e {
            Event::Enter { module, cell } => {
                at.insert(*module, *cell);
            }
            Event::Rotate { module, to, .. } => {
                at.insert(*module, *to);
            }
            other => panic!("a schedule of rolling modules has no {other:?}"),
        }
    }
    at
}
