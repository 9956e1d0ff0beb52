//! Atom sequences whose search is too long to repeat in every process (the
//! expanded model's SLIDE: about a minute in release; the contracted
//! model's four 1-TUNNELs: up to 720,000 states each, minutes in a debug
//! build), stored under `models/moves/` and **validated by replay whenever
//! they are loaded**: a stored sequence is never taken on trust. Replay
//! uses the search's own step rules ([`super::atom_search::Scene::step`]:
//! kinematics from the frame, exact moving-box collisions, connectivity)
//! and the search's own limits (only the actors act, with the allowed
//! faces; latches only with the latchable atoms); it must end exactly at
//! the goal: for the SLIDE every atom in its own goal cell (the expansion
//! keeps each slider's atoms), for a 1-TUNNEL any of an exchange group's
//! atoms on the group's goal cells, as the search's goal is met.
//! `reconfcheck derive-moves` runs the searches again and writes or checks
//! the files.
//!
//! The file is JSON: what was searched (in words), the search's state
//! count, and the parallel steps, one string per operation:
//! `expand 8 +y`, `contract 10 -x`, `attach 9 10`, `detach 2 8` (atoms
//! numbered as in the scene of the move's problem).

use super::atom_search::{
    Carry, EXPANDED_SLIDE_SEARCH, Found, Legs, Op, Problem, TUNNEL_SEARCH, expanded_slide_problem,
    tunnel_problem,
};
use crate::error::InputError;
use crate::lattice::{AtomRest, Face};
use serde::{Deserialize, Serialize};

/// Where the expanded model's SLIDE is stored (relative to the repository).
pub const EXPANDED_SLIDE_FILE: &str = "models/moves/slide-expanded.json";
const EXPANDED_SLIDE_TEXT: &str = include_str!("../../models/moves/slide-expanded.json");

/// A stored move, as read from its file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StoredMove {
    /// The move (`slide`).
    #[serde(rename = "move")]
    pub name: String,
    pub model: AtomRest,
    /// The scene and search, in words (for the reader; not parsed).
    pub searched: String,
    /// States the search explored to find it.
    pub states_explored: usize,
    /// Parallel steps, one string per operation.
    pub steps: Vec<Vec<String>>,
}

/// One operation as the file writes it.
pub fn op_text(op: Op) -> String {
    match op {
        Op::Expand(a, f) => format!("expand {a} {}", f.name()),
        Op::Contract(a, f) => format!("contract {a} {}", f.name()),
        Op::Attach(a, b) => format!("attach {a} {b}"),
        Op::Detach(a, b) => format!("detach {a} {b}"),
    }
}

/// Reads one operation (`op_text`'s form).
pub fn parse_op(text: &str) -> Result<Op, String> {
    let w: Vec<&str> = text.split_whitespace().collect();
    let atom = |s: &str| {
        s.parse::<usize>()
            .map_err(|_| format!("'{s}' is not an atom number"))
    };
    let face = |s: &str| {
        Face::ALL
            .into_iter()
            .find(|f| f.name() == s)
            .ok_or_else(|| format!("'{s}' is not a face (+x, -x, +y, -y, +z, -z)"))
    };
    match w.as_slice() {
        ["expand", a, f] => Ok(Op::Expand(atom(a)?, face(f)?)),
        ["contract", a, f] => Ok(Op::Contract(atom(a)?, face(f)?)),
        ["attach", a, b] | ["detach", a, b] => {
            let (a, b) = (atom(a)?, atom(b)?);
            if a == b {
                return Err(format!("atom {a} cannot latch to itself"));
            }
            let (a, b) = (a.min(b), a.max(b));
            Ok(if w[0] == "attach" {
                Op::Attach(a, b)
            } else {
                Op::Detach(a, b)
            })
        }
        _ => Err(format!(
            "'{text}' is not an operation (expand A FACE, contract A FACE, attach A B, detach A B)"
        )),
    }
}

impl StoredMove {
    /// Reads a stored move's JSON text (`file` names it in errors).
    pub fn parse(text: &str, file: &str) -> Result<StoredMove, InputError> {
        serde_json::from_str(text)
            .map_err(|e| InputError::new(format!("not a stored move: {e}")).in_file(file))
    }

    /// The stored record of a found sequence.
    pub fn of(name: &str, model: AtomRest, searched: &str, found: &Found) -> StoredMove {
        StoredMove {
            name: name.into(),
            model,
            searched: searched.into(),
            states_explored: found.states_explored,
            steps: found
                .steps
                .iter()
                .map(|st| st.iter().map(|&op| op_text(op)).collect())
                .collect(),
        }
    }

    /// The sequence, replayed in `problem` and checked: every operation
    /// within the problem's limits, every step valid by the certifier's
    /// rules, ending exactly at the goal (`end`: each atom on its own goal
    /// cell, or the search's goal within exchange groups). Errors name the
    /// file, the step (1-based) and, where one is at fault, the atom.
    pub fn validated(
        &self,
        problem: &Problem,
        end: GoalMatch,
        file: &str,
    ) -> Result<Found, InputError> {
        let n = problem.start.pos.len();
        let mut scene = problem.start.clone();
        let mut steps = Vec::with_capacity(self.steps.len());
        for (k, texts) in self.steps.iter().enumerate() {
            let err = |m: String| InputError::new(m).at_step(k + 1).in_file(file);
            if texts.is_empty() {
                return Err(err("an empty step".into()));
            }
            let mut ops = Vec::with_capacity(texts.len());
            for t in texts {
                let op = parse_op(t).map_err(&err)?;
                let (a, b) = op.atoms();
                let bad = |x: usize| x >= n;
                if bad(a) || b.is_some_and(bad) {
                    return Err(err(format!("'{t}' names an atom outside the scene's {n}")));
                }
                let allowed = match op {
                    Op::Expand(a, f) | Op::Contract(a, f) => {
                        problem.actors.contains(&a) && problem.faces.contains(&f)
                    }
                    Op::Attach(a, b) | Op::Detach(a, b) => {
                        (problem.actors.contains(&a) || problem.actors.contains(&b))
                            && problem.latchable.contains(&a)
                            && problem.latchable.contains(&b)
                    }
                };
                if !allowed {
                    return Err(err(format!(
                        "'{t}' is outside the move's limits (which atoms act, with which faces, latching to which)"
                    ))
                    .for_module(a as u32));
                }
                ops.push(op);
            }
            scene = scene
                .step(&ops, &problem.anchors, problem.eps)
                .ok_or_else(|| {
                    err("the step is invalid by the certifier's rules (kinematics, collision, latches or connectivity)".into())
                })?;
            steps.push(ops);
        }
        let reached = match end {
            GoalMatch::OwnCells => scene == problem.goal,
            GoalMatch::WithinGroups => problem.meets_goal(&scene),
        };
        if !reached {
            return Err(InputError::new(match end {
                GoalMatch::OwnCells => {
                    "the sequence does not end with every atom at its own goal, at rest, with the goal's bonds"
                }
                GoalMatch::WithinGroups => {
                    "the sequence does not end at the goal (its cells, faces and bonds, atoms exchanged only within their groups)"
                }
            })
            .in_file(file));
        }
        Ok(Found {
            ops: steps.iter().flatten().copied().collect(),
            steps,
            states_explored: self.states_explored,
        })
    }
}

/// How a replayed sequence must meet its problem's goal.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum GoalMatch {
    /// Every atom on its own goal cell.
    OwnCells,
    /// As the search's goal: an exchange group's atoms on its cells in
    /// any order.
    WithinGroups,
}

/// What the expanded SLIDE's record says was searched.
const EXPANDED_SLIDE_SEARCHED: &str = "atom_search::expanded_slide_problem(Carry::None): the SLIDE scene of slide_problem (slider A at meta cell (1, 1) slides -x along the wall B (1, 0) onto C (0, 0)), A acting with faces +x -x +y -y, A's atoms one exchange group; Problem::solve_bidirectional(2, 600000); valid carrying a meta-module behind A as well (checked on load)";

/// Searches the expanded model's SLIDE again (about a minute in release).
pub fn derive_expanded_slide() -> Option<StoredMove> {
    let (p, _) = expanded_slide_problem(Carry::None);
    let (weight, states) = EXPANDED_SLIDE_SEARCH;
    let found = p.solve_bidirectional(weight, states)?;
    let (name, model) = StoredId::ExpandedSlide.record();
    Some(StoredMove::of(
        &name,
        model,
        EXPANDED_SLIDE_SEARCHED,
        &found,
    ))
}

/// The stored expanded SLIDE, validated alone and carrying a meta-module
/// behind the slider; the result is in the scene `carry` (`None` or
/// `Behind`).
pub fn expanded_slide(carry: Carry) -> Result<(Problem, Found), InputError> {
    let stored = StoredId::ExpandedSlide.load()?;
    let mut out = None;
    for c in [Carry::None, Carry::Behind] {
        let (p, _) = expanded_slide_problem(c);
        let found = stored.validated(&p, GoalMatch::OwnCells, EXPANDED_SLIDE_FILE)?;
        if c == carry {
            out = Some((p, found));
        }
    }
    out.ok_or_else(|| {
        InputError::new(format!(
            "the stored SLIDE is checked alone and carrying one behind, not {}",
            carry.name()
        ))
        .in_file(EXPANDED_SLIDE_FILE)
    })
}

/// One of the stored moves: its file, its text, and its search.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum StoredId {
    ExpandedSlide,
    ContractedTunnel(Legs),
}

impl StoredId {
    pub const ALL: [StoredId; 5] = [
        StoredId::ExpandedSlide,
        StoredId::ContractedTunnel(Legs::ALL[0]),
        StoredId::ContractedTunnel(Legs::ALL[1]),
        StoredId::ContractedTunnel(Legs::ALL[2]),
        StoredId::ContractedTunnel(Legs::ALL[3]),
    ];

    /// Where it is stored (relative to the repository) and the text
    /// compiled in from there.
    pub fn file(self) -> (&'static str, &'static str) {
        match self {
            StoredId::ExpandedSlide => (EXPANDED_SLIDE_FILE, EXPANDED_SLIDE_TEXT),
            StoredId::ContractedTunnel(legs) => match (legs.behind, legs.ahead) {
                (false, false) => (
                    "models/moves/tunnel-contracted-alone.json",
                    include_str!("../../models/moves/tunnel-contracted-alone.json"),
                ),
                (true, false) => (
                    "models/moves/tunnel-contracted-leg-in.json",
                    include_str!("../../models/moves/tunnel-contracted-leg-in.json"),
                ),
                (false, true) => (
                    "models/moves/tunnel-contracted-leg-out.json",
                    include_str!("../../models/moves/tunnel-contracted-leg-out.json"),
                ),
                (true, true) => (
                    "models/moves/tunnel-contracted-both-legs.json",
                    include_str!("../../models/moves/tunnel-contracted-both-legs.json"),
                ),
            },
        }
    }

    /// The move and model its record must name.
    fn record(self) -> (String, AtomRest) {
        match self {
            StoredId::ExpandedSlide => ("slide".into(), AtomRest::Expanded),
            StoredId::ContractedTunnel(legs) => {
                (format!("1-tunnel, {}", legs.name()), AtomRest::Contracted)
            }
        }
    }

    /// Its record, read from the compiled-in text, refused (naming the
    /// file) unless it names this move and model; not yet validated
    /// ([`StoredMove::validated`] replays it).
    pub fn load(self) -> Result<StoredMove, InputError> {
        let (file, text) = self.file();
        let stored = StoredMove::parse(text, file)?;
        let (name, model) = self.record();
        if stored.name != name || stored.model != model {
            return Err(InputError::new(format!(
                "not the {} model's {name}",
                format!("{model:?}").to_lowercase()
            ))
            .in_file(file));
        }
        Ok(stored)
    }

    /// Its name on the command line: the file's stem.
    pub fn name(self) -> &'static str {
        let file = self.file().0;
        let stem = file.rsplit('/').next().unwrap_or(file);
        stem.strip_suffix(".json").unwrap_or(stem)
    }

    /// Runs its search again; `None` if the search finds nothing within
    /// its bounds.
    pub fn derive(self) -> Option<StoredMove> {
        match self {
            StoredId::ExpandedSlide => derive_expanded_slide(),
            StoredId::ContractedTunnel(legs) => derive_contracted_tunnel(legs),
        }
    }
}

/// Searches the contracted model's 1-TUNNEL with `legs` again (up to
/// about 720,000 states: seconds to a minute in release).
pub fn derive_contracted_tunnel(legs: Legs) -> Option<StoredMove> {
    let (p, _) = tunnel_problem(AtomRest::Contracted, legs);
    let (weight, states) = TUNNEL_SEARCH;
    let found = p.solve_bidirectional(weight, states)?;
    let searched = format!(
        "atom_search::tunnel_problem(Contracted, Legs {{ behind: {}, ahead: {} }}): the leaf A at meta cell (0, 1) pushed into the turn B (0, 0), whose mass pops out at (1, 0), B hanging on L (-1, 0); A's and B's atoms act and are one exchange group, a leg (D behind A, E ahead) moves rigidly; Problem::solve_bidirectional({weight}, {states})",
        legs.behind, legs.ahead
    );
    let (name, model) = StoredId::ContractedTunnel(legs).record();
    Some(StoredMove::of(&name, model, &searched, &found))
}

/// The stored contracted 1-TUNNEL with `legs`, validated by replay in its
/// problem (the search's goal, A's and B's atoms exchanged).
pub fn contracted_tunnel(legs: Legs) -> Result<(Problem, Found), InputError> {
    let id = StoredId::ContractedTunnel(legs);
    let stored = id.load()?;
    let (p, _) = tunnel_problem(AtomRest::Contracted, legs);
    let found = stored.validated(&p, GoalMatch::WithinGroups, id.file().0)?;
    Ok((p, found))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn operations_read_back_as_written() {
        for op in [
            Op::Expand(8, Face::PosY),
            Op::Contract(10, Face::NegX),
            Op::Attach(9, 10),
            Op::Detach(2, 8),
        ] {
            assert_eq!(parse_op(&op_text(op)), Ok(op));
        }
        assert_eq!(parse_op("attach 10 9"), Ok(Op::Attach(9, 10)));
        for bad in [
            "expand 8",
            "expand x +y",
            "expand 8 +w",
            "attach 3 3",
            "twist 1 2",
            "",
        ] {
            assert!(parse_op(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn the_stored_expanded_slide_replays_valid_alone_and_carrying_one_behind() {
        let (p, found) = expanded_slide(Carry::Behind).expect("valid");
        assert_eq!((found.ops.len(), found.steps.len()), (48, 12));
        assert_eq!(p.start.pos.len(), 24, "B, C, A, F, H and D");
        assert!(expanded_slide(Carry::None).is_ok());
        // The scene with a meta-module on A's far side is not what it was
        // checked for (that load needs a relatch: atom_expand).
        assert!(expanded_slide(Carry::Above).is_err());
    }

    /// The search run again finds exactly the stored sequence (about a
    /// minute in release, several in a test build: run it with
    /// `cargo test --release -- --ignored the_stored_expanded_slide_is`;
    /// `reconfcheck derive-moves --check` does the same).
    #[test]
    #[ignore = "a minute-long search; reconfcheck derive-moves --check runs it too"]
    fn the_stored_expanded_slide_is_what_the_search_finds() {
        let stored = StoredMove::parse(EXPANDED_SLIDE_TEXT, EXPANDED_SLIDE_FILE).unwrap();
        assert_eq!(derive_expanded_slide(), Some(stored));
    }

    /// Each kind of damage to the stored sequence is refused, naming the step.
    #[test]
    fn a_damaged_stored_sequence_is_refused_naming_its_step() {
        let good = StoredMove::parse(EXPANDED_SLIDE_TEXT, "f").unwrap();
        let (p, _) = expanded_slide_problem(Carry::None);
        let check = |m: &StoredMove| {
            m.validated(&p, GoalMatch::OwnCells, "f.json")
                .map(|_| ())
                .map_err(|e| e.to_string())
        };
        assert_eq!(check(&good), Ok(()));
        // A dropped operation (the first step's last).
        let mut m = good.clone();
        m.steps[0].pop();
        let e = check(&m).unwrap_err();
        assert!(e.contains("f.json"), "{e}");
        // The last step dropped: ends away from the goal.
        let mut m = good.clone();
        m.steps.pop();
        assert!(check(&m).unwrap_err().contains("goal"));
        // An operation by a wall atom (not an actor).
        let mut m = good.clone();
        m.steps[2].push("expand 0 +x".into());
        let e = check(&m).unwrap_err();
        assert!(e.contains("step 3") && e.contains("limits"), "{e}");
        // Two steps swapped.
        let mut m = good.clone();
        m.steps.swap(4, 5);
        assert!(check(&m).unwrap_err().contains("step 5"));
        // An atom beyond the scene; an empty step; a garbled operation.
        for (k, t) in [(1, "attach 9 99"), (1, "grow 9")] {
            let mut m = good.clone();
            m.steps[k].push(t.into());
            assert!(check(&m).unwrap_err().contains("step 2"), "{t}");
        }
        let mut m = good.clone();
        m.steps.insert(3, Vec::new());
        assert!(check(&m).unwrap_err().contains("step 4"));
    }

    /// Every stored 1-TUNNEL replays to its goal, at the documented sizes
    /// (docs/atoms.md: 2D slice operations and parallel steps, before
    /// lifting); and A's and B's atoms end exchanged, so a
    /// check that wanted each atom on its own goal cell would refuse them.
    #[test]
    fn the_stored_tunnels_replay_to_the_search_goal_with_atoms_exchanged() {
        // (operations, parallel steps) in the 2D slice, as docs/atoms.md
        // has them (alone, a leg in, a leg out, both).
        let sizes = [(20, 8), (46, 15), (46, 15), (58, 18)];
        for (legs, size) in Legs::ALL.into_iter().zip(sizes) {
            let (p, found) = contracted_tunnel(legs).expect("valid");
            assert_eq!(
                (found.ops.len(), found.steps.len()),
                size,
                "{}",
                legs.name()
            );
            let (file, text) = StoredId::ContractedTunnel(legs).file();
            let stored = StoredMove::parse(text, file).unwrap();
            let own = stored.validated(&p, GoalMatch::OwnCells, file);
            assert!(
                own.unwrap_err().to_string().contains("own goal"),
                "{}",
                legs.name()
            );
        }
    }

    /// A stored 1-TUNNEL cut short, or replayed in another leg's scene, is
    /// refused.
    #[test]
    fn a_tunnel_cut_short_or_in_another_scene_is_refused() {
        let id = StoredId::ContractedTunnel(Legs::ALL[0]);
        let (file, text) = id.file();
        let good = StoredMove::parse(text, file).unwrap();
        let (p, _) = tunnel_problem(AtomRest::Contracted, Legs::ALL[0]);
        let mut short = good.clone();
        short.steps.pop();
        let e = short
            .validated(&p, GoalMatch::WithinGroups, file)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("does not end at the goal") && e.contains(file),
            "{e}"
        );
        let (other, _) = tunnel_problem(AtomRest::Contracted, Legs::ALL[3]);
        assert!(
            good.validated(&other, GoalMatch::WithinGroups, file)
                .is_err()
        );
    }

    /// The searches run again find exactly the stored 1-TUNNELs (minutes
    /// in a test build: `cargo test --release -- --ignored
    /// the_stored_tunnels_are`; `reconfcheck derive-moves --check` does
    /// the same).
    #[test]
    #[ignore = "searches of up to 720,000 states; reconfcheck derive-moves --check runs them too"]
    fn the_stored_tunnels_are_what_the_search_finds() {
        for legs in Legs::ALL {
            let id = StoredId::ContractedTunnel(legs);
            let (file, text) = id.file();
            assert_eq!(
                id.derive(),
                Some(StoredMove::parse(text, file).unwrap()),
                "{file}"
            );
        }
    }
}
