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
    let mut prog = Program::new(6 * n_groups, PER_LINK * links.len());
    let frame = Frame {
        row_of: &row_of,
        origin: &origin,
    };
    equilibrium_rows(&mut prog, s, model, loads, part, &links, &frame);
    capacity_rows(&mut prog, s, model, &links);
    maximise(prog)
}

/// Columns per corner of a contact square: the normal force `n` (tension
/// > 0), the tangential force `(t_u, t_v)` and its bound `z ≥ ‖t‖`.
const PER_CORNER: usize = 4;
const PER_LINK: usize = 4 * PER_CORNER;
const CORNERS: [(f64, f64); 4] = [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)];

/// The conic program being assembled: `A x + s = b`, `s` in the zero cone
/// (equilibrium rows), the non-negative cone (capacity rows) and one
/// second-order cone per corner; the last column is `λ`.
struct Program {
    triplets: (Vec<usize>, Vec<usize>, Vec<f64>),
    rhs: Vec<f64>,
    n_eq: usize,
    /// `(z, t_u, t_v)` columns of each corner's friction cone.
    socs: Vec<(usize, usize, usize)>,
    lam: usize,
}

impl Program {
    fn new(n_eq: usize, n_forces: usize) -> Program {
        Program {
            triplets: Default::default(),
            rhs: vec![0.0; n_eq],
            n_eq,
            socs: Vec::new(),
            lam: n_forces,
        }
    }

    fn push(&mut self, r: usize, c: usize, v: f64) {
        if v != 0.0 {
            self.triplets.0.push(r);
            self.triplets.1.push(c);
            self.triplets.2.push(v);
        }
    }

    /// Appends a row `Σ coef·x ≤ b` (or `= −s` for cone rows).
    fn row(&mut self, terms: &[(usize, f64)], b: f64) {
        let r = self.rhs.len();
        for &(c, v) in terms {
            self.push(r, c, v);
        }
        self.rhs.push(b);
    }
}

/// Where each free body's equations are, and the point its moments are
/// taken about.
struct Frame<'a> {
    row_of: &'a [usize],
    origin: &'a dyn Fn(usize) -> glam::DVec3,
}

fn capacity<'m>(s: &Structure, model: &'m Model, li: usize) -> &'m Capacity {
    model.capacity_of(s.links[li].is_ground())
}

/// Equilibrium rows: Σ (corner forces on the group) + λ·load = 0.
fn equilibrium_rows(
    prog: &mut Program,
    s: &Structure,
    model: &Model,
    loads: &[Vec6],
    part: Part<'_>,
    links: &[usize],
    frame: &Frame<'_>,
) {
    let is_free = |i: usize| frame.row_of[i] != usize::MAX;
    for (k, &li) in links.iter().enumerate() {
        let l = &s.links[li];
        let half = 0.5 * capacity(s, model, li).side / model.spacing;
        for (ki, (su, sv)) in CORNERS.iter().enumerate() {
            let corner = l.contact + half * (su * l.u + sv * l.v);
            let col = PER_LINK * k + PER_CORNER * ki;
            // Unit forces on side b: a tension n pulls b towards a.
            let dirs = [-l.normal, l.u, l.v];
            let ends = [(Some(l.a), -1.0), (l.b.body(), 1.0)];
            for (body, sign) in ends {
                let Some(body) = body.filter(|&b| is_free(b)) else {
                    continue;
                };
                let r0 = frame.row_of[body];
                let arm = corner - (frame.origin)(body);
                for (j, f) in dirs.iter().enumerate() {
                    let m = arm.cross(*f);
                    for (a, v) in [f.x, f.y, f.z, m.x, m.y, m.z].into_iter().enumerate() {
                        prog.push(r0 + a, col + j, sign * v);
                    }
                }
            }
        }
    }
    for &i in part.bodies {
        if is_free(i) {
            let f = glam::DVec3::new(loads[i][0], loads[i][1], loads[i][2]);
            let m = glam::DVec3::new(loads[i][3], loads[i][4], loads[i][5])
                + (s.bodies[i].centre - (frame.origin)(i)).cross(f);
            for (a, v) in [f.x, f.y, f.z, m.x, m.y, m.z].into_iter().enumerate() {
                prog.push(frame.row_of[i] + a, prog.lam, v);
            }
        }
    }
}

/// Capacity rows (`A x ≤ b`) and friction cones of every link's corners.
fn capacity_rows(prog: &mut Program, s: &Structure, model: &Model, links: &[usize]) {
    let w = model.weight();
    for (k, &li) in links.iter().enumerate() {
        let cap = capacity(s, model, li);
        // The adhesion a corner holds: a quarter of the square's.
        let p = cap.tension() / w / 4.0;
        let col = |ki: usize| PER_LINK * k + PER_CORNER * ki;
        match cap.bending {
            Bending::RigidHinge => {
                // Each corner pulls at most p, pushes without limit: the
                // resultant anywhere in the square (a rigid, fully plastic
                // interface).
                for ki in 0..4 {
                    prog.row(&[(col(ki), 1.0)], p);
                }
            }
            Bending::Elastic => {
                // A linear stress distribution within the pressure:
                // N + 6(±M_u ± M_v)/L ≤ pL² on the corner forces'
                // resultants (a unit tension at corner (s_u, s_v) has
                // moments ±L/2 about the square's axes).
                for (eu, ev) in CORNERS {
                    let terms: Vec<(usize, f64)> = CORNERS
                        .iter()
                        .enumerate()
                        .map(|(ki, (su, sv))| (col(ki), 1.0 + 3.0 * (eu * su + ev * sv)))
                        .collect();
                    prog.row(&terms, 4.0 * p);
                }
            }
        }
        // Friction per corner: ‖t‖ ≤ μ (p − n), the exact cone about the
        // corner's share of adhesion.
        for ki in 0..4 {
            let (n, z) = (col(ki), col(ki) + 3);
            prog.row(&[(n, cap.friction), (z, 1.0)], cap.friction * p);
            prog.socs.push((z, col(ki) + 1, col(ki) + 2));
        }
    }
}

/// Maximises `λ ≤ LAMBDA_CAP` (clarabel). Interior point on these
/// degenerate problems (free tangential forces circulating between
/// corners) can stall on round-off: it retries with stronger
/// regularisation of the KKT system before giving up (NaN).
fn maximise(mut prog: Program) -> LimitResult {
    let lam = prog.lam;
    let ncol = lam + 1;
    prog.row(&[(lam, 1.0)], LAMBDA_CAP);
    let n_nonneg = prog.rhs.len() - prog.n_eq;
    // Second-order cones: s = (z, t_u, t_v) = −A x.
    for (z, tu, tv) in std::mem::take(&mut prog.socs).iter().copied() {
        for c in [z, tu, tv] {
            prog.row(&[(c, -1.0)], 0.0);
        }
        prog.socs.push((z, tu, tv));
    }
    let (ri, ci, vals) = std::mem::take(&mut prog.triplets);
    let a = CscMatrix::new_from_triplets(prog.rhs.len(), ncol, ri, ci, vals);
    let p = CscMatrix::<f64>::zeros((ncol, ncol));
    let mut q = vec![0.0; ncol];
    q[lam] = -1.0;
    let mut cones: Vec<SupportedConeT<f64>> = Vec::new();
    if prog.n_eq > 0 {
        cones.push(ZeroConeT(prog.n_eq));
    }
    cones.push(NonnegativeConeT(n_nonneg));
    cones.extend(prog.socs.iter().map(|_| SecondOrderConeT(3)));
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
        let Ok(mut solver) = DefaultSolver::new(&p, &q, &a, &prog.rhs, &cones, settings) else {
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
