//! Spectral point descriptors from an [`Eigenbasis`] of the unit-area shape
//! (docs/design.md, step 5): the heat kernel signature (Sun, Ovsjanikov and Guibas 2009) and the
//! wave kernel signature (Aubry, Schlickewei and Cremers 2011). Both are matrices with one
//! row per input vertex and one column per time (HKS) or energy (WKS).

use faer::Mat;

use crate::spectral::eigen::Eigenbasis;
use crate::{Error, Result};

/// Parameters of the heat kernel signature.
#[derive(Debug, Clone, PartialEq)]
pub struct HksParams {
    /// Number of diffusion times (paper: 15).
    pub n_times: usize,
    /// Smallest time on the unit-area shape (paper: 0.03).
    pub t_min: f64,
    /// Largest time on the unit-area shape (paper: 0.25).
    pub t_max: f64,
    /// Take the logarithm of the signature (the authors' code does; raw HKS measured better
    /// in the paper's pipeline, docs/decisions.md, "HKS: raw, not log").
    pub log: bool,
    /// Keeps the struct open to new fields: build it with `..Default::default()`.
    #[doc(hidden)]
    pub non_exhaustive: crate::NonExhaustive,
}

impl Default for HksParams {
    fn default() -> Self {
        HksParams {
            n_times: 15,
            t_min: 0.03,
            t_max: 0.25,
            log: false,
            non_exhaustive: crate::NonExhaustive(()),
        }
    }
}

impl HksParams {
    /// The diffusion times, log-spaced from `t_min` to `t_max`.
    pub fn times(&self) -> Vec<f64> {
        log_space(self.t_min, self.t_max, self.n_times)
    }

    /// Checks every field's range.
    pub fn validate(&self) -> Result<()> {
        if self.n_times == 0 {
            return Err(Error::InvalidParameter {
                name: "hks.n_times",
                reason: "must be at least 1".into(),
            });
        }
        if !(self.t_min > 0.0 && self.t_min <= self.t_max && self.t_max.is_finite()) {
            return Err(Error::InvalidParameter {
                name: "hks.t_min/t_max",
                reason: format!(
                    "need 0 < t_min <= t_max < inf, got t_min = {}, t_max = {}",
                    self.t_min, self.t_max
                ),
            });
        }
        Ok(())
    }
}

/// Heat kernel signature `HKS(x, t) = sum_i exp(-lambda_i t) phi_i(x)^2` at the given
/// parameters' times (natural logarithm of it when `params.log`).
pub fn hks(basis: &Eigenbasis, params: &HksParams) -> Result<Mat<f64>> {
    params.validate()?;
    let times = params.times();
    let weights = Mat::from_fn(basis.len(), times.len(), |i, j| {
        (-basis.values[i].max(0.0) * times[j]).exp()
    });
    let mut out = squared_vectors_times(basis, &weights);
    if params.log {
        for j in 0..out.ncols() {
            for i in 0..out.nrows() {
                out[(i, j)] = out[(i, j)].max(f64::MIN_POSITIVE).ln();
            }
        }
    }
    Ok(out)
}

/// Parameters of the wave kernel signature.
#[derive(Debug, Clone, PartialEq)]
pub struct WksParams {
    /// Number of energies.
    pub n_energies: usize,
    /// Width of each energy band relative to the log-eigenvalue range divided by the number
    /// of energies (pyFM and Aubry et al. use 7).
    pub variance: f64,
    /// Keeps the struct open to new fields: build it with `..Default::default()`.
    #[doc(hidden)]
    pub non_exhaustive: crate::NonExhaustive,
}

impl Default for WksParams {
    fn default() -> Self {
        WksParams {
            n_energies: 100,
            variance: 7.0,
            non_exhaustive: crate::NonExhaustive(()),
        }
    }
}

/// Wave kernel signature, normalised per energy:
/// `WKS(x, e) = sum_i w_i(e) phi_i(x)^2 / sum_i w_i(e)`,
/// `w_i(e) = exp(-(e - log lambda_i)^2 / (2 sigma^2))`, energies evenly spaced in
/// `[log lambda_1 + 2 sigma, log lambda_max - 2 sigma]`, `sigma = variance (range) / n`.
/// Zero eigenvalues (one per connected piece) do not contribute.
pub fn wks(basis: &Eigenbasis, params: &WksParams) -> Result<Mat<f64>> {
    if params.n_energies == 0 || !(params.variance > 0.0 && params.variance.is_finite()) {
        return Err(Error::InvalidParameter {
            name: "wks",
            reason: format!(
                "need n_energies >= 1 and variance > 0, got {} and {}",
                params.n_energies, params.variance
            ),
        });
    }
    let positive = |l: f64| l > ZERO_EIGENVALUE * basis.values.last().copied().unwrap_or(1.0);
    let logs: Vec<Option<f64>> = basis
        .values
        .iter()
        .map(|&l| positive(l).then(|| l.ln()))
        .collect();
    let present: Vec<f64> = logs.iter().flatten().copied().collect();
    let (Some(&e_min), Some(&e_max)) = (present.first(), present.last()) else {
        return Err(Error::InvalidParameter {
            name: "wks",
            reason: "the eigenbasis has no positive eigenvalue".into(),
        });
    };
    let sigma = params.variance * (e_max - e_min).max(f64::EPSILON) / params.n_energies as f64;
    let energies = lin_space(e_min + 2.0 * sigma, e_max - 2.0 * sigma, params.n_energies);
    let mut weights = Mat::from_fn(basis.len(), energies.len(), |i, j| match logs[i] {
        Some(log) => (-(energies[j] - log).powi(2) / (2.0 * sigma * sigma)).exp(),
        None => 0.0,
    });
    for j in 0..weights.ncols() {
        let total: f64 = (0..weights.nrows()).map(|i| weights[(i, j)]).sum();
        if total > 0.0 {
            for i in 0..weights.nrows() {
                weights[(i, j)] /= total;
            }
        }
    }
    Ok(squared_vectors_times(basis, &weights))
}

/// An eigenvalue below this fraction of the largest counts as zero (a constant mode).
const ZERO_EIGENVALUE: f64 = 1e-9;

/// `(Phi .* Phi) W`: squared eigenvectors combined with per-eigenvalue weights.
/// `out[v, j] = sum_i phi_i(v)^2 weights[i, j]`, summed in the order of `i` for every
/// vertex: a matrix product whose blocking (and so its rounding) would depend on the
/// number of threads (docs/decisions.md, "Determinism across thread counts": descriptors
/// differed in the last digits between 1 and 2 threads).
fn squared_vectors_times(basis: &Eigenbasis, weights: &Mat<f64>) -> Mat<f64> {
    use rayon::prelude::*;
    let (n, k, t) = (basis.vectors.nrows(), basis.len(), weights.ncols());
    let rows: Vec<Vec<f64>> = (0..n)
        .into_par_iter()
        .map(|v| {
            let mut row = vec![0.0; t];
            for i in 0..k {
                let squared = basis.vectors[(v, i)].powi(2);
                for (j, out) in row.iter_mut().enumerate() {
                    *out += squared * weights[(i, j)];
                }
            }
            row
        })
        .collect();
    Mat::from_fn(n, t, |v, j| rows[v][j])
}

/// `n` values from `a` to `b` evenly spaced in the logarithm.
pub fn log_space(a: f64, b: f64, n: usize) -> Vec<f64> {
    lin_space(a.ln(), b.ln(), n)
        .into_iter()
        .map(f64::exp)
        .collect()
}

/// `n` values evenly spaced from `a` to `b` (just `a` when `n == 1`).
pub fn lin_space(a: f64, b: f64, n: usize) -> Vec<f64> {
    match n {
        0 => Vec::new(),
        1 => vec![a],
        _ => (0..n)
            .map(|i| a + (b - a) * i as f64 / (n - 1) as f64)
            .collect(),
    }
}
