//! Property tests: random valid walks certify clean, and faults injected
//! into them are caught exactly where an independent oracle says.

use crate::common::*;
use proptest::prelude::*;
use reconfcheck::algorithms::random_walk::{WalkParams, walk};
use reconfcheck::certify::ViolationKind;
use reconfcheck::lattice::{Cell, FccLattice, Lattice};
use reconfcheck::schedule::{Event, ModuleSpec, Schedule};
use std::collections::{BTreeSet, HashMap};

fn params() -> impl Strategy<Value = WalkParams> {
    (
        3i32..8,
        3i32..8,
        1usize..12,
        1usize..30,
        0.1f64..1.0,
        any::<u64>(),
    )
        .prop_map(
            |(width, depth, walkers, steps, activity, seed)| WalkParams {
                width,
                depth,
                walkers: walkers.min(((width - 1) * (depth - 1)) as usize),
                steps,
                activity,
                seed,
                geometric: false,
            },
        )
}

/// Cells of every module at the start of each step (index 0 = initial).
fn cells_per_step(s: &Schedule) -> Vec<HashMap<u32, Cell>> {
    let mut now: HashMap<u32, Cell> = s.modules.iter().map(|m| (m.id, m.cell)).collect();
    let mut out = vec![now.clone()];
    for st in &s.steps {
        for e in &st.events {
            if let Event::Rotate { module, to, .. } = e {
                now.insert(*module, *to);
            }
        }
        out.push(now.clone());
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn random_valid_walks_certify_clean(p in params()) {
        let s = walk(&p, &|_, _, _| true);
        let r = lattice_report(&s);
        prop_assert!(r.certified, "{}", r.summary());
        prop_assert_eq!(r.moves, s.move_count());
    }

    /// A rider on top of a walker is disconnected exactly in the steps where
    /// none of its neighbours stays put (computed here independently).
    #[test]
    fn a_rider_is_disconnected_exactly_when_its_supports_all_move(p in params(), pick in any::<prop::sample::Index>()) {
        let mut s = walk(&p, &|_, _, _| true);
        let walkers: Vec<&ModuleSpec> = s.modules.iter().filter(|m| !m.fixed).collect();
        let host = walkers[pick.index(walkers.len())].cell;
        let l = FccLattice;
        let rider_cell = l.neighbour(host, 4); // straight up-and-over, layer 2
        s.modules.push(ModuleSpec { id: 10_000, cell: rider_cell, fixed: false });

        let cells = cells_per_step(&s);
        let mut expected = BTreeSet::new();
        for (k, st) in s.steps.iter().enumerate() {
            let moving: BTreeSet<u32> = st.events.iter().map(Event::module).collect();
            let held = cells[k].iter().any(|(id, c)| {
                *id != 10_000 && !moving.contains(id) && l.are_neighbours(*c, rider_cell)
            });
            if !held {
                expected.insert(k + 1);
            }
        }
        let last = cells.last().unwrap();
        if !last.iter().any(|(id, c)| *id != 10_000 && l.are_neighbours(*c, rider_cell)) {
            expected.insert(s.steps.len() + 1);
        }

        let r = lattice_report(&s);
        let got: BTreeSet<usize> = r.violations_of(ViolationKind::Disconnected)
            .filter(|v| v.modules == vec![10_000])
            .map(|v| v.step)
            .collect();
        prop_assert!(r.violations.iter().all(|v| v.kind == ViolationKind::Disconnected));
        prop_assert_eq!(got, expected);
    }

    /// Any span of steps (`--steps`) of a walk with a rider finds exactly the
    /// whole run's violations inside it, and a disconnected rider at its
    /// start where no neighbour holds it there (computed here
    /// independently, as for the final configuration).
    #[test]
    fn a_span_of_steps_finds_the_whole_runs_violations_inside_it(
        p in params(),
        pick in any::<prop::sample::Index>(),
        a in any::<prop::sample::Index>(),
        b in any::<prop::sample::Index>(),
    ) {
        let mut s = walk(&p, &|_, _, _| true);
        let walkers: Vec<&ModuleSpec> = s.modules.iter().filter(|m| !m.fixed).collect();
        let rider_cell = FccLattice.neighbour(walkers[pick.index(walkers.len())].cell, 4);
        s.modules.push(ModuleSpec { id: 10_000, cell: rider_cell, fixed: false });
        let n = s.steps.len();
        let (first, last) = {
            let (x, y) = (a.index(n) + 1, b.index(n) + 1);
            (x.min(y), x.max(y))
        };
        let whole = lattice_report(&s);
        let opts = reconfcheck::certify::Options {
            steps: Some(reconfcheck::certify::StepRequest { first, last: Some(last) }),
            ..reconfcheck::certify::Options::lattice_only()
        };
        let span = reconfcheck::certify::certify(&s, &opts).unwrap();
        let key = |v: &reconfcheck::certify::Violation| (v.kind, v.step, v.modules.clone());
        let mut expected: Vec<_> = whole.violations.iter()
            .filter(|v| (first..=last).contains(&v.step) || (v.step == n + 1 && last == n))
            .map(key)
            .collect();
        let cells = cells_per_step(&s);
        let held = cells[first - 1].iter()
            .any(|(id, c)| *id != 10_000 && FccLattice.are_neighbours(*c, rider_cell));
        if first > 1 && !held {
            expected.insert(0, (ViolationKind::Disconnected, first - 1, vec![10_000]));
        }
        prop_assert_eq!(span.violations.iter().map(key).collect::<Vec<_>>(), expected);
        prop_assert_eq!(span.per_step.len(), last - first + 1);
        prop_assert_eq!(span.certified, span.violations.is_empty());
    }

    /// Releasing the latch between a mover and its pivot one step before the
    /// move is caught as a detached mover at that move.
    #[test]
    fn a_released_latch_is_caught_at_the_next_move(p in params(), pick in any::<prop::sample::Index>()) {
        let mut s = walk(&p, &|_, _, _| true);
        let moves: Vec<(usize, u32, u32)> = s.steps.iter().enumerate().skip(1)
            .flat_map(|(k, st)| st.events.iter().filter_map(move |e| match e {
                Event::Rotate { module, pivot, .. } => Some((k, *module, *pivot)),
                _ => None,
            }))
            .collect();
        prop_assume!(!moves.is_empty());
        let (k, module, pivot) = moves[pick.index(moves.len())];
        s.steps[k - 1].events.push(Event::Detach { module, other: pivot });
        let r = lattice_report(&s);
        prop_assert!(!r.certified);
        let first = &r.violations[0];
        prop_assert_eq!(first.kind, ViolationKind::MoverDetached);
        prop_assert_eq!(first.step, k + 1);
        prop_assert_eq!(&first.modules, &vec![module, pivot]);
    }
}
