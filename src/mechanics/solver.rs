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

/// `G(r)`: generalised displacement (translation, rotation) of a point at
/// offset `r` from a rigid body's reference point, from the body's `(u, θ)`:
/// `u + θ × r = u − [r]ₓ θ`.
pub fn transfer(r: glam::DVec3) -> Block {
    let mut g = Block::identity();
    let s = nalgebra::Matrix3::new(0.0, -r.z, r.y, r.z, 0.0, -r.x, -r.y, r.x, 0.0);
    g.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-s));
    g
}

/// One level of the rigid-body aggregation hierarchy.
struct Level {
    k: BlockMatrix,
    dinv: Vec<Block>,
    /// Fine node → (aggregate, `G(x_fine − x_aggregate)`): the prolongation
    /// to this level from the next coarser one.
    agg: Vec<(u32, Block)>,
    coarse_len: usize,
}

/// A multigrid preconditioner by rigid-body aggregation: modules are
/// grouped by position into blocks of about 2 × 2 × 2 spacings, each group
/// moving as one rigid body on the coarse level (the exact near-null space
/// of an elastic structure), recursively, down to a small dense system.
/// Applied as one symmetric V-cycle with damped block-Jacobi smoothing.
pub struct Multigrid {
    levels: Vec<Level>,
    coarsest: nalgebra::DMatrix<f64>,
    coarse_chol: Option<nalgebra::Cholesky<f64, nalgebra::Dyn>>,
}

const OMEGA: f64 = 0.6;
const COARSEST: usize = 40;

fn block_inverse(d: &Block) -> Block {
    d.cholesky()
        .map(|c| c.inverse())
        .unwrap_or_else(|| Block::identity() / d.diagonal().max().max(1e-300))
}

impl Multigrid {
    /// Builds the hierarchy of `k`, whose nodes are at `positions` (units of d).
    pub fn new(k: &BlockMatrix, positions: &[glam::DVec3]) -> Multigrid {
        let mut levels = Vec::new();
        let mut cur = k.clone();
        let mut pos = positions.to_vec();
        let mut size = 2.0;
        while cur.len() > COARSEST && levels.len() < 12 {
            // Aggregate by grid box.
            let mut map: rustc_hash::FxHashMap<(i64, i64, i64), u32> = Default::default();
            let mut members: Vec<Vec<usize>> = Vec::new();
            let mut of = vec![0u32; cur.len()];
            for (i, p) in pos.iter().enumerate() {
                let key = (
                    (p.x / size).floor() as i64,
                    (p.y / size).floor() as i64,
                    (p.z / size).floor() as i64,
                );
                let a = *map.entry(key).or_insert_with(|| {
                    members.push(Vec::new());
                    members.len() as u32 - 1
                });
                members[a as usize].push(i);
                of[i] = a;
            }
            let nc = members.len();
            if nc as f64 > 0.8 * cur.len() as f64 {
                size *= 2.0;
                if size > 1e6 {
                    break;
                }
                continue;
            }
            let cpos: Vec<glam::DVec3> = members
                .iter()
                .map(|m| m.iter().map(|&i| pos[i]).sum::<glam::DVec3>() / m.len() as f64)
                .collect();
            let agg: Vec<(u32, Block)> = (0..cur.len())
                .map(|i| (of[i], transfer(pos[i] - cpos[of[i] as usize])))
                .collect();
            let mut coarse = BlockMatrix::new(nc);
            for (i, d) in cur.diag.iter().enumerate() {
                let (a, g) = &agg[i];
                coarse.diag[*a as usize] += g.transpose() * d * g;
            }
            let mut off: rustc_hash::FxHashMap<(u32, u32), Block> = Default::default();
            for (i, j, kij) in &cur.off {
                let (a, ga) = &agg[*i as usize];
                let (b, gb) = &agg[*j as usize];
                let c = ga.transpose() * kij * gb;
                if a == b {
                    coarse.diag[*a as usize] += c + c.transpose();
                } else if a < b {
                    *off.entry((*a, *b)).or_insert_with(Block::zeros) += c;
                } else {
                    *off.entry((*b, *a)).or_insert_with(Block::zeros) += c.transpose();
                }
            }
            coarse.off = off.into_iter().map(|((a, b), m)| (a, b, m)).collect();
            coarse.off.sort_unstable_by_key(|e| (e.0, e.1));
            let dinv = cur.diag.iter().map(block_inverse).collect();
            levels.push(Level {
                k: cur,
                dinv,
                agg,
                coarse_len: nc,
            });
            cur = coarse;
            pos = cpos;
            size *= 2.0;
        }
        let n = cur.len() * 6;
        let mut dense = nalgebra::DMatrix::<f64>::zeros(n, n);
        for (i, d) in cur.diag.iter().enumerate() {
            dense.view_mut((6 * i, 6 * i), (6, 6)).copy_from(d);
        }
        for (i, j, m) in &cur.off {
            let (i, j) = (*i as usize, *j as usize);
            dense.view_mut((6 * i, 6 * j), (6, 6)).copy_from(m);
            dense
                .view_mut((6 * j, 6 * i), (6, 6))
                .copy_from(&m.transpose());
        }
        let coarse_chol = dense.clone().cholesky();
        Multigrid {
            levels,
            coarsest: dense,
            coarse_chol,
        }
    }

    /// Number of levels above the dense one.
    pub fn depth(&self) -> usize {
        self.levels.len()
    }

    fn cycle(&self, l: usize, r: &[Vec6]) -> Vec<Vec6> {
        if l == self.levels.len() {
            let v = nalgebra::DVector::from_iterator(
                r.len() * 6,
                r.iter().flat_map(|b| b.iter().copied()),
            );
            let x = match &self.coarse_chol {
                Some(c) => c.solve(&v),
                None => {
                    // Semi-definite coarse system: fall back to Jacobi.
                    let d = self.coarsest.diagonal();
                    nalgebra::DVector::from_iterator(
                        v.len(),
                        v.iter().zip(d.iter()).map(|(a, b)| a / b.max(1e-300)),
                    )
                }
            };
            return (0..r.len())
                .map(|i| Vec6::from_iterator(x.rows(6 * i, 6).iter().copied()))
                .collect();
        }
        let lv = &self.levels[l];
        let n = r.len();
        let mut z: Vec<Vec6> = (0..n).map(|i| OMEGA * (lv.dinv[i] * r[i])).collect();
        let mut kz = vec![Vec6::zeros(); n];
        lv.k.mul(&z, &mut kz);
        let mut rc = vec![Vec6::zeros(); lv.coarse_len];
        for i in 0..n {
            let (a, g) = &lv.agg[i];
            rc[*a as usize] += g.tr_mul(&(r[i] - kz[i]));
        }
        let zc = self.cycle(l + 1, &rc);
        for i in 0..n {
            let (a, g) = &lv.agg[i];
            z[i] += g * zc[*a as usize];
        }
        lv.k.mul(&z, &mut kz);
        for i in 0..n {
            z[i] += OMEGA * (lv.dinv[i] * (r[i] - kz[i]));
        }
        z
    }

    /// Applies the preconditioner: `z ≈ K⁻¹ r`.
    pub fn apply(&self, r: &[Vec6]) -> Vec<Vec6> {
        self.cycle(0, r)
    }
}

/// Conjugate gradients preconditioned by a [`Multigrid`] V-cycle.
pub fn mg_pcg(
    k: &BlockMatrix,
    mg: &Multigrid,
    f: &[Vec6],
    x: &mut [Vec6],
    tol: f64,
    max_iter: usize,
) -> SolveStats {
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
    let mut r = vec![Vec6::zeros(); n];
    k.mul(x, &mut r);
    for (ri, fi) in r.iter_mut().zip(f) {
        *ri = fi - *ri;
    }
    let target = tol * fnorm;
    let mut rnorm = r.iter().map(|v| v.norm_squared()).sum::<f64>().sqrt();
    if rnorm <= target {
        return SolveStats {
            iterations: 0,
            relative_residual: rnorm / fnorm,
            converged: true,
        };
    }
    let mut z = mg.apply(&r);
    let mut p = z.clone();
    let mut q = vec![Vec6::zeros(); n];
    let mut rz: f64 = r.iter().zip(&z).map(|(a, b)| a.dot(b)).sum();
    let mut it = 0;
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
            rr += r[i].norm_squared();
        }
        rnorm = rr.sqrt();
        it += 1;
        if rnorm <= target {
            break;
        }
        z = mg.apply(&r);
        let rz_new: f64 = r.iter().zip(&z).map(|(a, b)| a.dot(b)).sum();
        let beta = rz_new / rz;
        rz = rz_new;
        for i in 0..n {
            p[i] = z[i] + beta * p[i];
        }
    }
    SolveStats {
        iterations: it,
        relative_residual: rnorm / fnorm,
        converged: rnorm <= target,
    }
}
