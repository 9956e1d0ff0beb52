//! Every injected fault kind is caught, with its violation kind and step.

use crate::common::*;
use reconfcheck::certify::ViolationKind::*;
use reconfcheck::lattice::Ground;
use reconfcheck::lattice::{Cell, LatticeKind};
use reconfcheck::schedule::{Event, Length, ModuleSpec, Schedule};

#[test]
fn a_clean_walk_certifies() {
    let mut s = fcc_platform();
    add(&mut s, 100, Cell::new(0, 0, 1));
    step(
        &mut s,
        vec![rot(100, 3, Cell::new(0, 0, 1), Cell::new(1, 0, 1))],
    );
    step(
        &mut s,
        vec![rot(100, 6, Cell::new(1, 0, 1), Cell::new(2, 0, 1))],
    );
    let r = lattice_report(&s);
    assert!(r.certified, "{}", r.summary());
    assert_eq!(r.moves, 2);
}

/// Modules 100 and 101 both rotate into cell (1, 0, 1) at step 1.
fn two_movers_into_one_cell() -> Schedule {
    let mut s = fcc_platform();
    add(&mut s, 100, Cell::new(0, 0, 1));
    add(&mut s, 101, Cell::new(1, 1, 1));
    step(
        &mut s,
        vec![
            rot(100, 3, Cell::new(0, 0, 1), Cell::new(1, 0, 1)),
            rot(101, 4, Cell::new(1, 1, 1), Cell::new(1, 0, 1)),
        ],
    );
    s
}

#[test]
fn two_movers_ending_in_one_cell_are_an_occupancy_violation() {
    let s = two_movers_into_one_cell();
    let r = lattice_report(&s);
    assert!(!r.certified);
    assert_eq!(kinds(&r), vec![(Occupancy, 1)]);
    assert_eq!(r.violations[0].cells, vec![Cell::new(1, 0, 1)]);
    assert_eq!(r.stopped_at, Some(1));
}

/// Module 100 on the platform, its latch to platform module 3 released
/// at step 1.
fn with_a_released_latch() -> Schedule {
    let mut s = fcc_platform();
    add(&mut s, 100, Cell::new(0, 0, 1));
    step(
        &mut s,
        vec![Event::Detach {
            module: 100,
            other: 3,
        }],
    );
    s
}

#[test]
fn a_mover_whose_latch_to_the_pivot_is_released_is_detached() {
    let mut s = with_a_released_latch();
    step(
        &mut s,
        vec![rot(100, 3, Cell::new(0, 0, 1), Cell::new(1, 0, 1))],
    );
    let r = lattice_report(&s);
    assert_eq!(kinds(&r), vec![(MoverDetached, 2)]);
    assert_eq!(r.violations[0].modules, vec![100, 3]);
}

/// [`with_a_released_latch`], latched again at step 2 and moved at 3.
fn relatched_then_moved() -> Schedule {
    let mut s = with_a_released_latch();
    step(
        &mut s,
        vec![Event::Attach {
            module: 100,
            other: 3,
        }],
    );
    step(
        &mut s,
        vec![rot(100, 3, Cell::new(0, 0, 1), Cell::new(1, 0, 1))],
    );
    s
}

/// A window (`certify::window`) cannot start where a latch is released:
/// a schedule's initial configuration latches every touching pair.
#[test]
fn a_window_that_starts_with_a_released_latch_is_refused() {
    let s = relatched_then_moved();
    let e = reconfcheck::certify::window(s.clone(), 1, 2)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("after step 1, 1 pairs of modules are detached"),
        "{e}"
    );
    // Latched again after step 2, and at the start: both windows stand.
    let w = reconfcheck::certify::window(s.clone(), 2, 1).unwrap();
    assert_eq!(kinds(&lattice_report(&w)), vec![]);
    assert!(reconfcheck::certify::window(s, 0, 3).is_ok());
}

/// Certifies steps `span` (`--steps`) with the lattice checks only.
fn span_report(s: &Schedule, span: &str) -> reconfcheck::certify::Report {
    let opts = reconfcheck::certify::Options {
        steps: Some(reconfcheck::certify::StepRequest::parse(span).unwrap()),
        ..reconfcheck::certify::Options::lattice_only()
    };
    reconfcheck::certify::certify(s, &opts).expect("usable input")
}

/// `--steps` starts from the scene the replay reaches, released latches
/// included (a window schedule cannot say so and is refused, above).
#[test]
fn a_span_of_steps_starts_with_the_latches_its_replay_released() {
    let mut s = with_a_released_latch();
    step(
        &mut s,
        vec![rot(100, 3, Cell::new(0, 0, 1), Cell::new(1, 0, 1))],
    );
    let r = span_report(&s, "2");
    assert_eq!(kinds(&r), vec![(MoverDetached, 2)]);
    let steps: Vec<usize> = r.per_step.iter().map(|p| p.step).collect();
    assert_eq!(steps, vec![2]);
    // Latched again before the move: clean, from step 2 on.
    let r = span_report(&relatched_then_moved(), "2-");
    assert!(r.certified, "{}", r.summary());
}

/// A clash in the steps replayed to reach a span stops there, reported:
/// the span's steps would start from no configuration.
#[test]
fn a_span_after_a_clash_reports_it_and_checks_nothing() {
    let mut s = two_movers_into_one_cell();
    step(&mut s, Vec::new());
    let r = span_report(&s, "2");
    assert!(!r.certified);
    assert_eq!(kinds(&r), vec![(Occupancy, 1)]);
    assert_eq!(r.stopped_at, Some(1));
    assert!(r.per_step.is_empty());
    assert!(
        r.summary().contains("checked: lattice (no step)"),
        "{}",
        r.summary()
    );
}

/// The scene a span starts from must stand on its own, as an initial
/// configuration must: the unchecked steps before it cannot vouch for it.
#[test]
fn a_span_starting_from_a_disconnected_scene_says_so() {
    let mut s = a_riders_only_support_lifted();
    step(&mut s, Vec::new());
    let r = span_report(&s, "2");
    let v = r
        .violations
        .iter()
        .find(|v| v.kind == Disconnected)
        .expect("the start of the span is disconnected");
    assert_eq!((v.step, v.modules.as_slice()), (1, [200].as_slice()));
    assert!(
        v.message.contains("after step 1, where --steps starts"),
        "{}",
        v.message
    );
}

/// Module 200 rides on 100 only; 100 rotates away at step 1.
fn a_riders_only_support_lifted() -> Schedule {
    let mut s = fcc_platform();
    add(&mut s, 100, Cell::new(0, 0, 1));
    add(&mut s, 200, Cell::new(1, 1, 2)); // rides on 100 only
    step(
        &mut s,
        vec![rot(100, 0, Cell::new(0, 0, 1), Cell::new(-1, 0, 1))],
    );
    s
}

#[test]
fn lifting_the_only_support_of_a_module_disconnects_it() {
    let s = a_riders_only_support_lifted();
    let r = lattice_report(&s);
    let k = kinds(&r);
    assert!(k.contains(&(Disconnected, 1)), "{k:?}");
    let v = r
        .violations
        .iter()
        .find(|v| v.kind == Disconnected && v.step == 1)
        .unwrap();
    assert_eq!(v.modules, vec![200]);
}

#[test]
fn a_pivot_that_left_the_scene_is_missing() {
    let mut s = fcc_platform();
    s.sinks = vec![Cell::new(2, 2, 1)];
    add(&mut s, 100, Cell::new(1, 2, 1));
    add(&mut s, 101, Cell::new(2, 2, 1));
    step(&mut s, vec![Event::Leave { module: 101 }]);
    step(
        &mut s,
        vec![rot(100, 101, Cell::new(1, 2, 1), Cell::new(1, 1, 1))],
    );
    let r = lattice_report(&s);
    assert_eq!(kinds(&r), vec![(PivotMissing, 2)]);
}

#[test]
fn a_pivot_moving_in_the_same_step_is_reported() {
    let mut s = fcc_platform();
    add(&mut s, 100, Cell::new(0, 0, 1));
    add(&mut s, 101, Cell::new(1, 0, 1));
    step(
        &mut s,
        vec![
            rot(100, 101, Cell::new(0, 0, 1), Cell::new(1, 1, 2)),
            rot(101, 3, Cell::new(1, 0, 1), Cell::new(1, -1, 1)),
        ],
    );
    let r = lattice_report(&s);
    assert_eq!(kinds(&r)[0], (PivotMoving, 1));
    assert_eq!(r.violations[0].modules, vec![100, 101]);
    // Both of 100's supports rolled away: the final configuration leaves it hanging.
    assert_eq!(kinds(&r)[1..], [(Disconnected, 2)]);
}

#[test]
fn a_module_given_two_moves_in_one_step_is_reported() {
    let mut s = fcc_platform();
    add(&mut s, 100, Cell::new(0, 0, 1));
    step(
        &mut s,
        vec![
            rot(100, 3, Cell::new(0, 0, 1), Cell::new(1, 0, 1)),
            rot(100, 0, Cell::new(0, 0, 1), Cell::new(-1, 0, 1)),
        ],
    );
    assert!(kinds(&lattice_report(&s)).contains(&(MultipleMoves, 1)));
}

/// A square-lattice scene: a row of three modules on the ground.
fn square_row() -> Schedule {
    let mut s = Schedule::new(LatticeKind::Square, Length::mm(10.0));
    s.ground = Some(Ground { layer: 1 });
    s.sinks = vec![Cell::xy(0, 1)];
    for (id, x) in [(1, 1), (2, 2), (3, 3)] {
        s.modules.push(ModuleSpec {
            id,
            cell: Cell::xy(x, 1),
            fixed: false,
        });
    }
    s
}

fn slide(module: u32, from: Cell, to: Cell, pivot: Option<u32>) -> Event {
    Event::Slide {
        module,
        from,
        to,
        pivot,
    }
}

#[test]
fn square_modules_slide_along_walls_and_leave_through_the_sink() {
    let mut s = square_row();
    s.modules.push(ModuleSpec {
        id: 4,
        cell: Cell::xy(3, 2),
        fixed: false,
    });
    // 4 slides west along the top of the row, turns the corner, reaches the sink.
    step(
        &mut s,
        vec![slide(4, Cell::xy(3, 2), Cell::xy(2, 2), Some(3))],
    );
    step(
        &mut s,
        vec![slide(4, Cell::xy(2, 2), Cell::xy(1, 2), Some(2))],
    );
    step(
        &mut s,
        vec![
            slide(4, Cell::xy(1, 2), Cell::xy(0, 1), Some(1)),
            Event::Leave { module: 4 },
        ],
    );
    let r = lattice_report(&s);
    assert!(r.certified, "{}", r.summary());
}

#[test]
fn a_slide_with_nothing_beside_the_target_is_detached() {
    let mut s = square_row();
    s.modules.push(ModuleSpec {
        id: 4,
        cell: Cell::xy(3, 2),
        fixed: false,
    });
    // Sliding east off the end of the row: nothing under (4, 2).
    step(
        &mut s,
        vec![slide(4, Cell::xy(3, 2), Cell::xy(4, 2), Some(3))],
    );
    let r = lattice_report(&s);
    assert!(kinds(&r).contains(&(MoverDetached, 1)), "{:?}", kinds(&r));
}

#[test]
fn a_corner_move_through_an_occupied_cell_is_blocked() {
    let scene = |with_blocker: bool| {
        let mut s = square_row();
        s.modules.push(ModuleSpec {
            id: 4,
            cell: Cell::xy(2, 2),
            fixed: false,
        });
        s.modules.push(ModuleSpec {
            id: 5,
            cell: Cell::xy(1, 2),
            fixed: false,
        });
        if with_blocker {
            s.modules.push(ModuleSpec {
                id: 6,
                cell: Cell::xy(1, 3),
                fixed: false,
            });
        }
        // 5 turns the corner of 4: (1,2) → (2,3), sweeping through (1,3).
        step(
            &mut s,
            vec![slide(5, Cell::xy(1, 2), Cell::xy(2, 3), Some(4))],
        );
        lattice_report(&s)
    };
    assert!(scene(false).certified, "{}", scene(false).summary());
    let r = scene(true);
    // 6 also rests on the mover only: lifting 5 leaves it unconnected.
    assert_eq!(kinds(&r), vec![(PassageBlocked, 1), (Disconnected, 1)]);
    assert_eq!(r.violations[0].cells, vec![Cell::xy(1, 3)]);
    assert_eq!(r.violations[0].modules, vec![5, 6]);
}

#[test]
fn leaving_away_from_a_sink_and_entering_away_from_a_source_are_reported() {
    let mut s = square_row();
    s.sources = vec![Cell::xy(4, 1)];
    step(&mut s, vec![Event::Leave { module: 3 }]);
    step(
        &mut s,
        vec![Event::Enter {
            module: 9,
            cell: Cell::xy(2, 2),
        }],
    );
    let r = lattice_report(&s);
    assert_eq!(kinds(&r), vec![(NotASink, 1), (NotASource, 2)]);
}

#[test]
fn a_disconnected_initial_configuration_is_reported() {
    let mut s = square_row();
    s.modules.push(ModuleSpec {
        id: 7,
        cell: Cell::xy(7, 4),
        fixed: false,
    });
    let r = lattice_report(&s);
    // Step 0 is the initial configuration; with no steps, step 1 is the final one.
    assert_eq!(kinds(&r), vec![(Disconnected, 0), (Disconnected, 1)]);
}
