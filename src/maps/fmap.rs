//! Functional maps (Ovsjanikov et al. 2012) between two eigenbases, and the conversions
//! between functional and pointwise maps, with ZoomOut (Melzi et al. 2019) and spectral ICP
//! refinement (docs/design.md, step 13; paper section 6.4).
//!
//! Direction lives in the name, as everywhere in the crate: `fmap_ab` is a `k_b x k_a` matrix
//! that maps the spectral coefficients of a function on shape A to those of the transported
//! function on shape B; `p2p_ba[i]` is the vertex of shape A matched to vertex `i` of
//! shape B (pyFM's `FM_12` and `p2p_21` with 1 = A, 2 = B). Both eigenbases are M-orthonormal (`Phi^T M Phi = I`), so the coefficients of
//! `f` are `Phi^T M f`.
//!
//! * [`project`]: spectral coefficients of functions.
//! * [`solve_fmap`]: `min_C ||C A - B||^2 + w ||C Lambda_a - Lambda_b C||^2`, solved row by
//!   row (the commutativity term is diagonal in the entries of C).
//! * [`solve_fmap_commuting`]: the same plus commutativity with operator pairs
//!   ([`Commutativity`]): [`multiplication_operators`] (Nogneng and Ovsjanikov 2017) and
//!   [`orientation_operators`] (Ren et al. 2018), by preconditioned conjugate gradients.
//! * [`fmap_to_p2p`]: nearest neighbours of the rows of `Phi_b` among the rows of
//!   `Phi_a C^T`, by a blocked dense search ([`nearest_rows`]).
//! * [`p2p_to_fmap`]: `C = Phi_b^T M_b Pi_ba Phi_a`.
//! * [`zoomout`]: grow the basis step by step, alternating the two conversions.
//! * [`icp_refine`]: spectral ICP: alternate conversion and projection of C on the
//!   orthogonal matrices (on vertex samples, like ZoomOut).

use faer::linalg::matmul::matmul;
use faer::linalg::solvers::Solve;
use faer::{Accum, Mat, MatRef, Par, Side};
use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use crate::progress::Cancel;
use crate::{Error, Result};

/// Query rows per block of the dense nearest-neighbour search: the block's distance matrix
/// (`NN_BLOCK x n_target`) stays in cache-sized pieces while the product is BLAS-3. Blocks
/// are the unit of parallel work, so results do not depend on the thread count.
const NN_BLOCK: usize = 256;

/// Candidates per query re-ranked in double precision by [`nearest_rows`].
const RERANK: usize = 4;
/// Targets scanned per chunk of [`nearest_rows`] (a multiple of 8).
const SCAN_LANES: usize = 32;

/// Seed of ZoomOut's vertex samples.
const SAMPLE_SEED: u64 = 0x200e;

/// Spectral coefficients `Phi[:, :k]^T M F` of the columns of `functions` (`n x d`), with
/// `mass` the lumped mass of the unit-area shape: a `k x d` matrix.
pub fn project(
    vectors: MatRef<'_, f64>,
    mass: &[f64],
    k: usize,
    functions: MatRef<'_, f64>,
) -> Mat<f64> {
    let n = vectors.nrows();
    let k = k.min(vectors.ncols());
    let weighted = Mat::from_fn(n, functions.ncols(), |i, j| mass[i] * functions[(i, j)]);
    let mut out = Mat::<f64>::zeros(k, functions.ncols());
    matmul(
        out.as_mut(),
        Accum::Replace,
        vectors.subcols(0, k).transpose(),
        weighted.as_ref(),
        1.0,
        Par::Seq,
    );
    out
}

/// The functional map `C_ab` (`k_b x k_a`) minimising
/// `||C A - B||_F^2 + w ||C Lambda_a - Lambda_b C||_F^2`, where `A = coef_a` (`k_a x d`) and
/// `B = coef_b` (`k_b x d`) hold corresponding descriptors' coefficients and the eigenvalue
/// differences are normalised to unit Frobenius norm (as pyFM does, so `w` is scale-free).
/// Row `i` of C solves `(A A^T + w diag((lambda_a - lambda_b,i)^2)) c_i = A b_i^T`.
pub fn solve_fmap(
    coef_a: MatRef<'_, f64>,
    coef_b: MatRef<'_, f64>,
    values_a: &[f64],
    values_b: &[f64],
    laplacian_weight: f64,
) -> Result<Mat<f64>> {
    let rows = RowSystems::new(coef_a, coef_b, values_a, values_b, laplacian_weight)?;
    let (k_a, k_b) = (coef_a.nrows(), coef_b.nrows());
    let mut fmap = Mat::<f64>::zeros(k_b, k_a);
    for i in 0..k_b {
        let system = Mat::from_fn(k_a, k_a, |r, c| rows.entry(i, r, c));
        let llt = system.llt(Side::Lower).map_err(|e| Error::Numerical {
            stage: "functional map",
            reason: format!("row {i}: {e:?}"),
        })?;
        let row = llt.solve(rows.rhs.col(i).as_mat());
        for j in 0..k_a {
            fmap[(i, j)] = row[(j, 0)];
        }
    }
    Ok(fmap)
}

/// Multiplication operators `Phi[:, :k]^T M diag(f) Phi[:, :k]` (`k x k`, symmetric) of
/// the columns `f` of `functions` (`n x d`), each column first scaled to unit M-norm: the
/// descriptor operators of Nogneng and Ovsjanikov (2017).
pub fn multiplication_operators(
    vectors: MatRef<'_, f64>,
    mass: &[f64],
    k: usize,
    functions: MatRef<'_, f64>,
) -> Vec<Mat<f64>> {
    let (n, k) = (vectors.nrows(), k.min(vectors.ncols()));
    let phi = vectors.subcols(0, k);
    (0..functions.ncols())
        .into_par_iter()
        .map(|j| {
            let f = functions.col(j);
            let norm = (0..n)
                .map(|v| mass[v] * f[v] * f[v])
                .sum::<f64>()
                .sqrt()
                .max(f64::MIN_POSITIVE);
            let weighted = Mat::from_fn(n, k, |v, c| mass[v] * f[v] / norm * phi[(v, c)]);
            let mut op = Mat::<f64>::zeros(k, k);
            matmul(
                op.as_mut(),
                Accum::Replace,
                phi.transpose(),
                weighted.as_ref(),
                1.0,
                Par::Seq,
            );
            op
        })
        .collect()
}

/// Orientation operators `O_f = Phi^T W_f Phi` (`k x k`) of the columns `f` of `functions`
/// (Ren et al. 2018): `g -> <n x grad f, grad g>`, integrated against the basis with
/// piecewise-linear functions. On a triangle the integral of `h <n x grad f, grad g>` is
/// `mean(h) sum_c g_c (f_(c-1) - f_(c+1)) / 2` (corners counter-clockwise), so `W_f` needs
/// no geometry, only consistently oriented faces. An orientation-preserving map commutes
/// with them, a reversing one anti-commutes. Each operator is scaled to unit Frobenius norm.
pub fn orientation_operators(
    vectors: MatRef<'_, f64>,
    k: usize,
    triangles: &[[u32; 3]],
    functions: MatRef<'_, f64>,
) -> Vec<Mat<f64>> {
    let (n, k) = (vectors.nrows(), k.min(vectors.ncols()));
    // The basis row by row (each vertex's k values contiguous) for the face loop.
    let rows: Vec<f64> = (0..n)
        .flat_map(|v| (0..k).map(move |c| vectors[(v, c)]))
        .collect();
    let phi = MatRef::from_row_major_slice(&rows, n, k);
    (0..functions.ncols())
        .into_par_iter()
        .map(|j| {
            let f = functions.col(j);
            // W Phi, accumulated face by face: every corner of a face receives
            // sum_c s_c Phi[v_c] with s_c = (f_(c-1) - f_(c+1)) / 6.
            let mut w_phi = vec![0.0; n * k];
            let mut sum = vec![0.0; k];
            for t in triangles {
                let v = t.map(|x| x as usize);
                let s = [0, 1, 2].map(|c| (f[v[(c + 2) % 3]] - f[v[(c + 1) % 3]]) / 6.0);
                let (r0, r_a, r_b) = (
                    &rows[v[0] * k..][..k],
                    &rows[v[1] * k..][..k],
                    &rows[v[2] * k..][..k],
                );
                for c in 0..k {
                    sum[c] = s[0] * r0[c] + s[1] * r_a[c] + s[2] * r_b[c];
                }
                for &corner in &v {
                    for (w, x) in w_phi[corner * k..][..k].iter_mut().zip(&sum) {
                        *w += x;
                    }
                }
            }
            let mut op = Mat::<f64>::zeros(k, k);
            matmul(
                op.as_mut(),
                Accum::Replace,
                phi.transpose(),
                MatRef::from_row_major_slice(&w_phi, n, k),
                1.0,
                Par::Seq,
            );
            let norm = op.norm_l2();
            if norm > 0.0 {
                op *= faer::Scale(1.0 / norm);
            }
            op
        })
        .collect()
}

/// A commutativity term `w sum_f ||C DA_f - DB_f C||_F^2` with operators of corresponding
/// descriptors on shape A (`k_a x k_a`) and shape B (`k_b x k_b`), in the same order:
/// multiplication operators (Nogneng and Ovsjanikov 2017) or orientation operators (Ren
/// et al. 2018).
#[derive(Debug, Clone, Copy)]
pub struct Commutativity<'a> {
    /// Operators `DA_f` on shape A (each `k_a x k_a`).
    pub operators_a: &'a [Mat<f64>],
    /// Operators `DB_f` on shape B (each `k_b x k_b`), one per operator in `operators_a`.
    pub operators_b: &'a [Mat<f64>],
    /// Weight `w` of the term (finite, >= 0; 0 drops it).
    pub weight: f64,
}

/// Largest number of conjugate-gradient iterations of [`solve_fmap_commuting`].
const CG_MAX_ITERATIONS: usize = 1000;
/// Relative residual at which [`solve_fmap_commuting`] stops.
const CG_TOLERANCE: f64 = 1e-9;

/// [`solve_fmap`] with commutativity terms added:
/// `||C A - B||^2 + w_L ||C Lambda_a - Lambda_b C||^2 + sum_terms w sum_f ||C DA_f - DB_f C||^2`.
/// The term couples the rows of C, so the normal equations are solved by conjugate
/// gradients, preconditioned by the row-wise systems (sequential, hence deterministic).
/// Stops with [`Error::Cancelled`] between conjugate-gradient iterations once `cancel` is
/// set (up to [`CG_MAX_ITERATIONS`] of them with a heavy commutativity weight).
pub fn solve_fmap_commuting(
    coef_a: MatRef<'_, f64>,
    coef_b: MatRef<'_, f64>,
    (values_a, values_b, laplacian_weight): (&[f64], &[f64], f64),
    terms: &[Commutativity<'_>],
    cancel: &Cancel,
) -> Result<Mat<f64>> {
    let (k_a, k_b) = (coef_a.nrows(), coef_b.nrows());
    let fits = |ops: &[Mat<f64>], k: usize| ops.iter().all(|d| d.nrows() == k && d.ncols() == k);
    for term in terms {
        let valid = term.operators_a.len() == term.operators_b.len()
            && fits(term.operators_a, k_a)
            && fits(term.operators_b, k_b)
            && term.weight >= 0.0
            && term.weight.is_finite();
        if !valid {
            return Err(Error::InvalidParameter {
                name: "descriptor operators",
                reason: format!(
                    "need as many {k_a}x{k_a} operators on shape A as {k_b}x{k_b} on shape B and a \
                     finite weight >= 0, got {} and {} with weight {}",
                    term.operators_a.len(),
                    term.operators_b.len(),
                    term.weight
                ),
            });
        }
    }
    let terms: Vec<&Commutativity<'_>> = terms
        .iter()
        .filter(|t| t.weight > 0.0 && !t.operators_a.is_empty())
        .collect();
    if terms.is_empty() {
        return solve_fmap(coef_a, coef_b, values_a, values_b, laplacian_weight);
    }
    let rows = RowSystems::new(coef_a, coef_b, values_a, values_b, laplacian_weight)?;
    // Sum over the terms of w D_a D_a^T and w D_b^T D_b.
    let (mut s_a, mut s_b) = (Mat::<f64>::zeros(k_a, k_a), Mat::<f64>::zeros(k_b, k_b));
    for term in &terms {
        for (d_a, d_b) in term.operators_a.iter().zip(term.operators_b) {
            matmul(
                s_a.as_mut(),
                Accum::Add,
                d_a,
                d_a.transpose(),
                term.weight,
                Par::Seq,
            );
            matmul(
                s_b.as_mut(),
                Accum::Add,
                d_b.transpose(),
                d_b,
                term.weight,
                Par::Seq,
            );
        }
    }
    // H(X) = X G + (lap o X) + sum_terms w sum_f (X D_a D_a^T + D_b^T D_b X - D_b X D_a^T
    // - D_b^T X D_a): the Hessian of the energy over 2.
    let apply = |x: &Mat<f64>| -> Mat<f64> {
        let mut out = rows.apply(x);
        matmul(out.as_mut(), Accum::Add, x, &s_a, 1.0, Par::Seq);
        matmul(out.as_mut(), Accum::Add, &s_b, x, 1.0, Par::Seq);
        let mut tmp = Mat::<f64>::zeros(k_b, k_a);
        for term in &terms {
            for (d_a, d_b) in term.operators_a.iter().zip(term.operators_b) {
                matmul(tmp.as_mut(), Accum::Replace, d_b, x, 1.0, Par::Seq);
                matmul(
                    out.as_mut(),
                    Accum::Add,
                    &tmp,
                    d_a.transpose(),
                    -term.weight,
                    Par::Seq,
                );
                matmul(
                    tmp.as_mut(),
                    Accum::Replace,
                    d_b.transpose(),
                    x,
                    1.0,
                    Par::Seq,
                );
                matmul(out.as_mut(), Accum::Add, &tmp, d_a, -term.weight, Par::Seq);
            }
        }
        out
    };
    // Preconditioner: each row's system with the coupling dropped.
    let factors = (0..k_b)
        .map(|i| {
            let system = Mat::from_fn(k_a, k_a, |r, c| {
                rows.entry(i, r, c) + s_a[(r, c)] + if r == c { s_b[(i, i)] } else { 0.0 }
            });
            system.llt(Side::Lower).map_err(|e| Error::Numerical {
                stage: "functional map",
                reason: format!("row {i}: {e:?}"),
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let precondition = |r: &Mat<f64>| -> Mat<f64> {
        let mut z = Mat::<f64>::zeros(k_b, k_a);
        for (i, llt) in factors.iter().enumerate() {
            let row = llt.solve(r.row(i).transpose().as_mat());
            for j in 0..k_a {
                z[(i, j)] = row[(j, 0)];
            }
        }
        z
    };
    let dot = |a: &Mat<f64>, b: &Mat<f64>| -> f64 {
        (0..k_a)
            .map(|j| (0..k_b).map(|i| a[(i, j)] * b[(i, j)]).sum::<f64>())
            .sum()
    };
    let rhs = rows.rhs();
    let rhs_norm = dot(&rhs, &rhs).sqrt().max(f64::MIN_POSITIVE);
    // Start from the solution without the coupling term's off-row part.
    let mut x = precondition(&rhs);
    let mut r = &rhs - apply(&x);
    let mut z = precondition(&r);
    let mut p = z.clone();
    let mut rz = dot(&r, &z);
    for _ in 0..CG_MAX_ITERATIONS {
        if dot(&r, &r).sqrt() <= CG_TOLERANCE * rhs_norm {
            break;
        }
        cancel.check()?;
        let hp = apply(&p);
        let alpha = rz / dot(&p, &hp);
        x += alpha * &p;
        r -= alpha * &hp;
        z = precondition(&r);
        let rz_next = dot(&r, &z);
        p = &z + (rz_next / rz) * &p;
        rz = rz_next;
    }
    Ok(x)
}

/// The row-separable part of the functional-map energy: `||C A - B||^2` and the Laplacian
/// commutativity, whose normal equations for row `i` of C are
/// `(A A^T + w diag((lambda_a - lambda_b,i)^2)) c_i = A b_i^T`.
struct RowSystems {
    gram: Mat<f64>,
    /// `A B^T` (`k_a x k_b`): column `i` is row `i`'s right-hand side.
    rhs: Mat<f64>,
    /// `w (lambda_a,j - lambda_b,i)^2 / norm + ridge`, indexed `(i, j)`.
    diagonal: Mat<f64>,
}

impl RowSystems {
    fn new(
        coef_a: MatRef<'_, f64>,
        coef_b: MatRef<'_, f64>,
        values_a: &[f64],
        values_b: &[f64],
        laplacian_weight: f64,
    ) -> Result<RowSystems> {
        let (k_a, k_b, d) = (coef_a.nrows(), coef_b.nrows(), coef_a.ncols());
        if coef_b.ncols() != d || values_a.len() < k_a || values_b.len() < k_b {
            return Err(Error::InvalidParameter {
                name: "descriptors",
                reason: format!(
                    "coefficients {k_a}x{d} and {k_b}x{} with {} and {} eigenvalues do not fit",
                    coef_b.ncols(),
                    values_a.len(),
                    values_b.len()
                ),
            });
        }
        let sq = |i: usize, j: usize| (values_a[j] - values_b[i]).powi(2);
        let norm = (0..k_b)
            .flat_map(|i| (0..k_a).map(move |j| (i, j)))
            .map(|(i, j)| sq(i, j).powi(2))
            .sum::<f64>()
            .sqrt()
            .max(f64::MIN_POSITIVE);
        let mut gram = Mat::<f64>::zeros(k_a, k_a);
        matmul(
            gram.as_mut(),
            Accum::Replace,
            coef_a,
            coef_a.transpose(),
            1.0,
            Par::Seq,
        );
        let mut rhs = Mat::<f64>::zeros(k_a, k_b);
        matmul(
            rhs.as_mut(),
            Accum::Replace,
            coef_a,
            coef_b.transpose(),
            1.0,
            Par::Seq,
        );
        // A tiny ridge keeps every row's system positive definite when the descriptors do
        // not span the basis and w = 0.
        let ridge = 1e-10 * (0..k_a).map(|j| gram[(j, j)]).sum::<f64>().max(1e-300) / k_a as f64;
        let diagonal = Mat::from_fn(k_b, k_a, |i, j| laplacian_weight * sq(i, j) / norm + ridge);
        Ok(RowSystems {
            gram,
            rhs,
            diagonal,
        })
    }

    /// Entry `(r, c)` of row `i`'s system matrix.
    fn entry(&self, i: usize, r: usize, c: usize) -> f64 {
        self.gram[(r, c)] + if r == c { self.diagonal[(i, r)] } else { 0.0 }
    }

    /// The right-hand sides as a `k_b x k_a` matrix (row `i` for row `i` of C).
    fn rhs(&self) -> Mat<f64> {
        self.rhs.transpose().to_owned()
    }

    /// `X G + diagonal o X` for a `k_b x k_a` matrix X.
    fn apply(&self, x: &Mat<f64>) -> Mat<f64> {
        let mut out = Mat::from_fn(x.nrows(), x.ncols(), |i, j| {
            self.diagonal[(i, j)] * x[(i, j)]
        });
        matmul(out.as_mut(), Accum::Add, x, &self.gram, 1.0, Par::Seq);
        out
    }
}

/// For every row of `query` (`m x k`), the index of the nearest row of `target` (`n x k`)
/// in Euclidean distance (the lowest index among exact ties). Blocked dense search:
/// `|q - t|^2 = |t|^2 - 2 q.t + |q|^2`, the middle term by matrix products in single
/// precision (three times the speed of double here), then the best `RERANK` = 4 candidates
/// re-ranked by their exact distance. Deterministic on any thread count.
/// Stops with [`Error::Cancelled`] between blocks of [`NN_BLOCK`] queries once `cancel` is
/// set (a block of a 50K-vertex target in 100 dimensions takes a few hundredths of a second).
pub fn nearest_rows(
    target: MatRef<'_, f64>,
    query: MatRef<'_, f64>,
    cancel: &Cancel,
) -> Result<Vec<u32>> {
    assert_eq!(
        target.ncols(),
        query.ncols(),
        "nearest_rows: dimensions differ"
    );
    let (n, dims) = (target.nrows(), target.ncols());
    // Row-major double-precision copies for the exact re-ranking (each row contiguous).
    let row_major = |m: MatRef<'_, f64>| -> Vec<f64> {
        let mut rows = vec![0.0; m.nrows() * dims];
        for c in 0..dims {
            for (i, &x) in m.col(c).iter().enumerate() {
                rows[i * dims + c] = x;
            }
        }
        rows
    };
    let (target_rows, query_rows) = (row_major(target), row_major(query));
    let target = Mat::<f32>::from_fn(n, dims, |i, j| target[(i, j)] as f32);
    let query = Mat::<f32>::from_fn(query.nrows(), dims, |i, j| query[(i, j)] as f32);
    let target_norms: Vec<f32> = (0..n)
        .map(|i| {
            target_rows[i * dims..][..dims]
                .iter()
                .map(|&x| (x as f32).powi(2))
                .sum()
        })
        .collect();
    let starts: Vec<usize> = (0..query.nrows()).step_by(NN_BLOCK).collect();
    // One distance block per worker, reused: a fresh n x NN_BLOCK block per query block
    // made the allocator keep up to 300 MiB more at 20K vertices (docs/decisions.md,
    // "Budget").
    let new_block = || Mat::<f32>::zeros(n, NN_BLOCK.min(query.nrows()));
    let blocks: Vec<Vec<u32>> = starts
        .par_iter()
        .map_init(new_block, |block, &start| {
            cancel.check()?;
            let rows = NN_BLOCK.min(query.nrows() - start);
            // n x rows, so that each query's column of dot products is contiguous.
            let mut dots = block.as_mut().subcols_mut(0, rows);
            matmul(
                dots.as_mut(),
                Accum::Replace,
                target.as_ref(),
                query.subrows(start, rows).transpose(),
                1.0,
                Par::Seq,
            );
            let dots = dots.as_ref();
            Ok((0..rows)
                .map(|r| {
                    let column = dots
                        .col(r)
                        .try_as_col_major()
                        .expect("owned column")
                        .as_slice();
                    // The best few by the single-precision expansion, then the exact double
                    // precision distance decides among them (the expansion loses the last
                    // digits when two vertices' embeddings nearly coincide).
                    let mut best = [(f32::INFINITY, 0u32); RERANK];
                    // Chunk by chunk: the chunk's minimum in SIMD lanes first, the ordered
                    // insertion only for a chunk that holds a candidate (the same result as
                    // offering every target in order).
                    let (norm_chunks, dot_chunks) = (
                        target_norms.chunks_exact(SCAN_LANES),
                        column.chunks_exact(SCAN_LANES),
                    );
                    let tail = norm_chunks.remainder().len();
                    for (c, (norms, dots)) in norm_chunks.zip(dot_chunks).enumerate() {
                        // `if x < m { x } else { m }` compiles to packed minimum
                        // instructions (f32::min's NaN rule does not).
                        let mut lanes = [f32::INFINITY; 8];
                        for (group_norms, group_dots) in
                            norms.chunks_exact(8).zip(dots.chunks_exact(8))
                        {
                            for l in 0..8 {
                                let d = group_norms[l] - 2.0 * group_dots[l];
                                lanes[l] = if d < lanes[l] { d } else { lanes[l] };
                            }
                        }
                        let least = lanes
                            .iter()
                            .fold(f32::INFINITY, |m, &d| if d < m { d } else { m });
                        if least < best[RERANK - 1].0 {
                            for l in 0..SCAN_LANES {
                                offer(&mut best, c * SCAN_LANES + l, norms[l] - 2.0 * dots[l]);
                            }
                        }
                    }
                    for j in n - tail..n {
                        offer(&mut best, j, target_norms[j] - 2.0 * column[j]);
                    }
                    let q = start + r;
                    let query_row = &query_rows[q * dims..][..dims];
                    let exact = |j: u32| {
                        query_row
                            .iter()
                            .zip(&target_rows[j as usize * dims..][..dims])
                            .map(|(x, y)| (x - y).powi(2))
                            .sum::<f64>()
                    };
                    let mut winner = (f64::INFINITY, 0u32);
                    for &(d, j) in &best {
                        if d.is_finite() {
                            let e = exact(j);
                            if e < winner.0 || (e == winner.0 && j < winner.1) {
                                winner = (e, j);
                            }
                        }
                    }
                    winner.1
                })
                .collect())
        })
        .collect::<Result<_>>()?;
    Ok(blocks.concat())
}

/// Puts target `j` at squared distance `d` among the best [`RERANK`] so far (sorted, the
/// earlier target first among equals).
fn offer(best: &mut [(f32, u32); RERANK], j: usize, d: f32) {
    if d < best[RERANK - 1].0 {
        let mut slot = RERANK - 1;
        while slot > 0 && d < best[slot - 1].0 {
            best[slot] = best[slot - 1];
            slot -= 1;
        }
        best[slot] = (d, j as u32);
    }
}

/// The pointwise map `p2p_ba` of a functional map `fmap_ab` (`k_b x k_a`): every vertex of
/// shape B (row of `phi_b[:, :k_b]`) goes to the vertex of shape A whose row of
/// `phi_a[:, :k_a] C^T` is nearest.
/// Honours `cancel` as [`nearest_rows`] does.
pub fn fmap_to_p2p(
    fmap_ab: MatRef<'_, f64>,
    phi_a: MatRef<'_, f64>,
    phi_b: MatRef<'_, f64>,
    cancel: &Cancel,
) -> Result<Vec<u32>> {
    let embedding_a = embedding_through(fmap_ab, phi_a);
    nearest_rows(
        embedding_a.as_ref(),
        phi_b.subcols(0, fmap_ab.nrows()),
        cancel,
    )
}

/// A's vertices in B's spectral coordinates through `fmap_ab` (`k_b x k_a`): the rows of
/// `phi_a[:, :k_a] C^T`, which [`fmap_to_p2p`] compares with B's rows.
pub fn embedding_through(fmap_ab: MatRef<'_, f64>, phi_a: MatRef<'_, f64>) -> Mat<f64> {
    let (k_b, k_a) = (fmap_ab.nrows(), fmap_ab.ncols());
    let mut embedding_a = Mat::<f64>::zeros(phi_a.nrows(), k_b);
    matmul(
        embedding_a.as_mut(),
        Accum::Replace,
        phi_a.subcols(0, k_a),
        fmap_ab.transpose(),
        1.0,
        Par::Seq,
    );
    embedding_a
}

/// The functional map `C_ab = Phi_b^T M_b Pi_ba Phi_a` (`k_b x k_a`) of a pointwise map
/// `p2p_ba` (one vertex of shape A per vertex of shape B).
pub fn p2p_to_fmap(
    p2p_ba: &[u32],
    phi_a: MatRef<'_, f64>,
    phi_b: MatRef<'_, f64>,
    mass_b: &[f64],
    k_a: usize,
    k_b: usize,
) -> Mat<f64> {
    let pulled = Mat::from_fn(p2p_ba.len(), k_a, |i, j| phi_a[(p2p_ba[i] as usize, j)]);
    project(phi_b, mass_b, k_b, pulled.as_ref())
}

/// A sub-sample on which ZoomOut runs (the "fast ZoomOut" of Magnet and Ovsjanikov 2021):
/// vertex indices and the weights that stand for the area around each.
#[derive(Debug, Clone)]
pub struct Sample {
    /// Sampled vertex indices (0-based rows of the eigenbasis), ascending.
    pub vertices: Vec<u32>,
    /// Weight of each vertex of `vertices`, in the same order: its mass.
    pub weights: Vec<f64>,
}

impl Sample {
    /// Every vertex, weighted by its mass (the exact case).
    pub fn all(mass: &[f64]) -> Sample {
        Sample {
            vertices: (0..mass.len() as u32).collect(),
            weights: mass.to_vec(),
        }
    }

    /// `size` vertices drawn uniformly without replacement (seeded), each weighted by its
    /// mass; the whole shape when it has at most `size` vertices. (Farthest-point sampling
    /// in the spectral embedding measured no more accurate on FAUST and cost 0.14 s per
    /// 7K-vertex shape, more than all ZoomOut iterations together.)
    pub fn random(mass: &[f64], size: usize, seed: u64) -> Sample {
        let n = mass.len();
        if size >= n {
            return Sample::all(mass);
        }
        let mut order: Vec<u32> = (0..n as u32).filter(|&v| mass[v as usize] > 0.0).collect();
        order.shuffle(&mut ChaCha8Rng::seed_from_u64(seed));
        order.truncate(size);
        order.sort_unstable();
        let weights = order.iter().map(|&v| mass[v as usize]).collect();
        Sample {
            vertices: order,
            weights,
        }
    }

    /// [`Sample::random`] of `size` vertices, or [`Sample::all`] for `size` 0.
    fn of_size(mass: &[f64], size: usize, seed: u64) -> Sample {
        if size == 0 {
            Sample::all(mass)
        } else {
            Sample::random(mass, size, seed)
        }
    }

    /// Sample positions (indices into `vertices`) as vertex indices.
    fn on_vertices(&self, positions: &[u32]) -> Vec<u32> {
        positions
            .iter()
            .map(|&s| self.vertices[s as usize])
            .collect()
    }

    fn rows(&self, phi: MatRef<'_, f64>, k: usize) -> Mat<f64> {
        Mat::from_fn(self.vertices.len(), k, |i, j| {
            phi[(self.vertices[i] as usize, j)]
        })
    }
}

/// ZoomOut parameters (Melzi et al. 2019).
#[derive(Debug, Clone, PartialEq)]
pub struct ZoomOutParams {
    /// Final basis size (both shapes).
    pub k_end: usize,
    /// Eigenfunctions added per iteration.
    pub step: usize,
    /// Vertices per shape on which the iterations run (0 = every vertex); the final map is
    /// always computed on every vertex.
    pub sample_size: usize,
    /// Keeps the struct open to new fields: build it with `..Default::default()`.
    #[doc(hidden)]
    pub non_exhaustive: crate::NonExhaustive,
}

impl Default for ZoomOutParams {
    fn default() -> Self {
        ZoomOutParams {
            k_end: 100,
            step: 5,
            sample_size: 2000,
            non_exhaustive: crate::NonExhaustive(()),
        }
    }
}

/// ZoomOut: starting from `fmap_ab` (`k x k`), repeatedly convert to a pointwise map and back
/// with `k + step` eigenfunctions until `k_end`; returns the final `fmap_ab` and the
/// full-resolution `p2p_ba`.
/// Stops with [`Error::Cancelled`] within an iteration once `cancel` is set.
pub fn zoomout(
    fmap_ab: MatRef<'_, f64>,
    (a, b): (BasisRef<'_>, BasisRef<'_>),
    params: &ZoomOutParams,
    cancel: &Cancel,
) -> Result<(Mat<f64>, Vec<u32>)> {
    zoomout_sloped(fmap_ab, (a, b), params, 1.0, cancel)
}

/// [`zoomout`] for a map between a part and a whole: B's basis grows `slope` times as fast
/// as A's (`slope` < 1 when B is a part of A: its share of A's area; > 1 when A is a part
/// of B), so the map stays on the slanted diagonal of a partial functional map (Rodolà et
/// al., "Partial Functional Correspondence", CGF 2017, section 4: by Weyl's law a part of
/// area share `s` has about `s` times as many eigenvalues below any bound). `params.k_end`
/// is the larger side's final size.
pub fn zoomout_sloped(
    fmap_ab: MatRef<'_, f64>,
    (a, b): (BasisRef<'_>, BasisRef<'_>),
    params: &ZoomOutParams,
    slope: f64,
    cancel: &Cancel,
) -> Result<(Mat<f64>, Vec<u32>)> {
    let run = ZoomOutRun::new(fmap_ab, (a, b), params, slope, cancel)?;
    let p2p_ba = fmap_to_p2p(run.fmap_ab.as_ref(), a.0, b.0, cancel)?;
    Ok((run.fmap_ab, p2p_ba))
}

/// The first rows (B's side) or columns (A's side) of a square map, as many as the slanted
/// diagonal of `slope` keeps ([`zoomout_sloped`]).
pub fn slanted(fmap_ab: MatRef<'_, f64>, slope: f64) -> Mat<f64> {
    let k = fmap_ab.nrows().max(fmap_ab.ncols());
    let (k_b, k_a) = sloped_sizes(k, slope);
    let (k_b, k_a) = (k_b.min(fmap_ab.nrows()), k_a.min(fmap_ab.ncols()));
    fmap_ab.submatrix(0, 0, k_b, k_a).to_owned()
}

/// The sizes `(k_b, k_a)` of a map whose larger side has `k` eigenfunctions, on the slanted
/// diagonal of `slope` ([`zoomout_sloped`]); each at least 1.
pub(crate) fn sloped_sizes(k: usize, slope: f64) -> (usize, usize) {
    let smaller = |k: usize, ratio: f64| ((k as f64 * ratio).round() as usize).clamp(1, k);
    if slope <= 1.0 {
        (smaller(k, slope), k)
    } else {
        (k, smaller(k, 1.0 / slope))
    }
}

/// A shape's eigenbasis (one row per vertex) and its vertex masses.
pub type BasisRef<'a> = (MatRef<'a, f64>, &'a [f64]);

/// ZoomOut's iterations without the final full-resolution conversion: the final functional
/// map and its pointwise map between the samples.
#[derive(Debug, Clone)]
pub struct SampledZoomOut {
    /// The final functional map (`k_end x k_end`).
    pub fmap_ab: Mat<f64>,
    /// The vertices of shape A on which the iterations ran.
    pub sample_a: Sample,
    /// The vertices of shape B on which the iterations ran.
    pub sample_b: Sample,
    /// For every vertex of `sample_b`, its vertex of shape A (one of `sample_a`'s) under the
    /// final map.
    pub p2p_ba: Vec<u32>,
}

/// [`zoomout_sloped`] up to, not including, the full-resolution conversion (for comparing
/// candidate maps before paying for it); `slope` 1 for two whole shapes.
/// Honours `cancel` as [`zoomout`] does.
pub fn zoomout_on_samples(
    fmap_ab: MatRef<'_, f64>,
    bases: (BasisRef<'_>, BasisRef<'_>),
    params: &ZoomOutParams,
    slope: f64,
    cancel: &Cancel,
) -> Result<SampledZoomOut> {
    let run = ZoomOutRun::new(fmap_ab, bases, params, slope, cancel)?;
    let (sub_a, sub_b) = (run.sub_a.as_ref(), run.sub_b.as_ref());
    let p2p_sub = fmap_to_p2p(run.fmap_ab.as_ref(), sub_a, sub_b, cancel)?;
    Ok(SampledZoomOut {
        p2p_ba: run.sample_a.on_vertices(&p2p_sub),
        fmap_ab: run.fmap_ab,
        sample_a: run.sample_a,
        sample_b: run.sample_b,
    })
}

/// ZoomOut's iterations on the samples.
struct ZoomOutRun {
    fmap_ab: Mat<f64>,
    sample_a: Sample,
    sample_b: Sample,
    /// The samples' rows of the bases (first `k_end` columns).
    sub_a: Mat<f64>,
    sub_b: Mat<f64>,
}

impl ZoomOutRun {
    fn new(
        fmap_ab: MatRef<'_, f64>,
        ((phi_a, mass_a), (phi_b, mass_b)): (BasisRef<'_>, BasisRef<'_>),
        params: &ZoomOutParams,
        slope: f64,
        cancel: &Cancel,
    ) -> Result<ZoomOutRun> {
        let k_max = phi_a.ncols().min(phi_b.ncols());
        let start = fmap_ab.nrows().max(fmap_ab.ncols());
        if params.step == 0
            || params.k_end > k_max
            || params.k_end < fmap_ab.nrows().min(fmap_ab.ncols())
            || !(slope > 0.0 && slope.is_finite())
        {
            return Err(Error::InvalidParameter {
                name: "zoomout",
                reason: format!(
                    "need step >= 1, start ({}) <= k_end ({}) <= eigenpairs ({k_max}) and a \
                     finite slope > 0 (got {slope})",
                    fmap_ab.nrows().min(fmap_ab.ncols()),
                    params.k_end
                ),
            });
        }
        let (k_end_b, k_end_a) = sloped_sizes(params.k_end, slope);
        let sample_a = Sample::of_size(mass_a, params.sample_size, SAMPLE_SEED);
        let sample_b = Sample::of_size(mass_b, params.sample_size, SAMPLE_SEED + 1);
        let sub_a = sample_a.rows(phi_a, k_end_a);
        let sub_b = sample_b.rows(phi_b, k_end_b);
        let mut fmap = fmap_ab.to_owned();
        let mut k = start.min(params.k_end);
        while k < params.k_end {
            // Pointwise map on the samples with the current map, then the functional map one
            // step larger from it.
            let p2p_sub = fmap_to_p2p(fmap.as_ref(), sub_a.as_ref(), sub_b.as_ref(), cancel)?;
            k = (k + params.step).min(params.k_end);
            fmap = weighted_fmap(
                &sample_a.on_vertices(&p2p_sub),
                phi_a,
                sub_b.as_ref(),
                &sample_b.weights,
                sloped_sizes(k, slope),
            )?;
        }
        Ok(ZoomOutRun {
            fmap_ab: fmap,
            sample_a,
            sample_b,
            sub_a,
            sub_b,
        })
    }
}

/// `C_ab (k_b x k_a)` from a pointwise map given on sample rows of shape B: the weighted
/// least squares `min_C sum_i w_i |Phi_b[i] C - Phi_a[p2p(i)]|^2`, which is exactly
/// `Phi_b^T M_b Pi Phi_a` when the sample is every vertex weighted by its mass.
fn weighted_fmap(
    p2p_ba: &[u32],
    phi_a: MatRef<'_, f64>,
    rows_b: MatRef<'_, f64>,
    weights: &[f64],
    (k_b, k_a): (usize, usize),
) -> Result<Mat<f64>> {
    let m = p2p_ba.len();
    let pulled = Mat::from_fn(m, k_a, |i, j| phi_a[(p2p_ba[i] as usize, j)]);
    let rows_b = rows_b.subcols(0, k_b);
    let weighted = Mat::from_fn(m, k_b, |i, j| weights[i] * rows_b[(i, j)]);
    let mut gram = Mat::<f64>::zeros(k_b, k_b);
    matmul(
        gram.as_mut(),
        Accum::Replace,
        weighted.transpose(),
        rows_b,
        1.0,
        Par::Seq,
    );
    let mut rhs = Mat::<f64>::zeros(k_b, k_a);
    matmul(
        rhs.as_mut(),
        Accum::Replace,
        weighted.transpose(),
        pulled.as_ref(),
        1.0,
        Par::Seq,
    );
    let llt = gram.llt(Side::Lower).map_err(|e| Error::Numerical {
        stage: "ZoomOut",
        reason: format!(
            "the sample does not determine {k_b} eigenfunctions ({e:?}): use a larger sample"
        ),
    })?;
    Ok(llt.solve(rhs.as_ref()))
}

/// Spectral ICP (Ovsjanikov et al. 2012, section 6.1): alternate the pointwise map of C and
/// the orthogonal matrix nearest to the functional map of that pointwise map, for
/// `iterations` rounds or until the map stops changing. Like [`zoomout`], the rounds run on
/// seeded vertex samples of `sample_size` per shape (0 = every vertex), then one
/// full-resolution conversion. Returns `fmap_ab` and `p2p_ba`.
/// Honours `cancel` between rounds.
pub fn icp_refine(
    fmap_ab: MatRef<'_, f64>,
    ((phi_a, mass_a), (phi_b, mass_b)): (BasisRef<'_>, BasisRef<'_>),
    (iterations, sample_size): (usize, usize),
    cancel: &Cancel,
) -> Result<(Mat<f64>, Vec<u32>)> {
    let (k_b, k_a) = (fmap_ab.nrows(), fmap_ab.ncols());
    if k_a != k_b || k_a > phi_a.ncols().min(phi_b.ncols()) {
        return Err(Error::InvalidParameter {
            name: "icp",
            reason: format!(
                "need a square map no larger than the bases ({} and {}), got {k_b}x{k_a}",
                phi_a.ncols(),
                phi_b.ncols()
            ),
        });
    }
    let sample_a = Sample::of_size(mass_a, sample_size, SAMPLE_SEED);
    let sample_b = Sample::of_size(mass_b, sample_size, SAMPLE_SEED + 1);
    let (sub_a, sub_b) = (sample_a.rows(phi_a, k_a), sample_b.rows(phi_b, k_b));
    let mut fmap = fmap_ab.to_owned();
    let convert = |fmap: &Mat<f64>, phi_a, phi_b| fmap_to_p2p(fmap.as_ref(), phi_a, phi_b, cancel);
    let mut p2p = convert(&fmap, sub_a.as_ref(), sub_b.as_ref())?;
    for _ in 0..iterations {
        let vertices = sample_a.on_vertices(&p2p);
        let c = weighted_fmap(
            &vertices,
            phi_a,
            sub_b.as_ref(),
            &sample_b.weights,
            (k_a, k_a),
        )?;
        let svd = c.svd().map_err(|e| Error::Numerical {
            stage: "spectral ICP",
            reason: format!("{e:?}"),
        })?;
        let mut next = Mat::<f64>::zeros(k_b, k_a);
        matmul(
            next.as_mut(),
            Accum::Replace,
            svd.U(),
            svd.V().transpose(),
            1.0,
            Par::Seq,
        );
        fmap = next;
        let next_p2p = convert(&fmap, sub_a.as_ref(), sub_b.as_ref())?;
        let unchanged = next_p2p == p2p;
        p2p = next_p2p;
        if unchanged {
            break;
        }
    }
    let p2p_ba = convert(&fmap, phi_a, phi_b)?;
    Ok((fmap, p2p_ba))
}
