//! The factor of an earlier step as the preconditioner of the current one.
//!
//! Consecutive steps share most of their bodies. Split the current bodies
//! into old ones `O` (in the kept factor `F`) and new ones `N` (modules
//! that came to rest in a new cell). The preconditioner is the symmetric
//! block Gauss–Seidel sweep over `(N, O)` with exact diagonal blocks:
//! `K_NN` factored afresh (it is small) and `K_OO ≈ F` restricted to the
//! old bodies still present. It is symmetric positive definite, exact
//! when nothing but the loads changed, and off the identity only by the
//! bodies that left and the links that changed around them — a low-rank,
//! local change, which CG resolves in a few iterations.

use super::direct::Factor;
use super::solver::{Block, BlockMatrix, Vec6, block_jacobi};

/// The symmetric block Gauss–Seidel preconditioner described above.
pub struct KeptFactor<'a> {
    factor: &'a Factor,
    /// Current body → its row in `factor` (`u32::MAX` for new bodies).
    map: &'a [u32],
    /// Current indices of the new bodies.
    new: Vec<usize>,
    /// `K_NN`'s factor, or its block-Jacobi inverse if that fails.
    knn: Result<Factor, Vec<Block>>,
    /// `(old body, new position, K_ON block)`.
    coupling: Vec<(usize, usize, Block)>,
    buf: Vec<Vec6>,
    yn: Vec<Vec6>,
    wn: Vec<Vec6>,
}

impl<'a> KeptFactor<'a> {
    pub fn new(factor: &'a Factor, map: &'a [u32], k: &BlockMatrix) -> KeptFactor<'a> {
        let mut pos = vec![u32::MAX; map.len()];
        let mut new = Vec::new();
        for (i, &m) in map.iter().enumerate() {
            if m == u32::MAX {
                pos[i] = new.len() as u32;
                new.push(i);
            }
        }
        let mut knn = BlockMatrix::new(new.len());
        for (p, &i) in new.iter().enumerate() {
            knn.diag[p] = k.diag[i];
        }
        let mut coupling = Vec::new();
        for (i, j, b) in &k.off {
            let (i, j) = (*i as usize, *j as usize);
            match (pos[i], pos[j]) {
                (u32::MAX, u32::MAX) => {}
                (u32::MAX, pj) => coupling.push((i, pj as usize, *b)),
                (pi, u32::MAX) => coupling.push((j, pi as usize, b.transpose())),
                (pi, pj) if pi < pj => knn.off.push((pi, pj, *b)),
                (pi, pj) => knn.off.push((pj, pi, b.transpose())),
            }
        }
        let knn = if knn.is_empty() {
            Err(Vec::new())
        } else {
            Factor::new(&knn).ok_or_else(|| block_jacobi(&knn))
        };
        let n_new = new.len();
        KeptFactor {
            factor,
            map,
            new,
            knn,
            coupling,
            buf: vec![Vec6::zeros(); factor.len()],
            yn: vec![Vec6::zeros(); n_new],
            wn: vec![Vec6::zeros(); n_new],
        }
    }

    fn solve_nn(knn: &Result<Factor, Vec<Block>>, x: &mut [Vec6]) {
        match knn {
            Ok(f) => f.solve_in_place(x),
            Err(jac) => x.iter_mut().zip(jac).for_each(|(v, d)| *v = d * *v),
        }
    }

    /// `z ≈ K⁻¹ r`.
    pub fn apply(&mut self, r: &[Vec6], z: &mut [Vec6]) {
        // Forward: new bodies first, then the old ones against them.
        for (p, &i) in self.new.iter().enumerate() {
            self.yn[p] = r[i];
        }
        Self::solve_nn(&self.knn, &mut self.yn);
        z.copy_from_slice(r);
        for (o, p, b) in &self.coupling {
            z[*o] -= b * self.yn[*p];
        }
        self.buf.iter_mut().for_each(|v| *v = Vec6::zeros());
        for (i, &m) in self.map.iter().enumerate() {
            if m != u32::MAX {
                self.buf[m as usize] = z[i];
            }
        }
        self.factor.solve_in_place(&mut self.buf);
        for (i, &m) in self.map.iter().enumerate() {
            if m != u32::MAX {
                z[i] = self.buf[m as usize];
            }
        }
        // Backward: correct the new bodies for the old ones' answer.
        self.wn.iter_mut().for_each(|v| *v = Vec6::zeros());
        for (o, p, b) in &self.coupling {
            self.wn[*p] += b.tr_mul(&z[*o]);
        }
        Self::solve_nn(&self.knn, &mut self.wn);
        for (p, &i) in self.new.iter().enumerate() {
            z[i] = self.yn[p] - self.wn[p];
        }
    }
}
