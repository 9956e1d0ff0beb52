//! Rigid-block limit analysis (lower-bound theorem): does *any* equilibrium
//! of the structure exist with every interface force within its capacity,
//! and by how much can gravity be scaled before none does (the load factor
//! `λ`)?
//!
//! Unknowns: forces at the four corners of every contact square
//! (connector or ground contact): the normal force `n` (tension > 0) and
//! the tangential force `t`, and `λ`. Constraints: the six equilibrium
//! equations of every free body under `λ` × its gravity loads, and the
//! capacities of the model:
//!
//! * rigid hinge: every corner pulls at most `pL²/4` and pushes without
//!   limit — the resultant's centre of pressure anywhere in the square,
//!   the fully plastic interface of [`super::capacity`];
//! * elastic: the corner forces' resultant within the linear stress
//!   distribution's bound `N + 6(±M_u ± M_v)/L ≤ pL²`;
//! * friction per corner: `‖t‖ ≤ μ(pL²/4 − n)` — the exact (second-order)
//!   cone about the corner's share of the adhesion. Torsion is carried by
//!   the corners' tangential forces, so it is coupled to where the square
//!   bears: a contact pressed on one edge resists no torsion about its
//!   centre (the resultant chord of the utilisation cannot say that).
//!
//! The problem is an SOCP solved by clarabel (interior point, pure Rust,
//! exact second-order cones; chosen over an LP with a friction pyramid so
//! that no polyhedral approximation decides a verdict). `λ = 0` with zero
//! forces is always feasible, so the answer is a number in
//! `[0, LAMBDA_CAP]`; a solver failure gives NaN, which every caller reads
//! as overloaded.

use super::model::{Bending, Capacity, Model};
use super::solver::Vec6;
use super::structure::{End, Structure};
use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, NonnegativeConeT, SecondOrderConeT,
    SolverStatus, SupportedConeT, ZeroConeT,
};

/// The largest load factor the analysis looks for: a structure that holds
/// this many times its weight is reported as holding it (a structure that
/// only rests on the ground without adhesion carries any multiple of its
/// weight, and the LP would be unbounded).
pub const LAMBDA_CAP: f64 = 1e4;

/// Which capacities bind.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Connectors {
    /// Every link within its capacity (the real question).
    Capacities,
    /// Connectors between modules infinitely strong, ground contacts as
    /// modelled: does the assembly stand as one rigid body on its supports?
    Rigid,
}

/// The part of a structure one analysis covers: a connected component of
/// free bodies and the links with a side in it (fixed bodies and the ground
/// are its supports).
#[derive(Copy, Clone, Debug)]
pub struct Part<'a> {
    pub bodies: &'a [usize],
    pub links: &'a [usize],
}

/// Result of a limit analysis.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct LimitResult {
    /// The load factor: the largest multiple of the loads an admissible
    /// equilibrium carries (capped at [`LAMBDA_CAP`]; NaN if the solver
    /// failed).
    pub lambda: f64,
    /// Solver iterations.
    pub iterations: u32,
}

/// The load factor of `part` of `s` under `loads` (one per body of `s`,
/// forces in `W`, moments about the body's centre in `W·d`), with the
/// capacities of `model`.
pub fn load_factor(
    s: &Structure,
    model: &Model,
    loads: &[Vec6],
    part: Part<'_>,
    which: Connectors,
) -> LimitResult {
    let nb = s.bodies.len();
    // Equation groups: with capacities, every free body of the part is
    // balanced on its own (moments about its centre); with rigid
    // connectors the part is one rigid body (moments about its first
    // body's centre) and only its supports carry unknowns — the connected
    // internal links can transmit any resultant, so any balance of the
    // whole extends to every body through a spanning tree.
    let rigid = which == Connectors::Rigid;
    let mut row_of = vec![usize::MAX; nb];
    let mut n_groups = 0;
    for &i in part.bodies {
        if !s.bodies[i].fixed {
            row_of[i] = if rigid { 0 } else { 6 * n_groups };
            if !rigid || n_groups == 0 {
                n_groups += 1;
            }
        }
    }
    let is_free = |i: usize| row_of[i] != usize::MAX;
    let origin = |i: usize| {
        if rigid {
            part.bodies
                .iter()
                .find(|&&b| is_free(b))
                .map_or(glam::DVec3::ZERO, |&b| s.bodies[b].centre)
        } else {
            s.bodies[i].centre
        }
    };
    // Links with a side in the part (with rigid connectors, only those
    // with one side outside it: ground contacts and fixed modules).
    let links: Vec<usize> = part
        .links
        .iter()
        .copied()
        .filter(|&li| {
            let l = &s.links[li];
            let (fa, fb) = (is_free(l.a), matches!(l.b, End::Body(b) if is_free(b)));
            if rigid { fa != fb } else { fa || fb }
        })
        .collect();
    if rigid && links.iter().any(|&li| !s.links[li].is_ground()) {
        // Held by a fixed module through rigid connectors: any load.
        return LimitResult {
            lambda: LAMBDA_CAP,
            iterations: 0,
        };
    }
    // Columns: per link, per corner of its contact square, the normal
    // force n (tension > 0), the tangential force (t_u, t_v) and its bound
    // z ≥ ‖t‖; then λ.
    const PER_CORNER: usize = 4;
    const PER_LINK: usize = 4 * PER_CORNER;
    let nl = links.len();
    let lam = PER_LINK * nl;
    let ncol = lam + 1;
    let (mut ri, mut ci, mut vals) = (Vec::new(), Vec::new(), Vec::new());
    let mut push = |r: usize, c: usize, v: f64| {
        if v != 0.0 {
            ri.push(r);
            ci.push(c);
            vals.push(v);
        }
    };
    let corners = [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)];
    let capacity = |li: usize| -> &Capacity {
        if s.links[li].is_ground() {
            &model.ground
        } else {
            &model.connector
        }
    };
    // Equilibrium rows: Σ (corner forces on the group) + λ·load = 0.
    let n_eq = 6 * n_groups;
    for (k, &li) in links.iter().enumerate() {
        let l = &s.links[li];
        let half = 0.5 * capacity(li).side / model.spacing;
        for (ki, (su, sv)) in corners.iter().enumerate() {
            let corner = l.contact + half * (su * l.u + sv * l.v);
            let col = PER_LINK * k + PER_CORNER * ki;
            // Unit forces on side b: a tension n pulls b towards a.
            let dirs = [-l.normal, l.u, l.v];
            let mut side = |body: usize, sign: f64| {
                if !is_free(body) {
                    return;
                }
                let r0 = row_of[body];
                let arm = corner - origin(body);
                for (j, f) in dirs.iter().enumerate() {
                    let m = arm.cross(*f);
                    for (a, v) in [f.x, f.y, f.z, m.x, m.y, m.z].into_iter().enumerate() {
                        push(r0 + a, col + j, sign * v);
                    }
                }
            };
            side(l.a, -1.0);
            if let End::Body(b) = l.b {
                side(b, 1.0);
            }
        }
    }
    for &i in part.bodies {
        if is_free(i) {
            let f = glam::DVec3::new(loads[i][0], loads[i][1], loads[i][2]);
            let m = glam::DVec3::new(loads[i][3], loads[i][4], loads[i][5])
                + (s.bodies[i].centre - origin(i)).cross(f);
            for (a, v) in [f.x, f.y, f.z, m.x, m.y, m.z].into_iter().enumerate() {
                push(row_of[i] + a, lam, v);
            }
        }
    }
    // Capacity rows (A x ≤ b).
    let w = model.weight();
    let mut rhs = vec![0.0; n_eq];
    let mut row = n_eq;
    let mut socs = Vec::new();
    for (k, &li) in links.iter().enumerate() {
        let cap = capacity(li);
        // The adhesion a corner holds: a quarter of the square's.
        let p = cap.tension() / w / 4.0;
        let col = |ki: usize| PER_LINK * k + PER_CORNER * ki;
        match cap.bending {
            Bending::RigidHinge => {
                // Each corner pulls at most p, pushes without limit: the
                // resultant anywhere in the square (a rigid, fully plastic
                // interface).
                for ki in 0..4 {
                    push(row, col(ki), 1.0);
                    rhs.push(p);
                    row += 1;
                }
            }
            Bending::Elastic => {
                // A linear stress distribution over the square within the
                // pressure: N + 6(±M_u ± M_v)/L ≤ pL², with the corner
                // forces' resultants (corner (s_u, s_v) contributes
                // n·(1 ± s_u·3 ± s_v·3)/… — written out per corner).
                for (eu, ev) in corners {
                    for (ki, (su, sv)) in corners.iter().enumerate() {
                        // Moment of a unit tension at this corner about
                        // the square's axes, in units of L/2: ±1.
                        push(row, col(ki), 1.0 + 3.0 * (eu * su + ev * sv));
                    }
                    rhs.push(4.0 * p);
                    row += 1;
                }
            }
        }
        // Friction per corner: ‖t‖ ≤ μ (p − n), the exact cone about the
        // corner's share of adhesion.
        for ki in 0..4 {
            let (n, z) = (col(ki), col(ki) + 3);
            push(row, n, cap.friction);
            push(row, z, 1.0);
            rhs.push(cap.friction * p);
            row += 1;
            socs.push((z, col(ki) + 1, col(ki) + 2));
        }
    }
    // λ ≤ cap.
    push(row, lam, 1.0);
    rhs.push(LAMBDA_CAP);
    row += 1;
    let n_nonneg = row - n_eq;
    // Second-order cones: s = (z, Vu, Vv) = −A x.
    for &(z, vu, vv) in &socs {
        for c in [z, vu, vv] {
            push(row, c, -1.0);
            rhs.push(0.0);
            row += 1;
        }
    }
    let a = CscMatrix::new_from_triplets(row, ncol, ri, ci, vals);
    let p = CscMatrix::<f64>::zeros((ncol, ncol));
    let mut q = vec![0.0; ncol];
    q[lam] = -1.0;
    let mut cones: Vec<SupportedConeT<f64>> = Vec::new();
    if n_eq > 0 {
        cones.push(ZeroConeT(n_eq));
    }
    cones.push(NonnegativeConeT(n_nonneg));
    cones.extend(socs.iter().map(|_| SecondOrderConeT(3)));
    // Interior point on these degenerate problems (free tangential forces
    // circulating between corners) can stall on round-off: retry with
    // stronger regularisation of the KKT system before giving up.
    let mut lambda = f64::NAN;
    let mut iterations = 0;
    for (regularisation, tolerance) in [(1e-8, 1e-8), (1e-6, 1e-7), (1e-5, 1e-6)] {
        let settings = DefaultSettingsBuilder::default()
            .verbose(false)
            .max_iter(200)
            .tol_gap_abs(tolerance)
            .tol_gap_rel(tolerance)
            .tol_feas(tolerance)
            .static_regularization_constant(regularisation)
            .build()
            .expect("valid settings");
        let Ok(mut solver) = DefaultSolver::new(&p, &q, &a, &rhs, &cones, settings) else {
            break;
        };
        solver.solve();
        let sol = &solver.solution;
        iterations += sol.iterations;
        if matches!(
            sol.status,
            SolverStatus::Solved | SolverStatus::AlmostSolved
        ) {
            lambda = sol.x[lam].clamp(0.0, LAMBDA_CAP);
            break;
        }
    }
    LimitResult { lambda, iterations }
}
