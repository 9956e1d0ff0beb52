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
//! as overloaded. The factor reported is the one [`proof`] proves from the
//! solver's forces (equilibrium repaired exactly, capacities checked with
//! explicit tolerances), never the solver's own `λ`, which is feasible
//! only to the solver's tolerance.

mod proof;

use super::model::{Bending, Capacity, Model};
use super::solver::Vec6;
use super::structure::{End, Link, Structure};
use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, NonnegativeConeT, SecondOrderConeT,
    SolverStatus, SupportedConeT, ZeroConeT,
};
use proof::EQUILIBRIUM_TOL;

/// The largest load factor the analysis looks for: a structure that holds
/// this many times its weight is reported as holding it (a structure that
/// only rests on the ground without adhesion carries any multiple of its
/// weight, and the LP would be unbounded).
pub const LAMBDA_CAP: f64 = 1e4;

/// The smaller factor; a NaN (a failed solve) sticks, so that it reads as
/// overloaded wherever it ends up.
pub fn lowest(x: f64, y: f64) -> f64 {
    if x.is_nan() || y.is_nan() {
        f64::NAN
    } else {
        x.min(y)
    }
}

/// A factor below 1, or NaN (a failed solve): the structure does not hold.
pub fn fails(x: f64) -> bool {
    x.partial_cmp(&1.0).is_none_or(|o| o.is_lt())
}

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
    /// Solver iterations, over every try.
    pub iterations: u32,
    /// Solver settings tried ([`SETTINGS`]), the last one the one that
    /// solved; 0 where no solve was needed.
    pub tries: u32,
    /// The index in [`SETTINGS`] of the setting that solved
    /// (`SETTINGS.len()` where none did, 0 where no solve was needed):
    /// the poses of one step start there ([`load_factor_from`]).
    pub setting: usize,
    /// The interior-point solver's own factor, before the proof
    /// ([`proof`]): `lambda` is what an admissible field proves (at most
    /// a round-off above this one, and 0 where nothing is proved).
    pub solver_lambda: f64,
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
    solve(s, model, loads, part, which, false, 0).0
}

/// [`load_factor`], trying the solver's [`SETTINGS`] from index `first`
/// on: the analyser solves a step's first pose from 0 and its other poses,
/// the same structure under loads that differ by a mover's moment, from
/// the setting that solved the first. A function of the step alone, so
/// results do not depend on the threads that solve the poses.
pub fn load_factor_from(
    s: &Structure,
    model: &Model,
    loads: &[Vec6],
    part: Part<'_>,
    which: Connectors,
    first: usize,
) -> LimitResult {
    solve(s, model, loads, part, which, false, first).0
}

/// An admissible equilibrium found by the limit analysis: the corner
/// forces of `links` (in the program's columns) carrying `lambda` × the
/// loads.
#[derive(Clone, Debug)]
pub struct Field {
    links: Vec<usize>,
    x: Vec<f64>,
    lambda: f64,
}

/// Where a structure that fails gives way: the collapse mechanism of
/// the limit analysis, read from the solver's dual (the upper-bound
/// theorem's virtual velocities). The dual of each capacity row is the
/// rate at which its corner yields; times the row's capacity it is the
/// work the corner dissipates, and the links' works sum to `λ` (strong
/// duality: the loads' work at unit rate). A link's share of that sum says
/// how much of the collapse happens there. A ground contact without
/// adhesion dissipates nothing (its capacity rows are 0): it lifts or
/// slides freely and is never named.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mechanism {
    /// `(link, share)`, largest share first, the shares of every link
    /// summing to 1; links below [`MECHANISM_FLOOR`] left out.
    pub links: Vec<(usize, f64)>,
}

/// The smallest share of the dissipated work a link of a [`Mechanism`]
/// keeps: below it, the interior-point dual's round-off.
pub const MECHANISM_FLOOR: f64 = 1e-4;

/// One limit analysis with capacities, everything it can tell.
pub struct Solved {
    pub result: LimitResult,
    /// The equilibrium that carries the factor, if asked for (none for a
    /// failed solve, or a part held by a fixed module).
    pub field: Option<Field>,
    /// Where it gives way (none where the solve failed, the part is held
    /// by a fixed module, or the factor is 0: no work to share).
    pub mechanism: Option<Mechanism>,
}

/// [`load_factor_from`] with capacities, with its collapse mechanism and,
/// if `keep_field`, the equilibrium that carries it.
pub fn solve_with_capacities(
    s: &Structure,
    model: &Model,
    loads: &[Vec6],
    part: Part<'_>,
    first: usize,
    keep_field: bool,
) -> Solved {
    let (result, field, mechanism) = solve(
        s,
        model,
        loads,
        part,
        Connectors::Capacities,
        keep_field,
        first,
    );
    Solved {
        result,
        field,
        mechanism,
    }
}

/// The largest multiple of the action of side `a` on side `b` through
/// link `li` alone — the force `force` and the moment `moment` about the
/// contact, in `W` and `W·d` — that the link's corners carry, proved as
/// [`load_factor`]'s is: the rows are the limit analysis's own
/// ([`capacity_rows`]) and six equations balance the corners against the
/// action. At least 1: one admissible corner distribution of that
/// resultant exists, so an equilibrium of the whole structure whose every
/// link passes carries its loads (lower-bound theorem). The elastic screen
/// asks this where the closed-form corner construction
/// ([`super::capacity::corner_ratio`], one distribution among many) does
/// not carry a link; NaN input gives NaN, read as overloaded.
pub fn link_load_factor(
    s: &Structure,
    model: &Model,
    li: usize,
    force: glam::DVec3,
    moment: glam::DVec3,
) -> f64 {
    let l = &s.links[li];
    let mut prog = Program::new(6, PER_LINK);
    let half = half_side(s, model, li);
    for (col, corner) in corners(l, half) {
        push_corner(&mut prog, l, 0, col, corner - l.contact, 1.0);
    }
    let action = [force.x, force.y, force.z, moment.x, moment.y, moment.z];
    if action.iter().any(|v| !v.is_finite()) {
        return f64::NAN;
    }
    for (a, v) in action.into_iter().enumerate() {
        prog.push(a, prog.lam, -v);
    }
    capacity_rows(&mut prog, s, model, &[li]);
    let to_prove = prog.clone();
    proof::reserve_pressure(&mut prog);
    let (r, x, _) = maximise(prog, 0);
    if r.lambda.is_nan() {
        return f64::NAN;
    }
    x.and_then(|x| proof::prove(&to_prove, &x, r.lambda))
        .map_or(0.0, |p| p.lambda)
}

/// A lower bound of the load factor of a component from an equilibrium
/// that is elastic outside a region and solved inside it: the limit
/// analysis of the free bodies `region` alone, on the links `links` with
/// no side outside the region and its supports, under `loads` plus the
/// elastic actions of the links that cross into the rest of the component
/// (`boundary`: link and its interface force `sf`, the action on side a,
/// `W` and `W·d` about the contact, as the screen computes it), all
/// scaled by `λ`, and `λ ≤ outside` (the largest multiple of the elastic
/// field that every link not in `links` carries). Such a field is in
/// equilibrium everywhere (the elastic one balances the bodies outside,
/// the solved one those inside) and within every capacity, so by the
/// lower-bound theorem the component carries at least this factor. With
/// the whole component as the region it is the limit analysis itself; a
/// region around the links the elastic field overloads costs a program of
/// their size, not of the component's. Proved as [`load_factor`]'s is
/// (0 where nothing is proved, NaN for NaN input).
#[allow(clippy::too_many_arguments)]
pub fn region_load_factor(
    s: &Structure,
    model: &Model,
    loads: &[Vec6],
    region: &[usize],
    links: &[usize],
    boundary: &[(usize, Vec6)],
    outside: f64,
    first: usize,
) -> f64 {
    if outside.is_nan()
        || boundary
            .iter()
            .any(|(_, f)| f.iter().any(|v| !v.is_finite()))
    {
        return f64::NAN;
    }
    let mut loads = loads.to_vec();
    let mut inside = vec![false; s.bodies.len()];
    for &i in region {
        inside[i] = true;
    }
    for &(li, f) in boundary {
        let l = &s.links[li];
        let (force, moment) = (
            glam::DVec3::new(f[0], f[1], f[2]),
            glam::DVec3::new(f[3], f[4], f[5]),
        );
        // A stretched interface pulls b towards a and a towards b.
        let sides = [(Some(l.a), 1.0), (l.b.body(), -1.0)];
        for (body, sign) in sides {
            let Some(i) = body.filter(|&i| inside[i]) else {
                continue;
            };
            let (fi, mi) = (
                sign * force,
                sign * moment + (l.contact - s.bodies[i].centre).cross(sign * force),
            );
            let add = Vec6::new(fi.x, fi.y, fi.z, mi.x, mi.y, mi.z);
            loads[i] += add;
        }
    }
    let part = Part {
        bodies: region,
        links,
    };
    let Some((mut prog, _)) = program(s, model, &loads, part, false) else {
        return LAMBDA_CAP.min(outside);
    };
    if outside < LAMBDA_CAP {
        let lam = prog.lam;
        prog.row(&[(lam, 1.0)], outside.max(0.0));
    }
    let to_prove = prog.clone();
    proof::reserve_pressure(&mut prog);
    let (r, x, _) = maximise(prog, first);
    if r.lambda.is_nan() {
        return f64::NAN;
    }
    x.and_then(|x| proof::prove(&to_prove, &x, r.lambda))
        .map_or(0.0, |p| p.lambda)
}

/// Where each free body's six equations start (`usize::MAX` for the
/// others), and how many groups of six there are. With capacities, every
/// free body of the part is balanced on its own (moments about its
/// centre); with rigid connectors the part is one rigid body (moments
/// about its first body's centre) and only its supports carry unknowns —
/// the connected internal links can transmit any resultant, so any
/// balance of the whole extends to every body through a spanning tree.
fn equation_groups(s: &Structure, part: Part<'_>, rigid: bool) -> (Vec<usize>, usize) {
    let mut row_of = vec![usize::MAX; s.bodies.len()];
    let mut n_groups = 0;
    for &i in part.bodies {
        if !s.bodies[i].fixed {
            row_of[i] = if rigid { 0 } else { 6 * n_groups };
            if !rigid || n_groups == 0 {
                n_groups += 1;
            }
        }
    }
    (row_of, n_groups)
}

fn solve(
    s: &Structure,
    model: &Model,
    loads: &[Vec6],
    part: Part<'_>,
    which: Connectors,
    keep_field: bool,
    first: usize,
) -> (LimitResult, Option<Field>, Option<Mechanism>) {
    let rigid = which == Connectors::Rigid;
    let Some((mut prog, links)) = program(s, model, loads, part, rigid) else {
        // Held by a fixed module through rigid connectors: any load.
        let r = LimitResult {
            lambda: LAMBDA_CAP,
            iterations: 0,
            tries: 0,
            setting: 0,
            solver_lambda: LAMBDA_CAP,
        };
        return (r, None, None);
    };
    if rigid {
        // Only a failing component is asked whether it stands rigidly
        // (tips or slides): no verdict rests on this factor.
        return (maximise(prog, first).0, None, None);
    }
    let to_prove = prog.clone();
    proof::reserve_pressure(&mut prog);
    let (mut r, x, work) = maximise(prog, first);
    let mechanism = work.and_then(|w| mechanism(&links, &w));
    let proof = x.and_then(|x| proof::prove(&to_prove, &x, r.lambda));
    r.solver_lambda = r.lambda;
    if !r.lambda.is_nan() {
        r.lambda = proof.as_ref().map_or(0.0, |p| p.lambda);
    }
    let field = proof
        .filter(|p| keep_field && p.lambda > 0.0)
        .map(|p| Field {
            links,
            x: p.v.iter().map(|v| v * p.lambda).collect(),
            lambda: p.lambda,
        });
    (r, field, mechanism)
}

/// Each link's share of the dissipated work `work` (one entry per
/// capacity row, [`CAPACITY_ROWS`] per link in the order of `links`);
/// `None` where nothing is dissipated (a factor of 0) or a figure is not
/// finite.
fn mechanism(links: &[usize], work: &[f64]) -> Option<Mechanism> {
    debug_assert_eq!(work.len(), CAPACITY_ROWS * links.len());
    // A NaN must not be read as no work (`f64::max` would drop it).
    if work.iter().any(|w| !w.is_finite()) {
        return None;
    }
    let per_link: Vec<f64> = work
        .chunks(CAPACITY_ROWS)
        .map(|rows| rows.iter().map(|w| w.max(0.0)).sum())
        .collect();
    let total: f64 = per_link.iter().sum();
    if !(total.is_finite() && total > 0.0) {
        return None;
    }
    let mut shares: Vec<(usize, f64)> = links
        .iter()
        .zip(&per_link)
        .map(|(&li, &w)| (li, w / total))
        .filter(|&(_, share)| share >= MECHANISM_FLOOR)
        .collect();
    shares.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    Some(Mechanism { links: shares })
}

/// The conic program of `part` under `loads` (equilibrium rows, capacity
/// rows and cones; [`maximise`] adds the objective) and the links whose
/// corners are its columns; `None` when rigid connectors to a fixed module
/// hold the part (any load, nothing to solve).
fn program(
    s: &Structure,
    model: &Model,
    loads: &[Vec6],
    part: Part<'_>,
    rigid: bool,
) -> Option<(Program, Vec<usize>)> {
    let (row_of, n_groups) = equation_groups(s, part, rigid);
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
        return None;
    }
    let mut prog = Program::new(6 * n_groups, PER_LINK * links.len());
    let frame = Frame {
        row_of: &row_of,
        origin: &origin,
    };
    equilibrium_rows(&mut prog, s, model, loads, part, &links, &frame);
    capacity_rows(&mut prog, s, model, &links);
    Some((prog, links))
}

/// The largest |value| (NaN if any is).
fn largest_residual(rows: &[f64]) -> f64 {
    rows.iter().fold(
        0.0,
        |m: f64, r| if r.is_nan() { f64::NAN } else { m.max(r.abs()) },
    )
}

/// Columns per corner of a contact square: the normal force `n` (tension
/// > 0), the tangential force `(t_u, t_v)` and its bound `z ≥ ‖t‖`.
const PER_CORNER: usize = 4;
const PER_LINK: usize = 4 * PER_CORNER;
/// Capacity rows per link ([`capacity_rows`]): four of adhesion, four of
/// friction.
const CAPACITY_ROWS: usize = 8;
const CORNERS: [(f64, f64); 4] = [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)];

/// The conic program being assembled: `A x + s = b`, `s` in the zero cone
/// (equilibrium rows), the non-negative cone (capacity rows) and one
/// second-order cone per corner; the last column is `λ`.
#[derive(Clone)]
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

    /// Every row's `Σ coef·x` at `x = v` and `λ = 1`: the equilibrium
    /// rows' residuals, then the capacity rows' left-hand sides.
    fn row_values(&self, v: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; self.rhs.len()];
        let (ri, ci, vals) = &self.triplets;
        for ((&r, &c), &a) in ri.iter().zip(ci).zip(vals) {
            out[r] += a * if c == self.lam { 1.0 } else { v[c] };
        }
        out
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

/// Half the side of link `li`'s contact square, in units of `d`.
pub(super) fn half_side(s: &Structure, model: &Model, li: usize) -> f64 {
    0.5 * capacity(s, model, li).side / model.spacing
}

/// Each corner of link `l`'s square (half side `half`, in `d`): its first
/// column within the link's and its position.
pub(super) fn corners(l: &Link, half: f64) -> impl Iterator<Item = (usize, glam::DVec3)> + '_ {
    CORNERS
        .iter()
        .enumerate()
        .map(move |(ki, (su, sv))| (PER_CORNER * ki, l.contact + half * (su * l.u + sv * l.v)))
}

/// One corner's three force columns from `col` in the six rows from
/// `row`: `sign` × the unit forces on side b (a tension n pulls b towards
/// a, then the two tangential directions) and their moments at `arm`
/// from the point the rows take moments about.
fn push_corner(prog: &mut Program, l: &Link, row: usize, col: usize, arm: glam::DVec3, sign: f64) {
    for (j, f) in [-l.normal, l.u, l.v].iter().enumerate() {
        let m = arm.cross(*f);
        for (a, v) in [f.x, f.y, f.z, m.x, m.y, m.z].into_iter().enumerate() {
            prog.push(row + a, col + j, sign * v);
        }
    }
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
        let half = half_side(s, model, li);
        for (col, corner) in corners(l, half) {
            let ends = [(Some(l.a), -1.0), (l.b.body(), 1.0)];
            for (body, sign) in ends {
                let Some(body) = body.filter(|&b| is_free(b)) else {
                    continue;
                };
                let arm = corner - (frame.origin)(body);
                push_corner(prog, l, frame.row_of[body], PER_LINK * k + col, arm, sign);
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

/// The solver's settings, tried in turn until one solves: the static
/// regularisation of the KKT system and the tolerance. Interior point on
/// these degenerate problems (free tangential forces circulating between
/// corners) can stall on round-off, and which setting solves depends on
/// the structure:
///
/// * at 1e-8, the limit analyses of the sandcastle's large components and
///   of every scaffold frame tried end in `NumericalError` or
///   `InsufficientProgress` after about 14 iterations, nearly a whole
///   solve; at 1e-7 they are solved to the same tolerance;
/// * the RePoSt L → C structure, resting on the ground, is solved at 1e-8
///   (`AlmostSolved`, 50–58 iterations); at 1e-7 it takes 73–81
///   iterations and proves a factor lower by 1e-4 of itself.
///
/// So every solve starts at 1e-8, and the analyser starts a step's other
/// poses at the setting that solved its first ([`load_factor_from`]).
/// The factor reported is [`proof`]'s whatever the setting.
pub const SETTINGS: [(f64, f64); 4] = [(1e-8, 1e-8), (1e-7, 1e-8), (1e-6, 1e-7), (1e-5, 1e-6)];

/// Maximises `λ ≤ LAMBDA_CAP` (clarabel), trying [`SETTINGS`] from index
/// `first` on before giving up (NaN). Returns the forces and, for the
/// [`Mechanism`], each capacity row's dissipated work (its capacity times
/// its dual).
fn maximise(mut prog: Program, first: usize) -> (LimitResult, Option<Vec<f64>>, Option<Vec<f64>>) {
    let lam = prog.lam;
    let ncol = lam + 1;
    let capacity = prog.n_eq..prog.rhs.len();
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
    let mut tries = 0;
    let mut setting = SETTINGS.len();
    let mut x = None;
    let mut work = None;
    for (k, &(regularisation, tolerance)) in SETTINGS.iter().enumerate().skip(first) {
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
        tries += 1;
        if matches!(
            sol.status,
            SolverStatus::Solved | SolverStatus::AlmostSolved
        ) {
            lambda = sol.x[lam].clamp(0.0, LAMBDA_CAP);
            x = Some(sol.x[..lam].to_vec());
            work = Some(capacity.clone().map(|r| prog.rhs[r] * sol.z[r]).collect());
            setting = k;
            break;
        }
    }
    let r = LimitResult {
        lambda,
        iterations,
        tries,
        setting,
        solver_lambda: lambda,
    };
    (r, x, work)
}

/// A lower bound of the load factor of `part` under `loads`, which differ
/// from the loads `field` carries by pure moments `extra` (body, moment in
/// `W·d`): a mover at another sample of its path turns its weight's arm,
/// not its force. The candidate equilibrium is `field` scaled by `1/λ`
/// plus, for each extra moment, a chain of pure couples through the links
/// of a shortest path from its body to a support; the bound is the largest
/// multiple of it within every capacity. The candidate is checked against
/// the equilibrium equations of `loads` before it counts: 0 (no bound)
/// where it balances them worse than [`EQUILIBRIUM_TOL`], as a proved
/// field balances its own (see [`proof`]). The rows are the limit analysis's own
/// ([`equilibrium_rows`], [`capacity_rows`]), so the bound judges exactly
/// what a solve would.
pub fn bound_from(
    s: &Structure,
    model: &Model,
    loads: &[Vec6],
    part: Part<'_>,
    field: &Field,
    extra: &[(usize, glam::DVec3)],
) -> f64 {
    let nb = s.bodies.len();
    let (row_of, n_groups) = equation_groups(s, part, false);
    let is_free = |i: usize| row_of[i] != usize::MAX;
    let mut col_of = vec![usize::MAX; s.links.len()];
    for (k, &li) in field.links.iter().enumerate() {
        col_of[li] = PER_LINK * k;
    }
    let mut v: Vec<f64> = field.x.iter().map(|x| x / field.lambda).collect();
    // Links at each free body, for the paths.
    let mut at: Vec<Vec<usize>> = vec![Vec::new(); nb];
    for &li in &field.links {
        let l = &s.links[li];
        at[l.a].push(li);
        if let End::Body(b) = l.b {
            at[b].push(li);
        }
    }
    for &(body, m) in extra {
        if m == glam::DVec3::ZERO {
            continue;
        }
        if !is_free(body) {
            // A fixed body or another part carries it: no load here.
            continue;
        }
        // A support link must take the couple where it has no capacity
        // to spare: a ground contact without adhesion may not be pulled
        // (its rows with nothing on the right stay ≤ 0), so the nearest
        // support that does not lift is taken, not merely the nearest.
        let takes = |li: usize, from: usize| {
            let on_b = if s.links[li].a == from { m } else { -m };
            let mut cols = v[col_of[li]..col_of[li] + PER_LINK].to_vec();
            add_couple(&mut cols, s, model, li, on_b);
            carries_without_capacity(s, model, li, &mut cols)
        };
        let Some(path) = path_to_support(s, &at, &is_free, body, &takes) else {
            return 0.0;
        };
        // Each link of the path passes the couple on: the body nearer the
        // mover receives −m from it, the next one +m.
        let mut cur = body;
        for li in path {
            let l = &s.links[li];
            // Couple on side b: +m when `cur` is side a (a receives −m).
            let (on_b, next) = if l.a == cur {
                (m, l.b.body())
            } else {
                (-m, Some(l.a))
            };
            add_couple(
                &mut v[col_of[li]..col_of[li] + PER_LINK],
                s,
                model,
                li,
                on_b,
            );
            match next {
                Some(n) => cur = n,
                None => break,
            }
        }
    }
    let mut prog = Program::new(6 * n_groups, PER_LINK * field.links.len());
    let origin = |i: usize| s.bodies[i].centre;
    let frame = Frame {
        row_of: &row_of,
        origin: &origin,
    };
    equilibrium_rows(&mut prog, s, model, loads, part, &field.links, &frame);
    capacity_rows(&mut prog, s, model, &field.links);
    // Each tangential bound at its least, ‖t‖.
    for &(z, tu, tv) in &prog.socs {
        v[z] = v[tu].hypot(v[tv]);
    }
    let values = prog.row_values(&v);
    // The candidate must balance `loads` (λ = 1) on every free body as
    // a proved field balances its own.
    let residual = largest_residual(&values[..prog.n_eq]);
    if residual
        .partial_cmp(&EQUILIBRIUM_TOL)
        .is_none_or(|o| o.is_gt())
    {
        return 0.0;
    }
    // The largest multiple within every capacity row `lhs ≤ rhs`.
    let mut mu = LAMBDA_CAP;
    for (lhs, rhs) in values[prog.n_eq..].iter().zip(&prog.rhs[prog.n_eq..]) {
        if lhs.is_nan() {
            return 0.0;
        }
        if *lhs > 0.0 {
            mu = mu.min(if *rhs > 0.0 { rhs / lhs } else { 0.0 });
        }
    }
    mu
}

/// Whether one link's corner forces `cols` (its [`PER_LINK`] columns)
/// satisfy every capacity row of that link whose right-hand side is not
/// positive: the rows no multiple can bring within capacity (a ground
/// contact without adhesion pulled, or sliding without a normal force).
/// Each tangential bound is taken at its least, `‖t‖`.
fn carries_without_capacity(s: &Structure, model: &Model, li: usize, cols: &mut [f64]) -> bool {
    let mut prog = Program::new(0, PER_LINK);
    capacity_rows(&mut prog, s, model, &[li]);
    for &(z, tu, tv) in &prog.socs {
        cols[z] = cols[tu].hypot(cols[tv]);
    }
    let values = prog.row_values(cols);
    values
        .iter()
        .zip(&prog.rhs)
        .all(|(lhs, rhs)| *rhs > 0.0 || *lhs <= *rhs)
}

/// The links from `body` to the nearest support (the ground, or a body
/// outside the free ones) whose link `takes` the load (called with the
/// link and the free body it is reached from), fewest first
/// (breadth-first).
fn path_to_support(
    s: &Structure,
    at: &[Vec<usize>],
    is_free: &dyn Fn(usize) -> bool,
    body: usize,
    takes: &dyn Fn(usize, usize) -> bool,
) -> Option<Vec<usize>> {
    let mut came: Vec<Option<usize>> = vec![None; s.bodies.len()];
    let mut seen = vec![false; s.bodies.len()];
    seen[body] = true;
    let mut queue = std::collections::VecDeque::from([body]);
    while let Some(b) = queue.pop_front() {
        for &li in &at[b] {
            let l = &s.links[li];
            let other = if l.a == b { l.b.body() } else { Some(l.a) };
            let support = other.is_none_or(|o| !is_free(o));
            if support && !takes(li, b) {
                continue;
            }
            if support {
                let mut path = vec![li];
                let mut x = b;
                while let Some(prev) = came[x] {
                    path.push(prev);
                    let p = &s.links[prev];
                    x = if p.a == x {
                        p.b.body().expect("a path link joins two bodies")
                    } else {
                        p.a
                    };
                }
                path.reverse();
                return Some(path);
            }
            let o = other.expect("not a support");
            if !seen[o] {
                seen[o] = true;
                came[o] = Some(li);
                queue.push_back(o);
            }
        }
    }
    None
}

/// Adds to one link's corner forces a pure couple `m` on its side b
/// (normal forces for the bending part, tangential ones for the torsion).
fn add_couple(cols: &mut [f64], s: &Structure, model: &Model, li: usize, m: glam::DVec3) {
    let l = &s.links[li];
    let h = half_side(s, model, li);
    let nrm = l.normal;
    let m_n = m.dot(nrm);
    let m_in = m - m_n * nrm;
    // Normal forces n_k = α s_u + β s_v push along −normal on side b:
    // their couple is −4h (α u×N̂ + β v×N̂).
    let (eu, ev) = (l.u.cross(nrm), l.v.cross(nrm));
    let alpha = -m_in.dot(eu) / (4.0 * h * eu.length_squared());
    let beta = -m_in.dot(ev) / (4.0 * h * ev.length_squared());
    // Tangential forces c·N̂ × r_k: their couple is 8h²c N̂.
    let c = m_n / (8.0 * h * h);
    for (ki, (su, sv)) in CORNERS.iter().enumerate() {
        let r = h * (su * l.u + sv * l.v);
        let t = c * nrm.cross(r);
        let col = PER_CORNER * ki;
        cols[col] += alpha * su + beta * sv;
        cols[col + 1] += t.dot(l.u);
        cols[col + 2] += t.dot(l.v);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lattice::config::Ground;
    use crate::lattice::{Cell, FccLattice};
    use crate::mechanics::validation::{frame, structure};
    use glam::DVec3;

    /// A mechanism's shares come from the work of every capacity row: a
    /// NaN among them gives no mechanism (never a share read as 0), and
    /// the shares of finite works sum to 1, largest first.
    #[test]
    fn a_mechanism_shares_finite_work_and_refuses_a_nan() {
        let mut work = vec![0.0; 2 * CAPACITY_ROWS];
        work[1] = 1.0;
        work[CAPACITY_ROWS + 3] = 3.0;
        let m = mechanism(&[7, 9], &work).unwrap();
        assert_eq!(m.links, vec![(9, 0.75), (7, 0.25)]);
        work[2] = f64::NAN;
        assert_eq!(mechanism(&[7, 9], &work), None);
        assert_eq!(mechanism(&[7, 9], &[0.0; 2 * CAPACITY_ROWS]), None);
    }

    /// Every body and every link of `s`: the part that is the whole.
    fn everything(s: &Structure) -> (Vec<usize>, Vec<usize>) {
        ((0..s.bodies.len()).collect(), (0..s.links.len()).collect())
    }

    /// Gravity on every body (units of `W`), as the analyser loads them.
    fn gravity(s: &Structure) -> Vec<Vec6> {
        let g = s.gravity;
        vec![Vec6::new(g.x, g.y, g.z, 0.0, 0.0, 0.0); s.bodies.len()]
    }

    fn with_moment(loads: &[Vec6], body: usize, m: DVec3) -> Vec<Vec6> {
        let mut l = loads.to_vec();
        l[body] += Vec6::new(0.0, 0.0, 0.0, m.x, m.y, m.z);
        l
    }

    /// Bounds from the equilibrium under `loads` at each body, for moments
    /// in many directions and sizes, against the limit analysis of the
    /// changed loads itself: never above it, and not trivially low.
    fn check_bounds(s: &Structure, model: &Model) -> usize {
        let (bodies, links) = everything(s);
        let part = Part {
            bodies: &bodies,
            links: &links,
        };
        let base = gravity(s);
        let Solved {
            result: r, field, ..
        } = solve_with_capacities(s, model, &base, part, 0, true);
        let field = field.expect("an equilibrium");
        assert!(r.lambda > 1.0 && r.lambda < LAMBDA_CAP, "{}", r.lambda);
        let mut tight = 0;
        let dirs = [
            DVec3::X,
            -DVec3::X,
            DVec3::Y,
            -DVec3::Y,
            DVec3::Z,
            DVec3::new(1.0, -2.0, 0.5),
        ];
        for body in bodies.iter().copied().filter(|&b| !s.bodies[b].fixed) {
            for dir in dirs {
                for size in [0.01, 0.1, 0.5, 5.0, 20.0] {
                    let m = dir.normalize() * size;
                    let loads = with_moment(&base, body, m);
                    let bound = bound_from(s, model, &loads, part, &field, &[(body, m)]);
                    let exact = load_factor(s, model, &loads, part, Connectors::Capacities).lambda;
                    assert!(
                        bound <= exact * (1.0 + 1e-6),
                        "body {body}, moment {m}: bound {bound} above the load factor {exact}"
                    );
                    if size == 0.01 && bound >= 0.9 * exact {
                        tight += 1;
                    }
                }
            }
        }
        tight
    }

    #[test]
    fn a_bound_from_a_neighbouring_load_case_never_exceeds_its_load_factor() {
        let model = Model::default_catom();
        // A cantilever from a fixed root, and its mirror image.
        for sign in [1, -1] {
            let cells: Vec<Cell> = (0..=4).map(|i| Cell::new(sign * i, 0, 0)).collect();
            let s = structure(&FccLattice, None, &cells, &[0], &[]);
            let tight = check_bounds(&s, &model);
            assert!(
                tight >= 4 * 6 / 2,
                "small moments give close bounds: {tight}"
            );
        }
        // A frame resting on the ground (no adhesion there), with an arm.
        // The equilibrium leaves some ground corners unloaded: a couple
        // passed to the nearest ground contact would lift one and give no
        // bound, so small moments are tight only if the chain ends at a
        // contact that takes them (28 of 36 when it did not).
        let ground = Some(Ground { layer: 0 });
        let mut cells = vec![Cell::new(0, 0, 0), Cell::new(1, 0, 0), Cell::new(0, 1, 0)];
        cells.extend([Cell::new(0, 0, 1), Cell::new(1, 0, 1), Cell::new(2, 0, 1)]);
        let s = structure(&FccLattice, ground, &cells, &[], &[]);
        let tight = check_bounds(&s, &model);
        assert_eq!(tight, cells.len() * 6, "small moments give close bounds");
    }

    #[test]
    fn a_frame_started_at_the_setting_that_solved_it_is_solved_at_once_to_the_same_factor() {
        // At clarabel's own regularisation (1e-8) a scaffold frame stalls
        // on round-off and is solved at the next setting (2 × 2 × 2 tiles:
        // 66 iterations over two tries), as are the sandcastle's large
        // components. The analyser starts a step's other poses at the
        // setting its first pose needed: one try, the same factor.
        let model = Model::default_catom();
        let s = frame(2, 2);
        let (bodies, links) = everything(&s);
        let part = Part {
            bodies: &bodies,
            links: &links,
        };
        let loads = gravity(&s);
        let c = Connectors::Capacities;
        let r = load_factor(&s, &model, &loads, part, c);
        assert_eq!(s.links.len(), 300);
        assert_eq!((r.tries, r.setting), (2, 1), "{r:?}");
        let again = load_factor_from(&s, &model, &loads, part, c, r.setting);
        assert_eq!((again.tries, again.setting), (1, 1), "{again:?}");
        assert_eq!(again.lambda, r.lambda);
        assert!(again.iterations < r.iterations);
        assert!(r.lambda > 11.6 && r.lambda < 11.7, "{r:?}");
        // Past the last setting nothing is tried: NaN, never a factor.
        let none = load_factor_from(&s, &model, &loads, part, c, SETTINGS.len());
        assert!(none.lambda.is_nan() && none.tries == 0, "{none:?}");
    }

    /// A fixed module at `(0, 0, 1)` and its neighbour in direction
    /// `dir`: one link, in each of the lattice's twelve frames.
    fn pair(dir: usize) -> Structure {
        use crate::lattice::Lattice;
        let centre = Cell::new(0, 0, 1);
        let cells = [centre, FccLattice.neighbour(centre, dir)];
        structure(&FccLattice, None, &cells, &[0], &[])
    }

    /// A connector square in the program's units: each corner's share of
    /// the adhesion (`W`), the friction coefficient, the half side (`d`).
    fn square(model: &Model) -> (f64, f64, f64) {
        let cap = &model.connector;
        (
            cap.tension() / model.weight() / 4.0,
            cap.friction,
            0.5 * cap.side / model.spacing,
        )
    }

    /// The action on side b (force, moment about the contact; `W`, `W·d`)
    /// of corner forces `(n, t_u, t_v)`, tension positive, summed here
    /// from the square's geometry.
    fn resultant(
        l: &crate::mechanics::structure::Link,
        half: f64,
        corners: &[[f64; 3]; 4],
    ) -> (DVec3, DVec3) {
        let (mut f, mut m) = (DVec3::ZERO, DVec3::ZERO);
        for ((su, sv), [n, tu, tv]) in CORNERS.iter().zip(corners) {
            let arm = half * (su * l.u + sv * l.v);
            let fk = -*n * l.normal + *tu * l.u + *tv * l.v;
            f += fk;
            m += arm.cross(fk);
        }
        (f, m)
    }

    #[test]
    fn a_link_carries_what_admissible_corner_forces_add_up_to() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        for bending in [Bending::RigidHinge, Bending::Elastic] {
            let mut model = Model::default_catom();
            model.connector.bending = bending;
            let (p, mu, half) = square(&model);
            let mut tried = 0;
            for dir in 0..12 {
                let s = pair(dir);
                let l = &s.links[0];
                while tried < 30 * (dir + 1) {
                    // Each corner pulls at most 90 % of its share, pushes
                    // up to three shares, and rubs within 90 % of its cone.
                    let corners: [[f64; 3]; 4] = std::array::from_fn(|_| {
                        let n = p * rng.random_range(-3.0..0.9);
                        let (r, a) = (
                            rng.random_range(0.0..0.9),
                            rng.random_range(0.0..std::f64::consts::TAU),
                        );
                        let t = r * mu * (p - n);
                        [n, t * a.cos(), t * a.sin()]
                    });
                    if bending == Bending::Elastic {
                        // The linear stress distribution's rows, with 10 % spare.
                        let ok = CORNERS.iter().all(|(eu, ev)| {
                            let lhs: f64 = CORNERS
                                .iter()
                                .zip(&corners)
                                .map(|((su, sv), c)| c[0] * (1.0 + 3.0 * (eu * su + ev * sv)))
                                .sum();
                            lhs <= 0.9 * 4.0 * p
                        });
                        if !ok {
                            continue;
                        }
                    }
                    tried += 1;
                    let (f, m) = resultant(l, half, &corners);
                    let lam = link_load_factor(&s, &model, 0, f, m);
                    assert!(
                        lam >= 1.0,
                        "{bending:?}, direction {dir}: {corners:?} carried {lam} times"
                    );
                    // The same forces mirrored across the square's u axis.
                    let mirrored: [[f64; 3]; 4] = [corners[1], corners[0], corners[3], corners[2]]
                        .map(|[n, tu, tv]| [n, tu, -tv]);
                    let (f, m) = resultant(l, half, &mirrored);
                    assert!(link_load_factor(&s, &model, 0, f, m) >= 1.0);
                }
            }
        }
    }

    #[test]
    fn a_link_refuses_what_no_corner_forces_can_carry() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(12);
        let model = Model::default_catom();
        let (p, mu, half) = square(&model);
        let p4 = 4.0 * p;
        let mut refused = 0;
        for dir in 0..12 {
            let s = pair(dir);
            let l = &s.links[0];
            for _ in 0..60 {
                let mut v = |k: f64| {
                    DVec3::new(
                        rng.random_range(-k..k),
                        rng.random_range(-k..k),
                        rng.random_range(-k..k),
                    )
                };
                let (f, m) = (v(2.0 * p4), v(2.0 * p4 * half));
                let lam = link_load_factor(&s, &model, 0, f, m);
                // Necessary for any corner forces: the tension within the
                // adhesion, the shear within the friction of the clamp, the
                // torsion within that friction at the corners' distance.
                let tension = -f.dot(l.normal);
                let clamp = p4 - tension;
                let shear = (f + tension * l.normal).length();
                let torsion = m.dot(l.normal).abs();
                let possible = clamp >= 0.0
                    && shear <= mu * clamp
                    && torsion <= mu * clamp * half * std::f64::consts::SQRT_2;
                if !possible {
                    refused += 1;
                    assert!(lam < 1.0, "direction {dir}: {f} {m} carried {lam} times");
                }
            }
        }
        assert!(refused > 300, "{refused}");
        // NaN in, NaN out: never a factor that reads as carried.
        let nan = link_load_factor(&pair(0), &model, 0, DVec3::NAN, DVec3::ZERO);
        assert!(nan.is_nan(), "{nan}");
    }

    #[test]
    fn a_candidate_that_does_not_balance_the_loads_gives_no_bound() {
        let model = Model::default_catom();
        let cells: Vec<Cell> = (0..=3).map(|i| Cell::new(i, 0, 0)).collect();
        let s = structure(&FccLattice, None, &cells, &[0], &[]);
        let (bodies, links) = everything(&s);
        let part = Part {
            bodies: &bodies,
            links: &links,
        };
        let base = gravity(&s);
        let field = solve_with_capacities(&s, &model, &base, part, 0, true).field;
        let field = field.unwrap();
        let tip = s
            .bodies
            .iter()
            .position(|b| b.cell == Cell::new(3, 0, 0))
            .unwrap();
        let m = DVec3::new(0.0, 0.1, 0.0);
        let loads = with_moment(&base, tip, m);
        // The moment is said to act elsewhere, or not at all: no bound.
        assert_eq!(
            bound_from(&s, &model, &loads, part, &field, &[(tip - 1, m)]),
            0.0
        );
        assert_eq!(bound_from(&s, &model, &loads, part, &field, &[]), 0.0);
        // A NaN moment gives none either.
        let nan = DVec3::new(f64::NAN, 0.0, 0.0);
        assert_eq!(
            bound_from(&s, &model, &loads, part, &field, &[(tip, nan)]),
            0.0
        );
        assert!(bound_from(&s, &model, &loads, part, &field, &[(tip, m)]) > 0.0);
    }
}
