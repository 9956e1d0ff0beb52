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
use faer::sparse::linalg::amd;
use faer::sparse::linalg::cholesky::{
    LltRef, SymbolicCholesky, SymmetricOrdering, factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use faer::{Conj, MatMut, Par, Side};

/// The Cholesky factor `K = LLᵀ` of a symmetric positive definite block
/// matrix.
pub struct Factor {
    symbolic: SymbolicCholesky<usize>,
    values: Vec<f64>,
    /// `order[new] = old` block index.
    order: Vec<usize>,
}

impl std::fmt::Debug for Factor {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Factor")
            .field("blocks", &self.order.len())
            .field("nnz_l", &self.values.len())
            .finish()
    }
}

/// A fill-reducing ordering of the modules: approximate minimum degree on
/// the block graph (one node per module) — 36 times fewer entries to order
/// than the scalar pattern, and a module's six unknowns stay together.
/// Returns `order[new] = old` and its inverse.
fn block_ordering(n: usize, adjacency: &[Vec<(usize, usize)>]) -> Option<(Vec<usize>, Vec<usize>)> {
    let mut col_ptr = Vec::with_capacity(n + 1);
    let mut rows = Vec::new();
    col_ptr.push(0);
    for (c, adj) in adjacency.iter().enumerate() {
        // Upper triangle, sorted: the neighbours above the diagonal, then it.
        rows.extend(adj.iter().map(|&(j, _)| j).filter(|&j| j < c));
        rows.push(c);
        col_ptr.push(rows.len());
    }
    let pattern = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, rows);
    let (mut fwd, mut inv) = (vec![0usize; n], vec![0usize; n]);
    let mut mem = MemBuffer::try_new(amd::order_scratch::<usize>(n, pattern.compute_nnz())).ok()?;
    amd::order(
        &mut fwd,
        &mut inv,
        pattern.as_ref(),
        amd::Control::default(),
        MemStack::new(&mut mem),
    )
    .ok()?;
    Some((fwd, inv))
}

impl Factor {
    /// Factors `k`; `None` when it is not positive definite (a part of the
    /// structure is free to move: a mechanism).
    ///
    /// The upper triangle of `PKPᵀ` (P: the block ordering) is written
    /// straight into compressed columns, sorted, so faer neither sorts
    /// triplets nor permutes the matrix again.
    pub fn new(k: &BlockMatrix) -> Option<Factor> {
        let n = k.len();
        // Neighbours of each block with the index of their `off` entry,
        // sorted by block index.
        let mut adjacency: Vec<Vec<(usize, usize)>> = vec![Vec::new(); n];
        for (e, (i, j, _)) in k.off.iter().enumerate() {
            adjacency[*i as usize].push((*j as usize, e));
            adjacency[*j as usize].push((*i as usize, e));
        }
        adjacency.iter_mut().for_each(|a| a.sort_unstable());
        let (order, position) = block_ordering(n, &adjacency)?;
        let mut col_ptr = Vec::with_capacity(6 * n + 1);
        let mut rows = Vec::with_capacity(21 * n + 36 * k.off.len());
        let mut values = Vec::with_capacity(rows.capacity());
        col_ptr.push(0);
        let mut above: Vec<(usize, usize)> = Vec::new();
        for (c, &o) in order.iter().enumerate() {
            above.clear();
            above.extend(
                adjacency[o]
                    .iter()
                    .map(|&(j, e)| (position[j], e))
                    .filter(|&(r, _)| r < c),
            );
            above.sort_unstable();
            for cc in 0..6 {
                for &(rb, e) in &above {
                    // Block (row rb, column c) of PKPᵀ is K[order[rb], o].
                    let (i, _, b) = &k.off[e];
                    let from_row = *i as usize == order[rb];
                    for r in 0..6 {
                        rows.push(6 * rb + r);
                        values.push(if from_row { b[(r, cc)] } else { b[(cc, r)] });
                    }
                }
                for r in 0..=cc {
                    rows.push(6 * c + r);
                    values.push(k.diag[o][(r, cc)]);
                }
                col_ptr.push(rows.len());
            }
        }
        let pattern = SymbolicSparseColMat::new_checked(6 * n, 6 * n, col_ptr, None, rows);
        let mat = SparseColMat::new(pattern, values);
        let symbolic = factorize_symbolic_cholesky(
            mat.symbolic(),
            Side::Upper,
            SymmetricOrdering::Identity,
            Default::default(),
        )
        .ok()?;
        let mut l = vec![0.0; symbolic.len_val()];
        let mut mem = MemBuffer::try_new(
            symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()),
        )
        .ok()?;
        symbolic
            .factorize_numeric_llt::<f64>(
                &mut l,
                mat.as_ref(),
                Side::Upper,
                LltRegularization::default(),
                Par::Seq,
                MemStack::new(&mut mem),
                Default::default(),
            )
            .ok()?;
        Some(Factor {
            symbolic,
            values: l,
            order,
        })
    }

    /// Number of 6 × 6 block rows.
    pub fn len(&self) -> usize {
        self.order.len()
    }

    pub fn is_empty(&self) -> bool {
        self.order.is_empty()
    }

    /// Solves `K x = b` in place (`b` has one block per row of `K`).
    /// Solves `K x = b` for several right-hand sides at once (one pass
    /// over the factor for all of them: the sampled poses of a step).
    pub fn solve_many_in_place(&self, bs: &mut [Vec<Vec6>]) {
        let m = bs.len();
        if m == 0 {
            return;
        }
        let n = 6 * self.len();
        let mut y = vec![0.0; n * m];
        for (j, b) in bs.iter().enumerate() {
            assert_eq!(b.len(), self.len(), "right-hand side size");
            for (c, &o) in self.order.iter().enumerate() {
                y[j * n + 6 * c..j * n + 6 * c + 6].copy_from_slice(b[o].as_slice());
            }
        }
        let mut mem = MemBuffer::new(self.symbolic.solve_in_place_scratch::<f64>(m, Par::Seq));
        LltRef::new(&self.symbolic, &self.values).solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(&mut y, n, m),
            Par::Seq,
            MemStack::new(&mut mem),
        );
        for (j, b) in bs.iter_mut().enumerate() {
            for (c, &o) in self.order.iter().enumerate() {
                b[o] = Vec6::from_column_slice(&y[j * n + 6 * c..j * n + 6 * c + 6]);
            }
        }
    }

    pub fn solve_in_place(&self, b: &mut [Vec6]) {
        assert_eq!(b.len(), self.len(), "right-hand side size");
        let mut y: Vec<f64> = self
            .order
            .iter()
            .flat_map(|&o| b[o].iter().copied())
            .collect();
        let n = y.len();
        let mut mem = MemBuffer::new(self.symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
        LltRef::new(&self.symbolic, &self.values).solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(&mut y, n, 1),
            Par::Seq,
            MemStack::new(&mut mem),
        );
        for (c, &o) in self.order.iter().enumerate() {
            b[o] = Vec6::from_column_slice(&y[6 * c..6 * c + 6]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mechanics::solver::Block;

    #[test]
    fn the_factor_solves_a_coupled_block_chain_exactly() {
        let (k, truth) = crate::mechanics::solver::tests::chain(7, 0.25);
        let mut x = vec![Vec6::zeros(); 7];
        k.mul(&truth, &mut x);
        Factor::new(&k).expect("SPD").solve_in_place(&mut x);
        for i in 0..7 {
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
