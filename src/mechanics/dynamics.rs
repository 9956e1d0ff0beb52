//! Dynamic cross-check of the static analysis with rapier (f64): the same
//! structure simulated under gravity, connectors as fixed joints that break
//! when overloaded, to see what actually falls.
//!
//! Breaking rule (SPEC §4.5): rapier's joint impulses give joint forces in
//! their linear rows only (the angular rows are orthogonalised internally
//! and are not connector moments), so a joint breaks when the static-model
//! utilisation of its connector, recomputed on the current structure (the
//! joints still intact), exceeds 1 — the most loaded one first, then the
//! structure is re-analysed. The linear joint forces are read back as an
//! independent check of the static forces.

use super::analysis::Analyzer;
use super::model::Model;
use super::structure::{End, Structure};
use rapier3d_f64::prelude::*;

/// What the simulation did.
#[derive(Clone, Debug, Default)]
pub struct Outcome {
    /// Links (indices into the structure's links) whose joints broke, in order.
    pub broken: Vec<usize>,
    /// Final displacement of every body, in units of `d`.
    pub displacement: Vec<f64>,
    /// Linear force (N) rapier's joint carried per link after settling,
    /// `None` for links without a joint or broken before the reading.
    pub joint_force: Vec<Option<[f64; 3]>>,
}

fn vector(v: glam::DVec3) -> Vector {
    Vector::new(v.x, v.y, v.z)
}

/// Simulates `s` for `duration` seconds of model time. Ground contacts are
/// not simulated (use fixed modules as supports).
pub fn simulate(model: &Model, s: &Structure, duration: f64) -> Outcome {
    let d = model.spacing;
    let mut world = PhysicsWorld::new();
    let g = s.gravity * model.gravity;
    world.gravity = vector(g);
    world.integration_parameters.length_unit = d;
    world.integration_parameters.dt = 1.0 / 1000.0;
    // Light, small bodies on stiff joints: many iterations at a short
    // step, or the default solver lets a chain of catoms sag by whole
    // spacings.
    world.integration_parameters.num_solver_iterations = 50;
    let iterations = world.integration_parameters.num_solver_iterations;
    let dt = world.integration_parameters.dt;
    let handles: Vec<RigidBodyHandle> = s
        .bodies
        .iter()
        .map(|b| {
            let builder = if b.fixed {
                RigidBodyBuilder::fixed()
            } else {
                RigidBodyBuilder::dynamic()
            };
            let r = 0.5 * d;
            let inertia = 0.4 * model.mass * r * r;
            world.insert_body(
                builder
                    .translation(vector(b.centre * d))
                    .additional_mass_properties(MassProperties::new(
                        Vector::ZERO,
                        model.mass,
                        Vector::new(inertia, inertia, inertia),
                    ))
                    .can_sleep(false),
            )
        })
        .collect();
    let mut joints: Vec<Option<ImpulseJointHandle>> = s
        .links
        .iter()
        .map(|l| match l.b {
            End::Body(b) => {
                let j = FixedJointBuilder::new()
                    .local_anchor1(vector((l.contact - s.bodies[l.a].centre) * d))
                    .local_anchor2(vector((l.contact - s.bodies[b].centre) * d));
                Some(world.insert_impulse_joint(handles[l.a], handles[b], j))
            }
            End::Ground(_) => None,
        })
        .collect();
    let mut out = Outcome {
        joint_force: vec![None; s.links.len()],
        ..Default::default()
    };
    let mut analyser = Analyzer::new(model.clone(), false);
    let steps = (duration / dt).ceil() as usize;
    let read_at = steps.min((0.1 / dt) as usize).max(1);
    for step in 0..steps {
        // Break the most overloaded intact connector, re-analysing after
        // each break, until none is beyond capacity.
        loop {
            let mut current = s.clone();
            let intact: Vec<usize> = (0..s.links.len())
                .filter(|&i| !out.broken.contains(&i))
                .collect();
            current.links = intact.iter().map(|&i| s.links[i].clone()).collect();
            let a = analyser.analyse(&current);
            let worst = a
                .links
                .iter()
                .enumerate()
                .filter(|(_, r)| super::capacity::overloaded(r.utilisation))
                .max_by(|x, y| {
                    super::capacity::severity(x.1.utilisation)
                        .total_cmp(&super::capacity::severity(y.1.utilisation))
                })
                .map(|(k, _)| intact[k]);
            let Some(li) = worst else { break };
            if let Some(h) = joints[li].take() {
                world.remove_impulse_joint(h);
            }
            out.broken.push(li);
        }
        world.step();
        if step + 1 == read_at {
            for (li, j) in joints.iter().enumerate() {
                if let Some(h) = j
                    && let Some(joint) = world.impulse_joints.get(*h)
                {
                    let imp = joint.impulses;
                    // The stored impulse is one solver iteration's
                    // share (SPEC §4.5): force = impulse · iterations / dt.
                    let k = iterations as f64 / dt;
                    out.joint_force[li] = Some([imp[0] * k, imp[1] * k, imp[2] * k]);
                }
            }
        }
    }
    out.displacement = s
        .bodies
        .iter()
        .zip(&handles)
        .map(|(b, h)| {
            let p = world.bodies[*h].translation();
            let p = glam::DVec3::new(p.x, p.y, p.z) / d;
            (p - b.centre).length()
        })
        .collect();
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lattice::{Cell, FccLattice};
    use crate::mechanics::analysis::Verdict;
    use crate::mechanics::model::Bending;
    use crate::mechanics::validation::structure;

    /// Displacement (units of d) below which a body "stays put".
    const STAYS: f64 = 0.02;
    /// Displacement (units of d) above which a body "falls".
    const FALLS: f64 = 1.0;

    fn overloaded(model: &Model, s: &Structure) -> Vec<usize> {
        let a = Analyzer::new(model.clone(), false).analyse(s);
        (0..s.links.len())
            .filter(|&i| crate::mechanics::capacity::overloaded(a.links[i].utilisation))
            .collect()
    }

    #[test]
    fn a_stable_cantilever_stays_put_and_its_joint_forces_match_the_statics() {
        let model = Model::default_catom();
        let cells: Vec<Cell> = (0..=4).map(|i| Cell::new(i, 0, 0)).collect();
        let s = structure(&FccLattice, None, &cells, &[0], &[]);
        assert!(overloaded(&model, &s).is_empty());
        let o = simulate(&model, &s, 0.5);
        assert!(o.broken.is_empty());
        let max = o.displacement.iter().cloned().fold(0.0, f64::max);
        assert!(max < STAYS, "moved {max} d");
        // Root joint: carries the weight of the 4 modules beyond it.
        let a = Analyzer::new(model.clone(), false).analyse(&s);
        for (li, f) in o.joint_force.iter().enumerate() {
            let f = f.expect("every link has a joint");
            let fz = f[2].abs();
            let statics = a.links[li].force[2].abs();
            assert!(
                (fz - statics).abs() < 0.05 * statics,
                "link {li}: rapier {fz} N vs static {statics} N"
            );
        }
    }

    #[test]
    fn the_overloaded_root_breaks_and_exactly_the_part_beyond_it_falls() {
        // 10 kPa, rigid hinge: a 3-module cantilever has root utilisation
        // 9·mgd/(pL³) ≈ 1.9; the next connector 4·mgd/(pL³) ≈ 0.86 holds.
        let model = Model::default_catom().with_connector(10e3, Bending::RigidHinge);
        let cells: Vec<Cell> = (0..=3).map(|i| Cell::new(i, 0, 0)).collect();
        let s = structure(&FccLattice, None, &cells, &[0], &[]);
        let predicted = overloaded(&model, &s);
        assert_eq!(predicted.len(), 1);
        let o = simulate(&model, &s, 0.3);
        assert_eq!(o.broken, predicted);
        assert!(o.displacement[0] == 0.0);
        for b in 1..=3 {
            assert!(
                o.displacement[b] > FALLS,
                "body {b} moved only {} d",
                o.displacement[b]
            );
        }
    }

    #[test]
    fn of_two_arms_the_overloaded_one_falls_and_the_other_stays() {
        // A fixed wall of two modules; a long arm along +x from one, a short
        // one along −x from the other.
        let model = Model::default_catom().with_connector(10e3, Bending::RigidHinge);
        let mut cells = vec![Cell::new(0, 0, 0), Cell::new(0, 1, 0)];
        cells.extend((1..=3).map(|x| Cell::new(x, 0, 0)));
        cells.extend((1..=2).map(|x| Cell::new(-x, 1, 0)));
        let s = structure(&FccLattice, None, &cells, &[0, 1], &[]);
        let a = Analyzer::new(model.clone(), false).analyse(&s);
        assert_eq!(a.verdict(), Verdict::Overloaded);
        let predicted = overloaded(&model, &s);
        let o = simulate(&model, &s, 0.3);
        assert_eq!(o.broken, predicted);
        for b in 2..5 {
            assert!(
                o.displacement[b] > FALLS,
                "long arm body {b}: {}",
                o.displacement[b]
            );
        }
        for b in 5..7 {
            assert!(
                o.displacement[b] < STAYS,
                "short arm body {b}: {}",
                o.displacement[b]
            );
        }
    }

    #[test]
    fn a_stable_indeterminate_frame_stays_put() {
        // Two layers bridging two fixed supports: statically indeterminate.
        let model = Model::default_catom();
        let mut cells = vec![Cell::new(0, 0, 0), Cell::new(4, 0, 0)];
        cells.extend((1..4).map(|x| Cell::new(x, 0, 0)));
        cells.extend((0..4).map(|x| Cell::new(x, 0, 1)));
        let s = structure(&FccLattice, None, &cells, &[0, 1], &[]);
        assert!(overloaded(&model, &s).is_empty());
        let o = simulate(&model, &s, 0.5);
        assert!(o.broken.is_empty());
        let max = o.displacement.iter().cloned().fold(0.0, f64::max);
        assert!(max < STAYS, "moved {max} d");
    }
}
