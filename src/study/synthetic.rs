//! Synthetic large workloads for the mechanics benchmark: a free FCC block
//! of `w × w × h` modules standing on a fixed sandbox layer, with walkers
//! rolling at random over its top — one large connected structure whose
//! loads change every step (the worst case for reuse between steps).

use crate::lattice::config::{Configuration, Ground, ModuleId};
use crate::lattice::{Cell, FccLattice, Lattice, LatticeKind, Route, fcc};
use crate::schedule::{Event, Length, ModuleSpec, Schedule, Step};
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rustc_hash::FxHashSet;

/// A block of `w × w × h` free catoms on a fixed `w × w` sandbox layer,
/// with `walkers` catoms rolling over the top for `steps` steps.
pub fn block_with_walkers(w: i32, h: i32, walkers: usize, steps: usize, seed: u64) -> Schedule {
    islands_with_walkers(1, w, h, walkers, steps, seed)
}

/// `n × n` separate blocks ("islands") of `w × w × h` free catoms, 3 cells
/// apart, on one fixed sandbox layer, with `walkers` catoms rolling over
/// their tops: many independent structures, few of which change per step.
pub fn islands_with_walkers(
    n: i32,
    w: i32,
    h: i32,
    walkers: usize,
    steps: usize,
    seed: u64,
) -> Schedule {
    let l = FccLattice;
    let mut s = Schedule::new(LatticeKind::Fcc, Length::mm(3.6));
    s.ground = Some(Ground { layer: 0 });
    let mut config = Configuration::new();
    let mut id: ModuleId = 0;
    let pitch = w + 3;
    let span = n * pitch;
    let island = move |x: i32, y: i32| {
        x.rem_euclid(pitch) < w && y.rem_euclid(pitch) < w && x < span && y < span
    };
    for z in 0..=h {
        for x in 0..span {
            for y in 0..span {
                if z > 0 && !island(x, y) {
                    continue;
                }
                let c = Cell::new(x, y, z);
                s.modules.push(ModuleSpec {
                    id,
                    cell: c,
                    fixed: z == 0,
                });
                config.insert(id, c).expect("distinct");
                id += 1;
            }
        }
    }
    let top = h;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut spots: Vec<Cell> = (0..span)
        .flat_map(|x| (0..span).map(move |y| Cell::new(x, y, top + 1)))
        .filter(|c| island(c.x, c.y) && island(c.x + 1, c.y + 1))
        .collect();
    spots.shuffle(&mut rng);
    let mut ws = Vec::new();
    for &c in spots.iter().take(walkers) {
        s.modules.push(ModuleSpec {
            id,
            cell: c,
            fixed: false,
        });
        config.insert(id, c).expect("distinct");
        ws.push(id);
        id += 1;
    }
    let in_top = |c: Cell| c.z == top && island(c.x, c.y) && c.x >= 0 && c.y >= 0;
    for _ in 0..steps {
        ws.shuffle(&mut rng);
        let mut events = Vec::new();
        let mut claimed: FxHashSet<Cell> = FxHashSet::default();
        let mut leaving: FxHashSet<Cell> = FxHashSet::default();
        for &m in &ws {
            if !rng.random_bool(0.5) {
                continue;
            }
            let from = config.cell_of(m).expect("walker");
            let Some((pivot, targets)) = crate::algorithms::random_walk::random_pivot_and_targets(
                &config, from, in_top, &claimed, &leaving, &mut rng,
            ) else {
                continue;
            };
            if let Some(&to) = targets.first() {
                let n_f = (l.centre(from) - l.centre(pivot)).normalize();
                let n_t = (l.centre(to) - l.centre(pivot)).normalize();
                assert!(fcc::rotation_axis(n_f, n_t, Route::Octagonal).is_some());
                let _ = (n_f, n_t);
                events.push(Event::Rotate {
                    module: m,
                    pivot: config.at(pivot).expect("top module"),
                    from,
                    to,
                    route: Route::Octagonal,
                });
                claimed.insert(to);
                leaving.insert(from);
            }
        }
        for e in &events {
            if let Event::Rotate { module, to, .. } = e {
                config.remove(*module);
                config
                    .insert(*module, *to)
                    .expect("claimed targets are distinct");
            }
        }
        events.sort_by_key(Event::module);
        s.steps.push(Step { events });
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::certify::{Options, certify};

    #[test]
    fn the_synthetic_block_schedule_is_lattice_valid() {
        let s = block_with_walkers(5, 2, 4, 10, 1);
        let r = certify(&s, &Options::lattice_only()).unwrap();
        assert!(r.certified, "{}", r.summary());
        assert!(s.move_count() > 0);
        let s = islands_with_walkers(3, 3, 2, 6, 10, 2);
        let r = certify(&s, &Options::lattice_only()).unwrap();
        assert!(r.certified, "{}", r.summary());
    }
}
