//! Static analysis of one structure under gravity: the linear-elastic
//! network of rigid modules joined by elastic connector interfaces (the
//! rigid-body–spring form of the beam networks of Hołobut & Lengiewicz and
//! Piranda et al.), solved per connected component by preconditioned CG,
//! with the ground contacts made unilateral by an active set.
//!
//! Units inside the solve: lengths in `d`, forces in the module weight
//! `W = m·g`; interface stiffnesses relative to the axial one (the absolute
//! modulus and layer thickness cancel out of the loads). Results are in SI.

use super::capacity::{ConnectorLoad, Mode, utilisation};
use super::model::{Capacity, Model};
use super::solver::{Block, BlockMatrix, Multigrid, SolveStats, Vec6, mg_pcg, pcg, transfer};
use super::structure::{End, Link, Structure};
use glam::DVec3;
use nalgebra::Matrix3;
use rustc_hash::{FxHashMap, FxHasher};
use std::hash::{Hash, Hasher};

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
    /// CG iterations summed over the components solved.
    pub iterations: usize,
    pub components_solved: usize,
    pub components_reused: usize,
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
    /// Components with at least this many modules use the multigrid
    /// preconditioner, smaller ones block Jacobi.
    pub multigrid_from: usize,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            tolerance: 1e-10,
            max_release_rounds: 30,
            multigrid_from: MULTIGRID_FROM,
        }
    }
}

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

/// A component's cached solution.
#[derive(Clone, Debug)]
struct Cached {
    q: Vec<Vec6>,
    /// Global link indices, valid only in the step that solved it.
    released: Vec<usize>,
    sliding: Vec<usize>,
    /// Link results in the component's link order (empty until evaluated).
    results: Vec<LinkResult>,
}

/// Analyses structures, optionally reusing work between consecutive calls
/// (the steps of a schedule): components whose bodies, links and loads are
/// unchanged are not solved again, and changed ones start CG from the
/// previous displacements of their modules.
pub struct Analyzer {
    pub model: Model,
    pub settings: Settings,
    pub incremental: bool,
    springs: Springs,
    ground_springs: Springs,
    cache: FxHashMap<u64, Cached>,
    warm: FxHashMap<u32, Vec6>,
    blocks: FxHashMap<([u64; 3], bool, bool), LinkBlocks>,
}

/// Components at least this large are solved with the multigrid
/// preconditioner; smaller ones with block Jacobi.
pub const MULTIGRID_FROM: usize = 64;

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
            cache: FxHashMap::default(),
            warm: FxHashMap::default(),
            blocks: FxHashMap::default(),
        }
    }

    /// Forgets cached solutions.
    pub fn reset(&mut self) {
        self.cache.clear();
        self.warm.clear();
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
        if standard {
            if let Some(b) = self.blocks.get(&key) {
                return b.clone();
            }
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
        // Components of free bodies joined by body–body links.
        let mut parent: Vec<usize> = (0..nb).collect();
        fn find(p: &mut [usize], mut x: usize) -> usize {
            while p[x] != x {
                p[x] = p[p[x]];
                x = p[x];
            }
            x
        }
        for l in &s.links {
            if let End::Body(b) = l.b {
                if !s.bodies[l.a].fixed && !s.bodies[b].fixed {
                    let (ra, rb) = (find(&mut parent, l.a), find(&mut parent, b));
                    if ra != rb {
                        parent[ra.max(rb)] = ra.min(rb);
                    }
                }
            }
        }
        let mut comp_of = vec![usize::MAX; nb];
        let mut comps: Vec<(Vec<usize>, Vec<usize>)> = Vec::new();
        for i in 0..nb {
            if s.bodies[i].fixed {
                continue;
            }
            let r = find(&mut parent, i);
            if comp_of[r] == usize::MAX {
                comp_of[r] = comps.len();
                comps.push((Vec::new(), Vec::new()));
            }
            let c = comp_of[r];
            comp_of[i] = c;
            comps[c].0.push(i);
        }
        for (li, l) in s.links.iter().enumerate() {
            let side = if s.bodies[l.a].fixed {
                match l.b {
                    End::Body(b) => b,
                    End::Ground(_) => continue,
                }
            } else {
                l.a
            };
            comps[comp_of[side]].1.push(li);
        }

        let mut out = Analysis {
            links: vec![LinkResult::default(); s.links.len()],
            ..Default::default()
        };
        let mut any_unsupported = false;
        let mut new_cache = FxHashMap::default();
        let mut local = vec![u32::MAX; nb];
        for (bodies, links) in &comps {
            let sig = self.signature(s, bodies, links, &loads);
            let cached = if self.incremental {
                self.cache.get(&sig).cloned()
            } else {
                None
            };
            let sol = match cached {
                Some(c) => {
                    out.components_reused += 1;
                    Some(c)
                }
                None => {
                    out.components_solved += 1;
                    for (k, &b) in bodies.iter().enumerate() {
                        local[b] = k as u32;
                    }
                    let r =
                        self.solve_component(s, bodies, links, &loads, &local, &mut out.iterations);
                    for &b in bodies {
                        local[b] = u32::MAX;
                    }
                    r
                }
            };
            let Some(mut sol) = sol else {
                any_unsupported = true;
                out.unsupported.extend(bodies.iter().copied());
                continue;
            };
            if sol.results.len() != links.len() {
                // Freshly solved: evaluate every link once and keep the
                // results (in the component's link order) for reuse.
                if self.incremental {
                    for (k, &b) in bodies.iter().enumerate() {
                        self.warm.insert(s.bodies[b].module, sol.q[k]);
                    }
                }
                for (k, &b) in bodies.iter().enumerate() {
                    local[b] = k as u32;
                }
                let mut results = Vec::with_capacity(links.len());
                for &li in links {
                    let l = &s.links[li];
                    results.push(if sol.released.contains(&li) {
                        LinkResult {
                            released: true,
                            ..Default::default()
                        }
                    } else {
                        let sliding = sol.sliding.contains(&li);
                        let (load, force, moment) = self.link_forces(s, l, &sol.q, &local, sliding);
                        let (u, m) = utilisation(&load, self.capacity(l));
                        LinkResult {
                            load,
                            utilisation: u,
                            mode: Some(m),
                            released: false,
                            sliding,
                            force: force.to_array(),
                            moment: moment.to_array(),
                        }
                    });
                }
                for &b in bodies {
                    local[b] = u32::MAX;
                }
                sol.results = results;
                sol.released.clear();
                sol.sliding.clear();
            }
            for (k, &li) in links.iter().enumerate() {
                out.links[li] = sol.results[k];
            }
            if self.incremental {
                new_cache.insert(sig, sol);
            }
        }
        if self.incremental {
            self.cache = new_cache;
        }

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
        let mut overloaded = false;
        let mut slides = false;
        for (i, r) in out.links.iter().enumerate() {
            if r.utilisation > max || (crit.is_none() && r.utilisation > 0.0) {
                max = r.utilisation;
                crit = Some(Critical::Link(i));
            }
            if r.utilisation > 1.0 + 1e-9 {
                if s.links[i].is_ground() {
                    slides = true;
                } else {
                    overloaded = true;
                }
            }
        }
        for (i, r) in out.pivots.iter().enumerate() {
            if r.utilisation > max {
                max = r.utilisation;
                crit = Some(Critical::Pivot(i));
            }
            if r.utilisation > 1.0 + 1e-9 {
                overloaded = true;
            }
        }
        out.max_utilisation = max;
        out.critical = crit;
        out.verdict = Some(if any_unsupported || slides {
            Verdict::NoEquilibrium
        } else if overloaded {
            Verdict::Overloaded
        } else {
            Verdict::Stable
        });
        out
    }

    fn signature(&self, s: &Structure, bodies: &[usize], links: &[usize], loads: &[Vec6]) -> u64 {
        let mut h = FxHasher::default();
        for &b in bodies {
            s.bodies[b].module.hash(&mut h);
            s.bodies[b].cell.to_array().hash(&mut h);
            for x in loads[b].iter() {
                x.to_bits().hash(&mut h);
            }
        }
        for &li in links {
            let l = &s.links[li];
            s.bodies[l.a].module.hash(&mut h);
            match l.b {
                End::Body(b) => (0u8, s.bodies[b].module).hash(&mut h),
                End::Ground(c) => (1u8, c.to_array()).hash(&mut h),
            }
        }
        h.finish()
    }

    fn side(&self, s: &Structure, e: End, local: &[u32]) -> Option<usize> {
        match e {
            End::Body(b) if !s.bodies[b].fixed && local[b] != u32::MAX => Some(local[b] as usize),
            _ => None,
        }
    }

    fn link_load(
        &mut self,
        s: &Structure,
        l: &Link,
        q: &[Vec6],
        local: &[u32],
        sliding: bool,
    ) -> ConnectorLoad {
        self.link_forces(s, l, q, local, sliding).0
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
        local: &[u32],
        sliding: bool,
    ) -> (ConnectorLoad, DVec3, DVec3) {
        let lb = self.link_blocks(s, l, sliding);
        let mut e = Vec6::zeros();
        if let Some(a) = self.side(s, End::Body(l.a), local) {
            e -= lb.ga * q[a];
        }
        if let Some(b) = self.side(s, l.b, local) {
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

    /// Solves one component, releasing ground contacts that would pull
    /// (or tip beyond the contact's edge) until the rest is consistent.
    /// `None` when nothing supports the component.
    fn solve_component(
        &mut self,
        s: &Structure,
        bodies: &[usize],
        links: &[usize],
        loads: &[Vec6],
        local: &[u32],
        iterations: &mut usize,
    ) -> Option<Cached> {
        let n = bodies.len();
        let f: Vec<Vec6> = bodies.iter().map(|&b| loads[b]).collect();
        let mut q: Vec<Vec6> = bodies
            .iter()
            .map(|&b| {
                if self.incremental {
                    self.warm
                        .get(&s.bodies[b].module)
                        .copied()
                        .unwrap_or_else(Vec6::zeros)
                } else {
                    Vec6::zeros()
                }
            })
            .collect();
        let mut released: Vec<usize> = Vec::new();
        let mut sliding: Vec<usize> = Vec::new();
        for _round in 0..=self.settings.max_release_rounds {
            let mut k = BlockMatrix::new(n);
            k.off.reserve(links.len());
            let mut anchored = false;
            for &li in links {
                if released.contains(&li) {
                    continue;
                }
                let l = &s.links[li];
                let lb = self.link_blocks(s, l, sliding.contains(&li));
                let ia = self.side(s, End::Body(l.a), local);
                let ib = self.side(s, l.b, local);
                if ia.is_none() || ib.is_none() {
                    anchored = true;
                }
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
            if !anchored {
                return None;
            }
            let stats: SolveStats = if n >= self.settings.multigrid_from {
                let pos: Vec<DVec3> = bodies.iter().map(|&b| s.bodies[b].centre).collect();
                let mg = Multigrid::new(&k, &pos);
                mg_pcg(&k, &mg, &f, &mut q, self.settings.tolerance, 2000)
            } else {
                pcg(&k, &f, &mut q, self.settings.tolerance, 50 * 6 * n + 1000)
            };
            *iterations += stats.iterations;
            // Ground contacts pulled or tipped beyond their edge let go;
            // failing that, those beyond their friction slide.
            let mut lift = Vec::new();
            let mut slide = Vec::new();
            for &li in links {
                let l = &s.links[li];
                if !l.is_ground() || released.contains(&li) {
                    continue;
                }
                let sl = sliding.contains(&li);
                let load = self.link_load(s, l, &q, local, sl);
                let (u, mode) = utilisation(&load, &self.model.ground);
                if u > 1.0 + 1e-9 {
                    match mode {
                        Mode::Bending => lift.push(li),
                        Mode::Friction if !sl => slide.push(li),
                        Mode::Friction => {}
                    }
                }
            }
            if !lift.is_empty() {
                released.extend(lift);
            } else if !slide.is_empty() {
                sliding.extend(slide);
            } else {
                return Some(Cached {
                    q,
                    released,
                    sliding,
                    results: Vec::new(),
                });
            }
        }
        Some(Cached {
            q,
            released,
            sliding,
            results: Vec::new(),
        })
    }
}
