//! Static analysis of one structure under gravity: the linear-elastic
//! network of rigid modules joined by elastic connector interfaces (the
//! rigid-body–spring form of the beam networks of Hołobut & Lengiewicz and
//! Piranda et al.), solved per connected component by preconditioned CG,
//! with the ground contacts made unilateral by an active set.
//!
//! Units inside the solve: lengths in `d`, forces in the module weight
//! `W = m·g`; interface stiffnesses relative to the axial one (the absolute
//! modulus and layer thickness cancel out of the loads). Results are in SI.

use super::capacity::{ConnectorLoad, Mode, overloaded, severity, utilisation};
use super::direct::Factor;
use super::model::{Capacity, Model};
use super::reuse::KeptFactor;
use super::solver::{Block, BlockMatrix, Vec6, jacobi_pcg, pcg, transfer};
use super::structure::{End, Link, Structure};
use glam::DVec3;
use nalgebra::Matrix3;
use rustc_hash::FxHashMap;

/// Result for one link (connector or ground contact).
#[derive(Copy, Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct LinkResult {
    pub load: ConnectorLoad,
    pub utilisation: f64,
    pub mode: Option<Mode>,
    /// A ground contact the active set let go (the module lifts off).
    pub released: bool,
    /// A ground contact that slides (its friction was exceeded): it keeps
    /// its normal and bending stiffness but transmits no friction.
    pub sliding: bool,
    /// Force side `a` exerts on side `b` through the link (world, N).
    pub force: [f64; 3],
    /// Moment side `a` exerts on side `b` about the contact (world, N·m).
    pub moment: [f64; 3],
}

/// The connector holding a mover on its pivot, at its worst instant.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct PivotResult {
    pub hanging: usize,
    pub load: ConnectorLoad,
    pub utilisation: f64,
    pub mode: Mode,
    /// Sweep parameter `s ∈ [0, 1]` of the worst instant.
    pub s: f64,
}

/// The verdict on a structure.
#[derive(Copy, Clone, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// In equilibrium with every connector within capacity.
    Stable,
    /// In equilibrium, but some connector is loaded beyond capacity.
    Overloaded,
    /// No static equilibrium: a part is unsupported, tips or slides.
    NoEquilibrium,
}

/// Where the largest utilisation is.
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize)]
pub enum Critical {
    Link(usize),
    Pivot(usize),
}

/// Full result of a static analysis.
#[derive(Clone, Debug, Default)]
pub struct Analysis {
    pub links: Vec<LinkResult>,
    pub pivots: Vec<PivotResult>,
    /// Bodies of components with no support left (nothing holds them).
    pub unsupported: Vec<usize>,
    pub max_utilisation: f64,
    pub critical: Option<Critical>,
    pub verdict: Option<Verdict>,
    /// CG iterations (preconditioned by a kept factor, or refining a fresh
    /// one) and sparse factorisations this analysis took.
    pub iterations: usize,
    pub factorizations: usize,
}

impl Analysis {
    pub fn verdict(&self) -> Verdict {
        self.verdict.unwrap_or(Verdict::Stable)
    }
}

/// Solver settings.
#[derive(Copy, Clone, Debug)]
pub struct Settings {
    /// CG stopping rule, `‖r‖ ≤ tol·‖f‖`.
    pub tolerance: f64,
    /// Rounds of releasing ground contacts in tension.
    pub max_release_rounds: usize,
    /// CG iterations allowed with a kept factor before it is refreshed.
    pub reuse_iterations: usize,
    /// The kept factor is tried only while at most this many bodies were
    /// added or removed since it was made.
    pub reuse_max_changed: usize,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            tolerance: 1e-10,
            max_release_rounds: 30,
            reuse_iterations: REUSE_ITERATIONS,
            reuse_max_changed: REUSE_MAX_CHANGED,
        }
    }
}

/// CG iterations with a kept factor before a fresh factorisation is made
/// instead. A solve with the factor costs about 1/15 of factoring on the
/// scaffold structures (measured on the sandcastle, `docs/mechanics.md`),
/// so beyond ~10 iterations the reuse would no longer pay.
pub const REUSE_ITERATIONS: usize = 10;

/// See [`Settings::reuse_max_changed`]. Measured on the cube-d5 scaffold
/// schedule (tolerance 1e-10): with only the loads changed, CG with the
/// kept factor converges in 1 iteration; with one body added or removed in
/// 1–9; with 2 or more it mostly needs over 10 — a removed body perturbs
/// the preconditioned matrix by the rank of all its links — so beyond one
/// changed body a fresh factor is cheaper.
pub const REUSE_MAX_CHANGED: usize = 1;

/// Interface stiffnesses relative to the axial one, lengths in `d`:
/// an elastic layer over the square of side `λ = L/d` — axial `EA/t`,
/// shear `GA/t`, bending `EI/t` (`I = λ⁴/12`), torsion `GJ/t`
/// (`J ≈ 0.1406 λ⁴` for a square), all divided by `EA/t`.
#[derive(Copy, Clone, Debug)]
struct Springs {
    axial: f64,
    shear: f64,
    torsion: f64,
    bending: f64,
}

impl Springs {
    fn new(model: &Model, cap: &Capacity) -> Springs {
        let lam = cap.side / model.spacing;
        let g = 1.0 / (2.0 * (1.0 + model.poisson));
        Springs {
            axial: 1.0,
            shear: g,
            torsion: g * 0.1406 * lam * lam,
            bending: lam * lam / 12.0,
        }
    }
}

/// Stiffness blocks of one link geometry (normal, kind), shared by every
/// link of the same direction: `D` (interface), `G_a`, `G_b`, and the
/// three blocks `G_aᵀDG_a`, `G_bᵀDG_b`, `−G_aᵀDG_b`.
#[derive(Clone, Debug)]
struct LinkBlocks {
    d: Block,
    ga: Block,
    gb: Block,
    kaa: Block,
    kbb: Block,
    kab: Block,
}

fn v3(v: DVec3) -> nalgebra::Vector3<f64> {
    nalgebra::Vector3::new(v.x, v.y, v.z)
}

/// The interface stiffness of a link in world axes.
fn link_stiffness(link: &Link, k: &Springs) -> Block {
    let r = Matrix3::from_rows(&[
        v3(link.normal).transpose(),
        v3(link.u).transpose(),
        v3(link.v).transpose(),
    ]);
    let dt = r.transpose()
        * Matrix3::from_diagonal(&nalgebra::Vector3::new(k.axial, k.shear, k.shear))
        * r;
    let dr = r.transpose()
        * Matrix3::from_diagonal(&nalgebra::Vector3::new(k.torsion, k.bending, k.bending))
        * r;
    let mut d = Block::zeros();
    d.fixed_view_mut::<3, 3>(0, 0).copy_from(&dt);
    d.fixed_view_mut::<3, 3>(3, 3).copy_from(&dr);
    d
}

/// Loads of one structure's modules (units of `W`, moments in `W·d`).
fn body_loads(s: &Structure) -> Vec<Vec6> {
    let g = s.gravity;
    let mut f = vec![Vec6::new(g.x, g.y, g.z, 0.0, 0.0, 0.0); s.bodies.len()];
    for h in &s.hanging {
        let p = s.bodies[h.pivot].centre;
        let r = worst_lever(h.path.iter().map(|c| *c - p), g);
        let m = r.cross(g);
        f[h.pivot] += Vec6::new(g.x, g.y, g.z, m.x, m.y, m.z);
    }
    f
}

/// The offset with the largest horizontal lever (component across gravity);
/// among equal levers (to 1e-9 d) the latest one, so that a mover sweeping
/// a horizontal arc is taken at its target cell.
fn worst_lever(offsets: impl Iterator<Item = DVec3>, g: DVec3) -> DVec3 {
    let mut best = DVec3::ZERO;
    let mut best_h = -1.0;
    for r in offsets {
        let h = (r - r.dot(g) * g).length();
        if h >= best_h - 1e-9 {
            if h > best_h {
                best_h = h;
            }
            best = r;
        }
    }
    best
}

/// A body's identity across steps: the module and the cell it rests in.
type BodyKey = (u32, [i32; 3]);

fn key(b: &super::structure::Body) -> BodyKey {
    (b.module, b.cell.to_array())
}

/// The factor kept from an earlier step: the preconditioner of later ones.
struct Reference {
    factor: Factor,
    /// Body → its block row in `factor`.
    index: FxHashMap<BodyKey, u32>,
}

/// Analyses structures, optionally reusing work between consecutive calls
/// (the steps of a schedule).
///
/// From scratch, every solve factors the step's stiffness matrix (sparse
/// Cholesky). Incrementally, each component keeps the factor of the last
/// step that factored it, and CG preconditioned by it, started from the
/// previous displacements of the same bodies, solves the current step —
/// exactly in one iteration when only the loads changed. It is tried only
/// while at most [`Settings::reuse_max_changed`] bodies changed, for at
/// most [`Settings::reuse_iterations`] iterations; otherwise the component
/// is factored afresh and that factor is kept.
pub struct Analyzer {
    pub model: Model,
    pub settings: Settings,
    pub incremental: bool,
    springs: Springs,
    ground_springs: Springs,
    warm: FxHashMap<BodyKey, Vec6>,
    /// One kept factor per component of the last step, and which one
    /// holds each body.
    references: Vec<Reference>,
    owner: FxHashMap<BodyKey, u32>,
    blocks: FxHashMap<([u64; 3], bool, bool), LinkBlocks>,
}

impl Analyzer {
    pub fn new(model: Model, incremental: bool) -> Analyzer {
        let springs = Springs::new(&model, &model.connector);
        let ground_springs = Springs::new(&model, &model.ground);
        Analyzer {
            model,
            settings: Settings::default(),
            incremental,
            springs,
            ground_springs,
            warm: FxHashMap::default(),
            references: Vec::new(),
            owner: FxHashMap::default(),
            blocks: FxHashMap::default(),
        }
    }

    /// Forgets what earlier steps left (factor and displacements).
    pub fn reset(&mut self) {
        self.warm.clear();
        self.references.clear();
        self.owner.clear();
    }

    /// The stiffness blocks of a link (cached by geometry: every link of a
    /// lattice direction has its contact at ±n·d/2 from both centres).
    fn link_blocks(&mut self, s: &Structure, l: &Link, sliding: bool) -> LinkBlocks {
        let ra = l.contact - s.bodies[l.a].centre;
        let rb = match l.b {
            End::Body(b) => Some(l.contact - s.bodies[b].centre),
            End::Ground(_) => None,
        };
        let key = (
            l.normal.to_array().map(f64::to_bits),
            l.is_ground(),
            sliding,
        );
        let standard = (ra - 0.5 * l.normal).length() < 1e-12
            && rb.is_none_or(|r| (r + 0.5 * l.normal).length() < 1e-12);
        if standard && let Some(b) = self.blocks.get(&key) {
            return b.clone();
        }
        let d = link_stiffness(l, &self.link_springs(l, sliding));
        let ga = transfer(ra);
        let gb = rb.map_or(Block::identity(), transfer);
        let b = LinkBlocks {
            kaa: ga.transpose() * d * ga,
            kbb: gb.transpose() * d * gb,
            kab: -(ga.transpose() * d * gb),
            d,
            ga,
            gb,
        };
        if standard {
            self.blocks.insert(key, b.clone());
        }
        b
    }

    fn capacity(&self, link: &Link) -> &Capacity {
        if link.is_ground() {
            &self.model.ground
        } else {
            &self.model.connector
        }
    }

    /// Analyses one structure.
    pub fn analyse(&mut self, s: &Structure) -> Analysis {
        let nb = s.bodies.len();
        let loads = body_loads(s);
        let comps = Components::of_structure(s);
        let mut out = Analysis {
            links: vec![LinkResult::default(); s.links.len()],
            ..Default::default()
        };
        let mut released = vec![false; s.links.len()];
        let mut sliding = vec![false; s.links.len()];
        // Displacements of every free body (zeros where unsupported).
        let mut q_all = vec![Vec6::zeros(); nb];
        let mut anchored = vec![false; comps.count];
        let mut local = vec![u32::MAX; nb];
        // The kept factors, looked up by body; this step's replace them.
        let mut kept: Vec<Option<Reference>> = std::mem::take(&mut self.references)
            .into_iter()
            .map(Some)
            .collect();
        let owner = std::mem::take(&mut self.owner);
        for c in 0..comps.count {
            let bodies = &comps.bodies[c];
            let links = &comps.links[c];
            for (k, &b) in bodies.iter().enumerate() {
                local[b] = k as u32;
            }
            let f: Vec<Vec6> = bodies.iter().map(|&b| loads[b]).collect();
            let mut q: Vec<Vec6> = bodies
                .iter()
                .map(|&b| {
                    self.warm
                        .get(&key(&s.bodies[b]))
                        .copied()
                        .unwrap_or_else(Vec6::zeros)
                })
                .collect();
            let mut reference = if self.incremental {
                bodies
                    .iter()
                    .find_map(|&b| owner.get(&key(&s.bodies[b])))
                    .and_then(|&r| kept[r as usize].take())
            } else {
                None
            };
            for _round in 0..=self.settings.max_release_rounds {
                // The component stands while some link ties it to the
                // ground or to a fixed module.
                anchored[c] = links.iter().any(|&li| {
                    !released[li]
                        && (comps.of(s, End::Body(s.links[li].a)).is_none()
                            || comps.of(s, s.links[li].b).is_none())
                });
                if !anchored[c] {
                    break;
                }
                let k = self.assemble(s, links, &local, &released, &sliding, bodies.len());
                self.solve(s, bodies, &k, &f, &mut q, &mut reference, &mut out);
                for (i, &b) in bodies.iter().enumerate() {
                    q_all[b] = q[i];
                }
                // Ground contacts pulled or tipped beyond their edge let
                // go; failing that, those beyond their friction slide.
                let mut lift = Vec::new();
                let mut slide = Vec::new();
                for &li in links {
                    let l = &s.links[li];
                    if !l.is_ground() || released[li] {
                        continue;
                    }
                    let load = self.link_forces(s, l, &q_all, sliding[li]).0;
                    let (u, mode) = utilisation(&load, &self.model.ground);
                    if overloaded(u) {
                        match mode {
                            Mode::Bending => lift.push(li),
                            Mode::Friction if !sliding[li] => slide.push(li),
                            Mode::Friction => {}
                        }
                    }
                }
                if !lift.is_empty() {
                    lift.into_iter().for_each(|li| released[li] = true);
                } else if !slide.is_empty() {
                    slide.into_iter().for_each(|li| sliding[li] = true);
                } else {
                    break;
                }
            }
            for &b in bodies {
                local[b] = u32::MAX;
            }
            if !anchored[c] {
                bodies.iter().for_each(|&b| q_all[b] = Vec6::zeros());
            }
            if let Some(r) = reference {
                self.references.push(r);
            }
        }
        if self.incremental {
            self.warm.clear();
            for (r, reference) in self.references.iter().enumerate() {
                for k in reference.index.keys() {
                    self.owner.insert(*k, r as u32);
                }
            }
        }
        let mut any_unsupported = false;
        for c in 0..comps.count {
            if !anchored[c] {
                any_unsupported = true;
                out.unsupported.extend(comps.bodies[c].iter().copied());
                continue;
            }
            if self.incremental {
                for &b in &comps.bodies[c] {
                    self.warm.insert(key(&s.bodies[b]), q_all[b]);
                }
            }
            for &li in &comps.links[c] {
                let l = &s.links[li];
                out.links[li] = if released[li] {
                    LinkResult {
                        released: true,
                        ..Default::default()
                    }
                } else {
                    let (load, force, moment) = self.link_forces(s, l, &q_all, sliding[li]);
                    let (u, m) = utilisation(&load, self.capacity(l));
                    LinkResult {
                        load,
                        utilisation: u,
                        mode: Some(m),
                        released: false,
                        sliding: sliding[li],
                        force: force.to_array(),
                        moment: moment.to_array(),
                    }
                };
            }
        }
        out.unsupported.sort_unstable();

        // The connector holding each mover on its pivot.
        let w = self.model.weight();
        for (hi, h) in s.hanging.iter().enumerate() {
            let p = s.bodies[h.pivot].centre;
            let n_samples = h.path.len();
            let mut worst: Option<PivotResult> = None;
            for (k, c) in h.path.iter().enumerate() {
                let n = (*c - p).normalize();
                let (u, v) = super::structure::face_frame(n);
                // The connector holds the mover's weight: force −W·ĝ on the
                // mover, moment −(c − contact) × W·ĝ with c − contact = n·r/2.
                let g = s.gravity;
                let r = (*c - p).length() * self.model.spacing / 2.0;
                let f_on_mover = -g * w;
                let m_on_mover = -(n * r).cross(g * w);
                let shear = f_on_mover - f_on_mover.dot(n) * n;
                let load = ConnectorLoad {
                    axial: -f_on_mover.dot(n),
                    shear: shear.length(),
                    torsion: m_on_mover.dot(n),
                    moment_u: m_on_mover.dot(u),
                    moment_v: m_on_mover.dot(v),
                };
                let (ut, mode) = utilisation(&load, &self.model.connector);
                if worst.as_ref().is_none_or(|w| ut > w.utilisation) {
                    worst = Some(PivotResult {
                        hanging: hi,
                        load,
                        utilisation: ut,
                        mode,
                        s: k as f64 / (n_samples - 1).max(1) as f64,
                    });
                }
            }
            out.pivots.extend(worst);
        }

        // Summary.
        let mut max = 0.0;
        let mut crit = None;
        let mut any_overloaded = false;
        let mut slides = false;
        for (i, r) in out.links.iter().enumerate() {
            let u = severity(r.utilisation);
            if u > max || (crit.is_none() && u > 0.0) {
                max = u;
                crit = Some(Critical::Link(i));
            }
            if overloaded(r.utilisation) {
                if s.links[i].is_ground() {
                    slides = true;
                } else {
                    any_overloaded = true;
                }
            }
        }
        for (i, r) in out.pivots.iter().enumerate() {
            let u = severity(r.utilisation);
            if u > max {
                max = u;
                crit = Some(Critical::Pivot(i));
            }
            if overloaded(r.utilisation) {
                any_overloaded = true;
            }
        }
        out.max_utilisation = max;
        out.critical = crit;
        out.verdict = Some(if any_unsupported || slides {
            Verdict::NoEquilibrium
        } else if any_overloaded {
            Verdict::Overloaded
        } else {
            Verdict::Stable
        });
        out
    }

    /// The stiffness matrix of every free body of `s` (in body order, fixed
    /// bodies left out), every link held and none sliding — the system a
    /// from-scratch step factors, for measurements such as
    /// `examples/mech_floor.rs`.
    pub fn stiffness_matrix(&mut self, s: &Structure) -> BlockMatrix {
        let mut local = vec![u32::MAX; s.bodies.len()];
        let mut n = 0;
        for (i, b) in s.bodies.iter().enumerate() {
            if !b.fixed {
                local[i] = n;
                n += 1;
            }
        }
        let links: Vec<usize> = (0..s.links.len()).collect();
        let no = vec![false; s.links.len()];
        self.assemble(s, &links, &local, &no, &no, n as usize)
    }

    fn link_springs(&self, l: &Link, sliding: bool) -> Springs {
        let mut k = if l.is_ground() {
            self.ground_springs
        } else {
            self.springs
        };
        if sliding {
            k.shear = 0.0;
            k.torsion = 0.0;
        }
        k
    }

    /// The link's load in its frame, and the force and moment side `a`
    /// exerts on side `b` (world, SI).
    fn link_forces(
        &mut self,
        s: &Structure,
        l: &Link,
        q: &[Vec6],
        sliding: bool,
    ) -> (ConnectorLoad, DVec3, DVec3) {
        let lb = self.link_blocks(s, l, sliding);
        let mut e = Vec6::zeros();
        if !s.bodies[l.a].fixed {
            e -= lb.ga * q[l.a];
        }
        if let End::Body(b) = l.b
            && !s.bodies[b].fixed
        {
            e += lb.gb * q[b];
        }
        let sf = lb.d * e;
        let f = DVec3::new(sf[0], sf[1], sf[2]);
        let m = DVec3::new(sf[3], sf[4], sf[5]);
        let axial = f.dot(l.normal);
        let w = self.model.weight();
        let wd = w * self.model.spacing;
        let load = ConnectorLoad {
            axial: axial * w,
            shear: (f - axial * l.normal).length() * w,
            torsion: m.dot(l.normal) * wd,
            moment_u: m.dot(l.u) * wd,
            moment_v: m.dot(l.v) * wd,
        };
        // A stretched interface (S·n > 0) pulls b back towards a.
        (load, -f * w, -m * wd)
    }

    /// The stiffness matrix of `links` over the bodies with a `local` index.
    fn assemble(
        &mut self,
        s: &Structure,
        links: &[usize],
        local: &[u32],
        released: &[bool],
        sliding: &[bool],
        n: usize,
    ) -> BlockMatrix {
        let mut k = BlockMatrix::new(n);
        k.off.reserve(s.links.len());
        let side = |e: End| match e {
            End::Body(b) if local[b] != u32::MAX => Some(local[b] as usize),
            _ => None,
        };
        for &li in links {
            let l = &s.links[li];
            let (ia, ib) = (side(End::Body(l.a)), side(l.b));
            if released[li] || (ia.is_none() && ib.is_none()) {
                continue;
            }
            let lb = self.link_blocks(s, l, sliding[li]);
            if let Some(a) = ia {
                k.diag[a] += lb.kaa;
            }
            if let Some(b) = ib {
                k.diag[b] += lb.kbb;
            }
            if let (Some(a), Some(b)) = (ia, ib) {
                if a < b {
                    k.off.push((a as u32, b as u32, lb.kab));
                } else {
                    k.off.push((b as u32, a as u32, lb.kab.transpose()));
                }
            }
        }
        k
    }

    /// Solves `K q = f` over one component's `active` bodies: by a fresh
    /// factor, or (incrementally) by CG preconditioned with the component's
    /// kept factor `reference`, falling back to a fresh factor — which then
    /// becomes the kept one — when that does not converge quickly.
    #[allow(clippy::too_many_arguments)]
    fn solve(
        &mut self,
        s: &Structure,
        active: &[usize],
        k: &BlockMatrix,
        f: &[Vec6],
        q: &mut [Vec6],
        reference: &mut Option<Reference>,
        out: &mut Analysis,
    ) {
        if k.is_empty() {
            return;
        }
        let tol = self.settings.tolerance;
        if self.incremental {
            if let Some(r) = reference.as_ref() {
                let map: Vec<u32> = active
                    .iter()
                    .map(|&b| r.index.get(&key(&s.bodies[b])).copied().unwrap_or(u32::MAX))
                    .collect();
                let kept = map.iter().filter(|&&m| m != u32::MAX).count();
                let changed = (map.len() - kept) + (r.index.len() - kept);
                if changed <= self.settings.reuse_max_changed {
                    let mut pre = KeptFactor::new(&r.factor, &map, k);
                    let mut apply = |res: &[Vec6], z: &mut [Vec6]| pre.apply(res, z);
                    let stats = pcg(k, &mut apply, f, q, tol, self.settings.reuse_iterations);
                    out.iterations += stats.iterations;
                    if stats.converged {
                        return;
                    }
                }
            } else if pcg(k, &mut |r, z| z.copy_from_slice(r), f, q, tol, 0).converged {
                // Already at the solution (nothing changed): no factor needed.
                return;
            }
        }
        let fac = Factor::new(k);
        match fac {
            Some(factor) => {
                out.factorizations += 1;
                q.copy_from_slice(f);
                factor.solve_in_place(q);
                // One step of refinement against round-off, if needed.
                let mut apply = |res: &[Vec6], z: &mut [Vec6]| {
                    z.copy_from_slice(res);
                    factor.solve_in_place(z);
                };
                out.iterations += pcg(k, &mut apply, f, q, tol, 5).iterations;
                if self.incremental {
                    let index = active
                        .iter()
                        .enumerate()
                        .map(|(i, &b)| (key(&s.bodies[b]), i as u32))
                        .collect();
                    *reference = Some(Reference { factor, index });
                }
            }
            None => {
                // Not positive definite (a mechanism, e.g. a contact that
                // slides): CG finds a least-energy answer in the range.
                let n = k.len();
                out.iterations += jacobi_pcg(k, f, q, tol, 50 * 6 * n + 1000).iterations;
            }
        }
    }
}

/// Connected components of the free bodies (joined by body–body links).
struct Components {
    of: Vec<u32>,
    count: usize,
    /// Bodies and links (by the free side) of each component.
    bodies: Vec<Vec<usize>>,
    links: Vec<Vec<usize>>,
}

impl Components {
    fn of_structure(s: &Structure) -> Components {
        let nb = s.bodies.len();
        let mut parent: Vec<usize> = (0..nb).collect();
        fn find(p: &mut [usize], mut x: usize) -> usize {
            while p[x] != x {
                p[x] = p[p[x]];
                x = p[x];
            }
            x
        }
        for l in &s.links {
            if let End::Body(b) = l.b
                && !s.bodies[l.a].fixed
                && !s.bodies[b].fixed
            {
                let (ra, rb) = (find(&mut parent, l.a), find(&mut parent, b));
                if ra != rb {
                    parent[ra.max(rb)] = ra.min(rb);
                }
            }
        }
        let mut id = vec![u32::MAX; nb];
        let mut of = vec![u32::MAX; nb];
        let mut count = 0;
        for i in 0..nb {
            if s.bodies[i].fixed {
                continue;
            }
            let r = find(&mut parent, i);
            if id[r] == u32::MAX {
                id[r] = count as u32;
                count += 1;
            }
            of[i] = id[r];
        }
        let mut bodies = vec![Vec::new(); count];
        for i in 0..nb {
            if of[i] != u32::MAX {
                bodies[of[i] as usize].push(i);
            }
        }
        let mut links = vec![Vec::new(); count];
        for (li, l) in s.links.iter().enumerate() {
            let side = if s.bodies[l.a].fixed {
                match l.b {
                    End::Body(b) if !s.bodies[b].fixed => b,
                    _ => continue,
                }
            } else {
                l.a
            };
            links[of[side] as usize].push(li);
        }
        Components {
            of,
            count,
            bodies,
            links,
        }
    }

    /// The component of a link end: `None` for fixed bodies and the ground.
    fn of(&self, s: &Structure, e: End) -> Option<usize> {
        match e {
            End::Body(b) if !s.bodies[b].fixed => Some(self.of[b] as usize),
            _ => None,
        }
    }
}
