//! The mechanical structure of one intermediate configuration: rigid
//! modules (bodies), the latched connectors and ground contacts between
//! them (links), and the movers hanging on their pivots. Built from any
//! [`Lattice`] through its neighbours, centres and gravity, so the same code
//! serves the FCC catoms and the 2D sliding squares.

use crate::lattice::config::{Ground, ModuleId};
use crate::lattice::{Cell, Configuration, Lattice, Motion, Route, fcc};
use glam::DVec3;
use rustc_hash::{FxHashMap, FxHashSet};

/// One module: a rigid body. Fixed modules are anchors (no motion).
#[derive(Clone, Debug, PartialEq)]
pub struct Body {
    pub module: ModuleId,
    pub cell: Cell,
    /// Centre, in units of `d`.
    pub centre: DVec3,
    pub fixed: bool,
}

/// The far side of a link.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum End {
    Body(usize),
    /// The solid ground cell at this position.
    Ground(Cell),
}

impl End {
    /// The body at this end, if it is one (not the ground).
    pub fn body(self) -> Option<usize> {
        match self {
            End::Body(b) => Some(b),
            End::Ground(_) => None,
        }
    }
}

/// A connector square between two latched modules, or a module's contact
/// with the ground.
#[derive(Clone, Debug, PartialEq)]
pub struct Link {
    pub a: usize,
    pub b: End,
    /// Contact point (centre of the square), in units of `d`.
    pub contact: DVec3,
    /// Unit normal, from `a` towards `b`.
    pub normal: DVec3,
    /// The square's edge axes (unit, orthogonal to the normal).
    pub u: DVec3,
    pub v: DVec3,
}

impl Link {
    pub fn is_ground(&self) -> bool {
        matches!(self.b, End::Ground(_))
    }
}

/// A module in motion during the step, carried by its pivot.
#[derive(Clone, Debug, PartialEq)]
pub struct Hanging {
    pub mover: ModuleId,
    /// Body index of the pivot.
    pub pivot: usize,
    /// Sampled centres of the mover along its motion, in units of `d`.
    pub path: Vec<DVec3>,
    /// Between each two consecutive samples, the point where the motion's
    /// tangents at them meet ([`tangent_points`]): the arc between the two
    /// lies in the triangle of the three, so a load affine in the mover's
    /// centre lies, all along the motion, in the convex hull of its values
    /// at the samples and at these points.
    pub hull: Vec<DVec3>,
    /// Movers whose paths turn by the same angle between every two
    /// samples form a group ([`Structure::between`]).
    pub group: usize,
}

/// Where a group of movers stands at a pose between samples `i` and
/// `i + 1`.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum Point {
    Sample(usize),
    Tangent(usize),
}

/// At most this many groups get poses between samples: each interval has
/// `3^G − 2` of them.
pub const MAX_HULL_GROUPS: usize = 3;

/// The tangent points of a path sampled on circular arcs about `centre`
/// (each pair of consecutive samples on one arc, less than a half turn
/// apart), or of a straight path (`None`: the midpoints). For samples at
/// `p + u₁`, `p + u₂` with `|u₁| = |u₂| = r`, the tangents meet at
/// `p + 2r²(u₁ + u₂)/|u₁ + u₂|²`, a factor `1/cos(δ/2)` beyond the arc's
/// middle (δ: the angle between the samples).
pub fn tangent_points(path: &[DVec3], centre: Option<DVec3>) -> Vec<DVec3> {
    path.windows(2)
        .map(|w| match centre {
            Some(p) => {
                let (u1, u2) = (w[0] - p, w[1] - p);
                let sum = u1 + u2;
                let r2 = u1.length() * u2.length();
                if sum.length_squared() <= 1e-24 {
                    // Opposite samples: no half turn has them (not made).
                    0.5 * (w[0] + w[1])
                } else {
                    p + 2.0 * r2 * sum / sum.length_squared()
                }
            }
            None => 0.5 * (w[0] + w[1]),
        })
        .collect()
}

/// The poses between `samples` samples for `groups` groups (see
/// [`Structure::between`]), interval by interval.
fn between_poses(samples: usize, groups: usize) -> Vec<Vec<Point>> {
    let mut out = Vec::new();
    for i in 0..samples.saturating_sub(1) {
        let choices = [Point::Sample(i), Point::Sample(i + 1), Point::Tangent(i)];
        for code in 0..3usize.pow(groups as u32) {
            let pose: Vec<Point> = (0..groups)
                .map(|g| choices[code / 3usize.pow(g as u32) % 3])
                .collect();
            let all_one_sample = pose.iter().all(|p| *p == pose[0]) && pose[0] != choices[2];
            if !all_one_sample {
                out.push(pose);
            }
        }
    }
    out
}

/// The centre of the arcs a motion's path follows (`None`: straight or no
/// path): the pivot of a rotation, the corner pivot of a slide around one.
pub fn arc_centre(lattice: &dyn Lattice, motion: &Motion) -> Option<DVec3> {
    match motion {
        Motion::Rotate { pivot, .. } => Some(lattice.centre(*pivot)),
        Motion::Slide { to, pivot, .. } => pivot
            .filter(|p| lattice.are_neighbours(*p, *to))
            .map(|p| lattice.centre(p)),
        Motion::Tunnel { .. } => None,
    }
}

/// A configuration as a mechanical structure.
#[derive(Clone, Debug, Default)]
pub struct Structure {
    pub bodies: Vec<Body>,
    pub links: Vec<Link>,
    pub hanging: Vec<Hanging>,
    /// Unit vector of gravity.
    pub gravity: DVec3,
    /// The poses between samples (pose `path.len() + v` is `between[v]`,
    /// one `Point` per group), interval by interval, `3^G − 2` each: the
    /// corners of the product of every group's triangles (two samples and
    /// their tangent point) but the two samples themselves. Movers of one
    /// group turn at the same rate, so their joint path between two
    /// samples is one planar ellipse arc, inside its triangle; the joint
    /// path of all movers lies in the product, the convex hull of these
    /// corners. Empty beyond `MAX_HULL_GROUPS` groups.
    pub between: Vec<Vec<Point>>,
    index: FxHashMap<ModuleId, usize>,
}

/// The square's edge axes for a connector of normal `n`: the edges run
/// along the module's cubic symmetry axes (SPEC §1–2: for a catom, one edge
/// of every connector square is the cubic axis perpendicular to it; for
/// squares and cubes, the lattice axes). Candidates are tried in order and
/// the first one perpendicular to `n` (or, failing that, the most nearly
/// perpendicular) is projected onto the square's plane.
pub fn face_frame(n: DVec3) -> (DVec3, DVec3) {
    let s = std::f64::consts::FRAC_1_SQRT_2;
    let candidates = [
        DVec3::Z,
        DVec3::new(s, s, 0.0),
        DVec3::new(s, -s, 0.0),
        DVec3::X,
        DVec3::Y,
    ];
    let a = candidates
        .iter()
        .copied()
        .find(|c| c.dot(n).abs() < 1e-9)
        .unwrap_or_else(|| {
            candidates
                .into_iter()
                .min_by(|p, q| p.dot(n).abs().total_cmp(&q.dot(n).abs()))
                .expect("non-empty")
        });
    let u = (a - a.dot(n) * n).normalize();
    (u, n.cross(u))
}

/// Sampled mover centres (units of `d`) along a motion around `pivot`.
/// Rotations follow the great-circle arcs of SPEC §3 (`n_f → a → n_t`) at
/// the lattice distance; slides move straight (wall slides) or around the
/// corner pivot. Tunnels are carried inside the structure: no path.
pub fn mover_path(lattice: &dyn Lattice, motion: &Motion, samples: usize) -> Vec<DVec3> {
    let samples = samples.max(2);
    let lerp_dir = |a: DVec3, b: DVec3, t: f64| -> DVec3 {
        let ang = a.angle_between(b);
        if ang < 1e-12 {
            return a;
        }
        (a * ((1.0 - t) * ang).sin() + b * (t * ang).sin()) / ang.sin()
    };
    match motion {
        Motion::Rotate {
            from,
            to,
            pivot,
            route,
        } => {
            let p = lattice.centre(*pivot);
            let f = lattice.centre(*from) - p;
            let t = lattice.centre(*to) - p;
            let r = f.length();
            let (nf, nt) = (f / r, t / t.length());
            let axis = fcc::rotation_axis(nf, nt, *route)
                .or_else(|| fcc::rotation_axis(nf, nt, Route::Octagonal));
            (0..samples)
                .map(|k| {
                    let s = k as f64 / (samples - 1) as f64;
                    let dir = match axis {
                        Some(a) if s <= 0.5 => lerp_dir(nf, a, 2.0 * s),
                        Some(a) => lerp_dir(a, nt, 2.0 * s - 1.0),
                        None => lerp_dir(nf, nt, s),
                    };
                    p + r * dir
                })
                .collect()
        }
        Motion::Slide { from, to, pivot } => {
            let (a, b) = (lattice.centre(*from), lattice.centre(*to));
            let corner = pivot.filter(|p| lattice.are_neighbours(*p, *to));
            (0..samples)
                .map(|k| {
                    let s = k as f64 / (samples - 1) as f64;
                    match corner {
                        Some(pc) => {
                            let p = lattice.centre(pc);
                            p + lerp_dir(a - p, b - p, s)
                        }
                        None => a + s * (b - a),
                    }
                })
                .collect()
        }
        Motion::Tunnel { .. } => Vec::new(),
    }
}

/// A mover during a step: its id, its pivot (if any) and its motion.
pub type MoverSpec = (ModuleId, Option<ModuleId>, Motion);

/// What [`Structure::build`] reads of a scene.
pub struct SceneRef<'a> {
    pub lattice: &'a dyn Lattice,
    pub ground: Option<Ground>,
    pub config: &'a Configuration,
    pub fixed: &'a FxHashSet<ModuleId>,
    /// Modules not part of the static structure (movers, leavers).
    pub exclude: &'a FxHashSet<ModuleId>,
    pub latched: &'a dyn Fn(ModuleId, ModuleId) -> bool,
}

/// Samples per mover path: fine enough that the worst lever of a 60°/90°
/// arc is found within 0.2 %. Odd, so that a rotation's two arcs meet at a
/// sample (`s = ½`) and every pair of consecutive samples lies on one arc
/// (what [`tangent_points`] needs).
pub const PATH_SAMPLES: usize = 25;
const _: () = assert!(PATH_SAMPLES % 2 == 1);

impl Structure {
    /// The static structure of a scene with `movers` hanging on their pivots.
    pub fn build(scene: &SceneRef<'_>, movers: &[MoverSpec]) -> Structure {
        let lattice = scene.lattice;
        let mut modules: Vec<(ModuleId, Cell)> = scene
            .config
            .iter()
            .filter(|(m, _)| !scene.exclude.contains(m))
            .collect();
        modules.sort_unstable();
        let mut s = Structure {
            gravity: lattice.gravity(),
            ..Default::default()
        };
        s.index.reserve(modules.len());
        for (m, c) in &modules {
            s.index.insert(*m, s.bodies.len());
            s.bodies.push(Body {
                module: *m,
                cell: *c,
                centre: lattice.centre(*c),
                fixed: scene.fixed.contains(m),
            });
        }
        for a in 0..s.bodies.len() {
            let (ma, ca, fa) = (s.bodies[a].module, s.bodies[a].cell, s.bodies[a].fixed);
            for nc in lattice.neighbours(ca) {
                let end = if let Some(mb) = scene.config.at(nc) {
                    let Some(&b) = s.index.get(&mb) else { continue };
                    if b <= a || (fa && s.bodies[b].fixed) || !(scene.latched)(ma, mb) {
                        continue;
                    }
                    End::Body(b)
                } else if !fa && scene.ground.is_some_and(|g| g.is_ground_cell(lattice, nc)) {
                    End::Ground(nc)
                } else {
                    continue;
                };
                let pa = s.bodies[a].centre;
                let pb = lattice.centre(nc);
                let normal = (pb - pa).normalize();
                let (u, v) = face_frame(normal);
                s.links.push(Link {
                    a,
                    b: end,
                    contact: 0.5 * (pa + pb),
                    normal,
                    u,
                    v,
                });
            }
        }
        let mut signatures: Vec<Vec<i64>> = Vec::new();
        for (m, pivot, motion) in movers {
            let Some(&pi) = pivot.as_ref().and_then(|p| s.index.get(p)) else {
                continue;
            };
            let path = mover_path(lattice, motion, PATH_SAMPLES);
            if !path.is_empty() {
                let centre = arc_centre(lattice, motion);
                let hull = tangent_points(&path, centre);
                // Turning angles, to 1e-9 rad, name the group.
                let turns: Vec<i64> = path
                    .windows(2)
                    .map(|w| {
                        centre.map_or(0, |p| {
                            ((w[0] - p).angle_between(w[1] - p) * 1e9).round() as i64
                        })
                    })
                    .collect();
                let group = match signatures.iter().position(|t| *t == turns) {
                    Some(g) => g,
                    None => {
                        signatures.push(turns);
                        signatures.len() - 1
                    }
                };
                s.hanging.push(Hanging {
                    mover: *m,
                    pivot: pi,
                    path,
                    hull,
                    group,
                });
            }
        }
        if (1..=MAX_HULL_GROUPS).contains(&signatures.len()) {
            s.between = between_poses(PATH_SAMPLES, signatures.len());
        }
        s
    }

    /// The turning rates the movers' sweeps fall into (`Hanging::group`).
    pub fn groups(&self) -> usize {
        self.hanging.iter().map(|h| h.group + 1).max().unwrap_or(0)
    }

    /// Mover `h`'s centre at pose `k`: sample `k` of its path, or a pose
    /// between samples ([`Structure::between`]).
    pub fn mover_point(&self, h: usize, k: usize) -> DVec3 {
        let hg = &self.hanging[h];
        let n = hg.path.len();
        if k < n {
            return hg.path[k];
        }
        match self.between[k - n][hg.group] {
            Point::Sample(i) => hg.path[i],
            Point::Tangent(i) => hg.hull[i],
        }
    }

    pub fn body_of(&self, m: ModuleId) -> Option<usize> {
        self.index.get(&m).copied()
    }

    /// Human-readable name of a link's two sides.
    pub fn describe(&self, link: &Link) -> String {
        let a = &self.bodies[link.a];
        match link.b {
            End::Body(b) => format!(
                "connector {}–{} (cells {} and {})",
                a.module, self.bodies[b].module, a.cell, self.bodies[b].cell
            ),
            End::Ground(c) => format!(
                "ground contact of {} (cell {}, ground {})",
                a.module, a.cell, c
            ),
        }
    }
}
