//! Validation of the static analysis against closed forms and first
//! principles: each test fails if the physics is wrong.

use super::analysis::{Analyzer, Verdict};
use super::model::{Bending, Model};
use super::structure::{MoverSpec, SceneRef, Structure};
use crate::lattice::config::{Ground, ModuleId};
use crate::lattice::{Cell, Configuration, FccLattice, Lattice, Motion, Route, SquareLattice};
use glam::DVec3;
use rustc_hash::FxHashSet;

/// A structure from cells (ids 1, 2, … in order); `fixed` lists indices.
pub(crate) fn structure(
    lattice: &dyn Lattice,
    ground: Option<Ground>,
    cells: &[Cell],
    fixed: &[usize],
    movers: &[MoverSpec],
) -> Structure {
    structure_without(lattice, ground, cells, fixed, movers, &[])
}

/// As [`structure`], with the modules `absent` left out of the scene.
pub(crate) fn structure_without(
    lattice: &dyn Lattice,
    ground: Option<Ground>,
    cells: &[Cell],
    fixed: &[usize],
    movers: &[MoverSpec],
    absent: &[ModuleId],
) -> Structure {
    let mut config = Configuration::new();
    for (i, c) in cells.iter().enumerate() {
        config.insert(i as ModuleId + 1, *c).unwrap();
    }
    let fixed: FxHashSet<ModuleId> = fixed.iter().map(|&i| i as ModuleId + 1).collect();
    let exclude: FxHashSet<ModuleId> = movers
        .iter()
        .map(|m| m.0)
        .chain(absent.iter().copied())
        .collect();
    let scene = SceneRef {
        lattice,
        ground,
        config: &config,
        fixed: &fixed,
        exclude: &exclude,
        latched: &|_, _| true,
    };
    Structure::build(&scene, movers)
}

/// A scaffold-like frame of `a × a × h` cubic tiles of side 6 (the
/// cells on the tiles' edges), fixed at its bottom layer.
pub(crate) fn frame(a: i32, h: i32) -> Structure {
    let b = 6;
    let mut cells = Vec::new();
    for x in 0..=a * b {
        for y in 0..=a * b {
            for z in 0..=h * b {
                let edges = [x % b, y % b, z % b].iter().filter(|&&r| r == 0).count();
                if edges >= 2 {
                    cells.push(Cell::new(x, y, z));
                }
            }
        }
    }
    let fixed: Vec<usize> = (0..cells.len()).filter(|&i| cells[i].z == 0).collect();
    structure(&FccLattice, None, &cells, &fixed, &[])
}

/// A 3 × 3 × 3 FCC block resting on the ground, with a mover swinging
/// on its top about the module at (2, 1, 2).
fn block_with_a_mover_on_top() -> Structure {
    let mut cells = block(3, 3, 3);
    let mover_cell = Cell::new(3, 1, 2);
    let pivot_cell = Cell::new(2, 1, 2);
    cells.push(mover_cell);
    let mover = cells.len() as ModuleId;
    let pivot = cells.iter().position(|c| *c == pivot_cell).unwrap() as ModuleId + 1;
    let motion = Motion::Rotate {
        from: mover_cell,
        to: FccLattice.neighbour(pivot_cell, 4),
        pivot: pivot_cell,
        route: Route::Octagonal,
    };
    structure(
        &FccLattice,
        Some(Ground { layer: 0 }),
        &cells,
        &[],
        &[(mover, Some(pivot), motion)],
    )
}

/// The cells of an `nx × ny × nz` block of FCC cells, layer by layer
/// (the first `nx·ny` are the bottom layer).
fn block(nx: i32, ny: i32, nz: i32) -> Vec<Cell> {
    (0..nz)
        .flat_map(|z| (0..nx).flat_map(move |x| (0..ny).map(move |y| Cell::new(x, y, z))))
        .collect()
}

fn tight(model: Model) -> Analyzer {
    let mut a = Analyzer::new(model, false);
    a.settings.tolerance = 1e-13;
    a
}

/// [`tight`] at the reference pose only: one consistent equilibrium.
fn one_pose(model: Model) -> Analyzer {
    let mut a = tight(model);
    a.settings.envelope = false;
    a
}

/// Index of the link between the modules with ids `a` and `b`.
fn link_between(s: &Structure, a: ModuleId, b: ModuleId) -> usize {
    let (ia, ib) = (s.body_of(a).unwrap(), s.body_of(b).unwrap());
    s.links
        .iter()
        .position(|l| {
            (l.a == ia && l.b == super::structure::End::Body(ib))
                || (l.a == ib && l.b == super::structure::End::Body(ia))
        })
        .unwrap()
}

fn bending(l: &super::capacity::ConnectorLoad) -> f64 {
    l.moment_u.hypot(l.moment_v)
}

#[test]
fn horizontal_cantilever_root_moment_matches_closed_form() {
    let model = Model::default_catom();
    let (w, d) = (model.weight(), model.spacing);
    let n = 6;
    let cells: Vec<Cell> = (0..=n).map(|i| Cell::new(i, 0, 0)).collect();
    let s = structure(&FccLattice, None, &cells, &[0], &[]);
    let a = tight(model.clone()).analyse(&s);
    // Every connector k (between modules k and k+1, 0 = fixed root)
    // carries the weight and moment of everything beyond it.
    for k in 0..n {
        let li = link_between(&s, k as u32 + 1, k as u32 + 2);
        let load = a.links[li].load;
        let beyond = (n - k) as f64;
        let moment: f64 = (1..=(n - k)).map(|j| j as f64 - 0.5).sum::<f64>() * w * d;
        assert!(
            (bending(&load) - moment).abs() <= 1e-6 * moment,
            "k={k}: {} vs {moment}",
            bending(&load)
        );
        assert!((load.shear - beyond * w).abs() <= 1e-6 * beyond * w);
        assert!(load.axial.abs() <= 1e-6 * w && load.torsion.abs() <= 1e-6 * w * d);
    }
    // The root is the critical connector, at the closed-form utilisation.
    let root = link_between(&s, 1, 2);
    assert_eq!(a.critical, Some(super::analysis::Critical::Link(root)));
    let expected = super::closed_form::cantilever_utilisation(&model, n as usize, false);
    assert!((a.max_utilisation - expected).abs() <= 1e-6 * expected);
    assert_eq!(a.verdict(), Verdict::Stable);
}

#[test]
fn loads_of_a_determinate_cantilever_do_not_depend_on_stiffness() {
    let cells: Vec<Cell> = (0..5).map(|i| Cell::new(i, 0, 0)).collect();
    let s = structure(&FccLattice, None, &cells, &[0], &[]);
    let mut soft = Model::default_catom();
    soft.poisson = 0.0;
    let mut hard = Model::default_catom();
    hard.poisson = 0.49;
    let (a, b) = (tight(soft).analyse(&s), tight(hard).analyse(&s));
    for (x, y) in a.links.iter().zip(&b.links) {
        assert!((x.utilisation - y.utilisation).abs() < 1e-7);
    }
}

#[test]
fn clamped_beam_on_two_supports_matches_the_compatibility_closed_form() {
    // Fixed supports at both ends, n free modules between: shear n/2 at
    // each end by symmetry; connector rotations (M_k / k_b, equal springs)
    // must add up to zero between two clamps, which fixes the end moment:
    // M_k = M_0 + W·d·(n·k − k²)/2 (statics of the left part), Σ_k M_k = 0.
    let model = Model::default_catom();
    let (w, d) = (model.weight(), model.spacing);
    let n = 7;
    let cells: Vec<Cell> = (0..=n + 1).map(|i| Cell::new(i, 0, 0)).collect();
    let s = structure(&FccLattice, None, &cells, &[0, n as usize + 1], &[]);
    let a = tight(model).analyse(&s);
    let statics: Vec<f64> = (0..=n)
        .map(|k| (n * k) as f64 / 2.0 - (k * k) as f64 / 2.0)
        .collect();
    let m0 = -statics.iter().sum::<f64>() / (n + 1) as f64;
    let scale = w * d * n as f64;
    for k in 0..=n {
        let li = link_between(&s, k as u32 + 1, k as u32 + 2);
        let expected = (m0 + statics[k as usize]).abs() * w * d;
        let got = bending(&a.links[li].load);
        assert!(
            (got - expected).abs() < 1e-6 * scale,
            "k={k}: {got} vs {expected}"
        );
    }
    let left = a.links[link_between(&s, 1, 2)].load.shear;
    assert!((left - n as f64 / 2.0 * w).abs() < 1e-6 * w);
}

#[test]
fn reactions_balance_the_total_weight_of_an_indeterminate_block() {
    let model = Model::default_catom();
    let s = block_with_a_mover_on_top();
    let mut m = model.clone();
    m.ground.pressure = m.connector.pressure; // latched to the sandbox: no lift-off
    let a = one_pose(m).analyse(&s);
    let mut total = DVec3::ZERO;
    for (l, r) in s.links.iter().zip(&a.links) {
        if l.is_ground() {
            total += DVec3::from_array(r.force);
        }
    }
    let expected = DVec3::new(
        0.0,
        0.0,
        -((s.bodies.len() + s.hanging.len()) as f64) * model.weight(),
    );
    assert!(
        (total - expected).length() < 1e-6 * expected.length(),
        "{total} vs {expected}"
    );
    assert_eq!(a.pivots.len(), 1);
}

#[test]
fn superposition_of_mover_loads_holds() {
    // On a fixed base (no unilateral contact), loads are linear: the
    // response to two movers is the sum of the responses to each.
    let mut cells = vec![Cell::new(0, 0, 0), Cell::new(1, 0, 0)];
    for x in 0..4 {
        cells.push(Cell::new(x, 0, 1));
    }
    cells.push(Cell::new(0, 0, 2));
    cells.push(Cell::new(3, 0, 2));
    let (m1, m2) = (7, 8);
    let rot = |from: Cell, pivot: Cell| Motion::Rotate {
        from,
        to: FccLattice.neighbour(pivot, 2),
        pivot,
        route: Route::Octagonal,
    };
    let mv1: MoverSpec = (m1, Some(3), rot(cells[6], cells[2]));
    let mv2: MoverSpec = (m2, Some(6), rot(cells[7], cells[5]));
    let model = Model::default_catom();
    let run = |movers: &[MoverSpec], absent: &[ModuleId]| {
        let s = structure_without(&FccLattice, None, &cells, &[0, 1], movers, absent);
        one_pose(model.clone()).analyse(&s)
    };
    // The movers are excluded from the static structure in every case.
    let none = {
        let s = structure(&FccLattice, None, &cells[..6], &[0, 1], &[]);
        tight(model.clone()).analyse(&s)
    };
    let a = run(std::slice::from_ref(&mv1), &[m2]);
    let b = run(std::slice::from_ref(&mv2), &[m1]);
    let ab = run(&[mv1, mv2], &[]);
    let scale = model.weight() * model.spacing;
    for i in 0..none.links.len() {
        for k in 0..3 {
            let sum = a.links[i].force[k] + b.links[i].force[k] - none.links[i].force[k];
            assert!((ab.links[i].force[k] - sum).abs() < 1e-8 * model.weight());
            let msum = a.links[i].moment[k] + b.links[i].moment[k] - none.links[i].moment[k];
            assert!((ab.links[i].moment[k] - msum).abs() < 1e-8 * scale);
        }
    }
    // And the movers do change the loads (the test is not vacuous).
    let changed = (0..none.links.len())
        .any(|i| (ab.links[i].moment[1] - none.links[i].moment[1]).abs() > 0.1 * scale);
    assert!(changed);
}

fn square_model(ground_kpa: f64) -> Model {
    let mut m = Model::from_toml(include_str!("../../models/sliding-square.toml")).unwrap();
    m.ground.pressure = ground_kpa * 1e3;
    m
}

#[test]
fn an_overhang_tips_without_ground_adhesion_and_holds_with_it() {
    // 2D: a base on the ground, a column, an arm over empty space. The
    // centre of mass of base + column + arm of length k is at x = k(k+1)/2/(k+2)
    // (units of d); the base's contact spans x ∈ [−½, ½].
    let ground = Some(Ground { layer: 0 });
    let arm = |k: i32| {
        let mut c = vec![Cell::xy(0, 0), Cell::xy(0, 1)];
        c.extend((1..=k).map(|x| Cell::xy(x, 1)));
        c
    };
    // k = 1: centre of mass at 1/3 < ½: stands on its own.
    let short = structure(&SquareLattice, ground, &arm(1), &[], &[]);
    let a = tight(square_model(0.0)).analyse(&short);
    assert_eq!(a.verdict(), Verdict::Stable, "{:?}", a.max_utilisation);
    // The ground contact's utilisation is the resultant's offset over the
    // half-width: (1/3)/(1/2).
    let g = short.links.iter().position(|l| l.is_ground()).unwrap();
    assert!((a.links[g].utilisation - 2.0 / 3.0).abs() < 1e-6);
    // k = 2: centre of mass at 3/4 > ½: tips over.
    let long = structure(&SquareLattice, ground, &arm(2), &[], &[]);
    let b = tight(square_model(0.0)).analyse(&long);
    assert_eq!(b.verdict(), Verdict::NoEquilibrium);
    assert_eq!(b.unsupported.len(), 4);
    // The tipping witness (gravity along −y here): the weight at x = ¾,
    // a quarter cell outside the contact.
    let t = b.tipping.as_ref().expect("a tipping witness");
    assert!((t.outside - 0.25).abs() < 1e-12, "{t:?}");
    assert!((t.weight_at_ground.x - 0.75).abs() < 1e-12, "{t:?}");
    // With the ground latched (adhesion), the same overhang holds.
    let c = tight(square_model(20.0)).analyse(&long);
    assert_eq!(c.verdict(), Verdict::Stable);
}

#[test]
fn a_structure_on_two_feet_tips_when_its_centre_of_mass_leaves_the_base() {
    // A deck on two ground modules (x = 0 and x = 2) with an arm to the
    // right. The base spans x ∈ [−½, 2½].
    let ground = Some(Ground { layer: 0 });
    let deck = |to: i32| {
        let mut c = vec![Cell::xy(0, 0), Cell::xy(2, 0)];
        c.extend((0..=to).map(|x| Cell::xy(x, 1)));
        c
    };
    // Arm to x = 3: centre of mass 4/3, inside: both feet press.
    let s = structure(&SquareLattice, ground, &deck(3), &[], &[]);
    let a = tight(square_model(0.0)).analyse(&s);
    assert_eq!(a.verdict(), Verdict::Stable);
    for (l, r) in s.links.iter().zip(&a.links) {
        if l.is_ground() {
            assert!(!r.released && r.load.axial < 0.0, "{r:?}");
        }
    }
    // Arm to x = 7: centre of mass 3 > 2½: both feet let go, it tips.
    let s2 = structure(&SquareLattice, ground, &deck(7), &[], &[]);
    let b = tight(square_model(0.0)).analyse(&s2);
    assert_eq!(b.verdict(), Verdict::NoEquilibrium);
    assert_eq!(b.unsupported.len(), 10);
    let t = b.tipping.as_ref().expect("a tipping witness");
    assert!((t.outside - 0.5).abs() < 1e-12, "{t:?}");
    assert_eq!(t.contacts, 2);
    // Latched to the ground it holds.
    let c = tight(square_model(20.0)).analyse(&s2);
    assert_eq!(c.verdict(), Verdict::Stable);
}

#[test]
fn a_floating_part_has_no_equilibrium() {
    let cells = vec![Cell::new(0, 0, 0), Cell::new(1, 0, 0), Cell::new(5, 5, 3)];
    let s = structure(&FccLattice, None, &cells, &[0], &[]);
    let a = tight(Model::default_catom()).analyse(&s);
    assert_eq!(a.verdict(), Verdict::NoEquilibrium);
    assert_eq!(a.unsupported, vec![s.body_of(3).unwrap()]);
}

#[test]
fn the_stiffness_matrix_of_a_step_leaves_out_fixed_modules_and_is_definite_when_anchored() {
    use super::direct::Factor;
    let cells: Vec<Cell> = (0..=4).map(|i| Cell::new(i, 0, 0)).collect();
    let anchored = structure(&FccLattice, None, &cells, &[0], &[]);
    let mut a = tight(Model::default_catom());
    let k = a.stiffness_matrix(&anchored);
    assert_eq!(k.len(), 4, "the fixed root has no unknowns");
    assert_eq!(k.off.len(), 3, "a chain: one block per free–free connector");
    assert!(Factor::new(&k).is_some());
    // Nothing fixed and no ground: the chain floats, K is singular.
    let floating = structure(&FccLattice, None, &cells, &[], &[]);
    assert!(Factor::new(&a.stiffness_matrix(&floating)).is_none());
}

#[test]
fn a_long_cantilever_is_overloaded_at_its_root() {
    let model = Model::default_catom().with_connector(10e3, Bending::RigidHinge);
    let cells: Vec<Cell> = (0..=4).map(|i| Cell::new(i, 0, 0)).collect();
    let s = structure(&FccLattice, None, &cells, &[0], &[]);
    let a = tight(model).analyse(&s);
    assert_eq!(a.verdict(), Verdict::Overloaded);
    assert_eq!(
        a.critical,
        Some(super::analysis::Critical::Link(link_between(&s, 1, 2)))
    );
}

#[test]
fn incremental_reuse_gives_the_same_answer_as_from_scratch() {
    let model = Model::default_catom();
    let mut cells: Vec<Cell> = Vec::new();
    for x in 0..6 {
        for y in 0..3 {
            cells.push(Cell::new(x, y, 0));
        }
    }
    let fixed: Vec<usize> = (0..3).collect();
    let mut inc = Analyzer::new(model.clone(), true);
    let mut scratch = Analyzer::new(model.clone(), false);
    // Grow a second layer module by module: each step the incremental
    // analyser reuses the previous displacements.
    for k in 0..5 {
        cells.push(Cell::new(k, 1, 1));
        let s = structure(&FccLattice, None, &cells, &fixed, &[]);
        let (a, b) = (inc.analyse(&s), scratch.analyse(&s));
        assert!((a.max_utilisation - b.max_utilisation).abs() < 1e-6 * b.max_utilisation);
        // Analysing the same structure again solves nothing.
        let again = inc.analyse(&s);
        assert_eq!((again.iterations, again.factorizations), (0, 0));
        assert_eq!(again.max_utilisation, a.max_utilisation);
    }
}

#[test]
fn the_kept_factor_and_a_fresh_one_agree_on_a_growing_block() {
    // 8 × 8 × 5 modules on a fixed layer, plus an overhanging arm grown one
    // module per step: the incremental analyser factors once and then
    // iterates with that factor, and agrees with a fresh factor every step.
    let mut cells = block(8, 8, 5);
    let fixed: Vec<usize> = (0..64).collect();
    let model = Model::default_catom();
    let mut inc = Analyzer::new(model.clone(), true);
    // Reuse however much changed: this tests the preconditioner, not the
    // rule that decides when to refresh it.
    inc.settings.reuse_max_changed = usize::MAX;
    inc.settings.reuse_iterations = 200;
    let mut fresh = tight(model.clone());
    let mut factorizations = 0;
    for x in 8..12 {
        cells.push(Cell::new(x, 3, 4));
        let s = structure(&FccLattice, None, &cells, &fixed, &[]);
        let (a, b) = (inc.analyse(&s), fresh.analyse(&s));
        factorizations += a.factorizations;
        assert!(a.iterations > 0 || a.factorizations > 0);
        let scale = b.max_utilisation;
        for (x, y) in a.links.iter().zip(&b.links) {
            assert!((x.utilisation - y.utilisation).abs() < 1e-6 * scale);
        }
        assert_eq!(b.factorizations, 1);
    }
    assert_eq!(factorizations, 1, "later steps reuse the first factor");
}

#[test]
fn incremental_steps_release_the_same_ground_contacts_as_from_scratch() {
    // The same tipping-prone deck, analysed in two steps with an unrelated
    // part changing in between: the second step lifts the same contact.
    let ground = Some(Ground { layer: 0 });
    let mut deck = vec![Cell::xy(0, 0), Cell::xy(2, 0)];
    deck.extend((0..=4).map(|x| Cell::xy(x, 1)));
    let mut inc = Analyzer::new(square_model(0.0), true);
    let mut first = deck.clone();
    first.push(Cell::xy(10, 0));
    let mut second = deck.clone();
    second.extend([Cell::xy(10, 0), Cell::xy(10, 1)]);
    let s1 = structure(&SquareLattice, ground, &first, &[], &[]);
    let s2 = structure(&SquareLattice, ground, &second, &[], &[]);
    let a1 = inc.analyse(&s1);
    let a2 = inc.analyse(&s2);
    let fresh = Analyzer::new(square_model(0.0), false).analyse(&s2);
    for (x, y) in a2.links.iter().zip(&fresh.links) {
        assert_eq!(x.released, y.released);
        assert!((x.utilisation - y.utilisation).abs() < 1e-6);
    }
    assert!(a1.links.iter().any(|r| r.released) == fresh.links.iter().any(|r| r.released));
}

#[test]
fn a_module_leaving_and_another_arriving_are_solved_with_the_kept_factor() {
    // A 10 × 10 × 3 block (300 free modules) on a fixed layer. Step 1 is
    // factored; in step 2 one top module is absent (it left) and a new one
    // sits on top elsewhere: 2 changed bodies. Allowed to, the kept factor
    // preconditions CG — and the answer is the fresh factor's.
    let mut cells = block(10, 10, 4);
    let fixed: Vec<usize> = (0..100).collect();
    let model = Model::default_catom();
    let mut inc = Analyzer::new(model.clone(), true);
    inc.settings.reuse_max_changed = 2;
    inc.settings.reuse_iterations = 100;
    let first = structure(&FccLattice, None, &cells, &fixed, &[]);
    assert_eq!(inc.analyse(&first).factorizations, 1);
    let leaver = cells.len() as ModuleId; // the last top-layer module
    cells.push(Cell::new(4, 4, 4));
    let second = structure_without(&FccLattice, None, &cells, &fixed, &[], &[leaver]);
    let a = inc.analyse(&second);
    assert_eq!(a.factorizations, 0, "the kept factor was reused");
    assert!(
        a.iterations > 1,
        "the change is not exact under the old factor"
    );
    let b = tight(model).analyse(&second);
    let scale = b.max_utilisation;
    for (x, y) in a.links.iter().zip(&b.links) {
        assert!((x.utilisation - y.utilisation).abs() < 1e-6 * scale);
    }
    // With the default rule (at most one changed body) the same step is
    // factored afresh.
    inc.settings = Default::default();
    inc.reset();
    inc.analyse(&first);
    assert_eq!(inc.analyse(&second).factorizations, 1);
}

/// A fixed root at x = 0, free modules at x = 1 … `n`, and the mover id
/// `n + 2` swinging about the tip from `from` to `to`.
fn swing(n: i32, from: Cell, to: Cell, route: Route) -> Structure {
    let mut cells: Vec<Cell> = (0..=n).map(|x| Cell::new(x, 0, 0)).collect();
    cells.push(from);
    let pivot = Cell::new(n, 0, 0);
    let mover: MoverSpec = (
        n as ModuleId + 2,
        Some(n as ModuleId + 1),
        Motion::Rotate {
            from,
            to,
            pivot,
            route,
        },
    );
    structure(&FccLattice, None, &cells, &[0], &[mover])
}

/// The finer look: the structure with the mover held at each sampled pose
/// in turn, one equilibrium each. Returns every pose's utilisation.
fn per_pose(model: &Model, s: &Structure) -> Vec<f64> {
    let n = s.hanging[0].path.len();
    (0..n)
        .map(|k| {
            let mut t = s.clone();
            t.hanging[0].path = vec![s.hanging[0].path[k]];
            one_pose(model.clone()).analyse(&t).max_utilisation
        })
        .collect()
}

/// The envelope's maximum is the largest over the poses (never less), and
/// the worst pose is `expected` (0: start, 12: middle, 24: end).
fn assert_envelope(model: &Model, s: &Structure, expected: usize) -> f64 {
    let poses = per_pose(model, s);
    let (worst, max) = poses
        .iter()
        .copied()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap();
    assert_eq!(worst, expected, "{poses:?}");
    let a = tight(model.clone()).analyse(s);
    assert!(
        (a.max_utilisation - max).abs() <= 1e-9 * max,
        "envelope {} vs worst pose {max}",
        a.max_utilisation
    );
    max
}

#[test]
fn a_swing_whose_worst_pose_is_its_start_is_judged_there() {
    // The case: a branch of 4 beyond the fixed root; the tip
    // module swings 90° from +x to +y about the 4th module. At the start it
    // is a straight cantilever of 4 modules plus the mover: 0.5420.
    let model = Model::default_catom();
    let s = swing(4, Cell::new(5, 0, 0), Cell::new(4, 1, 0), Route::Octagonal);
    let max = assert_envelope(&model, &s, 0);
    let closed = super::closed_form::cantilever_utilisation(&model, 4, true);
    assert!((max - closed).abs() < 1e-6 * closed, "{max} vs {closed}");
    assert!((max - 0.5420).abs() < 5e-4);
    // At 52 kPa the start pose is beyond capacity (1.042): the step must
    // not pass, and the load factor is that pose's.
    let weak = model.with_connector(52e3, Bending::RigidHinge);
    let a = tight(weak).analyse(&s);
    assert_eq!(a.verdict(), Verdict::Overloaded);
    assert!(
        (a.max_utilisation - max * 100.0 / 52.0).abs() < 1e-6,
        "{}",
        a.max_utilisation
    );
    let lf = a
        .load_factor
        .expect("the limit analysis judged the failing poses");
    assert!((lf - 52.0 / (100.0 * max)).abs() < 1e-6, "{lf}");
}

#[test]
fn a_swing_whose_worst_pose_is_its_end_is_judged_there() {
    let model = Model::default_catom();
    let s = swing(4, Cell::new(4, 1, 0), Cell::new(5, 0, 0), Route::Octagonal);
    assert_envelope(&model, &s, 24);
}

#[test]
fn a_swing_whose_worst_pose_is_mid_way_is_judged_there() {
    // The agent rolling from above onto the tip of a branch of one rounds
    // the corner at (1 + √½, √½, 0): torsion of the root connector peaks
    // there, above both ends (the b-study's b = 2 case).
    let model = Model::default_catom();
    let tip = Cell::new(1, 0, 0);
    let s = swing(
        1,
        FccLattice.neighbour(tip, 4),
        FccLattice.neighbour(tip, 0),
        Route::Octagonal,
    );
    let poses = per_pose(&model, &s);
    assert!(poses[12] > 1.1 * poses[0].max(poses[24]), "{poses:?}");
    assert_envelope(&model, &s, 12);
}

#[test]
fn the_actuator_hold_is_reported_apart_from_the_connectors() {
    let model = Model::default_catom();
    let s = swing(2, Cell::new(3, 0, 0), Cell::new(2, 1, 0), Route::Octagonal);
    let a = tight(model.clone()).analyse(&s);
    assert_eq!(a.pivots.len(), 1);
    // By default the hold is the connector's: the mover alone on one face.
    let hold = a.hold_utilisation;
    assert!(hold > 0.0 && hold < a.max_utilisation);
    // A weaker actuator: the hold's utilisation scales with 1/p, the
    // connectors' do not move.
    let mut weak = model.clone();
    weak.actuator = Some(super::model::Capacity {
        pressure: model.connector.pressure / 4.0,
        ..model.connector
    });
    let b = tight(weak).analyse(&s);
    assert!(
        (b.hold_utilisation - 4.0 * hold).abs() < 1e-9 * hold,
        "{} vs {hold}",
        b.hold_utilisation
    );
    for (x, y) in a.links.iter().zip(&b.links) {
        assert_eq!(x.utilisation, y.utilisation);
    }
    // Weak enough, the hold alone fails the step, named as the critical.
    let mut feeble = model.clone();
    feeble.actuator = Some(super::model::Capacity {
        pressure: model.connector.pressure * hold / 2.0,
        ..model.connector
    });
    let c = tight(feeble).analyse(&s);
    assert_eq!(c.verdict(), Verdict::Overloaded);
    assert_eq!(c.critical, Some(super::analysis::Critical::Pivot(0)));
    assert!((c.hold_utilisation - 2.0).abs() < 1e-9);
}

/// A cantilever two modules high from one fixed root, `n` long, with a
/// mover swinging on its upper tip towards `to` (`mirror`: the image in
/// y = 0): it holds only through the limit analysis at every pose.
fn deep_swing(n: i32, to: Cell, mirror: bool) -> Structure {
    wall_swing(n, to, mirror, false)
}

/// [`deep_swing`], or (`resting`) the same wall on the ground beside a
/// second ground row, nothing fixed.
fn wall_swing(n: i32, to: Cell, mirror: bool, resting: bool) -> Structure {
    let flip = |c: Cell| if mirror { Cell::new(c.x, -c.y, c.z) } else { c };
    let mut cells: Vec<Cell> = (0..2)
        .flat_map(|z| (0..=n).map(move |x| Cell::new(x, 0, z)))
        .collect();
    let (pivot, from) = (Cell::new(n, 0, 1), Cell::new(n + 1, 0, 1));
    cells.push(from);
    let mover: MoverSpec = (
        cells.len() as ModuleId,
        Some(2 * n as ModuleId + 2),
        Motion::Rotate {
            from: flip(from),
            to: flip(to),
            pivot: flip(pivot),
            route: Route::Octagonal,
        },
    );
    if resting {
        // A second ground row beside the first, so that the wall stands.
        cells.extend((0..=n).map(|x| Cell::new(x, -1, 0)));
    }
    let cells: Vec<Cell> = cells.into_iter().map(flip).collect();
    if resting {
        structure(
            &FccLattice,
            Some(Ground { layer: 0 }),
            &cells,
            &[],
            &[mover],
        )
    } else {
        structure(&FccLattice, None, &cells, &[0], &[mover])
    }
}

/// A sample lying between the tangent poses of its two intervals is not
/// solved: the loads are affine in the mover's centre and the loads a
/// component carries within capacity are convex, so its factor is at
/// least the smaller of theirs. The step's factor is still the smallest
/// of every pose's own analysis, enumerated here one pose at a time, on
/// a fixed root (mirrored too) and resting on the ground; a sample moved
/// off that segment is solved again. (The resting wall's image in y = 0
/// is not that wall mirrored: layer 1 sits half a cell along +y, so its
/// image leans the other way over its second row, and the elastic screen
/// clears it.)
#[test]
fn a_sample_between_its_tangent_poses_is_not_solved_and_the_factor_is_still_every_poses_smallest() {
    let model = Model::default_catom();
    // Every pose but the dominated samples (the bisection, on by default,
    // passes over more: tested below).
    let analyse = |s: &Structure| bisected(&model, s, false);
    let cases = [
        (7, Cell::new(7, 1, 1), false),
        (8, Cell::new(8, 0, 2), false),
        (3, Cell::new(3, 1, 1), true),
    ];
    for (n, to, resting) in cases {
        for mirror in [false, true].into_iter().filter(|&m| !(m && resting)) {
            let s = wall_swing(n, to, mirror, resting);
            let a = analyse(&s);
            let lambda = a.load_factor.expect("judged by the limit analysis");
            let h = &s.hanging[0];
            let case = format!("{n} {resting} {mirror}");
            assert_eq!(
                (h.path.len(), h.hull.len(), a.between_poses),
                (25, 24, 24),
                "{case}"
            );
            // The two end samples and the 24 tangent poses, of 49.
            assert_eq!(a.limit_analyses, 26, "{case}");
            // Every pose alone: the mover's centre at one sample or one
            // tangent point.
            let alone = |c: DVec3| {
                let mut one = s.clone();
                one.hanging[0].path = vec![c];
                one.hanging[0].hull.clear();
                one.between.clear();
                let b = analyse(&one);
                assert_eq!(b.limit_analyses, 1);
                b.load_factor.expect("judged by the limit analysis")
            };
            let ends_and_tangents = [h.path[0], h.path[24]]
                .into_iter()
                .chain(h.hull.iter().copied())
                .map(alone)
                .fold(f64::INFINITY, f64::min);
            let every = h.path[1..24]
                .iter()
                .map(|&c| alone(c))
                .fold(ends_and_tangents, f64::min);
            assert!(
                (lambda - ends_and_tangents).abs() <= 1e-12 * lambda,
                "{case}: {lambda} against {ends_and_tangents}"
            );
            // The samples passed over are no lower, but for the proof's
            // round-off (each factor is proved from the solver's
            // equilibrium, a little under the optimum).
            assert!(
                every <= lambda * (1.0 + 1e-12) && lambda <= every * (1.0 + 1e-5),
                "{case}: {lambda} against {every}"
            );
            let mut bent = s.clone();
            bent.hanging[0].path[12] += 1e-6 * s.gravity;
            assert_eq!(analyse(&bent).limit_analyses, 27);
        }
    }
}

/// The smallest factor over the poses of `s`'s one mover (its samples
/// and tangent points), each analysed alone.
fn smallest_alone(model: &Model, s: &Structure) -> f64 {
    let h = &s.hanging[0];
    h.path
        .iter()
        .chain(&h.hull)
        .map(|&c| factor_alone(model, s, c))
        .fold(f64::INFINITY, f64::min)
}

/// The analysis of `s`, its sweeps bisected or not
/// (`Settings::bisect_sweeps`).
fn bisected(model: &Model, s: &Structure, bisect: bool) -> super::analysis::Analysis {
    let mut a = Analyzer::new(model.clone(), false);
    a.settings.bisect_sweeps = bisect;
    a.analyse(s)
}

/// Each pose of a sweep alone: its factor by the limit analysis, the mover
/// centred at `c` (no path beyond it).
fn factor_alone(model: &Model, s: &Structure, c: DVec3) -> f64 {
    let mut one = s.clone();
    one.hanging[0].path = vec![c];
    one.hanging[0].hull.clear();
    one.between.clear();
    let b = Analyzer::new(model.clone(), false).analyse(&one);
    assert_eq!(b.limit_analyses, 1);
    b.load_factor.expect("judged by the limit analysis")
}

/// The bisection of a sweep (`sweep_bisection`) reports the smallest
/// factor over its 49 poses, each enumerated here by its own analysis,
/// within the proofs' round-off (each factor is proved from the solver's
/// equilibrium, a little under the optimum; neighbouring poses' proofs
/// scatter by up to 1e-5 of the factor), on a fixed root (mirrored too)
/// and resting on the ground, with fewer analyses than every pose; and
/// where the sweep fails, the same verdict and a lower end no higher than
/// any pose's factor.
#[test]
fn a_bisected_sweep_reports_every_poses_smallest_factor_from_fewer_analyses() {
    let model = Model::default_catom();
    let analyse = |s: &Structure, bisect: bool| bisected(&model, s, bisect);
    let cases = [
        (7, Cell::new(7, 1, 1), false),
        (8, Cell::new(8, 0, 2), false),
        (3, Cell::new(3, 1, 1), true),
        (4, Cell::new(4, 0, 2), true),
    ];
    let (mut bisected, mut every_pose) = (0, 0);
    for (n, to, resting) in cases {
        for mirror in [false, true].into_iter().filter(|&m| !(m && resting)) {
            let s = wall_swing(n, to, mirror, resting);
            let case = format!("{n} {to:?} {resting} {mirror}");
            let (a, full) = (analyse(&s, true), analyse(&s, false));
            let lambda = a.load_factor.expect("judged by the limit analysis");
            assert_eq!(
                (s.hanging[0].path.len(), a.between_poses),
                (25, 24),
                "{case}"
            );
            let every = smallest_alone(&model, &s);
            assert!(
                lambda <= every * (1.0 + 1e-5) && every <= lambda * (1.0 + 1e-5),
                "{case}: {lambda} against {every}"
            );
            assert_eq!(a.verdict(), full.verdict(), "{case}");
            assert!(a.limit_analyses <= full.limit_analyses, "{case}");
            bisected += a.limit_analyses;
            every_pose += full.limit_analyses;
        }
    }
    assert!(2 * bisected < every_pose, "{bisected} against {every_pose}");
    // A cantilever too long to hold: the same verdict, and the lower end
    // of the factor no higher than any pose's.
    let s = wall_swing(14, Cell::new(14, 1, 1), false, false);
    let (a, full) = (analyse(&s, true), analyse(&s, false));
    assert_eq!(a.verdict(), Verdict::Overloaded);
    assert_eq!(full.verdict(), Verdict::Overloaded);
    let every = smallest_alone(&model, &s);
    let lower = a.load_factor_lower.or(a.load_factor).unwrap();
    assert!(lower <= every * (1.0 + 1e-5), "{lower} against {every}");
    assert!(a.load_factor.unwrap() < 1.0);
    // Where it gives way does not depend on how the poses were searched:
    // the collapse mechanism names the same connector, which is the
    // critical one.
    let (m, m_full) = (a.mechanism.unwrap(), full.mechanism.unwrap());
    assert_eq!(m.links[0].0, m_full.links[0].0);
    assert!(m.links[0].1 > 0.5, "{:?}", m.links);
    assert_eq!(
        a.critical,
        Some(super::analysis::Critical::Link(m.links[0].0))
    );
}

/// [`wall_swing`]'s wall with a mover onto its top at each end, turning
/// the other way round: two groups of movers, so 7 poses between each two
/// samples (`Structure::between`).
fn two_group_swing(n: i32, resting: bool) -> Structure {
    let mut cells: Vec<Cell> = (0..2)
        .flat_map(|z| (0..=n).map(move |x| Cell::new(x, 0, z)))
        .collect();
    let (far, near) = (Cell::new(n + 1, 0, 1), Cell::new(-1, 0, 1));
    cells.push(far);
    cells.push(near);
    let movers: Vec<MoverSpec> = vec![
        (
            cells.len() as ModuleId - 1,
            Some(2 * n as ModuleId + 2),
            Motion::Rotate {
                from: far,
                to: Cell::new(n, 0, 2),
                pivot: Cell::new(n, 0, 1),
                route: Route::Octagonal,
            },
        ),
        (
            cells.len() as ModuleId,
            Some(n as ModuleId + 2),
            Motion::Rotate {
                from: near,
                to: Cell::new(0, 0, 2),
                pivot: Cell::new(0, 0, 1),
                route: Route::Octagonal,
            },
        ),
    ];
    if resting {
        cells.extend((0..=n).map(|x| Cell::new(x, -1, 0)));
        structure(&FccLattice, Some(Ground { layer: 0 }), &cells, &[], &movers)
    } else {
        structure(&FccLattice, None, &cells, &[0], &movers)
    }
}

/// Two groups of movers: the bisection bounds each run through the
/// product of the groups' triangles (9 corners, weighed by the groups'
/// coupling) and reports the factor the analysis of every pose (25
/// samples and 168 poses between them) finds, within the proofs'
/// round-off, with the same verdict and fewer analyses: on the
/// cantilever, whose factor varies by 1 % along the sweep, and on the
/// wall resting on the ground, whose screen clears 24 poses (those are
/// solved only as corners, and do not count).
#[test]
fn a_bisected_sweep_of_two_groups_reports_the_smallest_factor_of_every_pose() {
    let model = Model::default_catom();
    let analyse = |s: &Structure, bisect: bool| bisected(&model, s, bisect);
    for (n, resting) in [(7, false), (3, true)] {
        let s = two_group_swing(n, resting);
        let w = super::sweep_bisection::sweep(&s).expect("two groups, 25 samples");
        assert_eq!(
            (w.n, w.groups, w.per_interval, s.between.len()),
            (25, 2, 7, 168)
        );
        let (a, full) = (analyse(&s, true), analyse(&s, false));
        let (lambda, every) = (a.load_factor.unwrap(), full.load_factor.unwrap());
        assert!(
            lambda <= every * (1.0 + 1e-5) && every <= lambda * (1.0 + 1e-5),
            "{n} {resting}: {lambda} against {every}"
        );
        assert_eq!(a.verdict(), full.verdict());
        // Every pose fails the screen on the cantilever, most (169) on
        // the wall: both are bisected, at a fraction of the cost (115 and
        // 17 analyses when written; 158 on the cantilever with the
        // corners' smallest as the bound, and the wall not bisected).
        let (failing, at_most) = if resting { (169, 30) } else { (193, 125) };
        assert_eq!(full.limit_analyses, failing);
        assert!(
            a.limit_analyses <= at_most,
            "{n} {resting}: {} against {}",
            a.limit_analyses,
            full.limit_analyses
        );
    }
}

/// The bisection against an enumeration of the 49 poses of a real sweep,
/// with factors given in closed form: `1/λ = a + |M(c − c₀)|`, a convex
/// gauge of the mover's centre `c`, as the limit analysis's is. The
/// reported factor is never above the smallest pose's and at most the
/// pruning slack (1e-7) under it; a flat factor takes 3 analyses; a
/// minimum inside the sweep is found; a failing sweep reports a lower end
/// no higher than the smallest; a failed solve (NaN) sticks.
#[test]
fn the_sweep_bisection_finds_the_smallest_of_convex_factors_against_an_enumeration() {
    use super::sweep_bisection::{Corner, smallest_factor, sweep};
    use glam::DMat3;
    let s = wall_swing(7, Cell::new(7, 1, 1), false, false);
    let w = sweep(&s).expect("one mover, 25 samples, 24 tangent poses");
    assert_eq!((w.n, w.groups, w.per_interval), (25, 1, 1));
    let n = w.n;
    let pivot = s.bodies[s.hanging[0].pivot].centre;
    let middle = s.hanging[0].path[12] - pivot;
    let run_within = |gauge: &dyn Fn(DVec3) -> f64, nan_at: Option<usize>, tolerance: f64| {
        let exact = (0..2 * n - 1)
            .map(|k| 1.0 / gauge(s.mover_point(0, k)))
            .fold(f64::INFINITY, f64::min);
        let mut solve = |corners: &[Corner]| -> Vec<f64> {
            corners
                .iter()
                .map(|c| match c {
                    Corner::Pose(k) if Some(*k) == nan_at => f64::NAN,
                    Corner::Pose(k) => 1.0 / gauge(s.mover_point(0, *k)),
                    Corner::Centres(t) => 1.0 / gauge(t[0]),
                })
                .collect()
        };
        (
            smallest_factor(&s, &w, &mut solve, &|_| Some(0.0), tolerance),
            exact,
        )
    };
    let run = |gauge: &dyn Fn(DVec3) -> f64, nan_at: Option<usize>| run_within(gauge, nan_at, 0.0);
    let stretch = DMat3::from_diagonal(DVec3::new(1.0, 3.0, 0.5));
    type Gauge<'a> = Box<dyn Fn(DVec3) -> f64 + 'a>;
    let cases: Vec<(&str, Gauge)> = vec![
        ("flat", Box::new(|_| 0.2)),
        (
            "tilted",
            Box::new(|c: DVec3| 0.1 + 0.01 * (c - pivot).x.abs()),
        ),
        (
            "peaked inside",
            Box::new(move |c: DVec3| {
                0.05 + 0.02 * (stretch * (c - (pivot - 3.0 * middle))).length()
            }),
        ),
        (
            "round",
            Box::new(move |c: DVec3| 0.1 + 0.03 * (c - (pivot - middle)).length()),
        ),
    ];
    for (name, gauge) in &cases {
        let (o, exact) = run(gauge.as_ref(), None);
        assert!(
            o.smallest <= exact && o.smallest >= exact * (1.0 - 1e-7),
            "{name}: {} against {exact}",
            o.smallest
        );
        assert!(!o.partial && o.lower == o.smallest, "{name}");
        assert!(o.solves < 2 * n - 1, "{name}: {} analyses", o.solves);
        if *name == "flat" {
            assert_eq!(o.solves, 3);
        }
    }
    // The interior minimum is a tangent pose near the middle, found.
    let (o, exact) = run(cases[2].1.as_ref(), None);
    let at = o.poses.iter().find(|(_, v)| *v == exact).map(|(k, _)| *k);
    assert!(at.is_some_and(|k| k > n && k < 2 * n - 2), "{at:?}");
    // Failing inside the sweep: below 1, and the lower end no higher.
    let failing = |c: DVec3| 0.5 + 0.5 * (stretch * (c - (pivot - 3.0 * middle))).length();
    let (o, exact) = run(&failing, None);
    assert!(
        exact < 1.0 && o.smallest < 1.0 && o.lower <= exact,
        "{o:?} {exact}"
    );
    // A failed solve sticks.
    let (o, _) = run(cases[3].1.as_ref(), Some(12));
    assert!(o.smallest.is_nan(), "{o:?}");
    // A load-factor tolerance spares runs within it: fewer analyses, and
    // the exact smallest within [lower, smallest], lower at most the
    // tolerance under the factor.
    let (exact_run, exact) = run(cases[2].1.as_ref(), None);
    let (o, _) = run_within(cases[2].1.as_ref(), None, 0.05);
    assert!(
        o.solves < exact_run.solves,
        "{} against {}",
        o.solves,
        exact_run.solves
    );
    assert!(o.lower <= exact && exact <= o.smallest, "{o:?} {exact}");
    assert!(o.lower >= 0.95 * o.smallest, "{o:?}");
}

/// Two groups turning at different rates, factors in closed form (`1/λ`
/// convex in both movers' centres). A run's bound weighs its hull's
/// corners by the groups' coupling, so it is tighter than their smallest,
/// but never above the smallest pose: the bisection reports the smallest
/// of the 193 poses within the pruning slack, from fewer analyses. Poses
/// the screen cleared (`floor` None), here the lowest ones on purpose,
/// never count, even where solved as a corner: the factor is then the
/// smallest of the others.
#[test]
fn the_sweep_bisection_of_two_groups_finds_the_smallest_of_convex_factors_and_never_counts_a_cleared_pose()
 {
    use super::sweep_bisection::{Corner, smallest_factor, sweep};
    use glam::DMat3;
    let s = two_group_swing(7, false);
    let w = sweep(&s).expect("two groups, 25 samples");
    assert_eq!((w.groups, w.per_interval), (2, 7));
    let poses = w.n + s.between.len();
    let pivot = [0, 1].map(|h| s.bodies[s.hanging[h].pivot].centre);
    let middle = [0, 1].map(|h| s.hanging[h].path[12] - pivot[h]);
    let at = |k: usize| [s.mover_point(0, k), s.mover_point(1, k)];
    let stretch = DMat3::from_diagonal(DVec3::new(1.0, 3.0, 0.5));
    type Gauge<'a> = Box<dyn Fn([DVec3; 2]) -> f64 + 'a>;
    let cases: Vec<(&str, Gauge)> = vec![
        ("flat", Box::new(|_| 0.2)),
        (
            "each its own",
            Box::new(move |c: [DVec3; 2]| {
                0.05 + 0.02 * (stretch * (c[0] - (pivot[0] - 3.0 * middle[0]))).length()
                    + 0.01 * (c[1] - (pivot[1] + 2.0 * middle[1])).length()
            }),
        ),
        (
            "coupled",
            Box::new(move |c: [DVec3; 2]| {
                0.1 + 0.03 * (stretch * (c[0] - c[1] - (pivot[0] - pivot[1]))).length()
            }),
        ),
        (
            "at an end",
            Box::new(move |c: [DVec3; 2]| 0.1 + 0.02 * (c[0] - pivot[0] + middle[0]).length()),
        ),
    ];
    for (name, gauge) in &cases {
        let factor = |k: usize| 1.0 / gauge(at(k));
        let mut by_factor: Vec<usize> = (0..poses).collect();
        by_factor.sort_by(|&a, &b| factor(a).total_cmp(&factor(b)));
        // Every pose wanted, then the lowest 10 cleared.
        for cleared in [0, 10] {
            let gone: FxHashSet<usize> = by_factor[..cleared].iter().copied().collect();
            let exact = (0..poses)
                .filter(|k| !gone.contains(k))
                .map(factor)
                .fold(f64::INFINITY, f64::min);
            let mut solve = |corners: &[Corner]| -> Vec<f64> {
                corners
                    .iter()
                    .map(|c| match c {
                        Corner::Pose(k) => factor(*k),
                        Corner::Centres(t) => 1.0 / gauge([t[0], t[1]]),
                    })
                    .collect()
            };
            let floor = |k: usize| (!gone.contains(&k)).then_some(0.0);
            let o = smallest_factor(&s, &w, &mut solve, &floor, 0.0);
            assert!(
                o.smallest <= exact && o.smallest >= exact * (1.0 - 1e-7),
                "{name}, {cleared} cleared: {} against {exact}",
                o.smallest
            );
            assert!(!o.partial && o.lower == o.smallest, "{name}");
            assert!(o.poses.iter().all(|(k, _)| !gone.contains(k)), "{name}");
            assert!(
                o.solves < poses,
                "{name}, {cleared} cleared: {} analyses",
                o.solves
            );
        }
    }
}

/// A pose's elastic bound (`floor`) that reaches the smallest factor
/// found spares its run: with every pose's exact factor as its floor, the
/// bisection solves the two end samples and nothing else, and still
/// reports the smallest.
#[test]
fn a_run_whose_poses_elastic_bounds_reach_the_smallest_found_is_not_solved() {
    use super::sweep_bisection::{Corner, smallest_factor, sweep};
    let s = wall_swing(7, Cell::new(7, 1, 1), false, false);
    let w = sweep(&s).expect("one mover");
    // Lowest at the first sample (no corner is solved, so the factor
    // need not be a convex gauge's).
    let first = s.hanging[0].path[0];
    let factor = |c: DVec3| 2.0 + (c - first).length();
    let mut solve = |corners: &[Corner]| -> Vec<f64> {
        corners
            .iter()
            .map(|c| match c {
                Corner::Pose(k) => factor(s.mover_point(0, *k)),
                Corner::Centres(t) => factor(t[0]),
            })
            .collect()
    };
    let floor = |k: usize| Some(factor(s.mover_point(0, k)));
    let o = smallest_factor(&s, &w, &mut solve, &floor, 0.0);
    assert_eq!(o.solves, 2, "{o:?}");
    assert_eq!(o.smallest, 2.0);
}

#[test]
fn a_load_factor_tolerance_skips_poses_within_its_bound_whatever_the_threads() {
    let model = Model::default_catom();
    let on = |threads: usize, s: &Structure, tolerance: f64| {
        let mut a = Analyzer::new(model.clone(), false);
        a.settings.load_factor_tolerance = tolerance;
        // Exact against every pose (the bisection, which applies only
        // without a tolerance, is tested above).
        a.settings.bisect_sweeps = false;
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| a.analyse(s))
    };
    // τ = 0.01 solves several poses per step, so which poses a solved
    // field spares matters: counting fields of poses solved ahead before
    // the sequential logic reaches them fails here.
    let cases = [(7, Cell::new(7, 1, 1)), (8, Cell::new(8, 0, 2))];
    for ((n, to), tau) in cases.into_iter().flat_map(|c| [(c, 0.05), (c, 0.01)]) {
        for mirror in [false, true] {
            let s = deep_swing(n, to, mirror);
            let exact = on(1, &s, 0.0);
            let lambda = exact.load_factor.expect("judged by the limit analysis");
            // 25 samples, and the 24 tangent poses between them (one
            // mover: each interval's triangle), none cleared elastically;
            // the samples between two tangent poses are not solved.
            assert!(lambda > 1.0 && exact.limit_analyses == 26, "{lambda}");
            assert_eq!(exact.between_poses, 24);
            let spared = on(1, &s, tau);
            let skipping = spared.load_factor.unwrap();
            assert_eq!(spared.verdict(), exact.verdict());
            assert!(spared.limit_analyses < exact.limit_analyses);
            // The reported factor is at most 1/(1 − τ) above the exact one,
            // never below it.
            assert!(skipping >= lambda * (1.0 - 1e-9), "{skipping} < {lambda}");
            assert!(
                skipping * (1.0 - tau) <= lambda * (1.0 + 1e-9),
                "{skipping} vs {lambda}"
            );
            // The proven lower bound brackets the exact factor from below,
            // no looser than the tolerance; an exact run reports none.
            let lower = spared.load_factor_lower.expect("a lower bound with τ");
            assert!(lower <= lambda * (1.0 + 1e-9), "{lower} > {lambda}");
            assert!(lower >= skipping * (1.0 - tau) * (1.0 - 1e-9), "{lower}");
            assert!(lower < skipping, "some pose was spared: {lower}");
            assert_eq!(exact.load_factor_lower, None);
            // Waves of poses solved ahead on idle threads change nothing.
            let t = on(3, &s, tau);
            assert_eq!(t.load_factor.map(f64::to_bits), Some(skipping.to_bits()));
            assert_eq!(t.limit_analyses, spared.limit_analyses);
            assert_eq!(t.load_factor_lower.map(f64::to_bits), Some(lower.to_bits()));
            let e = on(3, &s, 0.0);
            assert_eq!(e.load_factor.map(f64::to_bits), Some(lambda.to_bits()));
        }
    }
}

#[test]
fn a_limit_analysis_starts_where_the_last_first_pose_was_solved_and_gives_the_same_factor() {
    // A 3 × 3 × 2-tile frame at an eighth of the adhesion, judged by the
    // limit analysis (λ = 1.35), which stalls at clarabel's own
    // regularisation (limit::SETTINGS) and is solved at the next setting
    // (the 2 × 2 × 2 frame, at this adhesion, is solved at 1e-8).
    let mut model = Model::default_catom();
    model.connector.pressure /= 8.0;
    let s = frame(3, 2);
    let mut analyzer = Analyzer::new(model.clone(), false);
    assert_eq!(analyzer.limit_setting(), 0);
    let first = analyzer.analyse(&s);
    assert!(first.limit_analyses >= 1, "{}", first.limit_analyses);
    assert_eq!(analyzer.limit_setting(), 1);
    // The next analysis starts there: one try instead of two, and the
    // same solve, so the same factor to the bit.
    let again = analyzer.analyse(&s);
    assert_eq!(again.load_factor, first.load_factor);
    assert!(first.load_factor.unwrap() > 1.0, "{:?}", first.load_factor);
    assert_eq!(analyzer.limit_setting(), 1);
}

#[test]
fn with_the_limit_analysis_off_a_component_the_screen_cannot_clear_is_bounded_from_above() {
    // A 2 × 2 × 2-tile frame the elastic screen cannot clear, holding
    // plastically (an eighth of the adhesion) and failing (a sixteenth):
    // without the limit analysis its utilisation is the screen's bound,
    // never below the proved 1/λ, and nothing is proved (`bounded`).
    let s = frame(2, 2);
    for divisor in [8.0, 16.0] {
        let mut model = Model::default_catom();
        model.connector.pressure /= divisor;
        let proved = Analyzer::new(model.clone(), false).analyse(&s);
        let mut analyzer = Analyzer::new(model, false);
        analyzer.settings.limit_analysis = false;
        // The elastic bound alone (a region's limit analysis tightens it:
        // the next test).
        analyzer.settings.region_hops = 0;
        let bounded = analyzer.analyse(&s);
        assert!(
            proved.limit_analyses >= 1 && proved.bounded == 0,
            "{proved:?}"
        );
        assert_eq!((bounded.limit_analyses, bounded.bounded), (0, 1));
        let lambda = proved.load_factor.expect("judged by the limit analysis");
        assert_eq!(lambda > 1.0, divisor == 8.0, "{divisor}: λ = {lambda}");
        assert!(
            (proved.max_utilisation - 1.0 / lambda).abs() <= 1e-12 * proved.max_utilisation,
            "{divisor}: {} against 1/λ = {}",
            proved.max_utilisation,
            1.0 / lambda
        );
        assert!(
            bounded.max_utilisation >= proved.max_utilisation,
            "{divisor}: bound {} below the proved {}",
            bounded.max_utilisation,
            proved.max_utilisation
        );
        assert!(
            bounded.max_utilisation > 1.0,
            "the screen failed: its bound is above 1"
        );
    }
}

#[test]
fn a_region_bound_proved_at_the_corners_of_the_poses_hull_holds_at_every_pose() {
    // One mover swinging 90° at the tip of a branch (every pose failing at
    // a fifth of the adhesion), and a block resting on the ground with a
    // mover on its top (at a fortieth): the region's bound from the three
    // corners of the triangle around the poses' moment changes is never
    // below the proved 1/λ of any pose (the limit analysis of each pose
    // alone), and it took three region analyses where pose by pose takes
    // one per pose.
    let base = Model::default_catom();
    let branch = swing(4, Cell::new(5, 0, 0), Cell::new(4, 1, 0), Route::Octagonal);
    let resting = block_with_a_mover_on_top();
    let bounded = |model: &Model, s: &Structure| {
        let mut analyzer = Analyzer::new(model.clone(), false);
        analyzer.settings.limit_analysis = false;
        analyzer.settings.region_hops = 1;
        analyzer.analyse(s)
    };
    for (s, divisors) in [
        (&branch, [5.0; 1].to_vec()),
        (&resting, vec![40.0, 100.0, 300.0, 1000.0]),
    ] {
        // The first adhesion, weakest last, at which the screen fails.
        let weak = |d: f64| {
            let mut model = base.clone();
            model.connector.pressure /= d;
            model
        };
        let divisor = *divisors
            .iter()
            .find(|&&d| bounded(&weak(d), s).bounded > 0)
            .expect("the screen fails at some adhesion");
        let model = weak(divisor);
        let n = s.hanging[0].path.len();
        assert!(n > 3, "{n} poses");
        let proved = per_pose_proved(&model, s);
        let a = bounded(&model, s);
        assert_eq!(
            a.region_analyses, 3,
            "{divisor}: the poses' hull was not used"
        );
        assert!(
            a.max_utilisation >= proved * (1.0 - 1e-9),
            "{divisor}: bound {} below the proved {proved}",
            a.max_utilisation
        );
        assert!(
            a.max_utilisation <= 1.5 * proved,
            "{divisor}: bound {} against the proved {proved}",
            a.max_utilisation
        );
    }
}

/// The largest proved 1/λ over `s`'s poses, each analysed alone (the
/// mover held there) by the limit analysis.
fn per_pose_proved(model: &Model, s: &Structure) -> f64 {
    let n = s.hanging[0].path.len();
    (0..n)
        .map(|k| {
            let mut t = s.clone();
            t.hanging[0].path = vec![s.hanging[0].path[k]];
            t.hanging[0].hull.clear();
            let mut a = Analyzer::new(model.clone(), false);
            a.settings.envelope = false;
            a.analyse(&t).max_utilisation
        })
        .fold(0.0, f64::max)
}

/// `s` analysed with the limit analysis off and a region of `hops` links
/// around the overloaded ones (0: the elastic bound alone).
fn bound_with_region(model: &Model, s: &Structure, hops: usize) -> f64 {
    let mut analyzer = Analyzer::new(model.clone(), false);
    analyzer.settings.limit_analysis = false;
    analyzer.settings.region_hops = hops;
    let a = analyzer.analyse(s);
    assert_eq!(a.limit_analyses, 0);
    a.max_utilisation
}

#[test]
fn a_region_limit_analysis_tightens_the_screens_bound_and_never_passes_the_proved_one() {
    // The frame the screen cannot clear, holding (an eighth of the
    // adhesion) and failing (a sixteenth): the bound from a region around
    // the overloaded links lies between the proved 1/λ and the elastic
    // bound, strictly below the latter (the region redistributes), and
    // with the whole frame as the region it is the proved 1/λ.
    let s = frame(2, 2);
    for divisor in [8.0, 16.0] {
        let mut model = Model::default_catom();
        model.connector.pressure /= divisor;
        let proved = Analyzer::new(model.clone(), false)
            .analyse(&s)
            .max_utilisation;
        let elastic = bound_with_region(&model, &s, 0);
        let mut last = elastic;
        for hops in 1..=3 {
            let bound = bound_with_region(&model, &s, hops);
            assert!(
                bound >= proved * (1.0 - 1e-9),
                "{divisor}, {hops} hops: bound {bound} below the proved {proved}"
            );
            assert!(
                bound <= elastic,
                "{divisor}, {hops} hops: {bound} > {elastic}"
            );
            last = last.min(bound);
        }
        assert!(
            last < 0.9 * elastic,
            "{divisor}: the region tightened {elastic} only to {last}"
        );
        let whole = bound_with_region(&model, &s, 1000);
        assert!(
            (whole - proved).abs() <= 1e-6 * proved,
            "{divisor}: whole frame {whole} against the proved {proved}"
        );
    }
}

/// A wall two layers high (x = 0 … `n`), fixed at x = 0, or (`resting`)
/// on the ground beside a second row with nothing fixed, and a crowd on
/// its top: two movers on every module of the top layer, rolling over it
/// from one cell above to another, one across a 90° link and (`two`) one
/// across a 60° link by the hexagonal route — one or two groups turning at
/// one rate, however many movers. `mirror` reflects it in y = 0.
fn crowded_wall(n: i32, resting: bool, mirror: bool, two: bool) -> Structure {
    let l = FccLattice;
    let flip = |c: Cell| if mirror { Cell::new(c.x, -c.y, c.z) } else { c };
    let mut cells: Vec<Cell> = (0..2)
        .flat_map(|z| (0..=n).map(move |x| flip(Cell::new(x, 0, z))))
        .collect();
    if resting {
        cells.extend((0..=n).map(|x| flip(Cell::new(x, -1, 0))));
    }
    // Two cells above a pivot whose directions from it meet at `cos`.
    let above = |pivot: Cell, cos: f64| -> (Cell, Cell) {
        let up: Vec<Cell> = (0..12)
            .map(|i| l.neighbour(pivot, i))
            .filter(|c| c.z == pivot.z + 1)
            .collect();
        let dir = |c: Cell| (l.centre(c) - l.centre(pivot)).normalize();
        up.iter()
            .flat_map(|&a| up.iter().map(move |&b| (a, b)))
            .find(|&(a, b)| (dir(a).dot(dir(b)) - cos).abs() < 1e-9)
            .expect("a pair of cells above the pivot")
    };
    let mut movers: Vec<MoverSpec> = Vec::new();
    let first_id = cells.len() as ModuleId + 1;
    for x in 0..=n {
        let pivot = flip(Cell::new(x, 0, 1));
        let pivot_id = (n + 1 + x) as ModuleId + 1;
        let links = if two {
            vec![(0.0, Route::Octagonal), (0.5, Route::Hexagonal)]
        } else {
            vec![(0.0, Route::Octagonal); 2]
        };
        for (cos, route) in links {
            let (from, to) = above(pivot, cos);
            movers.push((
                first_id + movers.len() as ModuleId,
                Some(pivot_id),
                Motion::Rotate {
                    from,
                    to,
                    pivot,
                    route,
                },
            ));
        }
    }
    if resting {
        structure(&l, Some(Ground { layer: 0 }), &cells, &[], &movers)
    } else {
        structure(&l, None, &cells, &[0], &movers)
    }
}

/// The analysis of `s`, its poses superposed from the groups' unit load
/// cases or (`superpose` off) each solved alone.
fn superposed(model: &Model, s: &Structure, superpose: bool) -> super::analysis::Analysis {
    let mut a = tight(model.clone());
    a.settings.superpose = superpose;
    a.analyse(s)
}

/// Superposing a crowd of movers from a few unit load cases per group
/// (`superposition`) gives every sampled pose the field of its own solve:
/// the same worst utilisation of every link, the same verdict and factor,
/// on a fixed root, its mirror image and a wall resting on the ground (its
/// contacts released at the reference pose either way); and it judges the
/// poses between samples that solving pose by pose leaves unjudged.
#[test]
fn a_crowd_superposed_by_groups_gives_every_sampled_pose_its_own_solve() {
    use super::analysis::SampledOnly;
    let model = Model::default_catom();
    for (n, resting, mirror, two) in [
        (5, false, false, true),
        (5, false, true, true),
        (4, true, false, true),
        (6, false, false, false),
    ] {
        let s = crowded_wall(n, resting, mirror, two);
        let movers = s.hanging.len();
        assert_eq!(
            (movers, s.groups()),
            (2 * (n as usize + 1), 1 + two as usize)
        );
        let (by_groups, alone) = (superposed(&model, &s, true), superposed(&model, &s, false));
        let case = format!("n {n} resting {resting} mirror {mirror} two {two}");
        assert_eq!(by_groups.verdict(), alone.verdict(), "{case}");
        let (u, v) = (by_groups.max_utilisation, alone.max_utilisation);
        assert!(u.is_finite() && u > 0.01, "{case}: {u}");
        match (by_groups.load_factor, alone.load_factor) {
            (None, None) => assert!((u - v).abs() <= 1e-9 * v, "{case}: {u} against {v}"),
            // Poses between samples may lower the smallest factor: never
            // raise it (the enumeration is the next test's).
            (Some(a), Some(b)) => assert!(a <= b * (1.0 + 1e-7), "{case}: {a} against {b}"),
            other => panic!("{case}: {other:?}"),
        }
        for (a, b) in by_groups.links.iter().zip(&alone.links) {
            // (A ground contact the elastic field pulls: ∞ in both.)
            assert!(
                a.utilisation == b.utilisation || (a.utilisation - b.utilisation).abs() <= 1e-9 * v,
                "{case}: a link at {} against {}",
                a.utilisation,
                b.utilisation
            );
        }
        assert!(by_groups.sampled_only.is_empty(), "{case}");
        assert_eq!(
            alone.sampled_only,
            vec![SampledOnly::PoseByPose { movers }],
            "{case}"
        );
    }
}

/// The load factor of `s` with every mover held at pose `k` (a sample or
/// a pose between samples, `Structure::mover_point`), no path beyond it;
/// `None` where the elastic screen clears it.
fn factor_at_pose(model: &Model, s: &Structure, k: usize) -> Option<f64> {
    let mut one = s.clone();
    for h in 0..one.hanging.len() {
        one.hanging[h].path = vec![s.mover_point(h, k)];
        one.hanging[h].hull.clear();
    }
    one.between.clear();
    Analyzer::new(model.clone(), false)
        .analyse(&one)
        .load_factor
}

/// Where the smallest load factor of a crowd's sweep lies between two
/// samples, superposition finds it and solving pose by pose does not: with
/// the connectors' pressure set between the two, the samples alone hold
/// and a pose between them does not. The crowd turns at two rates on a
/// wall resting on the ground; every one of its 193 poses (25 samples and
/// the 168 corners between them) is analysed alone here, the crowd held
/// at it.
#[test]
fn a_crowd_failing_only_between_its_samples_is_refused() {
    let base = Model::default_catom();
    let s = crowded_wall(4, true, false, true);
    assert_eq!(s.groups(), 2);
    let n = s.hanging[0].path.len();
    let m = n + s.between.len();
    let smallest = |model: &Model, poses: std::ops::Range<usize>| {
        poses
            .map(|k| factor_at_pose(model, &s, k).unwrap_or(f64::INFINITY))
            .fold(f64::INFINITY, f64::min)
    };
    let (samples, between) = (smallest(&base, 0..n), smallest(&base, n..m));
    assert!(between < samples, "{between} against {samples}");
    // The pressure at which the samples' smallest factor is
    // sqrt(samples / between) > 1 and the tangent poses' its inverse.
    let mut model = base.clone();
    model.connector.pressure *= 1.0 / (samples * between).sqrt();
    let at_between: Vec<f64> = (n..m)
        .map(|k| factor_at_pose(&model, &s, k).unwrap_or(f64::INFINITY))
        .collect();
    let samples = smallest(&model, 0..n);
    let between = at_between.iter().copied().fold(f64::INFINITY, f64::min);
    assert!(samples > 1.0 && between < 1.0, "{samples} {between}");
    let alone = Analyzer::new(model.clone(), false);
    let mut alone = alone;
    alone.settings.superpose = false;
    let a = alone.analyse(&s);
    assert_eq!(a.verdict(), Verdict::Stable, "the samples alone hold");
    let b = Analyzer::new(model.clone(), false).analyse(&s);
    assert_eq!(b.verdict(), Verdict::Overloaded);
    let lambda = b.load_factor.unwrap();
    assert!(
        (lambda - between).abs() <= 1e-5 * between,
        "{lambda} against {between}"
    );
    // The bisection keeps factors only; the failing pose it found is
    // solved again for its collapse mechanism, which names the connector
    // the worst pose analysed alone names.
    let worst = n
        + (0..at_between.len())
            .min_by(|&i, &j| at_between[i].total_cmp(&at_between[j]))
            .unwrap();
    let mut one = s.clone();
    for h in 0..one.hanging.len() {
        one.hanging[h].path = vec![s.mover_point(h, worst)];
        one.hanging[h].hull.clear();
    }
    one.between.clear();
    let alone = Analyzer::new(model.clone(), false).analyse(&one);
    let (m_b, m_alone) = (b.mechanism.unwrap(), alone.mechanism.unwrap());
    assert_eq!(
        m_b.links[0].0, m_alone.links[0].0,
        "{m_b:?} against {m_alone:?}"
    );
    assert_eq!(
        b.critical,
        Some(super::analysis::Critical::Link(m_b.links[0].0))
    );
}

/// A failing step usually fails at its worst pose: where the bisection
/// would take a sweep (every pose of two groups failing the screen), that
/// pose is solved first, alone, and the step is refused after that one
/// limit analysis, as the enumeration refuses it, with the same factor
/// and lower end; a holding sweep is bisected as before, the probe's pose
/// not solved twice.
#[test]
fn a_failing_sweep_is_refused_after_its_worst_pose_alone() {
    let base = Model::default_catom();
    let s = two_group_swing(7, false);
    let holding = bisected(&base, &s, true);
    assert_eq!(holding.verdict(), Verdict::Stable);
    assert!(holding.load_factor.is_some());
    // The weakest connectors that still leave a failing step's factor
    // well above 0.
    let mut weak = base.clone();
    let (a, full) = loop {
        weak.connector.pressure *= 0.8;
        let full = bisected(&weak, &s, false);
        if full.verdict() == Verdict::Overloaded {
            break (bisected(&weak, &s, true), full);
        }
        assert!(weak.connector.pressure > 1e-3 * base.connector.pressure);
    };
    assert_eq!(a.verdict(), Verdict::Overloaded);
    assert_eq!(a.limit_analyses, 1);
    assert_eq!(full.limit_analyses, 1);
    assert_eq!(a.load_factor, full.load_factor);
    assert_eq!(a.load_factor_lower, full.load_factor_lower);
    assert!(a.load_factor_partial);
    // Every pose alone: none lower than the reported lower end.
    let every = (0..s.hanging[0].path.len() + s.between.len())
        .map(|k| factor_at_pose(&weak, &s, k).unwrap())
        .fold(f64::INFINITY, f64::min);
    let lower = a.load_factor_lower.unwrap();
    assert!(lower <= every * (1.0 + 1e-5), "{lower} against {every}");
    assert!(a.load_factor.unwrap() >= every * (1.0 - 1e-5));
}

/// A stepped tower resting on the ground (nothing fixed, no adhesion
/// there) and an arm of `n` modules held by one connector at its top, the
/// arm along −x, or along +x in the mirror image (`x ↦ −x`). Returns the
/// cells and the index of the top module (the arm's are the last `n`).
fn tower_with_arm(n: i32, mirror: bool) -> (Vec<Cell>, usize) {
    // Centres: (x + ½p, y + ½p) with p the layer's parity; the mirror
    // maps an even layer's x to −x and an odd layer's to −x − 1.
    let m = |x: i32, y: i32, z: i32| {
        let x = if !mirror {
            x
        } else if z % 2 == 0 {
            -x
        } else {
            -x - 1
        };
        Cell::new(x, y, z)
    };
    let mut cells = Vec::new();
    for x in 0..4 {
        for y in 0..4 {
            cells.push(m(x, y, 0));
        }
    }
    for x in 0..3 {
        for y in 0..3 {
            cells.push(m(x, y, 1));
        }
    }
    for (x, y) in [(2, 1), (3, 1), (2, 2), (3, 2)] {
        cells.push(m(x, y, 2));
    }
    // The top, over the layer-2 cells at centres x = 2 only: the arm's
    // first module (centre x = ½) has nothing below it.
    let top = cells.len();
    cells.push(m(1, 1, 3));
    for i in 1..=n {
        cells.push(m(1 - i, 1, 3));
    }
    (cells, top)
}

/// Where a structure resting on the ground fails by the limit analysis,
/// the critical link is where its collapse mechanism opens, checked
/// against the upper-bound theorem computed here by hand: the arm turns
/// as one body about the horizontal line through the lowest corner(s) of
/// its root square; each corner pulls `pL²/4` (rigid hinge) over the
/// opening its height above that line gives, against the arm's weight
/// times its lever. The limit analysis's factor (a lower bound) must equal
/// it (to 10⁻¹³ as measured) and its mechanism must put the whole
/// dissipated work at the root, in the tower as built and in its mirror
/// image. (The arm is determinate, so the elastic estimate peaks at the
/// root too, at utilisation 2; the mechanism is what names it where the
/// screen left no estimate, as in the 20-meta-module RePoSt L → C's step
/// 159, `docs/mechanics.md`.)
#[test]
fn a_resting_tower_whose_arm_breaks_names_the_root_its_collapse_mechanism_opens() {
    use super::analysis::Critical;
    for mirror in [false, true] {
        let n = 3;
        let (cells, top) = tower_with_arm(n, mirror);
        let ground = Some(Ground { layer: 0 });
        let s = structure(&FccLattice, ground, &cells, &[], &[]);
        // The premise: the arm's root module is held by the top alone, and
        // nothing is fixed.
        let first = top + 1;
        let (top_id, first_id) = (top as ModuleId + 1, first as ModuleId + 1);
        let root = link_between(&s, top_id, first_id);
        let at_first = s
            .links
            .iter()
            .filter(|l| {
                let b = s.body_of(first_id).unwrap();
                l.a == b || l.b == super::structure::End::Body(b)
            })
            .count();
        assert_eq!(at_first, 2, "the root and the next arm module");
        assert!(s.bodies.iter().all(|b| !b.fixed));
        // The upper bound by hand, at a pressure that makes it 1/2.
        let base = Model::default_catom().with_connector(1.0, Bending::RigidHinge);
        let (w, d) = (base.weight(), base.spacing);
        let side = base.connector.side;
        let l = &s.links[root];
        let h = 0.5 * side / d;
        let z: Vec<f64> = [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)]
            .iter()
            .map(|(a, b)| (l.contact + h * (a * l.u + b * l.v)).z)
            .collect();
        let z_min = z.iter().copied().fold(f64::INFINITY, f64::min);
        let openings: f64 = z.iter().map(|zk| (zk - z_min) * d).sum();
        let x_hinge = l.contact.x;
        let lever: f64 = (0..n as usize)
            .map(|i| (FccLattice.centre(cells[first + i]).x - x_hinge).abs() * d)
            .sum();
        // λ = p·(L²/4)·Σ openings / (W·Σ levers) = 1/2.
        let pressure = 0.5 * w * lever / (side * side / 4.0 * openings);
        let model = base.with_connector(pressure, Bending::RigidHinge);
        let a = tight(model).analyse(&s);
        assert_eq!(a.verdict(), Verdict::Overloaded, "mirror {mirror}");
        let lf = a.load_factor.expect("the limit analysis judged it");
        assert!(
            (lf - 0.5).abs() <= 1e-5,
            "mirror {mirror}: λ = {lf} against 0.5"
        );
        assert_eq!(a.critical, Some(Critical::Link(root)), "mirror {mirror}");
        let m = a
            .mechanism
            .expect("a failing limit analysis has a mechanism");
        assert_eq!(m.links[0].0, root);
        assert!(m.links[0].1 >= 0.999, "mirror {mirror}: {:?}", m.links);
        let total: f64 = m.links.iter().map(|x| x.1).sum();
        assert!((0.999..=1.0 + 1e-9).contains(&total), "{total}");
    }
}

/// Where a structure resting on the ground falls as a whole, the witness
/// is its weight against its support polygon, checked by hand: with equal
/// modules and nothing moving, the weight acts at the mean of the module
/// centres, which a long arm carries past the slab's edge; the distance
/// outside is that mean's x against the outermost ground-contact corner
/// (the slab's edge is parallel to y and the mean lies at its middle, y =
/// 1.5). Connectors too strong to break, so only the balance fails — as
/// built and mirrored. (With 12 arm modules the mean lies at x = −0.26,
/// past the slab's centres but over its lower faces' squares, which reach
/// further out: the tower stands, as it must.)
#[test]
fn a_resting_tower_tipped_by_its_arm_reports_its_weight_outside_its_ground_contacts() {
    let strong = Model::default_catom().with_connector(1e9, Bending::RigidHinge);
    let (cells, _) = tower_with_arm(12, false);
    let s = structure(&FccLattice, Some(Ground { layer: 0 }), &cells, &[], &[]);
    let a = tight(strong).analyse(&s);
    assert_eq!(a.verdict(), Verdict::Stable, "12 arm modules: it stands");
    assert!(a.tipping.is_none());
    for mirror in [false, true] {
        let (cells, _) = tower_with_arm(13, mirror);
        let ground = Some(Ground { layer: 0 });
        let s = structure(&FccLattice, ground, &cells, &[], &[]);
        let model = Model::default_catom().with_connector(1e9, Bending::RigidHinge);
        let half = 0.5 * model.ground.side / model.spacing;
        let a = tight(model).analyse(&s);
        assert_eq!(a.verdict(), Verdict::NoEquilibrium, "mirror {mirror}");
        let n = cells.len() as f64;
        let mean = cells.iter().map(|&c| FccLattice.centre(c)).sum::<DVec3>() / n;
        // The outermost corner of the ground contacts on the arm's side.
        let corners = s.links.iter().filter(|l| l.is_ground()).flat_map(|l| {
            [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)]
                .map(|(p, q)| (l.contact + half * (p * l.u + q * l.v)).x)
        });
        let expected = if mirror {
            mean.x - corners.fold(f64::NEG_INFINITY, f64::max)
        } else {
            corners.fold(f64::INFINITY, f64::min) - mean.x
        };
        assert!(
            expected > 0.05,
            "the premise: the weight is outside ({expected})"
        );
        let t = a.tipping.expect("a tipping witness");
        assert!(
            (t.outside - expected).abs() < 1e-9,
            "mirror {mirror}: {} against {expected}",
            t.outside
        );
        assert!((t.weight_at_ground.x - mean.x).abs() < 1e-9);
        assert!((t.weight_at_ground.y - 1.5).abs() < 1e-9);
        // The four lower faces of each of the slab's 16 modules.
        assert_eq!(t.contacts, 64);
    }
}
