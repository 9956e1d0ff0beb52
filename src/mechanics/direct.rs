//! Sparse direct solve of a [`BlockMatrix`]: faer's supernodal Cholesky
//! with its fill-reducing (AMD) ordering.
//!
//! faer is the well-kept pure-Rust sparse Cholesky (no C libraries, so CI
//! builds it from crates.io alone). A module network is a sparse frame —
//! pillars, branches and plates of modules — whose separators are small,
//! so the factor has little fill and a solve costs a few passes over it.
//! The factor of one step is then kept as the preconditioner of the next
//! steps (see [`super::analysis`]), which is where the reuse comes from.

use super::solver::{BlockMatrix, Vec6};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::perm::PermRef;
use faer::sparse::linalg::amd;
use faer::sparse::linalg::cholesky::{
    SymbolicCholesky, SymmetricOrdering, factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMat, SymbolicSparseColMat, Triplet};
use faer::{Conj, MatMut, Par, Side};

/// The Cholesky factor `K = LLᵀ` of a symmetric positive definite block
/// matrix.
pub struct Factor {
    symbolic: SymbolicCholesky<usize>,
    values: Vec<f64>,
    blocks: usize,
}

impl std::fmt::Debug for Factor {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Factor")
            .field("blocks", &self.blocks)
            .field("nnz_l", &self.values.len())
            .finish()
    }
}

/// A fill-reducing ordering of the scalar unknowns from approximate
/// minimum degree on the block graph (one node per module): 36 times
/// fewer entries to order than the scalar pattern, and a module's six
/// unknowns stay together.
fn block_ordering(k: &BlockMatrix) -> Option<(Vec<usize>, Vec<usize>)> {
    let n = k.len();
    let mut idx: Vec<(usize, usize)> = (0..n).map(|i| (i, i)).collect();
    idx.extend(k.off.iter().map(|(i, j, _)| (*i as usize, *j as usize)));
    idx.sort_unstable_by_key(|&(r, c)| (c, r));
    idx.dedup();
    let mut col_ptr = vec![0usize; n + 1];
    for &(_, c) in &idx {
        col_ptr[c + 1] += 1;
    }
    for c in 0..n {
        col_ptr[c + 1] += col_ptr[c];
    }
    let rows: Vec<usize> = idx.iter().map(|&(r, _)| r).collect();
    let pattern = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, rows);
    let (mut fwd, mut inv) = (vec![0usize; n], vec![0usize; n]);
    let mut mem = MemBuffer::try_new(amd::order_scratch::<usize>(n, idx.len())).ok()?;
    amd::order(
        &mut fwd,
        &mut inv,
        pattern.as_ref(),
        amd::Control::default(),
        MemStack::new(&mut mem),
    )
    .ok()?;
    let fwd6: Vec<usize> = fwd
        .iter()
        .flat_map(|&b| (0..6).map(move |r| 6 * b + r))
        .collect();
    let mut inv6 = vec![0usize; 6 * n];
    for (k, &o) in fwd6.iter().enumerate() {
        inv6[o] = k;
    }
    Some((fwd6, inv6))
}

impl Factor {
    /// Factors `k`; `None` when it is not positive definite (a part of the
    /// structure is free to move: a mechanism).
    pub fn new(k: &BlockMatrix) -> Option<Factor> {
        let n = k.len();
        let mut entries: Vec<Triplet<usize, usize, f64>> =
            Vec::with_capacity(21 * n + 36 * k.off.len());
        for (i, d) in k.diag.iter().enumerate() {
            for c in 0..6 {
                for r in c..6 {
                    entries.push(Triplet::new(6 * i + r, 6 * i + c, d[(r, c)]));
                }
            }
        }
        // `off` holds K_ij for i < j; its lower-triangle mirror is
        // K_ji = K_ijᵀ at block row j, block column i.
        for (i, j, b) in &k.off {
            let (i, j) = (*i as usize, *j as usize);
            debug_assert!(i < j);
            for c in 0..6 {
                for r in 0..6 {
                    entries.push(Triplet::new(6 * j + r, 6 * i + c, b[(c, r)]));
                }
            }
        }
        let mat = SparseColMat::<usize, f64>::try_new_from_triplets(6 * n, 6 * n, &entries).ok()?;
        let (fwd, inv) = block_ordering(k)?;
        let perm = PermRef::new_checked(&fwd, &inv, 6 * n);
        let symbolic = factorize_symbolic_cholesky(
            mat.symbolic(),
            Side::Lower,
            SymmetricOrdering::Custom(perm),
            Default::default(),
        )
        .ok()?;
        let mut values = vec![0.0; symbolic.len_val()];
        let mut mem = MemBuffer::try_new(
            symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()),
        )
        .ok()?;
        symbolic
            .factorize_numeric_llt::<f64>(
                &mut values,
                mat.as_ref(),
                Side::Lower,
                LltRegularization::default(),
                Par::Seq,
                MemStack::new(&mut mem),
                Default::default(),
            )
            .ok()?;
        Some(Factor {
            symbolic,
            values,
            blocks: n,
        })
    }

    /// Number of 6 × 6 block rows.
    pub fn len(&self) -> usize {
        self.blocks
    }

    pub fn is_empty(&self) -> bool {
        self.blocks == 0
    }

    /// Solves `K x = b` in place (`b` has one block per row of `K`).
    pub fn solve_in_place(&self, b: &mut [Vec6]) {
        assert_eq!(b.len(), self.blocks, "right-hand side size");
        // Vector6<f64> is six contiguous f64 (nalgebra's column-major
        // array storage), so the blocks are one column of 6n values.
        let flat: &mut [f64] =
            unsafe { std::slice::from_raw_parts_mut(b.as_mut_ptr().cast::<f64>(), 6 * b.len()) };
        let n = flat.len();
        let mut mem = MemBuffer::new(self.symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
        faer::sparse::linalg::cholesky::LltRef::new(&self.symbolic, &self.values)
            .solve_in_place_with_conj(
                Conj::No,
                MatMut::from_column_major_slice_mut(flat, n, 1),
                Par::Seq,
                MemStack::new(&mut mem),
            );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mechanics::solver::Block;

    #[test]
    fn the_factor_solves_a_coupled_block_chain_exactly() {
        let n = 7;
        let mut k = BlockMatrix::new(n);
        for i in 0..n {
            k.diag[i] = Block::identity() * 4.0;
            k.diag[i][(0, 1)] = 0.5;
            k.diag[i][(1, 0)] = 0.5;
        }
        for i in 0..n - 1 {
            let mut b = -Block::identity();
            b[(2, 4)] = 0.25; // not symmetric within the block
            k.off.push((i as u32, i as u32 + 1, b));
        }
        let truth: Vec<Vec6> = (0..n)
            .map(|i| Vec6::from_fn(|r, _| (i * 6 + r) as f64 - 10.0))
            .collect();
        let mut x = vec![Vec6::zeros(); n];
        k.mul(&truth, &mut x);
        Factor::new(&k).expect("SPD").solve_in_place(&mut x);
        for i in 0..n {
            assert!((x[i] - truth[i]).norm() < 1e-10, "{i}: {:?}", x[i]);
        }
    }

    #[test]
    fn a_singular_matrix_is_refused() {
        let mut k = BlockMatrix::new(2);
        k.diag[0] = Block::identity();
        // Block 1 is all zeros: a free body.
        k.diag[1][(0, 0)] = 1.0;
        assert!(Factor::new(&k).is_none());
    }
}
