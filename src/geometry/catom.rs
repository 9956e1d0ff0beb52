//! The exact 3D Catom body (SPEC §2).
//!
//! The catom is the Minkowski sum of a small rhombicuboctahedron `Q` (edge
//! `L = d/(3+√2)`) and a ball of radius `L`. parry3d-f64 represents that
//! sum exactly as a *round* convex polyhedron (`RoundShape<ConvexPolyhedron>`
//! with border radius `L`); we use parry for the signed distance because its
//! GJK/EPA on support maps is well tested and f64 throughout, and the body
//! here is never deeper than `2L` into another one (the inner polyhedra stay
//! apart), so the signed distance is a GJK *distance* of the inner shapes
//! minus `2L` — accurate to round-off.
//!
//! Units: lattice spacing `d = 1`. Orientation at rest (SPEC §1): the
//! catom's cubic axes are `(x̂+ŷ)/√2`, `(x̂−ŷ)/√2`, `ẑ`.

#[cfg(test)]
use glam::DQuat;
use glam::DVec3;
use parry3d_f64::math::Pose;
use parry3d_f64::query;
use parry3d_f64::shape::{ConvexPolyhedron, RoundShape};
use std::f64::consts::SQRT_2;
use std::sync::OnceLock;

/// Edge length of `Q` and border radius: `L = d/(3+√2)` ≈ 0.2265 d.
pub const L: f64 = 1.0 / (3.0 + SQRT_2);

/// The catom body at rest, with its support function and parry shape.
pub struct Catom {
    /// The 24 vertices of `Q` in the world frame at rest.
    vertices: [DVec3; 24],
    shape: RoundShape<ConvexPolyhedron>,
}

/// A signed distance between two bodies with its witness points.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Gap {
    /// Signed distance (negative: penetration depth), units of d.
    pub dist: f64,
    /// Witness point on the first and on the second body (world frame).
    pub p1: DVec3,
    pub p2: DVec3,
    /// Contact normal, from the first body towards the second.
    pub normal: DVec3,
}

/// The shared catom body.
pub fn catom() -> &'static Catom {
    static BODY: OnceLock<Catom> = OnceLock::new();
    BODY.get_or_init(Catom::build)
}

impl Catom {
    fn build() -> Catom {
        let b = L / 2.0;
        let a = b * (1.0 + SQRT_2);
        // Cubic frame → world frame (SPEC §1).
        let e1 = DVec3::new(1.0, 1.0, 0.0) / SQRT_2;
        let e2 = DVec3::new(1.0, -1.0, 0.0) / SQRT_2;
        let e3 = DVec3::Z;
        let mut vertices = [DVec3::ZERO; 24];
        let mut n = 0;
        for axis in 0..3 {
            for sa in [-1.0, 1.0] {
                for sb in [-1.0, 1.0] {
                    for sc in [-1.0, 1.0] {
                        // `a` on coordinate `axis`, `b` on the other two.
                        let mut c = [0.0; 3];
                        c[axis] = sa * a;
                        c[(axis + 1) % 3] = sb * b;
                        c[(axis + 2) % 3] = sc * b;
                        vertices[n] = c[0] * e1 + c[1] * e2 + c[2] * e3;
                        n += 1;
                    }
                }
            }
        }
        let inner = ConvexPolyhedron::from_convex_hull(&vertices)
            .expect("the rhombicuboctahedron is a non-degenerate convex hull");
        Catom {
            vertices,
            shape: RoundShape {
                inner_shape: inner,
                border_radius: L,
            },
        }
    }

    /// The vertices of `Q` at rest (world frame, body centred at the origin).
    pub fn vertices(&self) -> &[DVec3; 24] {
        &self.vertices
    }

    /// The parry shape (body centred at the origin, at rest).
    pub fn shape(&self) -> &RoundShape<ConvexPolyhedron> {
        &self.shape
    }

    /// Support function of `Q` at rest: `max_v u·v`.
    pub fn support_q(&self, u: DVec3) -> f64 {
        self.vertices
            .iter()
            .map(|v| u.dot(*v))
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// Support point of the body at rest in the unit direction `u` (a
    /// vertex of `Q` pushed out by `L` along `u`).
    pub fn support_point(&self, u: DVec3) -> DVec3 {
        let v = self
            .vertices
            .iter()
            .copied()
            .max_by(|a, b| a.dot(u).total_cmp(&b.dot(u)))
            .expect("24 vertices");
        v + L * u
    }

    /// Support function `h_B(u) = h_Q(u) + L|u|` of the body at rest.
    pub fn support(&self, u: DVec3) -> f64 {
        self.support_q(u) + L * u.length()
    }

    /// Circumradius of `Q` (largest distance of a point of `Q` from the centre).
    pub fn radius_q(&self) -> f64 {
        self.vertices.iter().map(|v| v.length()).fold(0.0, f64::max)
    }

    /// Circumradius of the body: `radius_q() + L` ≈ 0.5434 d.
    pub fn radius(&self) -> f64 {
        self.radius_q() + L
    }

    /// Signed distance between two catoms at the given poses, if it is below
    /// `prediction` (a larger distance returns `None`).
    pub fn gap(&self, a: &Pose, b: &Pose, prediction: f64) -> Option<Gap> {
        // The rounded bodies' signed distance is the inner polyhedra's minus
        // 2L, with the witnesses pushed out by L along the normal. Querying
        // the inner polyhedra (apart by up to 2L even when the bodies
        // penetrate) keeps GJK away from touching configurations, where
        // parry's rounded-shape path can return a spurious 0.
        let inner = &self.shape.inner_shape;
        let c = query::contact(a, inner, b, inner, prediction + 2.0 * L)
            .expect("parry supports convex polyhedra")?;
        Some(Gap {
            dist: c.dist - 2.0 * L,
            p1: c.point1 + L * c.normal1,
            p2: c.point2 + L * c.normal2,
            normal: c.normal1,
        })
    }
}

/// A triangle mesh of a body's surface, for viewers (f32: what WebGL reads).
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceMesh {
    pub positions: Vec<[f32; 3]>,
    /// Outward unit normal at each position.
    pub normals: Vec<[f32; 3]>,
    /// Counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
}

impl Catom {
    /// The surface of the rounded body (units of d, at rest), sampled from
    /// its exact support map: each direction `u` of a geodesic sphere
    /// (an icosahedron split `subdivisions` times) maps to the surface
    /// point whose outward normal is `u`. Every point lies on the real
    /// body, the normals are exact, and the sphere's triangles stay a
    /// closed surface; flat faces appear where neighbouring directions
    /// pick different vertices of `Q`.
    pub fn surface_mesh(&self, subdivisions: u32) -> SurfaceMesh {
        let (dirs, triangles) = geodesic_sphere(subdivisions);
        let positions = dirs
            .iter()
            .map(|u| self.support_point(*u).as_vec3().to_array())
            .collect();
        let normals = dirs.iter().map(|u| u.as_vec3().to_array()).collect();
        SurfaceMesh {
            positions,
            normals,
            triangles,
        }
    }
}

/// Unit directions of an icosahedron split `n` times (each triangle into
/// four), with its triangles.
fn geodesic_sphere(n: u32) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut v: Vec<DVec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| DVec3::new(x, y, z).normalize())
    .collect();
    let mut f: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..n {
        let mut mid = std::collections::HashMap::new();
        let mut split = |a: u32, b: u32, v: &mut Vec<DVec3>| -> u32 {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                v.push(((v[a as usize] + v[b as usize]) / 2.0).normalize());
                (v.len() - 1) as u32
            })
        };
        let mut next = Vec::with_capacity(f.len() * 4);
        for [a, b, c] in f {
            let ab = split(a, b, &mut v);
            let bc = split(b, c, &mut v);
            let ca = split(c, a, &mut v);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        f = next;
    }
    (v, f)
}

/// A rigid pose from a centre and a rotation.
#[cfg(test)]
pub fn pose(centre: DVec3, rotation: DQuat) -> Pose {
    Pose::from_parts(centre, rotation)
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_surface_mesh_lies_on_the_body_and_is_closed() {
        let body = super::catom();
        let m = body.surface_mesh(2);
        assert_eq!(m.triangles.len(), 320);
        for (p, n) in m.positions.iter().zip(&m.normals) {
            let p = glam::Vec3::from_array(*p).as_dvec3();
            let n = glam::Vec3::from_array(*n).as_dvec3();
            // On the surface: the support function in direction n is p·n.
            assert!((body.support(n) - p.dot(n)).abs() < 1e-6);
        }
        // Wound counter-clockwise seen from outside (what WebGL culls by).
        for t in &m.triangles {
            let [a, b, c] = t.map(|i| glam::Vec3::from_array(m.normals[i as usize]));
            assert!((b - a).cross(c - a).dot(a + b + c) > 0.0);
        }
        // Closed: every edge is shared by exactly two triangles.
        let mut edges = std::collections::HashMap::new();
        for t in &m.triangles {
            for i in 0..3 {
                let (a, b) = (t[i], t[(i + 1) % 3]);
                *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
        assert!(edges.values().all(|&k| k == 2));
    }

    use super::*;
    use crate::lattice::fcc;

    fn at(c: DVec3) -> Pose {
        pose(c, DQuat::IDENTITY)
    }

    #[test]
    fn connectors_and_actuators_sit_at_the_spec_distances() {
        let b = catom();
        for k in 0..12 {
            assert!(
                (b.support(fcc::direction(k)) - 0.5).abs() < 1e-12,
                "connector {k}"
            );
        }
        for o in fcc::octagonal_axes() {
            assert!((b.support(o) - 0.5).abs() < 1e-12);
        }
        let hex = 1.0 / (2.0 * 3f64.sqrt()) + 1.0 / (3.0 + SQRT_2);
        assert!((hex - 0.5152).abs() < 1e-4);
        for h in fcc::hexagonal_axes() {
            assert!((b.support(h) - hex).abs() < 1e-12);
        }
        // The body's largest extent is at Q's vertices, beyond every face.
        assert!(b.radius() > hex && (b.radius() - 0.5434).abs() < 1e-4);
    }

    /// Q's faces normal to a neighbour direction are squares of side L: the
    /// 4 vertices supporting it are at mutual distances L (sides) and L√2.
    #[test]
    fn connector_faces_are_squares_of_side_l() {
        let b = catom();
        for k in 0..12 {
            let n = fcc::direction(k);
            let h = b.support_q(n);
            let face: Vec<DVec3> = b
                .vertices()
                .iter()
                .copied()
                .filter(|v| (v.dot(n) - h).abs() < 1e-12)
                .collect();
            assert_eq!(face.len(), 4, "connector {k}");
            let mut d: Vec<f64> = face
                .iter()
                .enumerate()
                .flat_map(|(i, p)| face[i + 1..].iter().map(move |q| (*p - *q).length()))
                .collect();
            d.sort_by(f64::total_cmp);
            for x in &d[..4] {
                assert!((x - L).abs() < 1e-12);
            }
            for x in &d[4..] {
                assert!((x - L * SQRT_2).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn latched_neighbours_touch_face_to_face() {
        let b = catom();
        for k in 0..12 {
            let n = fcc::direction(k);
            let g = b.gap(&at(DVec3::ZERO), &at(n), 1.0).expect("touching");
            assert!(g.dist.abs() <= 1e-7, "connector {k}: {}", g.dist);
            // The witness points lie on the contact plane at d/2.
            assert!((g.p1.dot(n) - 0.5).abs() < 1e-7 && (g.p2.dot(n) - 0.5).abs() < 1e-7);
            // A body moved towards its neighbour by 1e-3 d penetrates by 1e-3 d.
            let g = b.gap(&at(DVec3::ZERO), &at(n * 0.999), 1.0).unwrap();
            assert!((g.dist + 1e-3).abs() < 1e-7, "{}", g.dist);
        }
    }

    #[test]
    fn catoms_in_distinct_cells_never_overlap() {
        use crate::lattice::{Cell, FccLattice, Lattice};
        let l = FccLattice;
        for pz in 0..2 {
            let c = Cell::new(0, 0, pz);
            let pc = l.centre(c);
            for x in -2..=2 {
                for y in -2..=2 {
                    for z in pz - 2..=pz + 2 {
                        let o = Cell::new(x, y, z);
                        if o == c {
                            continue;
                        }
                        let oc = l.centre(o);
                        if let Some(g) = b_gap(pc, oc) {
                            assert!(g >= -1e-7, "{c} / {o}: {g}");
                        }
                    }
                }
            }
        }
        fn b_gap(a: DVec3, b: DVec3) -> Option<f64> {
            catom().gap(&at(a), &at(b), 0.5).map(|g| g.dist)
        }
    }
}
