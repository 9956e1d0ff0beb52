//! The load factor proved, not read off the solver.
//!
//! The interior-point solution is feasible only to the solver's tolerance
//! (1e-8 when solved, about 1e-4 when clarabel reports `AlmostSolved`), so
//! its `λ` a hair above 1 does not show that the structure holds: the
//! forces balance the loads only nearly. The proof repairs the
//! equilibrium and then measures the repaired field against the
//! capacities with explicit tolerances, as a lower-bound (static) theorem
//! asks:
//!
//! 1. `v = x / λ` balances the loads up to the residual `R(v) = A v + g`;
//! 2. the least-norm correction `v' = v + Aᵀy`, `(A Aᵀ) y = −R(v)`, balances
//!    them to round-off (`A Aᵀ` has one 6 × 6 block per free body, like a
//!    stiffness matrix, and is factored by [`crate::mechanics::Factor`];
//!    one step of iterative refinement follows);
//! 3. every tangential bound is set to its least, `z = ‖t‖`;
//! 4. the proved factor is the largest `s` with `s·v'` within every
//!    capacity row, exactly, provided `v'` balances the loads to
//!    [`EQUILIBRIUM_TOL`]; 0 otherwise (nothing proved). The rows with
//!    nothing to spare, which no multiple helps, were solved with
//!    [`PRESSURE_RESERVE`] in hand ([`reserve_pressure`]).
//!
//! By the lower-bound theorem the structure carries at least `s` times its
//! loads, whatever the solver's accuracy was: a verdict `λ ≥ 1` rests on
//! the proof alone.

use super::{LAMBDA_CAP, Program, largest_residual};
use crate::mechanics::direct::Factor;
use crate::mechanics::solver::{Block, BlockMatrix, Vec6};
use rustc_hash::FxHashMap;

/// How far a proved field may leave a body's loads unbalanced, in module
/// weights `W` (forces) and `W·d` (moments): round-off, 1e-10 of a
/// module's weight.
pub const EQUILIBRIUM_TOL: f64 = 1e-10;

/// The pressure, in module weights `W` per unit of `λ`, that the solved
/// program keeps in reserve in every row with nothing to spare (a ground
/// contact without adhesion: each corner pushes at least this much, and
/// its friction stays this far inside the cone). The interior-point
/// solution meets its rows only to the solver's tolerance; in these rows
/// no multiple of the field would absorb the excess, so the reserve does.
/// The proof then checks the rows exactly, without the reserve: the
/// proved factor is that of a problem asking slightly more, never less.
pub const PRESSURE_RESERVE: f64 = 1e-6;

/// A proved admissible field: `v` balances the loads (`λ = 1`) to
/// [`EQUILIBRIUM_TOL`], and `lambda · v` lies within every capacity row.
pub(super) struct Proof {
    pub lambda: f64,
    pub v: Vec<f64>,
}

/// Proves a load factor from the solver's forces `x` at its factor
/// `lambda` for `prog` (equilibrium rows first, then the capacity rows and
/// the cones, before [`super::maximise`] appends its own rows). `None`
/// when nothing can be proved: a NaN, no positive factor, or an
/// equilibrium the correction cannot close (its bodies are not held: the
/// factor is then 0).
pub(super) fn prove(prog: &Program, x: &[f64], lambda: f64) -> Option<Proof> {
    if !(lambda.is_finite() && lambda > 0.0) || x.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let n_eq = prog.n_eq;
    let mut v: Vec<f64> = x.iter().map(|x| x / lambda).collect();
    if n_eq > 0 {
        let columns = equilibrium_columns(prog);
        let factor = Factor::new(&normal_matrix(&columns, n_eq))?;
        // Two corrections: the second removes what round-off in the
        // first left (iterative refinement).
        for _ in 0..2 {
            let values = prog.row_values(&v);
            let mut rhs: Vec<Vec6> = values[..n_eq]
                .chunks_exact(6)
                .map(|r| -Vec6::from_column_slice(r))
                .collect();
            factor.solve_in_place(&mut rhs);
            for (c, entries) in columns.iter().enumerate() {
                v[c] += entries
                    .iter()
                    .map(|&(r, a)| a * rhs[r / 6][r % 6])
                    .sum::<f64>();
            }
        }
    }
    for &(z, tu, tv) in &prog.socs {
        v[z] = v[tu].hypot(v[tv]);
    }
    let values = prog.row_values(&v);
    let residual = largest_residual(&values[..n_eq]);
    if residual
        .partial_cmp(&EQUILIBRIUM_TOL)
        .is_none_or(|o| o.is_gt())
    {
        return None;
    }
    let mut s = LAMBDA_CAP;
    for (lhs, rhs) in values[n_eq..].iter().zip(&prog.rhs[n_eq..]) {
        if lhs.is_nan() {
            return None;
        }
        if *lhs > 0.0 {
            s = s.min(if *rhs > 0.0 { rhs / lhs } else { 0.0 });
        }
    }
    Some(Proof { lambda: s, v })
}

/// Keeps [`PRESSURE_RESERVE`] · `λ` in every capacity row of `prog` whose
/// right-hand side is not positive (`λ = 0` with no forces stays
/// feasible).
pub(super) fn reserve_pressure(prog: &mut Program) {
    for r in prog.n_eq..prog.rhs.len() {
        if prog.rhs[r] <= 0.0 {
            prog.push(r, prog.lam, PRESSURE_RESERVE);
        }
    }
}

/// The equilibrium rows' entries of every force column: `(row, a)`.
fn equilibrium_columns(prog: &Program) -> Vec<Vec<(usize, f64)>> {
    let mut columns: Vec<Vec<(usize, f64)>> = vec![Vec::new(); prog.lam];
    let (ri, ci, vals) = &prog.triplets;
    for ((&r, &c), &a) in ri.iter().zip(ci).zip(vals) {
        if r < prog.n_eq && c != prog.lam {
            columns[c].push((r, a));
        }
    }
    columns
}

/// `A Aᵀ` over the equilibrium rows, as 6 × 6 blocks (one per free body,
/// or one for a rigid group).
fn normal_matrix(columns: &[Vec<(usize, f64)>], n_eq: usize) -> BlockMatrix {
    let mut m = BlockMatrix::new(n_eq / 6);
    let mut off: FxHashMap<(usize, usize), Block> = FxHashMap::default();
    for entries in columns {
        for &(r1, a1) in entries {
            for &(r2, a2) in entries {
                let (g1, g2) = (r1 / 6, r2 / 6);
                if g1 == g2 {
                    m.diag[g1][(r1 % 6, r2 % 6)] += a1 * a2;
                } else if g1 < g2 {
                    off.entry((g1, g2)).or_insert_with(Block::zeros)[(r1 % 6, r2 % 6)] += a1 * a2;
                }
            }
        }
    }
    let mut off: Vec<_> = off.into_iter().collect();
    off.sort_unstable_by_key(|&(k, _)| k);
    m.off = off
        .into_iter()
        .map(|((i, j), b)| (i as u32, j as u32, b))
        .collect();
    m
}

#[cfg(test)]
mod tests {
    use super::super::{Connectors, Part, load_factor, maximise, program};
    use super::*;
    use crate::lattice::config::Ground;
    use crate::lattice::{Cell, FccLattice, Lattice};
    use crate::mechanics::analysis::{Analyzer, Verdict};
    use crate::mechanics::closed_form::cantilever_utilisation;
    use crate::mechanics::model::{Bending, Model};
    use crate::mechanics::structure::Structure;
    use crate::mechanics::validation::structure;

    fn gravity(s: &Structure) -> Vec<Vec6> {
        let g = s.gravity;
        vec![Vec6::new(g.x, g.y, g.z, 0.0, 0.0, 0.0); s.bodies.len()]
    }

    /// The whole structure's program (as proved, without the reserve) and
    /// the solver's forces and factor (solved with it).
    fn solved(s: &Structure, model: &Model) -> (Program, Vec<f64>, f64) {
        let bodies: Vec<usize> = (0..s.bodies.len()).collect();
        let links: Vec<usize> = (0..s.links.len()).collect();
        let part = Part {
            bodies: &bodies,
            links: &links,
        };
        let (prog, _) = program(s, model, &gravity(s), part, false).expect("a program");
        let mut with_reserve = prog.clone();
        reserve_pressure(&mut with_reserve);
        let (r, x, _) = maximise(with_reserve, 0);
        (prog, x.expect("solved"), r.lambda)
    }

    fn whole_factor(s: &Structure, model: &Model) -> (f64, f64) {
        let bodies: Vec<usize> = (0..s.bodies.len()).collect();
        let links: Vec<usize> = (0..s.links.len()).collect();
        let part = Part {
            bodies: &bodies,
            links: &links,
        };
        let r = load_factor(s, model, &gravity(s), part, Connectors::Capacities);
        (r.lambda, r.solver_lambda)
    }

    /// A horizontal cantilever of `n` modules beyond a fixed root, along
    /// +x or its mirror image.
    fn cantilever(n: i32, sign: i32) -> Structure {
        let cells: Vec<Cell> = (0..=n).map(|i| Cell::new(sign * i, 0, 0)).collect();
        structure(&FccLattice, None, &cells, &[0], &[])
    }

    /// The rigid hinge's closed form: the root moment limit over the
    /// root moment, `1 / utilisation`.
    fn exact(model: &Model, n: usize) -> f64 {
        1.0 / cantilever_utilisation(model, n, false)
    }

    #[test]
    fn a_factor_the_forces_do_not_carry_is_not_proved() {
        let model = Model::default_catom().with_connector(20e3, Bending::RigidHinge);
        for sign in [1, -1] {
            let s = cantilever(3, sign);
            let exact = exact(&model, 3);
            let (prog, x, lambda) = solved(&s, &model);
            let proved = prove(&prog, &x, lambda).expect("a proof").lambda;
            assert!(proved <= exact * (1.0 + 1e-9), "{proved} > {exact}");
            assert!(proved >= exact * (1.0 - 1e-7), "{proved} ≪ {exact}");
            // The same forces said to carry 0.1 % more: they balance less
            // than the loads, and the repair costs what was claimed.
            let claim = prove(&prog, &x, lambda * 1.001).expect("a proof").lambda;
            assert!(claim <= exact * (1.0 + 1e-9), "{claim} > {exact}");
            // Forces off by 0.1 % of the largest, everywhere.
            let big = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let noisy: Vec<f64> = (0..x.len())
                .map(|i| x[i] + 1e-3 * big * (i as f64 * 1.7).sin())
                .collect();
            let repaired = prove(&prog, &noisy, lambda).expect("a proof").lambda;
            assert!(repaired <= exact * (1.0 + 1e-9), "{repaired} > {exact}");
            assert!(repaired >= 0.98 * exact, "the repair proves {repaired}");
        }
    }

    #[test]
    fn nothing_is_proved_from_a_nan_or_a_factor_that_is_not_positive() {
        let model = Model::default_catom();
        let (prog, x, lambda) = solved(&cantilever(2, 1), &model);
        for bad in [f64::NAN, f64::INFINITY, 0.0, -1.0] {
            assert!(prove(&prog, &x, bad).is_none(), "λ = {bad}");
        }
        let mut nan = x.clone();
        nan[3] = f64::NAN;
        assert!(prove(&prog, &nan, lambda).is_none());
    }

    #[test]
    fn at_the_knife_edge_the_verdict_is_the_closed_forms() {
        // The root moment limit is proportional to the pressure: at
        // p = p₁ (1 ± δ) the exact factor is 1 ± δ.
        let base = Model::default_catom().with_connector(20e3, Bending::RigidHinge);
        let p1 = 20e3 * cantilever_utilisation(&base, 4, false);
        let s = cantilever(4, 1);
        for (delta, holds) in [(-1e-7, false), (1e-6, true)] {
            let model = base.with_connector(p1 * (1.0 + delta), Bending::RigidHinge);
            let exact = exact(&model, 4);
            assert!((exact - (1.0 + delta)).abs() < 1e-12, "{exact}");
            let (lambda, _) = whole_factor(&s, &model);
            assert!(lambda <= exact * (1.0 + 1e-12), "{lambda} > {exact}");
            let a = Analyzer::new(model, false).analyse(&s);
            assert_eq!(a.verdict() == Verdict::Stable, holds, "δ = {delta}");
        }
    }

    #[test]
    fn on_the_ground_the_reserve_keeps_the_solvers_factor() {
        // A structure grown at random on the ground (no adhesion there),
        // found by the mirrored-images property test: without the
        // reserve, the solver's forces pulled one ground corner by
        // round-off and proved 0.364 where it solved 50.5.
        let choices = [(0, 2), (1, 6), (8, 7), (3, 10), (12, 5), (1, 5)];
        let mut cells = vec![Cell::new(0, 0, 0)];
        for (from, dir) in choices {
            let n = FccLattice.neighbour(cells[from % cells.len()], dir);
            if (0..=3).contains(&n.z) && !cells.contains(&n) {
                cells.push(n);
            }
        }
        let model = Model::default_catom();
        let s = structure(&FccLattice, Some(Ground { layer: 0 }), &cells, &[], &[]);
        let (lambda, solver) = whole_factor(&s, &model);
        assert!(lambda > 1.0, "{lambda}");
        assert!(
            (lambda - solver).abs() <= 1e-6 * solver,
            "{lambda} vs {solver}"
        );
    }
}
