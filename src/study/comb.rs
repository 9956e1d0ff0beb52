//! Seed 004's claims measured: parallel steps and atom operations of the
//! 2D combing (Algorithm 1, expanded into atom operations) against the
//! number of atoms n, on random connected polyominoes from a seeded
//! generator, beside a naive sequential baseline; log–log fits.

use crate::algorithms::comb::{Robot, meta_schedule, random_polyomino};
use crate::certify::{self, Options};
use crate::error::InputError;
use crate::geometry::atom_expand::{expand, slide_library};
use crate::lattice::AtomRest;
use crate::study::fit::LinearFit;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::time::Instant;

/// One size of the study.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Row {
    pub metas: usize,
    pub atoms: usize,
    /// Meta-module steps of the combing (slides and latch sets).
    pub meta_steps: usize,
    /// Parallel steps and atom operations of the expanded schedule.
    pub steps: usize,
    pub operations: usize,
    /// The naive baseline: one meta-module at a time, each SLIDE of its
    /// shortest path done alone (Σ distance × the SLIDE's cost).
    pub baseline_steps: usize,
    pub baseline_operations: usize,
    /// Seconds to generate (comb and expand) and to certify, if certified.
    pub generate_s: f64,
    pub certify_s: Option<f64>,
    pub certified: Option<bool>,
}

/// Runs the study at each size (meta-modules); certifies the sizes up to
/// `certify_up_to`.
pub fn run(
    sizes: &[usize],
    seed: u64,
    rest: AtomRest,
    certify_up_to: usize,
) -> Result<Vec<Row>, InputError> {
    let lib = slide_library(rest).ok_or_else(|| InputError::new("no SLIDE found"))?;
    let slide_steps = lib.steps.len();
    let slide_ops: usize = lib.steps.iter().map(Vec::len).sum();
    let mut rows = Vec::new();
    for &m in sizes {
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ (m as u64).wrapping_mul(0x9E37_79B9));
        let shape = random_polyomino(m, &mut rng);
        let t0 = Instant::now();
        let mut robot = Robot::new(&shape);
        robot.comb();
        let meta = meta_schedule(&shape, &robot.steps, rest);
        let atoms = expand(&meta, rest)?;
        let generate_s = t0.elapsed().as_secs_f64();
        let distance: usize = shape
            .iter()
            .zip(&robot.at)
            .map(|(a, b)| ((a.0 - b.0).abs() + (a.1 - b.1).abs()) as usize)
            .sum();
        let (certify_s, certified) = if m <= certify_up_to {
            let t1 = Instant::now();
            let r = certify::certify(&atoms, &Options::lattice_only())?;
            (Some(t1.elapsed().as_secs_f64()), Some(r.certified))
        } else {
            (None, None)
        };
        rows.push(Row {
            metas: m,
            atoms: 8 * m,
            meta_steps: meta.steps.len(),
            steps: atoms.steps.len(),
            operations: atoms.steps.iter().map(|s| s.events.len()).sum(),
            baseline_steps: distance * slide_steps,
            baseline_operations: distance * slide_ops,
            generate_s,
            certify_s,
            certified,
        });
    }
    Ok(rows)
}

/// One size of Theorem 1 in 2D (source to target through the common comb).
#[derive(Clone, Debug, serde::Serialize)]
pub struct TheoremRow {
    pub metas: usize,
    pub atoms: usize,
    /// Meta-module steps of each phase: the source's combing, its comb to
    /// the common comb, the target's comb-to-common-comb reversed (with the
    /// latch steps joining the two), the target's combing reversed.
    pub phase_steps: [usize; 4],
    /// Tunnels with one and with two turns (phases 2 and 3).
    pub tunnels: [usize; 2],
    /// Tunnels whose every leg is one meta-module long.
    pub short_tunnels: usize,
    /// The longest leg of any tunnel (meta-modules between its end and its
    /// turn, or between two turns).
    pub longest_leg: usize,
    /// Parallel steps and atom operations of the two combing phases,
    /// expanded into atom operations (the tunnels of the other two are not).
    pub comb_steps: usize,
    pub comb_operations: usize,
    /// Whether the whole schedule certifies at the meta-module level, and
    /// the combing phases atom by atom (lattice, collision, connectivity,
    /// in place), with the seconds each took.
    pub meta_certified: Option<bool>,
    pub atoms_certified: Option<bool>,
    pub generate_s: f64,
    pub certify_s: Option<f64>,
}

/// Legs of an orthogonal path: the straight runs between its ends and
/// turns, each as the number of cell-to-cell steps it makes (a 1-TUNNEL
/// of Fig. 12, leaf on the turn and exit beside it: legs 1 and 1).
fn legs(path: &[crate::lattice::Cell]) -> Vec<usize> {
    let ends: Vec<usize> = std::iter::once(0)
        .chain(crate::lattice::path_turns(path))
        .chain(std::iter::once(path.len() - 1))
        .collect();
    ends.windows(2).map(|w| w[1] - w[0]).collect()
}

/// Theorem 1 at each size: a seeded random source and target of `m`
/// meta-modules; certifies up to `certify_up_to` meta-modules.
pub fn theorem(
    sizes: &[usize],
    seed: u64,
    rest: AtomRest,
    certify_up_to: usize,
) -> Result<Vec<TheoremRow>, InputError> {
    use crate::algorithms::comb::common_comb::reconfigure;
    use crate::algorithms::comb::{meta_schedule_at, meta_schedule_framed};
    use crate::schedule::Event;
    let mut rows = Vec::new();
    for &m in sizes {
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ (m as u64).wrapping_mul(0x85EB_CA6B));
        let (src, tgt) = (random_polyomino(m, &mut rng), random_polyomino(m, &mut rng));
        let t0 = Instant::now();
        let plan = reconfigure(&src, &tgt);
        let whole = meta_schedule_framed(&src, &plan.steps(), rest, None);
        // The combing phases alone, from the robot where each starts.
        let mut robot = Robot::new(&src);
        // Each phase's frame: a meta-module it never moves (the source's,
        // the target's lowest row).
        let lowest =
            |s: &crate::algorithms::comb::Shape| s.iter().min_by_key(|c| (c.1, c.0)).copied();
        let first = meta_schedule_at(&robot.at, &plan.phases[0], rest, lowest(&src));
        for es in plan.phases[..3].iter().flatten() {
            robot.apply(es);
        }
        let loose = detached_neighbours(&robot);
        let mut phase4 = plan.phases[3].clone();
        if !loose.is_empty() {
            phase4.insert(0, loose);
        }
        let last = meta_schedule_at(&robot.at, &phase4, rest, lowest(&plan.target));
        let (a, b) = (expand(&first, rest)?, expand(&last, rest)?);
        let generate_s = t0.elapsed().as_secs_f64();
        let mut tunnels = [0; 2];
        let (mut short, mut longest) = (0, 0);
        for e in plan.phases[1..3].iter().flatten().flatten() {
            if let Event::Tunnel { path, .. } = e {
                tunnels[crate::lattice::path_turns(path).len().clamp(1, 2) - 1] += 1;
                let l = legs(path);
                short += usize::from(l.iter().all(|&n| n == 1));
                longest = longest.max(l.into_iter().max().unwrap_or(0));
            }
        }
        let (mut meta_certified, mut atoms_certified, mut certify_s) = (None, None, None);
        if m <= certify_up_to {
            let t1 = Instant::now();
            let (meta, atoms, _) = certify_phases(&whole, [&a, &b], None)?;
            (meta_certified, atoms_certified) = (Some(meta), Some(atoms));
            certify_s = Some(t1.elapsed().as_secs_f64());
        }
        let count = |s: &crate::schedule::Schedule| -> usize {
            s.steps.iter().map(|st| st.events.len()).sum()
        };
        rows.push(TheoremRow {
            metas: m,
            atoms: 8 * m,
            phase_steps: std::array::from_fn(|i| plan.phases[i].len()),
            tunnels,
            short_tunnels: short,
            longest_leg: longest,
            comb_steps: a.steps.len() + b.steps.len(),
            comb_operations: count(&a) + count(&b),
            meta_certified,
            atoms_certified,
            generate_s,
            certify_s,
        });
    }
    Ok(rows)
}

/// Theorem 1's series against atoms n: meta-module steps of the whole
/// reconfiguration, tunnels, and the combing phases' parallel steps and
/// atom operations.
pub fn theorem_series(rows: &[TheoremRow]) -> [(&'static str, Vec<(f64, f64)>); 4] {
    let pts = |f: fn(&TheoremRow) -> usize| -> Vec<(f64, f64)> {
        rows.iter().map(|r| (r.atoms as f64, f(r) as f64)).collect()
    };
    [
        (
            "meta-module steps, S to T",
            pts(|r| r.phase_steps.iter().sum()),
        ),
        ("tunnels", pts(|r| r.tunnels.iter().sum())),
        ("combing phases' parallel steps", pts(|r| r.comb_steps)),
        (
            "combing phases' atom operations",
            pts(|r| r.comb_operations),
        ),
    ]
}

/// One size of §3.2 (Theorem 2) in 3D, at the meta-module level.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Theorem3Row {
    pub metas: usize,
    pub atoms: usize,
    /// Steps of the four phases, as in [`TheoremRow::phase_steps`].
    pub phase_steps: [usize; 4],
    /// Tunnels with 1, 2, 3 and 4 turns.
    pub tunnels: [usize; 4],
    /// Parallel steps and atom operations of the two combing phases (the
    /// source's to a terrain and a 3D comb, the target's in reverse),
    /// expanded into atom operations (the k-TUNNELs of the other two are
    /// not).
    pub comb_steps: usize,
    pub comb_operations: usize,
    pub meta_certified: Option<bool>,
    /// The combing phases certified atom by atom (lattice, collision,
    /// connectivity, in place).
    pub atoms_certified: Option<bool>,
    /// The combing phases' highest drive-load utilisation under
    /// `models/cube-atom.toml` (assumed figures), when certified.
    pub comb_utilisation: Option<f64>,
    pub generate_s: f64,
    /// Seconds to certify, the mechanics included when a model is given
    /// (one pass over the combing phases).
    pub certify_s: Option<f64>,
}

/// Theorem 2 at each size: a seeded random source and target polycube of
/// `m` meta-modules, certified at the meta-module level up to
/// `certify_up_to`.
pub fn theorem3(
    sizes: &[usize],
    seed: u64,
    rest: AtomRest,
    certify_up_to: usize,
    mechanics: Option<std::path::PathBuf>,
) -> Result<Vec<Theorem3Row>, InputError> {
    use crate::algorithms::comb::common_comb::apply;
    use crate::algorithms::comb::three_d::{
        Robot3, random_polycube, reconfigure3, schedule_at, schedule_of,
    };
    use crate::schedule::Event;
    let mut rows = Vec::new();
    for &m in sizes {
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ (m as u64).wrapping_mul(0xC2B2_AE35));
        let (a, b) = (random_polycube(m, &mut rng), random_polycube(m, &mut rng));
        let t0 = Instant::now();
        let plan = reconfigure3(&a, &b);
        let s = schedule_of(&a, plan.steps(), rest);
        // The combing phases alone, from the robot where each starts, as
        // in 2D (`theorem`), with no frame: the robot lies free.
        let first = schedule_of(&a, plan.phases[0].clone(), rest);
        let mut robot = Robot3::new(&a);
        for es in plan.phases[..3].iter().flatten() {
            apply(&mut robot, es);
        }
        let mut phase4 = plan.phases[3].clone();
        let loose = detached_neighbours(&robot);
        if !loose.is_empty() {
            phase4.insert(0, loose);
        }
        let last = schedule_at(&robot.at, phase4, rest);
        let (ea, eb) = (expand(&first, rest)?, expand(&last, rest)?);
        let generate_s = t0.elapsed().as_secs_f64();
        let mut tunnels = [0; 4];
        for e in plan.steps().iter().flatten() {
            if let Event::Tunnel { path, .. } = e {
                let k = crate::lattice::path_turns(path).len();
                tunnels[k.clamp(1, 4) - 1] += 1;
            }
        }
        let (mut meta_certified, mut atoms_certified, mut comb_utilisation, mut certify_s) =
            (None, None, None, None);
        if m <= certify_up_to {
            let t1 = Instant::now();
            let (meta, atoms, worst) = certify_phases(&s, [&ea, &eb], mechanics.as_deref())?;
            (meta_certified, atoms_certified) = (Some(meta), Some(atoms));
            certify_s = Some(t1.elapsed().as_secs_f64());
            comb_utilisation = worst;
        }
        let count = |s: &crate::schedule::Schedule| -> usize {
            s.steps.iter().map(|st| st.events.len()).sum()
        };
        rows.push(Theorem3Row {
            metas: m,
            atoms: 8 * m,
            phase_steps: std::array::from_fn(|i| plan.phases[i].len()),
            tunnels,
            comb_steps: ea.steps.len() + eb.steps.len(),
            comb_operations: count(&ea) + count(&eb),
            meta_certified,
            atoms_certified,
            comb_utilisation,
            generate_s,
            certify_s,
        });
    }
    Ok(rows)
}

/// The whole schedule certified at the meta-module level, and the
/// combing phases (expanded into atoms) atom by atom. With a `model`, the
/// same pass also runs the mechanics: the phases then count as certified
/// when overloads are their only violations (the study reports those as
/// the worst utilisation, returned third), so they are replayed once.
fn certify_phases(
    whole: &crate::schedule::Schedule,
    phases: [&crate::schedule::Schedule; 2],
    model: Option<&std::path::Path>,
) -> Result<(bool, bool, Option<f64>), InputError> {
    let opts = Options {
        meta_level: true,
        ..Options::lattice_only()
    };
    let meta = certify::certify(whole, &opts)?.certified;
    let opts = match model {
        Some(m) => Options {
            model: Some(m.to_path_buf()),
            ..Options::default()
        },
        None => Options::lattice_only(),
    };
    let mut atoms = true;
    let mut worst: Option<f64> = model.map(|_| 0.0);
    for p in phases {
        let r = certify::certify(p, &opts)?;
        atoms &= r
            .violations
            .iter()
            .all(|v| v.kind == crate::certify::ViolationKind::Overload);
        for st in &r.per_step {
            if let (Some(w), Some(&u)) = (worst.as_mut(), st.metrics.get("max_utilisation")) {
                *w = w.max(u);
            }
        }
    }
    Ok((meta, atoms, worst))
}

/// Detach events for the neighbouring pairs a robot (2D or 3D) holds
/// apart: a schedule starts with every neighbouring pair attached.
fn detached_neighbours<R: crate::algorithms::comb::common_comb::MetaRobot>(
    r: &R,
) -> Vec<crate::schedule::Event> {
    use crate::lattice::Cell;
    let mut out = Vec::new();
    for a in 0..r.count() {
        let c = r.cell_of(a);
        for d in [Cell::new(1, 0, 0), Cell::new(0, 1, 0), Cell::new(0, 0, 1)] {
            if let Some(b) = r.at_cell(c + d)
                && !r.attached().contains(&(a.min(b), a.max(b)))
            {
                out.push(crate::schedule::Event::Detach {
                    module: a as u32,
                    other: b as u32,
                });
            }
        }
    }
    out
}

/// Theorem 2's series against atoms n: meta-module steps of the whole
/// reconfiguration, and the combing phases' parallel steps and atom
/// operations.
pub fn theorem3_series(rows: &[Theorem3Row]) -> [(&'static str, Vec<(f64, f64)>); 3] {
    let pts = |f: fn(&Theorem3Row) -> usize| -> Vec<(f64, f64)> {
        rows.iter().map(|r| (r.atoms as f64, f(r) as f64)).collect()
    };
    [
        (
            "meta-module steps, S to T",
            pts(|r| r.phase_steps.iter().sum()),
        ),
        ("combing phases' parallel steps", pts(|r| r.comb_steps)),
        (
            "combing phases' atom operations",
            pts(|r| r.comb_operations),
        ),
    ]
}

/// Least-squares fit of `ln y = a + b·ln x` (slope `b`, intercept `a`,
/// R² in log space): the power law `y = eᵃ·xᵇ`. Points with a
/// non-positive coordinate are left out.
pub fn loglog_fit(points: &[(f64, f64)]) -> Option<LinearFit> {
    let p: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0)
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    super::fit::linear_fit(&p)
}

/// The study's four measured series against atoms n, in the order the
/// table prints them: parallel steps, atom operations, and the naive
/// baseline's steps and operations.
pub fn series(rows: &[Row]) -> [(&'static str, Vec<(f64, f64)>); 4] {
    let pts = |f: fn(&Row) -> usize| -> Vec<(f64, f64)> {
        rows.iter().map(|r| (r.atoms as f64, f(r) as f64)).collect()
    };
    [
        ("parallel steps", pts(|r| r.steps)),
        ("atom operations", pts(|r| r.operations)),
        ("naive steps", pts(|r| r.baseline_steps)),
        ("naive operations", pts(|r| r.baseline_operations)),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fit_recovers_a_power_law_and_skips_bad_points() {
        let pts: Vec<(f64, f64)> = [8.0, 64.0, 512.0]
            .iter()
            .map(|&x: &f64| (x, 3.0 * x.powf(1.5)))
            .chain([(0.0, 1.0), (f64::NAN, 2.0)])
            .collect();
        let f = loglog_fit(&pts).unwrap();
        assert!((f.slope - 1.5).abs() < 1e-12);
        assert!((f.intercept - 3f64.ln()).abs() < 1e-12);
        assert!((f.r2 - 1.0).abs() < 1e-12);
        assert!(loglog_fit(&[(1.0, 1.0)]).is_none());
    }
}
