//! Motion rules derived from the body geometry (SPEC §4.4).
//!
//! For each of the 120 rotation links of a pivot, an exact sweep
//! ([`super::sweep::sweep_pair`]) against a single catom at rest in every
//! cell within reach says whether a module there would be penetrated
//! (a *blocking* cell), touched within ±ε away from the latched ends
//! (a *sliding* cell), or left clear. Collisions between a mover and static
//! modules are pairwise, so the table answers any neighbourhood: a move is
//! collision-free against static modules iff none of its blocking cells is
//! occupied. The table is derived once per process ([`table`]) and is the
//! fast path of certification; `certify --exact` bypasses it.
//!
//! Cells are stored as lattice offsets from the pivot ([`Offset`]), which
//! are the same on even and odd layers.

use super::catom::catom;
use super::rolling::{Link, Roll, links};
use super::sweep::{PairOutcome, Path, Sample, sweep_pair};
use super::{ContactKind, MotionRules, Tolerance};
use crate::lattice::{Cell, FccLattice, Lattice, Motion};
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::sync::OnceLock;

/// A lattice vector: centre offset `(x2/2, y2/2, z/√2)` in units of d.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct Offset {
    pub x2: i32,
    pub y2: i32,
    pub z: i32,
}

impl Offset {
    /// The offset from cell `a` to cell `b`.
    pub fn between(a: Cell, b: Cell) -> Offset {
        let (pa, pb) = (a.z.rem_euclid(2), b.z.rem_euclid(2));
        Offset {
            x2: 2 * (b.x - a.x) + pb - pa,
            y2: 2 * (b.y - a.y) + pb - pa,
            z: b.z - a.z,
        }
    }

    /// The cell at this offset from `a`.
    pub fn from(self, a: Cell) -> Cell {
        let z = a.z + self.z;
        let (pa, pz) = (a.z.rem_euclid(2), z.rem_euclid(2));
        Cell::new(
            (2 * a.x + pa + self.x2 - pz) / 2,
            (2 * a.y + pa + self.y2 - pz) / 2,
            z,
        )
    }

    /// The centre offset in units of d.
    pub fn vector(self) -> DVec3 {
        DVec3::new(
            0.5 * self.x2 as f64,
            0.5 * self.y2 as f64,
            self.z as f64 / std::f64::consts::SQRT_2,
        )
    }
}

/// Every lattice offset (other than 0) whose catom a rolling mover could
/// touch: centre within `reach + 2·R_B` of the pivot (≈ 2.13 d; the next
/// shell is at √5 d). 54 offsets.
pub fn offsets_within_reach() -> &'static [Offset] {
    static OFFSETS: OnceLock<Vec<Offset>> = OnceLock::new();
    OFFSETS.get_or_init(|| {
        let reach = links()
            .iter()
            .map(|l| Roll::new(DVec3::ZERO, *l).reach())
            .fold(0.0, f64::max)
            + 2.0 * catom().radius();
        let l = FccLattice;
        let o = Cell::new(0, 0, 0);
        let mut v = Vec::new();
        for x in -4..=4 {
            for y in -4..=4 {
                for z in -4..=4 {
                    let c = Cell::new(x, y, z);
                    if c != o && l.centre(c).length() <= reach {
                        v.push(Offset::between(o, c));
                    }
                }
            }
        }
        v.sort();
        v
    })
}

/// What a catom at one offset does to one link's sweep.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RuleEntry {
    pub offset: Offset,
    pub kind: ContactKind,
    /// Sweep parameter of the deepest penetration (collision) or of the
    /// first sliding contact.
    pub s: f64,
    /// Penetration depth in units of d (0 for sliding contact).
    pub depth: f64,
    /// Witness points relative to the pivot centre.
    pub witness_mover: DVec3,
    pub witness_other: DVec3,
    /// Contact normal (mover → obstacle) at `s`.
    pub normal: DVec3,
}

/// The derived rules of one link.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct LinkRules {
    pub link: Link,
    /// Every offset whose occupant is penetrated or touched, sorted by
    /// offset. Includes the target cell (a module there is penetrated).
    pub entries: Vec<RuleEntry>,
    /// Pairs of sliding cells that touch the mover from opposite sides
    /// (contact normals anti-parallel): together they pinch it at zero
    /// clearance, so a move needs at least one of them empty.
    pub pinches: Vec<(Offset, Offset)>,
}

impl LinkRules {
    /// Offsets whose occupant the sweep penetrates (including the target).
    pub fn blocking(&self) -> impl Iterator<Item = Offset> + '_ {
        self.entries
            .iter()
            .filter(|e| e.kind == ContactKind::Collision)
            .map(|e| e.offset)
    }
}

/// Cosine above which two sliding contacts' normals count as opposite.
const PINCH_COSINE: f64 = 0.99;

/// The compiled rule table of all 120 links.
pub struct RuleTable {
    pub links: Vec<LinkRules>,
    /// The tolerance the table was derived with: it answers for sweeps at
    /// this ε only.
    tolerance: Tolerance,
    /// Index of `links` by (from, to, route).
    index: [[[u8; 2]; 12]; 12],
}

impl RuleTable {
    /// Derives the table by exact sweeps against a single obstacle in each
    /// cell within reach, with tolerance `eps`.
    pub fn derive(tolerance: Tolerance) -> RuleTable {
        let eps = tolerance.get();
        let offsets = offsets_within_reach();
        let all = links();
        // Plain scoped threads, not rayon: the table is built inside a
        // OnceLock that rayon workers may be blocked on (a rayon pool
        // would deadlock waiting for them).
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
        let chunk = all.len().div_ceil(threads);
        let derive_link = |link: Link| {
            let roll = Roll::new(DVec3::ZERO, link);
            let from = Offset::between(
                Cell::new(0, 0, 0),
                FccLattice.neighbour(Cell::new(0, 0, 0), link.from as usize),
            );
            let mut halves: Vec<(Offset, [Option<Sample>; 2])> = Vec::new();
            let entries = offsets
                .iter()
                .filter(|o| **o != from)
                .filter_map(|&offset| {
                    let sw = sweep_pair(&roll, &Path::Static(offset.vector()), eps);
                    let (kind, x) = match sw.outcome {
                        PairOutcome::Clear => return None,
                        PairOutcome::Sliding(x) => (ContactKind::SlidingContact, x),
                        PairOutcome::Collision(x) => (ContactKind::Collision, x),
                    };
                    if kind == ContactKind::SlidingContact {
                        halves.push((offset, sw.sliding));
                    }
                    Some(RuleEntry {
                        offset,
                        kind,
                        s: x.s,
                        depth: if kind == ContactKind::Collision {
                            -x.gap.dist
                        } else {
                            0.0
                        },
                        witness_mover: x.gap.p1,
                        witness_other: x.gap.p2,
                        normal: x.gap.normal,
                    })
                })
                .collect::<Vec<_>>();
            let mut pinches = Vec::new();
            for (i, (a, ha)) in halves.iter().enumerate() {
                for (b, hb) in &halves[i + 1..] {
                    let opposite = ha.iter().zip(hb).any(|(x, y)| match (x, y) {
                        (Some(x), Some(y)) => x.gap.normal.dot(y.gap.normal) < -PINCH_COSINE,
                        _ => false,
                    });
                    if opposite {
                        pinches.push((*a, *b));
                    }
                }
            }
            LinkRules {
                link,
                entries,
                pinches,
            }
        };
        let links: Vec<LinkRules> = std::thread::scope(|scope| {
            let handles: Vec<_> = all
                .chunks(chunk)
                .map(|part| {
                    scope.spawn(|| part.iter().map(|l| derive_link(*l)).collect::<Vec<_>>())
                })
                .collect();
            handles
                .into_iter()
                .flat_map(|h| h.join().expect("rule derivation does not panic"))
                .collect()
        });
        let mut index = [[[u8::MAX; 2]; 12]; 12];
        for (i, r) in links.iter().enumerate() {
            index[r.link.from as usize][r.link.to as usize][r.link.route as usize] = i as u8;
        }
        RuleTable {
            links,
            index,
            tolerance,
        }
    }

    /// The rules of one link.
    pub fn get(&self, link: Link) -> &LinkRules {
        let i = self.index[link.from as usize][link.to as usize][link.route as usize];
        &self.links[i as usize]
    }
}

impl RuleTable {
    /// The table as text: one line per link, cells written relative to a
    /// pivot at cell (0,0,0) (an even layer), the deepest penetration, the
    /// sliding cells and the pinches.
    pub fn to_text(&self) -> String {
        use std::fmt::Write;
        let o = Cell::new(0, 0, 0);
        let mut out = String::new();
        let _ = writeln!(
            out,
            "# Derived motion rules: {} rotation links of a pivot at (0,0,0); connector numbering of lattice::fcc.",
            self.links.len()
        );
        let _ = writeln!(
            out,
            "# blocking: cells whose occupant the sweep penetrates by more than ε (target excluded); max depth in d."
        );
        let _ = writeln!(
            out,
            "# sliding: cells touched within ±ε away from the latched ends; pinch: two sliding cells on opposite sides."
        );
        let _ = writeln!(
            out,
            "{:<12} {:>4} {:>7}  blocking | sliding | pinches",
            "link", "#blk", "depth"
        );
        for r in &self.links {
            let target = Offset::between(o, FccLattice.neighbour(o, r.link.to as usize));
            let blocking: Vec<&RuleEntry> = r
                .entries
                .iter()
                .filter(|e| e.kind == ContactKind::Collision && e.offset != target)
                .collect();
            let depth = blocking.iter().map(|e| e.depth).fold(0.0, f64::max);
            let cells = |es: &mut dyn Iterator<Item = Offset>| {
                es.map(|x| x.from(o).to_string())
                    .collect::<Vec<_>>()
                    .join(" ")
            };
            let sliding = cells(
                &mut r
                    .entries
                    .iter()
                    .filter(|e| e.kind == ContactKind::SlidingContact)
                    .map(|e| e.offset),
            );
            let pinches: Vec<String> = r
                .pinches
                .iter()
                .map(|(a, b)| format!("{}+{}", a.from(o), b.from(o)))
                .collect();
            let _ = writeln!(
                out,
                "{:<12} {:>4} {:>7.4}  {} | {} | {}",
                r.link.to_string(),
                blocking.len(),
                depth,
                cells(&mut blocking.iter().map(|e| e.offset)),
                if sliding.is_empty() {
                    "-".into()
                } else {
                    sliding
                },
                if pinches.is_empty() {
                    "-".into()
                } else {
                    pinches.join(" ")
                },
            );
        }
        out
    }

    /// The table as JSON (`format: "reconfcheck-rules"`).
    /// The tolerance the table was derived with.
    pub fn tolerance(&self) -> Tolerance {
        self.tolerance
    }

    pub fn to_json(&self) -> String {
        let eps = self.tolerance.get();
        let o = Cell::new(0, 0, 0);
        let links: Vec<serde_json::Value> = self
            .links
            .iter()
            .map(|r| {
                let entries: Vec<serde_json::Value> = r
                    .entries
                    .iter()
                    .map(|e| {
                        serde_json::json!({
                            "cell": e.offset.from(o),
                            "offset": e.offset,
                            "kind": e.kind,
                            "s": e.s,
                            "depth": e.depth,
                            "witness_mover": e.witness_mover.to_array(),
                            "witness_other": e.witness_other.to_array(),
                        })
                    })
                    .collect();
                serde_json::json!({
                    "from": r.link.from,
                    "to": r.link.to,
                    "route": r.link.route,
                    "via": r.link.via().map(|v| v.to_array()),
                    "target": FccLattice.neighbour(o, r.link.to as usize),
                    "entries": entries,
                    "pinches": r.pinches.iter().map(|(a, b)| [a.from(o), b.from(o)]).collect::<Vec<_>>(),
                })
            })
            .collect();
        serde_json::to_string_pretty(&serde_json::json!({
            "format": "reconfcheck-rules",
            "version": 1,
            "epsilon": eps,
            "pivot": o,
            "links": links,
        }))
        .expect("rules serialise")
    }
}

/// The table at the default tolerance, derived on first use.
pub fn table() -> &'static RuleTable {
    static TABLE: OnceLock<RuleTable> = OnceLock::new();
    TABLE.get_or_init(|| RuleTable::derive(Tolerance::DEFAULT))
}

/// Cells whose occupant the move's sweep penetrates *or touches* (blocking
/// and sliding cells, the target excluded): what a planner that wants
/// neither collisions nor sliding contact keeps empty. Empty for a motion
/// that is not an FCC rotation.
pub fn touched_cells(motion: &Motion) -> Vec<Cell> {
    let (Some(link), Motion::Rotate { pivot, to, .. }) =
        (Link::of_motion(&FccLattice, motion), motion)
    else {
        return Vec::new();
    };
    table()
        .get(link)
        .entries
        .iter()
        .map(|e| e.offset.from(*pivot))
        .filter(|c| c != to)
        .collect()
}

/// [`MotionRules`] of the FCC lattice from the derived table.
pub struct FccRules;

impl MotionRules for FccRules {
    fn touched_cells(&self, motion: &Motion) -> Vec<Cell> {
        touched_cells(motion)
    }

    fn concurrent_clear(&self, a: &Motion, b: &Motion) -> bool {
        super::fcc_sweep::rotations_clear(a, b)
    }

    fn blocking_cells(&self, motion: &Motion) -> Vec<Cell> {
        let Some(link) = Link::of_motion(&FccLattice, motion) else {
            return Vec::new();
        };
        let Motion::Rotate { pivot, to, .. } = motion else {
            return Vec::new();
        };
        table()
            .get(link)
            .blocking()
            .map(|o| o.from(*pivot))
            .filter(|c| c != to)
            .collect()
    }

    /// No blocking cell occupied, and no pinch (two sliding contacts from
    /// opposite sides) fully occupied.
    fn allows(&self, motion: &Motion, occupied: &dyn Fn(Cell) -> bool) -> bool {
        let Some(link) = Link::of_motion(&FccLattice, motion) else {
            return true;
        };
        let Motion::Rotate { pivot, to, .. } = motion else {
            return true;
        };
        let rules = table().get(link);
        let blocked = rules
            .blocking()
            .any(|o| o.from(*pivot) != *to && occupied(o.from(*pivot)));
        let pinched = rules
            .pinches
            .iter()
            .any(|(a, b)| occupied(a.from(*pivot)) && occupied(b.from(*pivot)));
        !blocked && !pinched
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lattice::Route;

    #[test]
    fn offsets_round_trip_on_both_parities() {
        let l = FccLattice;
        for p in [
            Cell::new(0, 0, 0),
            Cell::new(3, -2, 1),
            Cell::new(-1, 4, -3),
        ] {
            for o in offsets_within_reach() {
                let c = o.from(p);
                assert_eq!(Offset::between(p, c), *o);
                assert!((l.centre(c) - l.centre(p) - o.vector()).length() < 1e-12);
            }
        }
        // The shells at 1, √2, √3 and 2 d: 12 + 6 + 24 + 12 cells.
        assert_eq!(offsets_within_reach().len(), 54);
    }

    #[test]
    fn every_link_blocks_its_target_and_the_corner_it_cuts() {
        let t = table();
        assert_eq!(t.links.len(), 120);
        let o = Cell::new(0, 0, 0);
        for r in &t.links {
            let target = Offset::between(o, FccLattice.neighbour(o, r.link.to as usize));
            assert!(r.blocking().any(|b| b == target), "{}", r.link);
            // The cell beyond the rolling axis, adjacent to pivot, start
            // and target, is deeply penetrated on every route through it.
            let via = r.link.via().unwrap();
            let corner = (0..12).find(|&k| {
                crate::lattice::fcc::direction(k).dot(via) > 0.7
                    && k != r.link.from as usize
                    && k != r.link.to as usize
            });
            if let (Some(k), Route::Octagonal, false) =
                (corner, r.link.route, r.link.is_right_angle())
            {
                let c = Offset::between(o, FccLattice.neighbour(o, k));
                assert!(r.blocking().any(|b| b == c), "{}", r.link);
            }
        }
    }

    #[test]
    fn blocking_cells_exclude_pivot_start_and_target() {
        let l = FccLattice;
        for pivot in [Cell::new(2, 2, 0), Cell::new(2, 2, 1)] {
            for link in links() {
                let from = l.neighbour(pivot, link.from as usize);
                let to = l.neighbour(pivot, link.to as usize);
                let m = Motion::Rotate {
                    from,
                    to,
                    pivot,
                    route: link.route,
                };
                let cells = FccRules.blocking_cells(&m);
                assert!(!cells.is_empty());
                assert!(!cells.contains(&pivot) && !cells.contains(&from) && !cells.contains(&to));
                assert!(
                    cells
                        .iter()
                        .all(|c| (l.centre(*c) - l.centre(pivot)).length() < 2.2)
                );
            }
        }
    }

    /// Seed 000's bridging constraint — no entry into, or exit from, a cell
    /// between two opposite modules — follows from the derived table: for
    /// every link and every pair of opposite neighbours of the target (for
    /// entry) or of the start (for exit), other than the pivot and the
    /// mover's own cells, occupying both blocks the move.
    #[test]
    fn bridging_constraint_emerges_from_the_derivation() {
        let l = FccLattice;
        let rules = crate::geometry::motion_rules(crate::lattice::LatticeKind::Fcc).unwrap();
        let mut pairs_checked = 0;
        let mut pinch_only = 0;
        for pivot in [Cell::new(0, 0, 0), Cell::new(1, 0, 1)] {
            for link in links() {
                let from = l.neighbour(pivot, link.from as usize);
                let to = l.neighbour(pivot, link.to as usize);
                let m = Motion::Rotate {
                    from,
                    to,
                    pivot,
                    route: link.route,
                };
                for centre in [to, from] {
                    for k in 0..12 {
                        let (a, b) = (
                            l.neighbour(centre, k),
                            l.neighbour(centre, crate::lattice::fcc::opposite(k)),
                        );
                        if [a, b].iter().any(|c| *c == pivot || *c == from || *c == to) {
                            continue;
                        }
                        pairs_checked += 1;
                        let occupied = |c: Cell| c == a || c == b;
                        assert!(!rules.allows(&m, &occupied), "{} between {a} and {b}", link);
                        let alone = |c: Cell| move |x: Cell| x == c;
                        if rules.allows(&m, &alone(a)) && rules.allows(&m, &alone(b)) {
                            pinch_only += 1;
                        }
                    }
                }
            }
        }
        assert!(pairs_checked > 1000);
        // On hexagonal routes neither module alone blocks: the mover slides
        // flush between them (zero clearance), which the pinch rule forbids.
        assert!(pinch_only > 0);
    }

    #[test]
    fn text_and_json_list_all_120_links() {
        let t = table();
        let text = t.to_text();
        assert_eq!(
            text.lines()
                .filter(|l| l.contains(" hex ") || l.contains(" oct "))
                .count(),
            120
        );
        assert!(text.contains(" 0→1  oct"));
        let v: serde_json::Value = serde_json::from_str(&t.to_json()).unwrap();
        assert_eq!(v["links"].as_array().unwrap().len(), 120);
        let first = &v["links"][0];
        assert!(
            first["entries"]
                .as_array()
                .unwrap()
                .iter()
                .any(|e| e["kind"] == "collision")
        );
    }

    /// The lattice's symmetry maps links of one class onto each other, so
    /// an independent derivation per link must give the same counts within
    /// each class: hexagonal 60°, octagonal 60° and octagonal 90°.
    #[test]
    fn derivation_respects_the_lattice_symmetry() {
        let o = Cell::new(0, 0, 0);
        type Class = Vec<(usize, usize, usize)>;
        let mut classes: std::collections::BTreeMap<(Route, bool), Class> = Default::default();
        for r in &table().links {
            let target = Offset::between(o, FccLattice.neighbour(o, r.link.to as usize));
            let blocking = r.blocking().filter(|b| *b != target).count();
            let sliding = r
                .entries
                .iter()
                .filter(|e| e.kind == ContactKind::SlidingContact)
                .count();
            classes
                .entry((r.link.route, r.link.is_right_angle()))
                .or_default()
                .push((blocking, sliding, r.pinches.len()));
        }
        let expect = [
            ((Route::Hexagonal, false), 48, (6, 3, 2)),
            ((Route::Octagonal, false), 48, (8, 0, 0)),
            ((Route::Octagonal, true), 24, (9, 0, 0)),
        ];
        for (class, n, counts) in expect {
            let v = &classes[&class];
            assert_eq!(v.len(), n, "{class:?}");
            assert!(v.iter().all(|c| *c == counts), "{class:?}: {v:?}");
        }
    }
}
