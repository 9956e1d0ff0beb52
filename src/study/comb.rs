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
