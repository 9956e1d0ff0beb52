//! Surplus modules (seed 000 §4.3.1): No-Surplus, or Continuous Flow.
//!
//! The paper describes two variants and runs its experiments with the
//! first; the scenario chooses (`flow = "no-surplus" | "continuous"`):
//!
//! * **No-Surplus** (default): the sandbox sends exactly the modules the
//!   scaffold needs.
//! * **Continuous Flow** (Thalamy et al. 2019c): modules keep flowing from
//!   the sandbox "to any available path in the structure, even though
//!   they might not be needed", and the finished shape carries a surplus
//!   on its branches. The paper gives the surplus as a formula only
//!   (`E = N_UBranches × b/2 − 2`); where it goes is read from the
//!   authors' implementation (VisibleSim 1aa66fe4, `scaffolding_csg`,
//!   flooding when `NO_FLOODING` is off): a module that reaches a tile
//!   with nothing left to build there is sent on up the tile's outgoing
//!   upward branch that its ingoing branch feeds, *only if that branch is
//!   whole*; otherwise it stays at the tile's entry point. Modules behind
//!   it stop where their way is taken.
//!
//! Modelled here as follows (the choices where the paper is silent):
//! * every sandbox entry point starts a **chain**: up the ground tile's
//!   outgoing branch that its ingoing branch feeds (direction `mirror`,
//!   as [`Scaffold::source_for`] traces it down), through each tile whose
//!   such branch is whole, to the **terminal** entry point of the first
//!   tile whose branch is missing or cut short;
//! * the chain's surplus modules **park** on the route a module takes
//!   from the entry point to the terminal (the planner's own route over
//!   the finished scaffold): the terminal, then, back towards the
//!   sandbox, a cell every second layer ([`PARKING_GAP`]: aiming at one
//!   beside every second module of a branch, the paper's `b/2`, with none
//!   touching another; routes that climb two layers in one rotation skip
//!   layers, so ⌊(b − 1)/2⌋ park per whole branch, measured), leaving the
//!   entry point and the cell after it free ([`PARKING_CLEARANCE`]);
//! * the coordinators regulate the flow by construction needs, so the
//!   scaffold's modules have priority: the surplus is planned after every
//!   scaffold module, into the space and time they leave free. The
//!   scaffold's own schedule is unchanged (tested), and its completion
//!   step is recorded beside the step at which the last surplus module
//!   parks;
//! * parking cells are filled terminal first, round-robin over the
//!   chains, then one gap further back each round; a cell that no route
//!   reaches (a module parked on another chain walls it in) is tried one
//!   cell further back, then given up and counted (`surplus_unreached`).

use super::scaffold::{Dir, Scaffold};
use super::shape::Skew;

/// At least how many skewed layers apart two parked surplus modules of a
/// chain stand: at most one beside every second module of a branch (the
/// paper's `b/2` per branch, which the routes' two-layer rotations bring
/// down to ⌊(b − 1)/2⌋), and never two touching (lattice neighbours are
/// at most one layer apart), so each hangs on the scaffold, not on
/// another.
pub const PARKING_GAP: i32 = 2;

/// Route cells kept free at the sandbox end of a chain: the entry point,
/// where the next module appears, and the cell it rolls to first.
pub const PARKING_CLEARANCE: usize = 2;

/// Whether modules beyond the scaffold's needs flow into the structure.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Default)]
pub enum Flow {
    /// Exactly the modules the scaffold needs.
    #[default]
    NoSurplus,
    /// Modules keep flowing and park on the branches.
    Continuous,
}

impl Flow {
    /// Parses a scenario's `flow` parameter.
    pub fn parse(s: &str) -> Option<Flow> {
        match s {
            "no-surplus" => Some(Flow::NoSurplus),
            "continuous" => Some(Flow::Continuous),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Flow::NoSurplus => "no-surplus",
            Flow::Continuous => "continuous",
        }
    }
}

/// A chain of whole upward branches from a sandbox entry point.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Chain {
    /// The sandbox entry point the chain starts at.
    pub source: Skew,
    /// Tile roots along the chain, the ground tile first.
    pub tiles: Vec<Skew>,
    /// Whole upward branches the chain climbs (`tiles.len() − 1`).
    pub branches: usize,
    /// Entry point of the last tile, where the first surplus module stops.
    pub terminal: Skew,
}

/// The chain of every sandbox entry point of `s`, in the order of the
/// ground tiles and [`Dir::UPWARD`].
pub fn chains(s: &Scaffold) -> Vec<Chain> {
    let b = s.b;
    let mut out = Vec::new();
    for (&g, t) in s.tiles.iter().filter(|(_, t)| t.layer == 0) {
        for d0 in Dir::UPWARD {
            if !t.ingoing_up.contains(&d0) {
                continue;
            }
            let mut tiles = vec![g];
            let (mut tile, mut d) = (g, d0);
            loop {
                let out_dir = d.mirror();
                let whole = s.tiles[&tile]
                    .branches
                    .iter()
                    .any(|&(o, len)| o == out_dir && len as i32 == b - 1);
                let next = tile.offset(out_dir.step().scale(b));
                let fed = s
                    .tiles
                    .get(&next)
                    .is_some_and(|n| n.ingoing_up.contains(&out_dir));
                if !(whole && fed) {
                    break;
                }
                tiles.push(next);
                (tile, d) = (next, out_dir);
            }
            out.push(Chain {
                source: s.source(g, d0),
                branches: tiles.len() - 1,
                terminal: tile.offset(d.epl_offset()),
                tiles,
            });
        }
    }
    out
}

/// Parking cells of a route whose cells lie on skewed layers `layers`
/// (entry point first, terminal last): the terminal, then, walking back,
/// each cell at least [`PARKING_GAP`] layers below the last one parked,
/// keeping the first [`PARKING_CLEARANCE`] cells free.
pub fn parking_indices(layers: &[i32]) -> Vec<usize> {
    let mut out = Vec::new();
    let mut last = i32::MAX;
    for i in (PARKING_CLEARANCE..layers.len()).rev() {
        if last == i32::MAX || layers[i] <= last - PARKING_GAP {
            out.push(i);
            last = layers[i];
        }
    }
    out
}

/// Upward branches of the scaffold's tiles, whole or cut short (the
/// `N_UBranches` of the paper's surplus formula; the sandbox's are not in
/// the shape).
pub fn upward_branches(s: &Scaffold) -> usize {
    s.tiles
        .values()
        .flat_map(|t| &t.branches)
        .filter(|(d, _)| d.is_upward())
        .count()
}

/// The paper's surplus, `E = N_UBranches × b/2 − 2`, as printed.
pub fn paper_surplus(upward_branches: usize, b: u32) -> f64 {
    upward_branches as f64 * b as f64 / 2.0 - 2.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parking_keeps_two_layers_apart_and_the_entry_point_free() {
        assert_eq!(parking_indices(&[-1, 0]), Vec::<usize>::new());
        assert_eq!(parking_indices(&[-1, 0, 1]), vec![2]);
        // A route that climbs two layers in one rotation, then one.
        assert_eq!(parking_indices(&[-1, 0, 2, 3, 4, 6, 7]), vec![6, 4, 2]);
        // Level stretches park once.
        assert_eq!(parking_indices(&[-1, 0, 1, 1, 1, 3, 3]), vec![6, 4]);
    }

    /// Chains are disjoint and climb every whole upward branch once: an
    /// h-pyramid has 4·Σ k² of them (k = 1 … h − 1), each ground tile
    /// starts four chains, and every terminal is a free cell.
    #[test]
    fn an_h_pyramids_chains_climb_each_upward_branch_once_to_a_free_terminal() {
        use crate::algorithms::scaffold::{ShapeSpec, build_scaffold};
        for h in 2..=5u32 {
            let s = build_scaffold(&ShapeSpec::Pyramid { h }, 6).unwrap();
            let c = chains(&s);
            assert_eq!(c.len(), 4 * (h * h) as usize, "h = {h}");
            let whole: usize = (1..h as usize).map(|k| 4 * k * k).sum();
            assert_eq!(
                c.iter().map(|c| c.branches).sum::<usize>(),
                whole,
                "h = {h}"
            );
            assert_eq!(upward_branches(&s), whole, "h = {h}");
            let mut climbed = std::collections::BTreeSet::new();
            for ch in &c {
                assert_eq!(ch.tiles.len(), ch.branches + 1);
                for w in ch.tiles.windows(2) {
                    assert!(climbed.insert((w[0], w[1])), "h = {h}: {w:?} climbed twice");
                }
                let free = !s.index.contains_key(&ch.terminal) && !s.sandbox.contains(&ch.terminal);
                assert!(free, "h = {h}: {:?}", ch.terminal);
            }
        }
    }

    #[test]
    fn flow_names_round_trip() {
        for f in [Flow::NoSurplus, Flow::Continuous] {
            assert_eq!(Flow::parse(f.name()), Some(f));
        }
        assert_eq!(Flow::parse("flood"), None);
    }
}
