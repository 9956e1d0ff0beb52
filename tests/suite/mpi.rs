//! Certification and the b-study split over MPI processes give the report
//! of one process, byte for byte (built with the `mpi` feature; Open MPI's
//! `mpirun` on localhost). Without the feature, an MPI launch is refused
//! with a clear message instead of every process doing all the work.

use crate::common;

use std::path::PathBuf;
use std::process::{Command, Output};

fn bin() -> &'static str {
    env!("CARGO_BIN_EXE_reconfcheck")
}

#[cfg_attr(not(feature = "mpi"), allow(dead_code))]
fn scratch(name: &str) -> PathBuf {
    common::scratch("mpi", name)
}

#[cfg(feature = "mpi")]
fn mpirun(n: usize, args: &[&str]) -> Output {
    Command::new("mpirun")
        .args([
            "--allow-run-as-root",
            "--oversubscribe",
            "-n",
            &n.to_string(),
            bin(),
        ])
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("mpirun (Open MPI) is installed: .ci/setup installs it")
}

#[cfg_attr(not(feature = "mpi"), allow(dead_code))]
fn alone(args: &[&str]) -> Output {
    Command::new(bin())
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap()
}

/// Runs `args(one)` alone and `args(many)` on `n` processes: both exit
/// with `code`, print the same, and write the same bytes, which contain
/// `marker` (the work was done).
#[cfg(feature = "mpi")]
fn alone_and_on(
    n: usize,
    args: impl Fn(&PathBuf) -> Vec<String>,
    (one, many): (PathBuf, PathBuf),
    code: i32,
    marker: &str,
) {
    let (a1, an) = (args(&one), args(&many));
    let a = alone(&a1.iter().map(String::as_str).collect::<Vec<_>>());
    let b = mpirun(n, &an.iter().map(String::as_str).collect::<Vec<_>>());
    for o in [&a, &b] {
        assert_eq!(
            o.status.code(),
            Some(code),
            "{}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
    let written = std::fs::read(&one).unwrap();
    assert!(
        String::from_utf8_lossy(&written).contains(marker),
        "{marker}"
    );
    assert!(
        written == std::fs::read(&many).unwrap(),
        "the outputs differ"
    );
    assert_eq!(a.stdout, b.stdout, "one summary, printed by rank 0 only");
}

#[cfg(feature = "mpi")]
#[test]
fn two_processes_certify_to_the_same_report_as_one() {
    let run = |out: &PathBuf| {
        vec![
            "run".to_string(),
            "--no-progress".into(),
            format!("--json={}", out.display()),
        ]
    };
    let files = (scratch("one.json"), scratch("two.json"));
    alone_and_on(2, run, files, 0, "max_utilisation");
}

#[cfg(feature = "mpi")]
#[test]
fn two_processes_certify_a_span_of_steps_to_the_same_report_as_one() {
    // Steps 60-174 of the default scenario: 8 ranges from step 60.
    let run = |out: &PathBuf| {
        vec![
            "run".to_string(),
            "--no-progress".into(),
            "--steps=60-".into(),
            format!("--json={}", out.display()),
        ]
    };
    let files = (scratch("span-one.json"), scratch("span-two.json"));
    alone_and_on(2, run, files, 0, "\"window\"");
}

#[cfg(feature = "mpi")]
#[test]
fn three_processes_certify_an_overloaded_schedule_to_the_same_report_as_one() {
    // The 2-pyramid at b = 9 is overloaded at steps 36-39 and 73-77: its violations
    // travel between ranks (their encoding skips default fields), and its
    // 8 ranges are handed out one by one by rank 0's dispatcher.
    let scenario = scratch("p2b9.toml");
    let model = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("models/catom-3.6mm.toml");
    std::fs::write(
        &scenario,
        format!(
            "name = \"p2b9\"\nalgorithm = \"scaffold\"\nmodel = {:?}\n\n[parameters]\nshape = \"pyramid\"\nh = 2\nb = 9\n",
            model.display().to_string()
        ),
    )
    .unwrap();
    let run = |out: &PathBuf| {
        vec![
            "run".to_string(),
            scenario.display().to_string(),
            "--no-progress".into(),
            format!("--json={}", out.display()),
        ]
    };
    let files = (scratch("p2b9-1.json"), scratch("p2b9-3.json"));
    alone_and_on(3, run, files, 1, "\"overload\"");
}

#[cfg(feature = "mpi")]
#[test]
fn two_processes_study_the_same_branch_lengths_as_one() {
    let args = |p: &PathBuf| {
        vec![
            "b-study".to_string(),
            "--family=pyramid".into(),
            "--size=2".into(),
            "--b-min=4".into(),
            "--b-max=6".into(),
            "--no-progress".into(),
            format!("--json={}", p.display()),
        ]
    };
    let files = (scratch("b1.json"), scratch("b2.json"));
    alone_and_on(2, args, files, 0, "\"rows\"");
}

#[cfg(feature = "mpi")]
#[test]
fn more_processes_than_work_is_refused_not_a_hang() {
    // One short branch: one range of steps and the final structure.
    let b = mpirun(
        3,
        &[
            "b-study",
            "--family=branch",
            "--b-min=1",
            "--b-max=1",
            "--no-progress",
        ],
    );
    assert_eq!(b.status.code(), Some(2));
    let err = String::from_utf8_lossy(&b.stderr);
    assert!(
        err.contains("3 processes for 2 jobs (ranges of steps and final structures)"),
        "{err}"
    );
}

#[cfg(feature = "mpi")]
#[test]
fn three_processes_share_the_ranges_of_one_branch_length() {
    // One b, more processes than b values: the processes share its ranges
    // of steps (the 2-pyramid at b = 9 is overloaded from step 84 on, so
    // limit analyses and critical steps travel between ranks).
    let args = |p: &PathBuf| {
        vec![
            "b-study".to_string(),
            "--family=pyramid".into(),
            "--size=2".into(),
            "--b-min=9".into(),
            "--b-max=9".into(),
            "--no-progress".into(),
            format!("--json={}", p.display()),
        ]
    };
    let files = (scratch("b9-1.json"), scratch("b9-3.json"));
    alone_and_on(3, args, files, 0, "\"limit_analyses\"");
}

#[cfg(not(feature = "mpi"))]
#[test]
fn an_mpi_launch_without_the_feature_is_refused_with_a_clear_message() {
    let o = Command::new(bin())
        .args(["run", "--no-progress"])
        .env("OMPI_COMM_WORLD_SIZE", "2")
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("without the `mpi` feature"), "{err}");
    assert!(o.stdout.is_empty(), "no process does the work");
}
