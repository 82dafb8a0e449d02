//! Functional maps (Ovsjanikov et al. 2012) between two eigenbases, and the conversions
//! between functional and pointwise maps, with ZoomOut (Melzi et al. 2019) and spectral ICP
//! refinement (DESIGN.md step 13; paper section 6.4).
//!
//! Conventions (pyFM's): shape 1 is A, shape 2 is B. `fmap_12` is a `k2 x k1` matrix that
//! maps the spectral coefficients of a function on shape 1 to those of the transported
//! function on shape 2; `p2p_21[i]` is the vertex of shape 1 matched to vertex `i` of
//! shape 2. Both eigenbases are M-orthonormal (`Phi^T M Phi = I`), so the coefficients of
//! `f` are `Phi^T M f`.
//!
//! * [`project`]: spectral coefficients of functions.
//! * [`solve_fmap`]: `min_C ||C A - B||^2 + w ||C Lambda_1 - Lambda_2 C||^2`, solved row by
//!   row (the commutativity term is diagonal in the entries of C).
//! * [`fmap_to_p2p`]: nearest neighbours of the rows of `Phi_2` among the rows of
//!   `Phi_1 C^T`, by a blocked dense search ([`nearest_rows`]).
//! * [`p2p_to_fmap`]: `C = Phi_2^T M_2 Pi_21 Phi_1`.
//! * [`zoomout`]: grow the basis step by step, alternating the two conversions.
//! * [`icp_refine`]: spectral ICP: alternate conversion and projection of C on the
//!   orthogonal matrices.

use faer::linalg::matmul::matmul;
use faer::linalg::solvers::Solve;
use faer::{Accum, Mat, MatRef, Par, Side};
use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use crate::{Error, Result};

/// Query rows per block of the dense nearest-neighbour search: the block's distance matrix
/// (`NN_BLOCK x n_target`) stays in cache-sized pieces while the product is BLAS-3. Blocks
/// are the unit of parallel work, so results do not depend on the thread count.
const NN_BLOCK: usize = 256;

/// Candidates per query re-ranked in double precision by [`nearest_rows`].
const RERANK: usize = 4;

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

/// The functional map `C_12` (`k2 x k1`) minimising
/// `||C A - B||_F^2 + w ||C Lambda_1 - Lambda_2 C||_F^2`, where `A = coef_1` (`k1 x d`) and
/// `B = coef_2` (`k2 x d`) hold corresponding descriptors' coefficients and the eigenvalue
/// differences are normalised to unit Frobenius norm (as pyFM does, so `w` is scale-free).
/// Row `i` of C solves `(A A^T + w diag((lambda_1 - lambda_2,i)^2)) c_i = A b_i^T`.
pub fn solve_fmap(
    coef_1: MatRef<'_, f64>,
    coef_2: MatRef<'_, f64>,
    values_1: &[f64],
    values_2: &[f64],
    laplacian_weight: f64,
) -> Result<Mat<f64>> {
    let (k1, k2, d) = (coef_1.nrows(), coef_2.nrows(), coef_1.ncols());
    if coef_2.ncols() != d || values_1.len() < k1 || values_2.len() < k2 {
        return Err(Error::InvalidParameter {
            name: "descriptors",
            reason: format!(
                "coefficients {k1}x{d} and {k2}x{} with {} and {} eigenvalues do not fit",
                coef_2.ncols(),
                values_1.len(),
                values_2.len()
            ),
        });
    }
    let sq = |i: usize, j: usize| (values_1[j] - values_2[i]).powi(2);
    let norm = (0..k2)
        .flat_map(|i| (0..k1).map(move |j| (i, j)))
        .map(|(i, j)| sq(i, j).powi(2))
        .sum::<f64>()
        .sqrt()
        .max(f64::MIN_POSITIVE);
    let mut gram = Mat::<f64>::zeros(k1, k1);
    matmul(
        gram.as_mut(),
        Accum::Replace,
        coef_1,
        coef_1.transpose(),
        1.0,
        Par::Seq,
    );
    let mut rhs = Mat::<f64>::zeros(k1, k2);
    matmul(
        rhs.as_mut(),
        Accum::Replace,
        coef_1,
        coef_2.transpose(),
        1.0,
        Par::Seq,
    );
    // A tiny ridge keeps every row's system positive definite when the descriptors do not
    // span the basis and w = 0.
    let ridge = 1e-10 * (0..k1).map(|j| gram[(j, j)]).sum::<f64>().max(1e-300) / k1 as f64;
    let mut fmap = Mat::<f64>::zeros(k2, k1);
    for i in 0..k2 {
        let system = Mat::from_fn(k1, k1, |r, c| {
            gram[(r, c)]
                + if r == c {
                    laplacian_weight * sq(i, r) / norm + ridge
                } else {
                    0.0
                }
        });
        let llt = system.llt(Side::Lower).map_err(|e| Error::Numerical {
            stage: "functional map",
            reason: format!("row {i}: {e:?}"),
        })?;
        let row = llt.solve(rhs.col(i).as_mat());
        for j in 0..k1 {
            fmap[(i, j)] = row[(j, 0)];
        }
    }
    Ok(fmap)
}

/// For every row of `query` (`m x k`), the index of the nearest row of `target` (`n x k`)
/// in Euclidean distance (the lowest index among exact ties). Blocked dense search:
/// `|q - t|^2 = |t|^2 - 2 q.t + |q|^2`, the middle term by matrix products in single
/// precision (three times the speed of double here), then the best [`RERANK`] candidates
/// re-ranked by their exact distance. Deterministic on any thread count.
pub fn nearest_rows(target: MatRef<'_, f64>, query: MatRef<'_, f64>) -> Vec<u32> {
    assert_eq!(
        target.ncols(),
        query.ncols(),
        "nearest_rows: dimensions differ"
    );
    let (n, dims) = (target.nrows(), target.ncols());
    let (target_f64, query_f64) = (target, query);
    let target = Mat::<f32>::from_fn(n, dims, |i, j| target[(i, j)] as f32);
    let query = Mat::<f32>::from_fn(query.nrows(), dims, |i, j| query[(i, j)] as f32);
    let target_norms: Vec<f32> = (0..n)
        .map(|i| (0..target.ncols()).map(|j| target[(i, j)].powi(2)).sum())
        .collect();
    let starts: Vec<usize> = (0..query.nrows()).step_by(NN_BLOCK).collect();
    let blocks: Vec<Vec<u32>> = starts
        .par_iter()
        .map(|&start| {
            let rows = NN_BLOCK.min(query.nrows() - start);
            // n x rows, so that each query's column of dot products is contiguous.
            let mut dots = Mat::<f32>::zeros(n, rows);
            matmul(
                dots.as_mut(),
                Accum::Replace,
                target.as_ref(),
                query.subrows(start, rows).transpose(),
                1.0,
                Par::Seq,
            );
            (0..rows)
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
                    for (j, (&t, &dot)) in target_norms.iter().zip(column).enumerate() {
                        let d = t - 2.0 * dot;
                        if d < best[RERANK - 1].0 {
                            let mut slot = RERANK - 1;
                            while slot > 0 && d < best[slot - 1].0 {
                                best[slot] = best[slot - 1];
                                slot -= 1;
                            }
                            best[slot] = (d, j as u32);
                        }
                    }
                    let q = start + r;
                    let exact = |j: u32| {
                        (0..dims)
                            .map(|c| (query_f64[(q, c)] - target_f64[(j as usize, c)]).powi(2))
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
                .collect()
        })
        .collect();
    blocks.concat()
}

/// The pointwise map `p2p_21` of a functional map `fmap_12` (`k2 x k1`): every vertex of
/// shape 2 (row of `phi_2[:, :k2]`) goes to the vertex of shape 1 whose row of
/// `phi_1[:, :k1] C^T` is nearest.
pub fn fmap_to_p2p(
    fmap_12: MatRef<'_, f64>,
    phi_1: MatRef<'_, f64>,
    phi_2: MatRef<'_, f64>,
) -> Vec<u32> {
    let (k2, k1) = (fmap_12.nrows(), fmap_12.ncols());
    let mut embedding_1 = Mat::<f64>::zeros(phi_1.nrows(), k2);
    matmul(
        embedding_1.as_mut(),
        Accum::Replace,
        phi_1.subcols(0, k1),
        fmap_12.transpose(),
        1.0,
        Par::Seq,
    );
    nearest_rows(embedding_1.as_ref(), phi_2.subcols(0, k2))
}

/// The functional map `C_12 = Phi_2^T M_2 Pi_21 Phi_1` (`k2 x k1`) of a pointwise map
/// `p2p_21` (one vertex of shape 1 per vertex of shape 2).
pub fn p2p_to_fmap(
    p2p_21: &[u32],
    phi_1: MatRef<'_, f64>,
    phi_2: MatRef<'_, f64>,
    mass_2: &[f64],
    k1: usize,
    k2: usize,
) -> Mat<f64> {
    let pulled = Mat::from_fn(p2p_21.len(), k1, |i, j| phi_1[(p2p_21[i] as usize, j)]);
    project(phi_2, mass_2, k2, pulled.as_ref())
}

/// A sub-sample on which ZoomOut runs (the "fast ZoomOut" of Magnet and Ovsjanikov 2021):
/// vertex indices and the weights that stand for the area around each.
#[derive(Debug, Clone)]
pub struct Sample {
    pub vertices: Vec<u32>,
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
}

impl Default for ZoomOutParams {
    fn default() -> Self {
        ZoomOutParams {
            k_end: 100,
            step: 5,
            sample_size: 2000,
        }
    }
}

/// ZoomOut: starting from `fmap_12` (`k x k`), repeatedly convert to a pointwise map and back
/// with `k + step` eigenfunctions until `k_end`; returns the final `fmap_12` and the
/// full-resolution `p2p_21`.
pub fn zoomout(
    fmap_12: MatRef<'_, f64>,
    phi_1: MatRef<'_, f64>,
    mass_1: &[f64],
    phi_2: MatRef<'_, f64>,
    mass_2: &[f64],
    params: &ZoomOutParams,
) -> Result<(Mat<f64>, Vec<u32>)> {
    let k_max = phi_1.ncols().min(phi_2.ncols());
    if params.step == 0
        || params.k_end > k_max
        || params.k_end < fmap_12.nrows().min(fmap_12.ncols())
    {
        return Err(Error::InvalidParameter {
            name: "zoomout",
            reason: format!(
                "need step >= 1 and start ({}) <= k_end ({}) <= eigenpairs ({k_max})",
                fmap_12.nrows().min(fmap_12.ncols()),
                params.k_end
            ),
        });
    }
    let sample_1 = if params.sample_size == 0 {
        Sample::all(mass_1)
    } else {
        Sample::random(mass_1, params.sample_size, SAMPLE_SEED)
    };
    let sample_2 = if params.sample_size == 0 {
        Sample::all(mass_2)
    } else {
        Sample::random(mass_2, params.sample_size, SAMPLE_SEED + 1)
    };
    let sub_1 = sample_1.rows(phi_1, params.k_end);
    let sub_2 = sample_2.rows(phi_2, params.k_end);
    let mut fmap = fmap_12.to_owned();
    let mut k = fmap.nrows().min(fmap.ncols());
    while k < params.k_end {
        // Pointwise map on the samples with the current map, then the functional map one
        // step larger from it.
        let p2p_sub = fmap_to_p2p(fmap.as_ref(), sub_1.as_ref(), sub_2.as_ref());
        k = (k + params.step).min(params.k_end);
        let p2p_vertices: Vec<u32> = p2p_sub
            .iter()
            .map(|&s| sample_1.vertices[s as usize])
            .collect();
        fmap = weighted_fmap(&p2p_vertices, phi_1, sub_2.as_ref(), &sample_2.weights, k)?;
    }
    let p2p_21 = fmap_to_p2p(fmap.as_ref(), phi_1, phi_2);
    Ok((fmap, p2p_21))
}

/// `C_12 (k x k)` from a pointwise map given on sample rows of shape 2: the weighted least
/// squares `min_C sum_i w_i |Phi_2[i] C - Phi_1[p2p(i)]|^2`, which is exactly
/// `Phi_2^T M_2 Pi Phi_1` when the sample is every vertex weighted by its mass.
fn weighted_fmap(
    p2p_21: &[u32],
    phi_1: MatRef<'_, f64>,
    rows_2: MatRef<'_, f64>,
    weights: &[f64],
    k: usize,
) -> Result<Mat<f64>> {
    let m = p2p_21.len();
    let pulled = Mat::from_fn(m, k, |i, j| phi_1[(p2p_21[i] as usize, j)]);
    let rows_2 = rows_2.subcols(0, k);
    let weighted = Mat::from_fn(m, k, |i, j| weights[i] * rows_2[(i, j)]);
    let mut gram = Mat::<f64>::zeros(k, k);
    matmul(
        gram.as_mut(),
        Accum::Replace,
        weighted.transpose(),
        rows_2,
        1.0,
        Par::Seq,
    );
    let mut rhs = Mat::<f64>::zeros(k, k);
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
            "the sample does not determine {k} eigenfunctions ({e:?}): use a larger sample"
        ),
    })?;
    Ok(llt.solve(rhs.as_ref()))
}

/// Spectral ICP (Ovsjanikov et al. 2012, section 6.1): alternate the pointwise map of C and
/// the orthogonal matrix nearest to the functional map of that pointwise map, for
/// `iterations` rounds or until the map stops changing. Returns `fmap_12` and `p2p_21`.
pub fn icp_refine(
    fmap_12: MatRef<'_, f64>,
    phi_1: MatRef<'_, f64>,
    phi_2: MatRef<'_, f64>,
    mass_2: &[f64],
    iterations: usize,
) -> Result<(Mat<f64>, Vec<u32>)> {
    let (k2, k1) = (fmap_12.nrows(), fmap_12.ncols());
    let mut fmap = fmap_12.to_owned();
    let mut p2p = fmap_to_p2p(fmap.as_ref(), phi_1, phi_2);
    for _ in 0..iterations {
        let c = p2p_to_fmap(&p2p, phi_1, phi_2, mass_2, k1, k2);
        let svd = c.svd().map_err(|e| Error::Numerical {
            stage: "spectral ICP",
            reason: format!("{e:?}"),
        })?;
        let u = svd.U().subcols(0, k2.min(k1));
        let v = svd.V().subcols(0, k2.min(k1));
        let mut next = Mat::<f64>::zeros(k2, k1);
        matmul(
            next.as_mut(),
            Accum::Replace,
            u,
            v.transpose(),
            1.0,
            Par::Seq,
        );
        fmap = next;
        let next_p2p = fmap_to_p2p(fmap.as_ref(), phi_1, phi_2);
        let unchanged = next_p2p == p2p;
        p2p = next_p2p;
        if unchanged {
            break;
        }
    }
    Ok((fmap, p2p))
}
