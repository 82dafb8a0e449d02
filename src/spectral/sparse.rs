//! A factored sparse symmetric positive definite matrix (faer's supernodal Cholesky),
//! shared by the eigensolver (`L + sigma M`) and the heat method (`M + t L`, `L + eps M`).

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LltRef, SymbolicCholesky,
    SymmetricOrdering,
};
use faer::sparse::{SparseColMat, Triplet};
use faer::{Conj, MatMut, Par, Side};
use sprs::CsMat;

use crate::{Error, Result};

/// The scratch memory of `stage` could not be allocated: the shape is too large for the
/// memory the system can give.
fn out_of_memory(stage: &str) -> Error {
    Error::ResourceLimit {
        limit: "available_memory",
        reason: format!(
            "the scratch memory of the {stage} could not be allocated; simplify the shape or \
             free memory"
        ),
    }
}

/// `A = a L + diag(d)` for a symmetric stiffness `L` (both triangles stored), factored once.
pub(crate) struct SparseCholesky {
    symbolic: SymbolicCholesky<usize>,
    factor_values: Vec<f64>,
    n: usize,
    par: Par,
}

impl SparseCholesky {
    /// Factors `stiffness_scale * L + diag(diagonal)`; `stage` names the failure.
    pub fn new(
        stiffness: &CsMat<f64>,
        stiffness_scale: f64,
        diagonal: &[f64],
        par: Par,
        stage: &'static str,
    ) -> Result<SparseCholesky> {
        let n = diagonal.len();
        let numerical = |reason: String| Error::Numerical { stage, reason };
        // Upper triangle only.
        let mut triplets = Vec::with_capacity(stiffness.nnz() / 2 + n);
        for (col, column) in stiffness.outer_iterator().enumerate() {
            for (row, &value) in column.iter() {
                if row < col {
                    triplets.push(Triplet::new(row, col, stiffness_scale * value));
                }
            }
        }
        for (i, &d) in diagonal.iter().enumerate() {
            let l_ii = stiffness.get(i, i).copied().unwrap_or(0.0);
            triplets.push(Triplet::new(i, i, stiffness_scale * l_ii + d));
        }
        let a = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &triplets)
            .map_err(|e| numerical(format!("{e:?}")))?;
        let symbolic = factorize_symbolic_cholesky(
            a.symbolic(),
            Side::Upper,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams::default(),
        )
        .map_err(|e| numerical(format!("{e:?}")))?;
        let mut factor_values = vec![0.0; symbolic.len_val()];
        let mut buffer = MemBuffer::try_new(
            symbolic.factorize_numeric_llt_scratch::<f64>(par, Default::default()),
        )
        .map_err(|_| out_of_memory(stage))?;
        symbolic
            .factorize_numeric_llt(
                &mut factor_values,
                a.as_ref(),
                Side::Upper,
                LltRegularization::default(),
                par,
                MemStack::new(&mut buffer),
                Default::default(),
            )
            .map_err(|e| numerical(format!("not positive definite ({e:?})")))?;
        Ok(SparseCholesky {
            symbolic,
            factor_values,
            n,
            par,
        })
    }

    /// Order of the matrix.
    pub fn len(&self) -> usize {
        self.n
    }

    /// Scratch memory for solving `ncols` right-hand sides.
    pub fn scratch(&self, ncols: usize) -> Result<MemBuffer> {
        MemBuffer::try_new(self.symbolic.solve_in_place_scratch::<f64>(ncols, self.par))
            .map_err(|_| out_of_memory("sparse solve"))
    }

    /// Overwrites `rhs` with `A^{-1} rhs`.
    pub fn solve_in_place(&self, rhs: MatMut<'_, f64>, buffer: &mut MemBuffer) {
        let llt = LltRef::<'_, usize, f64>::new(&self.symbolic, &self.factor_values);
        llt.solve_in_place_with_conj(Conj::No, rhs, self.par, MemStack::new(buffer));
    }
}
