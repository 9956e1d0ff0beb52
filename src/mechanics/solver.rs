//! A symmetric positive definite system with 6 × 6 blocks (one block row
//! per module: 3 translations, 3 rotations) and its preconditioned
//! conjugate-gradient solve.
//!
//! CG is hand-written (it is a dozen lines over nalgebra's fixed-size
//! 6 × 6 blocks) because its preconditioner is ours: the sparse Cholesky
//! factor of an earlier step ([`super::direct`]), which makes re-solving
//! the next steps a few iterations from a warm start.

use nalgebra::{Matrix6, Vector6};

pub type Block = Matrix6<f64>;
pub type Vec6 = Vector6<f64>;

/// Block-sparse symmetric matrix: diagonal blocks plus one copy of each
/// off-diagonal pair (`K_ij`, with `K_ji = K_ijᵀ`).
#[derive(Clone, Debug, Default)]
pub struct BlockMatrix {
    pub diag: Vec<Block>,
    pub off: Vec<(u32, u32, Block)>,
}

impl BlockMatrix {
    pub fn new(n: usize) -> Self {
        BlockMatrix {
            diag: vec![Block::zeros(); n],
            off: Vec::new(),
        }
    }

    pub fn len(&self) -> usize {
        self.diag.len()
    }

    pub fn is_empty(&self) -> bool {
        self.diag.is_empty()
    }

    /// `y = K x`.
    pub fn mul(&self, x: &[Vec6], y: &mut [Vec6]) {
        for (i, (yi, d)) in y.iter_mut().zip(&self.diag).enumerate() {
            *yi = d * x[i];
        }
        for (i, j, k) in &self.off {
            let (i, j) = (*i as usize, *j as usize);
            y[i] += k * x[j];
            y[j] += k.tr_mul(&x[i]);
        }
    }
}

/// Outcome of a CG solve.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct SolveStats {
    pub iterations: usize,
    /// Final residual norm over the right-hand side's norm.
    pub relative_residual: f64,
    pub converged: bool,
}

/// Block-Jacobi preconditioner: the inverse of each 6 × 6 diagonal block.
pub fn block_jacobi(k: &BlockMatrix) -> Vec<Block> {
    k.diag.iter().map(block_inverse).collect()
}

fn block_inverse(d: &Block) -> Block {
    d.cholesky()
        .map(|c| c.inverse())
        .unwrap_or_else(|| Block::identity() / d.diagonal().max().max(1e-300))
}

fn dot(a: &[Vec6], b: &[Vec6]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x.dot(y)).sum()
}

/// Solves `K x = f` by preconditioned conjugate gradients, starting from
/// `x` (a warm start from a neighbouring step's solution, or zeros);
/// `precondition(r, z)` writes `z ≈ K⁻¹ r`. Stops at `‖r‖ ≤ tol·‖f‖`.
pub fn pcg(
    k: &BlockMatrix,
    precondition: &mut dyn FnMut(&[Vec6], &mut [Vec6]),
    f: &[Vec6],
    x: &mut [Vec6],
    tol: f64,
    max_iter: usize,
) -> SolveStats {
    let n = k.len();
    let fnorm = dot(f, f).sqrt();
    if fnorm == 0.0 {
        x.iter_mut().for_each(|v| *v = Vec6::zeros());
        return SolveStats {
            iterations: 0,
            relative_residual: 0.0,
            converged: true,
        };
    }
    let mut r = vec![Vec6::zeros(); n];
    k.mul(x, &mut r);
    for (ri, fi) in r.iter_mut().zip(f) {
        *ri = fi - *ri;
    }
    let target = tol * fnorm;
    let mut rnorm = dot(&r, &r).sqrt();
    let mut z = vec![Vec6::zeros(); n];
    let mut p = vec![Vec6::zeros(); n];
    let mut q = vec![Vec6::zeros(); n];
    let mut rz = 0.0;
    let mut it = 0;
    while rnorm > target && it < max_iter {
        precondition(&r, &mut z);
        let rz_new = dot(&r, &z);
        let beta = if it == 0 { 0.0 } else { rz_new / rz };
        rz = rz_new;
        for (pi, zi) in p.iter_mut().zip(&z) {
            *pi = zi + beta * *pi;
        }
        k.mul(&p, &mut q);
        let pq = dot(&p, &q);
        if pq <= 0.0 {
            break;
        }
        let alpha = rz / pq;
        let mut rr = 0.0;
        for i in 0..n {
            x[i] += alpha * p[i];
            r[i] -= alpha * q[i];
            rr += r[i].norm_squared();
        }
        rnorm = rr.sqrt();
        it += 1;
    }
    SolveStats {
        iterations: it,
        relative_residual: rnorm / fnorm,
        converged: rnorm <= target,
    }
}

/// [`pcg`] with the block-Jacobi preconditioner.
pub fn jacobi_pcg(
    k: &BlockMatrix,
    f: &[Vec6],
    x: &mut [Vec6],
    tol: f64,
    max_iter: usize,
) -> SolveStats {
    let pre = block_jacobi(k);
    let mut apply = |r: &[Vec6], z: &mut [Vec6]| {
        for ((zi, ri), p) in z.iter_mut().zip(r).zip(&pre) {
            *zi = p * ri;
        }
    };
    pcg(k, &mut apply, f, x, tol, max_iter)
}

/// `G(r)`: generalised displacement (translation, rotation) of a point at
/// offset `r` from a rigid body's reference point, from the body's `(u, θ)`:
/// `u + θ × r = u − [r]ₓ θ`.
pub fn transfer(r: glam::DVec3) -> Block {
    let mut g = Block::identity();
    let s = nalgebra::Matrix3::new(0.0, -r.z, r.y, r.z, 0.0, -r.x, -r.y, r.x, 0.0);
    g.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-s));
    g
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A chain of `n` blocks coupled to their neighbours (diagonally
    /// dominant, so SPD); `skew` makes the coupling blocks unsymmetric.
    /// Returns the matrix and a known solution.
    pub(crate) fn chain(n: usize, skew: f64) -> (BlockMatrix, Vec<Vec6>) {
        let mut k = BlockMatrix::new(n);
        for i in 0..n {
            k.diag[i] = Block::identity() * 4.0;
            k.diag[i][(0, 1)] = 0.5;
            k.diag[i][(1, 0)] = 0.5;
        }
        for i in 0..n - 1 {
            let mut b = -Block::identity();
            b[(2, 4)] = skew;
            k.off.push((i as u32, i as u32 + 1, b));
        }
        let truth = (0..n)
            .map(|i| Vec6::from_fn(|r, _| (i * 6 + r) as f64 - 10.0))
            .collect();
        (k, truth)
    }

    #[test]
    fn cg_solves_a_small_spd_chain_exactly() {
        let (k, truth) = chain(5, 0.0);
        let mut f = vec![Vec6::zeros(); 5];
        k.mul(&truth, &mut f);
        let mut x = vec![Vec6::zeros(); 5];
        let s = jacobi_pcg(&k, &f, &mut x, 1e-13, 1000);
        assert!(s.converged);
        for i in 0..5 {
            assert!((x[i] - truth[i]).norm() < 1e-9);
        }
        // A warm start at the solution needs no iteration.
        let s2 = jacobi_pcg(&k, &f, &mut x, 1e-10, 1000);
        assert_eq!(s2.iterations, 0);
    }
}
