//! A symmetric positive definite system with 6 × 6 blocks (one block row
//! per module: 3 translations, 3 rotations) and its preconditioned
//! conjugate-gradient solve.
//!
//! Hand-written rather than a sparse-direct crate: the systems are a few
//! hundred thousand unknowns at most, CG with a block-Jacobi preconditioner
//! needs no fill-in and takes a warm start — which is what makes re-solving
//! consecutive steps cheap — and the crate stays free of heavy numeric
//! dependencies (nalgebra's fixed-size 6 × 6 blocks do the arithmetic).

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

/// Solves `K x = f` by conjugate gradients with the block-Jacobi
/// preconditioner, starting from `x` (a warm start from a neighbouring
/// step's solution, or zeros). Stops at `‖r‖ ≤ tol·‖f‖`.
pub fn pcg(k: &BlockMatrix, f: &[Vec6], x: &mut [Vec6], tol: f64, max_iter: usize) -> SolveStats {
    let n = k.len();
    let fnorm = f.iter().map(|v| v.norm_squared()).sum::<f64>().sqrt();
    if fnorm == 0.0 {
        x.iter_mut().for_each(|v| *v = Vec6::zeros());
        return SolveStats {
            iterations: 0,
            relative_residual: 0.0,
            converged: true,
        };
    }
    let pre: Vec<Block> = k
        .diag
        .iter()
        .map(|d| {
            d.cholesky()
                .map(|c| c.inverse())
                .unwrap_or_else(|| Block::identity() / d.diagonal().max().max(1e-300))
        })
        .collect();
    let mut r = vec![Vec6::zeros(); n];
    k.mul(x, &mut r);
    for (ri, fi) in r.iter_mut().zip(f) {
        *ri = fi - *ri;
    }
    let mut z: Vec<Vec6> = r.iter().zip(&pre).map(|(ri, p)| p * ri).collect();
    let mut p = z.clone();
    let mut q = vec![Vec6::zeros(); n];
    let mut rz: f64 = r.iter().zip(&z).map(|(a, b)| a.dot(b)).sum();
    let target = tol * fnorm;
    let mut it = 0;
    let mut rnorm = r.iter().map(|v| v.norm_squared()).sum::<f64>().sqrt();
    while rnorm > target && it < max_iter {
        k.mul(&p, &mut q);
        let pq: f64 = p.iter().zip(&q).map(|(a, b)| a.dot(b)).sum();
        if pq <= 0.0 {
            break;
        }
        let alpha = rz / pq;
        let mut rr = 0.0;
        for i in 0..n {
            x[i] += alpha * p[i];
            r[i] -= alpha * q[i];
            z[i] = pre[i] * r[i];
            rr += r[i].norm_squared();
        }
        rnorm = rr.sqrt();
        let rz_new: f64 = r.iter().zip(&z).map(|(a, b)| a.dot(b)).sum();
        let beta = rz_new / rz;
        rz = rz_new;
        for i in 0..n {
            p[i] = z[i] + beta * p[i];
        }
        it += 1;
    }
    SolveStats {
        iterations: it,
        relative_residual: rnorm / fnorm,
        converged: rnorm <= target,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cg_solves_a_small_spd_chain_exactly() {
        // A chain of 5 blocks coupled to their neighbours (diagonally dominant).
        let n = 5;
        let mut k = BlockMatrix::new(n);
        for i in 0..n {
            k.diag[i] = Block::identity() * 4.0;
            k.diag[i][(0, 1)] = 0.5;
            k.diag[i][(1, 0)] = 0.5;
        }
        for i in 0..n - 1 {
            k.off.push((i as u32, i as u32 + 1, -Block::identity()));
        }
        let truth: Vec<Vec6> = (0..n)
            .map(|i| Vec6::from_fn(|r, _| (i * 6 + r) as f64))
            .collect();
        let mut f = vec![Vec6::zeros(); n];
        k.mul(&truth, &mut f);
        let mut x = vec![Vec6::zeros(); n];
        let s = pcg(&k, &f, &mut x, 1e-13, 1000);
        assert!(s.converged);
        for i in 0..n {
            assert!((x[i] - truth[i]).norm() < 1e-9);
        }
        // A warm start at the solution needs no iteration.
        let s2 = pcg(&k, &f, &mut x, 1e-10, 1000);
        assert_eq!(s2.iterations, 0);
    }
}
