//! Structures resting on the ground (nothing fixed), judged against an
//! independent formulation written here: a plain LP over corner forces of
//! the same contact squares, with a polyhedral friction pyramid, solved for
//! feasibility — or, on the square lattice's flat ground, the exact rule
//! that the centre of mass lies over the support.
//!
//! The LP here shares nothing with [`super::limit`] but the contact list:
//! forces live at the four corners of each contact square (not as
//! resultants), friction is an octagonal pyramid per corner (inscribed in
//! the cone, or circumscribed about it — the two bracket the exact cone),
//! and each case asserts that the bracket is decisive before it compares.

use super::analysis::{Analyzer, Verdict};
use super::model::Model;
use super::structure::{End, Structure};
use super::validation::structure;
use crate::lattice::config::Ground;
use crate::lattice::{Cell, FccLattice, Lattice, SquareLattice};
use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, NonnegativeConeT, SolverStatus,
    SupportedConeT, ZeroConeT,
};
use glam::DVec3;
use proptest::prelude::*;

/// How the test LP treats connectors between modules.
#[derive(Copy, Clone, PartialEq)]
enum Joints {
    /// Any force at every corner: the structure stands or tips as a whole.
    Rigid,
    /// Corners push but never pull, friction as on the ground: what stands
    /// without any connector adhesion.
    NoTension,
    /// The model's rigid-hinge connectors: each corner pulls at most its
    /// quarter of the adhesion, and rubs within μ times its clamp.
    Capacities,
}

/// Friction pyramid per corner: octagon inscribed in the cone (`Inner`,
/// stricter than the cone) or circumscribed about it (`Outer`, looser).
#[derive(Copy, Clone, PartialEq)]
enum Pyramid {
    Inner,
    Outer,
}

/// Whether some set of corner forces balances every module's weight.
fn lp_stands(s: &Structure, model: &Model, joints: Joints, pyramid: Pyramid) -> bool {
    let free: Vec<usize> = (0..s.bodies.len())
        .filter(|&i| !s.bodies[i].fixed)
        .collect();
    let mut row_of = vec![usize::MAX; s.bodies.len()];
    for (k, &i) in free.iter().enumerate() {
        row_of[i] = 6 * k;
    }
    let n_eq = 6 * free.len();
    let facets = 8;
    let kappa = match pyramid {
        Pyramid::Inner => 1.0,
        Pyramid::Outer => 1.0 / (std::f64::consts::PI / facets as f64).cos(),
    };
    // Per corner: the normal push c and the 8 friction multipliers β_k
    // (tangential force Σ β_k t_k, Σ β_k ≤ κ μ c), or, at a rigid joint,
    // a free normal force and two free tangential components.
    let (mut ri, mut ci, mut vals) = (Vec::new(), Vec::new(), Vec::new());
    let mut ineq: Vec<(Vec<(usize, f64)>, f64)> = Vec::new();
    let mut col = 0;
    for l in &s.links {
        let (cap, rigid) = match l.b {
            End::Ground(_) => (&model.ground, false),
            End::Body(_) => (&model.connector, joints == Joints::Rigid),
        };
        let half = 0.5 * cap.side / model.spacing;
        for (su, sv) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
            let corner = l.contact + half * (su * l.u + sv * l.v);
            // Unit forces on side a at this corner, one per column; side b
            // gets the opposite.
            let dirs: Vec<DVec3> = if rigid {
                vec![-l.normal, l.u, l.v]
            } else {
                let mut d = vec![-l.normal];
                for k in 0..facets {
                    let t = 2.0 * std::f64::consts::PI * k as f64 / facets as f64;
                    d.push(t.cos() * l.u + t.sin() * l.v);
                }
                d
            };
            for (j, f) in dirs.iter().enumerate() {
                for (body, sign) in [(Some(l.a), 1.0), (l.b.body(), -1.0)] {
                    let Some(b) = body.filter(|&b| row_of[b] != usize::MAX) else {
                        continue;
                    };
                    let m = (corner - s.bodies[b].centre).cross(*f);
                    for (a, v) in [f.x, f.y, f.z, m.x, m.y, m.z].into_iter().enumerate() {
                        if v != 0.0 {
                            ri.push(row_of[b] + a);
                            ci.push(col + j);
                            vals.push(sign * v);
                        }
                    }
                }
            }
            if !rigid {
                // c ≥ −a, β ≥ 0, Σβ ≤ κμ(c + a), with `a` the corner's
                // share of the adhesion (none on the ground or without
                // tension).
                let a = match (l.b, joints) {
                    (End::Body(_), Joints::Capacities) => cap.tension() / model.weight() / 4.0,
                    _ => 0.0,
                };
                ineq.push((vec![(col, -1.0)], a));
                for j in 1..dirs.len() {
                    ineq.push((vec![(col + j, -1.0)], 0.0));
                }
                let mut friction: Vec<(usize, f64)> =
                    (1..dirs.len()).map(|j| (col + j, 1.0)).collect();
                friction.push((col, -kappa * cap.friction));
                ineq.push((friction, kappa * cap.friction * a));
            }
            col += dirs.len();
        }
    }
    // Equilibrium: Σ link forces + λ·weight (ĝ·1 W at the centre) = 0;
    // maximise λ ≤ 1 (λ = 0, no forces, is always feasible).
    let lam = col;
    for &i in &free {
        let g = s.gravity;
        for (a, v) in [g.x, g.y, g.z].into_iter().enumerate() {
            if v != 0.0 {
                ri.push(row_of[i] + a);
                ci.push(lam);
                vals.push(v);
            }
        }
    }
    let mut rhs = vec![0.0; n_eq];
    ineq.push((vec![(lam, 1.0)], 1.0));
    let mut row = n_eq;
    for (terms, b) in &ineq {
        for &(c, v) in terms {
            ri.push(row);
            ci.push(c);
            vals.push(v);
        }
        rhs.push(*b);
        row += 1;
    }
    let ncol = col + 1;
    let a = CscMatrix::new_from_triplets(row, ncol, ri, ci, vals);
    let p = CscMatrix::<f64>::zeros((ncol, ncol));
    let mut q = vec![0.0; ncol];
    q[lam] = -1.0;
    let cones: Vec<SupportedConeT<f64>> = vec![ZeroConeT(n_eq), NonnegativeConeT(row - n_eq)];
    let settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .max_iter(400)
        .build()
        .unwrap();
    let mut solver = DefaultSolver::new(&p, &q, &a, &rhs, &cones, settings).unwrap();
    solver.solve();
    match solver.solution.status {
        SolverStatus::Solved | SolverStatus::AlmostSolved => solver.solution.x[lam] > 1.0 - 1e-6,
        other => panic!("test LP: {other:?}"),
    }
}

/// The test's verdict, which the friction bracket must decide.
fn independent(s: &Structure, model: &Model, joints: Joints) -> bool {
    let (inner, outer) = (
        lp_stands(s, model, joints, Pyramid::Inner),
        lp_stands(s, model, joints, Pyramid::Outer),
    );
    assert_eq!(
        inner, outer,
        "the friction bracket does not decide this case"
    );
    inner
}

fn stands(model: &Model, s: &Structure) -> bool {
    Analyzer::new(model.clone(), false).analyse(s).verdict() != Verdict::NoEquilibrium
}

fn fcc(cells: &[Cell]) -> Structure {
    structure(&FccLattice, Some(Ground { layer: 0 }), cells, &[], &[])
}

fn c(x: i32, y: i32, z: i32) -> Cell {
    Cell::new(x, y, z)
}

/// A base of three modules on the ground in a row along `step` and an arm
/// of `n` modules in layer 1 above it, running on along `step` past the
/// base's end: it overhangs more as `n` grows.
fn arm(n: i32, step: (i32, i32)) -> Vec<Cell> {
    let at = |k: i32, z: i32| {
        // Layer-1 cells sit at +½ in x and y: index them so the arm starts
        // over the base's last module in every direction.
        let o = if z == 1 {
            (step.0.min(0), step.1.min(0))
        } else {
            (0, 0)
        };
        c(k * step.0 + o.0, k * step.1 + o.1, z)
    };
    let mut cells: Vec<Cell> = (0..3).map(|k| at(k, 0)).collect();
    cells.extend((0..n).map(|k| at(2 + k, 1)));
    cells
}

/// The resting FCC cases: (name, cells).
fn fcc_cases() -> Vec<(String, Vec<Cell>)> {
    let mut v: Vec<(String, Vec<Cell>)> = vec![
        ("lone catom".into(), vec![c(0, 0, 0)]),
        ("pair on the ground".into(), vec![c(0, 0, 0), c(1, 0, 0)]),
        ("one on one".into(), vec![c(0, 0, 0), c(0, 0, 1)]),
        (
            "bridge of the issue".into(),
            vec![c(0, 0, 0), c(3, 0, 0), c(0, 0, 1), c(1, 0, 1), c(2, 0, 1)],
        ),
        (
            "long bridge".into(),
            [c(0, 0, 0), c(5, 0, 0)]
                .into_iter()
                .chain((0..5).map(|x| c(x, 0, 1)))
                .collect(),
        ),
        (
            "zig-zag tower".into(),
            vec![c(0, 0, 0), c(0, 0, 1), c(0, 0, 2), c(0, 0, 3)],
        ),
        (
            "leaning tower of 5".into(),
            vec![c(0, 0, 0), c(0, 0, 1), c(1, 1, 2), c(1, 1, 3), c(2, 2, 4)],
        ),
        (
            "T on two feet".into(),
            vec![c(0, 0, 0), c(1, 0, 0), c(0, 0, 1), c(1, 0, 1), c(-1, 0, 1)],
        ),
    ];
    for (name, step) in [
        ("+x", (1, 0)),
        ("+y", (0, 1)),
        ("-x", (-1, 0)),
        ("-y", (0, -1)),
    ] {
        for n in [1, 3, 5, 7] {
            v.push((format!("arm of {n} along {name}"), arm(n, step)));
        }
    }
    v
}

#[test]
fn resting_fcc_structures_stand_or_tip_as_the_independent_lp_says() {
    let model = Model::default_catom();
    let mut table = Vec::new();
    let (mut stood, mut tipped) = (0, 0);
    for (name, cells) in fcc_cases() {
        let s = fcc(&cells);
        let expected = independent(&s, &model, Joints::Rigid);
        let ours = stands(&model, &s);
        table.push(format!("{name}: LP {expected}, ours {ours}"));
        assert_eq!(ours, expected, "{name}");
        if expected { stood += 1 } else { tipped += 1 }
    }
    eprintln!("{}", table.join("\n"));
    // The cases exercise both verdicts.
    assert!(stood >= 5 && tipped >= 3, "{stood} stand, {tipped} tip");
}

#[test]
fn arms_tip_at_the_same_length_along_x_and_along_y() {
    let model = Model::default_catom();
    let tips_at = |step| (1..=12).find(|&n| !stands(&model, &fcc(&arm(n, step))));
    let x = tips_at((1, 0));
    assert!(x.is_some(), "a long enough arm must tip");
    for step in [(0, 1), (-1, 0), (0, -1)] {
        assert_eq!(tips_at(step), x, "{step:?}");
    }
}

#[test]
fn the_bridge_of_the_issue_stands_with_friction_and_slides_without_enough() {
    let s = fcc(&[c(0, 0, 0), c(3, 0, 0), c(0, 0, 1), c(1, 0, 1), c(2, 0, 1)]);
    let at = |mu: f64| {
        let mut m = Model::default_catom();
        m.ground.friction = mu;
        m
    };
    for (mu, expected) in [(0.1, false), (0.15, false), (0.3, true), (0.5, true)] {
        let m = at(mu);
        assert_eq!(
            independent(&s, &m, Joints::Rigid),
            expected,
            "LP at μ = {mu}"
        );
        assert_eq!(stands(&m, &s), expected, "ours at μ = {mu}");
    }
    // Standing, it is within capacity: stable, not overloaded.
    let a = Analyzer::new(at(0.5), false).analyse(&s);
    assert_eq!(a.verdict(), Verdict::Stable, "{a:?}");
}

#[test]
fn an_arm_stands_only_through_connector_adhesion() {
    // A module on one other: the upper one touches it by a single tilted
    // square whose centre is off its centre of mass, so with joints that
    // only push it rolls off; with rigid connectors the pair stands.
    let s = fcc(&[c(0, 0, 0), c(0, 0, 1)]);
    let model = Model::default_catom();
    assert!(independent(&s, &model, Joints::Rigid));
    assert!(!independent(&s, &model, Joints::NoTension));
    let a = Analyzer::new(model.clone(), false).analyse(&s);
    assert_eq!(a.verdict(), Verdict::Stable);
    // Take the adhesion away: it stands as a rigid body (not "no
    // equilibrium") but the connectors are overloaded.
    let weak = model.with_connector(1e-3, model.connector.bending);
    let a = Analyzer::new(weak, false).analyse(&s);
    assert_eq!(a.verdict(), Verdict::Overloaded, "{a:?}");
}

#[test]
fn a_lone_catom_stands_whatever_the_stiffness_ratio_and_ground_friction() {
    let s = fcc(&[c(0, 0, 0)]);
    for poisson in [0.0, 0.2, 0.35, 0.49] {
        for mu in [0.05, 0.37, 0.5, 1.0] {
            let mut m = Model::default_catom();
            m.poisson = poisson;
            m.ground.friction = mu;
            assert!(independent(&s, &m, Joints::Rigid));
            let a = Analyzer::new(m, false).analyse(&s);
            assert_eq!(
                a.verdict(),
                Verdict::Stable,
                "ν = {poisson}, μ = {mu}: {a:?}"
            );
            assert!(!super::overloaded(a.max_utilisation) && a.unsupported.is_empty());
        }
    }
}

/// Square lattice: the exact rule. With flat ground contacts (normal along
/// gravity) and rigid connectors, a structure stands iff its centre of
/// mass lies over the span of its ground contacts.
#[test]
fn resting_squares_stand_iff_the_centre_of_mass_is_over_the_support() {
    let model = Model::load(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("models/sliding-square.toml"),
    )
    .unwrap();
    let sq = |x: i32, y: i32| Cell::new(x, y, 0);
    let cases: Vec<Vec<Cell>> = vec![
        vec![sq(0, 0)],
        vec![sq(0, 0), sq(0, 1), sq(1, 1)],
        vec![sq(0, 0), sq(0, 1), sq(1, 1), sq(2, 1)],
        vec![sq(0, 0), sq(0, 1), sq(1, 1), sq(2, 1), sq(3, 1)],
        vec![sq(0, 0), sq(3, 0), sq(0, 1), sq(1, 1), sq(2, 1), sq(3, 1)],
        vec![sq(0, 0), sq(0, 1), sq(0, 2), sq(1, 2), sq(-1, 2)],
        vec![sq(0, 0), sq(0, 1), sq(-1, 1), sq(-2, 1), sq(-2, 2)],
        vec![sq(0, 0), sq(1, 0), sq(1, 1), sq(2, 1), sq(3, 1), sq(4, 1)],
    ];
    let (mut stood, mut tipped) = (0, 0);
    for cells in cases {
        let s = structure(&SquareLattice, Some(Ground { layer: 0 }), &cells, &[], &[]);
        let com = cells
            .iter()
            .map(|c| SquareLattice.centre(*c).x)
            .sum::<f64>()
            / cells.len() as f64;
        let feet: Vec<f64> = cells
            .iter()
            .filter(|c| c.y == 0)
            .map(|c| c.x as f64)
            .collect();
        let lo = feet.iter().cloned().fold(f64::INFINITY, f64::min) - 0.5;
        let hi = feet.iter().cloned().fold(f64::NEG_INFINITY, f64::max) + 0.5;
        assert!(
            (com - lo).abs() > 1e-6 && (com - hi).abs() > 1e-6,
            "marginal case"
        );
        let expected = com > lo && com < hi;
        assert_eq!(
            stands(&model, &s),
            expected,
            "{cells:?}: com {com} in [{lo}, {hi}]"
        );
        assert_eq!(
            independent(&s, &model, Joints::Rigid),
            expected,
            "{cells:?}"
        );
        if expected { stood += 1 } else { tipped += 1 }
    }
    assert!(stood >= 3 && tipped >= 2);
}

/// The images of a cell under the symmetries of the layered FCC lattice
/// that keep gravity and the ground: mirrors across x and y, the swap of
/// x and y, and the quarter turn about z (centres `(x + o, y + o, z/√2)`,
/// `o = ½·parity(z)`).
fn images(c: Cell) -> [Cell; 4] {
    let o = c.z.rem_euclid(2);
    [
        Cell::new(-c.x - o, c.y, c.z),
        Cell::new(c.x, -c.y - o, c.z),
        Cell::new(c.y, c.x, c.z),
        Cell::new(-c.y - o, c.x, c.z),
    ]
}

/// A random connected structure grown from a module on the ground.
fn grown(choices: &[(u8, u8)]) -> Vec<Cell> {
    let mut cells = vec![c(0, 0, 0)];
    for &(from, dir) in choices {
        let base = cells[from as usize % cells.len()];
        let n = FccLattice.neighbour(base, dir as usize % 12);
        if n.z >= 0 && n.z <= 3 && !cells.contains(&n) {
            cells.push(n);
        }
    }
    cells
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn lattice_symmetric_images_get_the_same_verdict_and_utilisations(
        choices in proptest::collection::vec((0u8..16, 0u8..12), 1..9),
    ) {
        let model = Model::default_catom();
        let cells = grown(&choices);
        let s = fcc(&cells);
        let a = Analyzer::new(model.clone(), false).analyse(&s);
        // Our stand/tip verdict is the independent LP's, where the
        // friction bracket decides.
        let (inner, outer) = (
            lp_stands(&s, &model, Joints::Rigid, Pyramid::Inner),
            lp_stands(&s, &model, Joints::Rigid, Pyramid::Outer),
        );
        if inner == outer {
            prop_assert_eq!(a.verdict() != Verdict::NoEquilibrium, inner, "{:?}", cells);
        }
        let mut sorted: Vec<f64> = a.links.iter().map(|r| r.utilisation).collect();
        sorted.sort_by(f64::total_cmp);
        for k in 0..4 {
            let image: Vec<Cell> = cells.iter().map(|&c| images(c)[k]).collect();
            let b = Analyzer::new(model.clone(), false).analyse(&fcc(&image));
            prop_assert_eq!(a.verdict(), b.verdict(), "image {} of {:?}", k, cells);
            if a.verdict() == Verdict::NoEquilibrium {
                // Nothing to compare but what tips.
                prop_assert_eq!(a.unsupported.len(), b.unsupported.len());
                continue;
            }
            // The elastic figures agree to 1e-9; those of the limit
            // analysis (interior point) to its tolerance.
            let tol = if a.load_factor.is_some() { 1e-6 } else { 1e-9 } * a.max_utilisation.max(1.0);
            prop_assert!((a.max_utilisation - b.max_utilisation).abs() <= tol,
                "image {}: {} vs {}", k, a.max_utilisation, b.max_utilisation);
            // Where the elastic screen was the witness its utilisations are
            // the report; where the limit analysis judged, its load factor.
            match (a.load_factor, b.load_factor) {
                (None, None) => {
                    let mut other: Vec<f64> = b.links.iter().map(|r| r.utilisation).collect();
                    other.sort_by(f64::total_cmp);
                    for (x, y) in sorted.iter().zip(&other) {
                        prop_assert!((x - y).abs() <= tol, "image {}: {} vs {}", k, x, y);
                    }
                }
                // Each factor is an interior-point solve that may stop at
                // its loosest accepted gap (1e-6, `limit::maximise`), so two
                // solves of mirrored programs differ by a few of those
                // (52.67116 against 52.67123 on a regression case).
                (Some(x), Some(y)) => prop_assert!(
                    (x - y).abs() <= 1e-5 * x.abs().max(1.0),
                    "image {}: λ {} vs {}", k, x, y
                ),
                (x, y) => prop_assert!(false, "image {}: λ {:?} vs {:?}", k, x, y),
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    /// The bound of `1/λ` from a region's limit analysis with the elastic
    /// field outside it (limit analysis off) is never below the proved
    /// `1/λ` and never above the elastic bound, on random structures
    /// resting on the ground with a tenth of the adhesion, and their
    /// mirror images (the region's boundary crosses links of every
    /// orientation).
    #[test]
    fn a_region_bound_lies_between_the_proved_and_the_elastic_bound(
        choices in proptest::collection::vec((0u8..16, 0u8..12), 3..12),
        image in 0usize..5,
    ) {
        let mut model = Model::default_catom();
        model.connector.pressure /= 10.0;
        model.ground.pressure /= 10.0;
        let mut cells = grown(&choices);
        if image < 4 {
            cells = cells.iter().map(|&c| images(c)[image]).collect();
        }
        let s = fcc(&cells);
        let proved = Analyzer::new(model.clone(), false).analyse(&s);
        if proved.verdict() == Verdict::NoEquilibrium || proved.load_factor.is_none() {
            return Ok(());
        }
        let bound = |hops: usize| {
            let mut a = Analyzer::new(model.clone(), false);
            a.settings.limit_analysis = false;
            a.settings.region_hops = hops;
            a.analyse(&s).max_utilisation
        };
        let elastic = bound(0);
        for hops in 1..=2 {
            let b = bound(hops);
            // The proved factor is itself a lower bound, within 5e-7 of
            // the solver's (docs/mechanics.md).
            prop_assert!(b >= proved.max_utilisation * (1.0 - 1e-6),
                "{:?}, {} hops: {} below the proved {}", cells, hops, b, proved.max_utilisation);
            prop_assert!(b <= elastic, "{:?}, {} hops: {} above {}", cells, hops, b, elastic);
        }
    }
}

/// The links whose elastic forces the closed-form corner construction does
/// not carry, with the multiple of those forces the link alone carries
/// under any corner distribution (`limit::link_load_factor`).
fn beyond_the_construction(
    s: &Structure,
    model: &Model,
    a: &super::analysis::Analysis,
) -> Vec<f64> {
    let (w, wd) = (model.weight(), model.weight() * model.spacing);
    s.links
        .iter()
        .zip(&a.links)
        .enumerate()
        .filter(|(_, (l, r))| {
            let cap = if l.is_ground() {
                &model.ground
            } else {
                &model.connector
            };
            super::overloaded(super::capacity::corner_ratio(&r.load, cap))
        })
        .map(|(li, (_, r))| {
            let (f, m) = (
                DVec3::from_array(r.force) / w,
                DVec3::from_array(r.moment) / wd,
            );
            super::limit::link_load_factor(s, model, li, f, m)
        })
        .collect()
}

/// The analysis without the corner gate: its elastic field, whatever the
/// corners carry.
fn ungated(model: &Model, s: &Structure) -> super::analysis::Analysis {
    let mut ungated = Analyzer::new(model.clone(), false);
    ungated.settings.corner_gate = false;
    ungated.analyse(s)
}

#[test]
fn an_elastic_witness_no_corner_distribution_carries_goes_to_the_limit_analysis() {
    // Resting on the ground, every link within the utilisation's chord,
    // but one link's elastic forces carried by no corner forces at all
    // (found by a search over 40,000 random structures: of the 1,077 whose
    // elastic field the closed-form construction does not carry, another
    // distribution carries 1,074; this is one of the other three).
    let model = Model::default_catom();
    let s = fcc(&[
        c(0, 0, 0),
        c(0, 0, 1),
        c(1, 0, 1),
        c(1, 1, 0),
        c(0, 1, 1),
        c(0, 2, 0),
    ]);
    let a = ungated(&model, &s);
    assert!(a.load_factor.is_none() && a.verdict() == Verdict::Stable);
    let links = beyond_the_construction(&s, &model, &a);
    assert!(links.iter().any(|&f| f < 1.0), "{links:?}");
    let b = Analyzer::new(model.clone(), false).analyse(&s);
    // One solve with capacities; its factor above 1 shows the component
    // stands, so the rigid case (which only tells tipping from breaking)
    // is not solved.
    assert_eq!(b.limit_analyses, 1);
    assert_eq!(b.verdict(), Verdict::Stable);
    assert!(b.load_factor.unwrap() > 1.0);
    assert!(lp_stands(&s, &model, Joints::Capacities, Pyramid::Inner));
}

#[test]
fn an_elastic_witness_another_corner_distribution_carries_is_kept() {
    // One ground contact twisted while pressed off-centre: the closed-form
    // construction does not carry it (before, this sent the structure to
    // the limit analysis), another corner distribution does.
    let model = Model::default_catom();
    let s = fcc(&[
        c(0, 0, 0),
        c(0, -1, 1),
        c(1, 0, 0),
        c(0, -2, 1),
        c(1, -1, 0),
    ]);
    let a = ungated(&model, &s);
    assert!(a.load_factor.is_none() && a.verdict() == Verdict::Stable);
    let links = beyond_the_construction(&s, &model, &a);
    assert!(
        !links.is_empty() && links.iter().all(|&f| f >= 1.0),
        "{links:?}"
    );
    let b = Analyzer::new(model.clone(), false).analyse(&s);
    assert_eq!((b.limit_analyses, b.verdict()), (0, Verdict::Stable));
    assert_eq!(b.max_utilisation, a.max_utilisation);
    // The test's own LP, with friction pyramids inside the cones: it stands.
    assert!(lp_stands(&s, &model, Joints::Capacities, Pyramid::Inner));
}

#[test]
fn every_witness_kept_past_the_construction_stands_in_the_test_lp() {
    // Random structures resting on the ground: wherever the screen keeps
    // an elastic field that the closed-form construction does not carry,
    // the test's LP with the pyramids about the cones (looser than the
    // cones) must find the structure standing: a screen that kept a
    // field no equilibrium within the capacities matches would fail here.
    // Near their capacities too: the default adhesion, and a twentieth and
    // a hundredth of it.
    use rand::{Rng, SeedableRng};
    for (pressure, at_least) in [(100e3, 60), (5e3, 60), (1e3, 40)] {
        let mut model = Model::default_catom();
        model.connector.pressure = pressure;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let mut kept = 0;
        let mut near = 0;
        for _ in 0..3000 {
            let choices: Vec<(u8, u8)> = (0..rng.random_range(1..9))
                .map(|_| (rng.random_range(0..16), rng.random_range(0..12)))
                .collect();
            let cells = grown(&choices);
            let s = fcc(&cells);
            let a = ungated(&model, &s);
            if a.load_factor.is_some()
                || a.verdict() != Verdict::Stable
                || beyond_the_construction(&s, &model, &a).is_empty()
            {
                continue;
            }
            let b = Analyzer::new(model.clone(), false).analyse(&s);
            if b.limit_analyses == 0 {
                kept += 1;
                near += usize::from(b.max_utilisation > 0.5);
                assert!(
                    lp_stands(&s, &model, Joints::Capacities, Pyramid::Outer),
                    "{cells:?}"
                );
            }
        }
        // (85, 85 and 59 of the 3,000, each with a link above half its
        // utilisation: the construction is tried only there.)
        assert!(kept >= at_least && near == kept, "{kept}, {near}");
    }
}
/// Each body's balance under the forces an analysis reports for its
/// links (`LinkResult::force` and `moment`, on side b about the contact,
/// N and N·m) and its weight: the largest residual, in `W` and `W·d`.
fn largest_imbalance(model: &Model, s: &Structure, a: &super::analysis::Analysis) -> f64 {
    let (w, d) = (model.weight(), model.spacing);
    let mut sum = vec![(s.gravity * w, DVec3::ZERO); s.bodies.len()];
    for (l, r) in s.links.iter().zip(&a.links) {
        let (f, m) = (DVec3::from_array(r.force), DVec3::from_array(r.moment));
        for (body, sign) in [(l.b.body(), 1.0), (Some(l.a), -1.0)] {
            if let Some(i) = body {
                let arm = (l.contact - s.bodies[i].centre) * d;
                sum[i].0 += sign * f;
                sum[i].1 += sign * (m + arm.cross(f));
            }
        }
    }
    s.bodies
        .iter()
        .zip(&sum)
        .filter(|(b, _)| !b.fixed)
        .map(|(_, (f, m))| (f.length() / w).max(m.length() / (w * d)))
        .fold(0.0, f64::max)
}

#[test]
fn an_elastic_witness_balances_every_body_where_sliding_contacts_leave_a_near_mechanism() {
    // Found by the region bound's property test: with a tenth of the
    // adhesion the active set lets go of five ground contacts and slides
    // others; the factor of that nearly singular matrix left the elastic
    // field 10 W out of balance while CG's recurrence said converged.
    let mut model = Model::default_catom();
    model.connector.pressure /= 10.0;
    model.ground.pressure /= 10.0;
    let cells = [
        c(0, 0, 0),
        c(0, 0, 1),
        c(0, 1, 2),
        c(-1, 1, 2),
        c(-2, 1, 3),
        c(0, 1, 0),
        c(-1, 1, 3),
        c(0, 0, 2),
    ];
    let s = fcc(&cells);
    let proved = Analyzer::new(model.clone(), false)
        .analyse(&s)
        .max_utilisation;
    for hops in 0..=3 {
        let mut analyzer = Analyzer::new(model.clone(), false);
        analyzer.settings.limit_analysis = false;
        analyzer.settings.region_hops = hops;
        let a = analyzer.analyse(&s);
        // No elastic equilibrium, so no witness and no finite bound (a
        // region's limit analysis on the unbalanced field once bounded
        // 1/λ by 0.306, below the proved 0.708).
        assert_eq!(a.bounded, 1);
        assert!(
            a.max_utilisation >= proved,
            "{hops} hops: {} below {proved}",
            a.max_utilisation
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// Where the elastic screen is the witness (no limit analysis ran), the
    /// forces it reports balance every body to round-off, checked here
    /// from the reported link forces alone, on random structures resting
    /// on the ground at full and at a tenth of the adhesion.
    #[test]
    fn the_elastic_witness_balances_every_body(
        choices in proptest::collection::vec((0u8..16, 0u8..12), 1..12),
        weak in proptest::bool::ANY,
    ) {
        let mut model = Model::default_catom();
        if weak {
            model.connector.pressure /= 10.0;
            model.ground.pressure /= 10.0;
        }
        let cells = grown(&choices);
        let s = fcc(&cells);
        let a = Analyzer::new(model.clone(), false).analyse(&s);
        if a.load_factor.is_none() && a.verdict() != Verdict::NoEquilibrium {
            let r = largest_imbalance(&model, &s, &a);
            prop_assert!(r <= 1e-6, "{:?}: a body out of balance by {}", cells, r);
        }
    }
}
