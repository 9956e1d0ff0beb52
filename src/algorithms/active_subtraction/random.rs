//! Random desired configurations as seed 003 §V-B generates them: an
//! included seed module on the ground, grown one random neighbour at a time
//! (which keeps it connected), hollow results discarded.
//!
//! Where the paper is silent: the seed module's position on the ground is
//! uniform; the number of included modules is `round(ρ · width · height)`
//! (at least 1); a hollow sample is replaced by the next sample of the same
//! random stream, so a `(seed, size, ρ)` triple always gives one shape.

use super::shape::{Shape, neighbours4};
use crate::lattice::Cell;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Attempts before giving up on finding a non-hollow sample.
const MAX_ATTEMPTS: usize = 100_000;

/// A non-hollow random desired configuration of density `density` (a
/// fraction of the `width × height` modules), reproducible from `seed`.
pub fn random_shape(width: i32, height: i32, density: f64, seed: u64) -> Result<Shape, String> {
    if width < 1 || height < 1 {
        return Err(format!(
            "random configuration of size {width} × {height} is empty"
        ));
    }
    if !(density > 0.0 && density <= 1.0) {
        return Err(format!("density {density} is not a fraction in (0, 1]"));
    }
    let total = (width * height) as usize;
    let n = ((density * total as f64).round() as usize).clamp(1, total);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    for _ in 0..MAX_ATTEMPTS {
        let s = grow(width, height, n, &mut rng);
        if s.enclosed().is_empty() {
            return Ok(s);
        }
    }
    Err(format!(
        "no non-hollow configuration of density {density} found in {MAX_ATTEMPTS} samples"
    ))
}

/// One grown sample (connected, possibly hollow).
fn grow(width: i32, height: i32, n: usize, rng: &mut ChaCha8Rng) -> Shape {
    let w = width as usize;
    let idx = |c: Cell| (c.y as usize - 1) * w + (c.x as usize - 1);
    let mut inc = vec![false; w * height as usize];
    let seed = Cell::xy(rng.random_range(1..=width), 1);
    inc[idx(seed)] = true;
    let mut members = vec![seed];
    while members.len() < n {
        // A random included module, then a random free neighbour of it.
        let u = members[rng.random_range(0..members.len())];
        let free: Vec<Cell> = neighbours4(u)
            .into_iter()
            .filter(|c| c.x >= 1 && c.y >= 1 && c.x <= width && c.y <= height && !inc[idx(*c)])
            .collect();
        if free.is_empty() {
            continue;
        }
        let c = free[rng.random_range(0..free.len())];
        inc[idx(c)] = true;
        members.push(c);
    }
    Shape::from_fn(width, height, |c| inc[idx(c)])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn random_shapes_are_valid_reproducible_and_of_the_asked_density() {
        for (k, rho) in [0.1, 0.4, 0.7].into_iter().enumerate() {
            let a = random_shape(10, 10, rho, k as u64).unwrap();
            assert_eq!(a, random_shape(10, 10, rho, k as u64).unwrap());
            assert_ne!(a, random_shape(10, 10, rho, k as u64 + 100).unwrap());
            assert_eq!(a.included_count(), (rho * 100.0).round() as usize);
            a.validate().unwrap();
        }
        assert!(random_shape(10, 10, 1.5, 0).is_err());
    }
}
