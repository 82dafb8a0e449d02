//! Carrying per-vertex data from A to B through a [`SurfaceMap`] (docs/transfer.md):
//! continuous values interpolated, labels taken from the nearest vertex, skin weights
//! interpolated and renormalised; per-corner data (texture coordinates) with its seams
//! ([`SurfaceMap::transfer_corners`]); values files read exactly ([`read_values`]).

mod corners;
mod values;

pub use values::{parse_values, read_values, Values};

use crate::maps::surface::SurfaceMap;
use crate::{Error, Result};

/// How values of A become values of B.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TransferMode {
    /// The surface point's weighted mean of its three vertices' values (continuous data:
    /// colours, positions, any smooth attribute).
    Interpolate,
    /// The value of the surface point's nearest vertex (labels, ids, integer attributes).
    Nearest,
    /// Skin weights: interpolated, then at most `max_influences` of the largest kept (0: all)
    /// and the row scaled to sum to 1. A row of A must be non-negative; a vertex of B whose
    /// three vertices of A have no weight at all keeps a row of zeros.
    Weights {
        /// Largest number of non-zero weights per vertex (0: no limit).
        max_influences: usize,
    },
}

impl SurfaceMap {
    /// `values_a` (A's vertices by `channels` values, row-major) carried to B's vertices
    /// (B's vertices by `channels`, row-major) by `mode`. Errors on a wrong length, a value
    /// that is not finite, or a negative skin weight, naming the vertex.
    pub fn transfer(
        &self,
        values_a: &[f64],
        channels: usize,
        mode: TransferMode,
    ) -> Result<Vec<f64>> {
        check_values(values_a, channels, self.n_vertices_a, mode)?;
        let row = |v: u32| &values_a[v as usize * channels..][..channels];
        let mut out = Vec::with_capacity(self.points.len() * channels);
        let mut mean = vec![0.0; channels];
        for point in &self.points {
            if mode == TransferMode::Nearest {
                out.extend_from_slice(row(point.nearest()));
                continue;
            }
            let rows = point.vertices.map(row);
            for (c, m) in mean.iter_mut().enumerate() {
                *m = weighted_mean(rows.map(|r| r[c]), point.weights);
            }
            if let TransferMode::Weights { max_influences } = mode {
                keep_largest(&mut mean, max_influences);
                scale_to_one(&mut mean);
            }
            out.extend_from_slice(&mean);
        }
        Ok(out)
    }
}

/// `sum_i w_i x_i` for weights summing to 1 (heaviest first), as `x_0 + sum_i w_i (x_i -
/// x_0)`: a constant stays exactly itself, and a mean of finite values stays finite (values
/// near `f64::MAX` of both signs are scaled by the largest first).
fn weighted_mean(x: [f64; 3], w: [f64; 3]) -> f64 {
    let offset: f64 = (1..3)
        .filter(|&i| w[i] > 0.0)
        .map(|i| w[i] * (x[i] - x[0]))
        .sum();
    let mean = x[0] + offset;
    if mean.is_finite() {
        return mean;
    }
    let scale = x.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    scale
        * (0..3)
            .filter(|&i| w[i] > 0.0)
            .map(|i| w[i] * (x[i] / scale))
            .sum::<f64>()
}

/// Scales non-negative weights to sum to 1, dividing by the largest first so that the sum
/// stays finite for weights near `f64::MAX`; a row of zeros stays zeros.
fn scale_to_one(weights: &mut [f64]) {
    let largest = weights.iter().fold(0.0_f64, |m, &w| m.max(w));
    if largest > 0.0 {
        weights.iter_mut().for_each(|w| *w /= largest);
        let total: f64 = weights.iter().sum();
        weights.iter_mut().for_each(|w| *w /= total);
    }
}

/// Zeroes all but the `max_influences` largest weights (0: keeps all; the lower channel wins
/// a tie).
fn keep_largest(weights: &mut [f64], max_influences: usize) {
    if max_influences == 0 || weights.iter().filter(|&&w| w > 0.0).count() <= max_influences {
        return;
    }
    let mut order: Vec<usize> = (0..weights.len()).collect();
    order.sort_by(|&i, &j| weights[j].total_cmp(&weights[i]).then(i.cmp(&j)));
    for &c in &order[max_influences..] {
        weights[c] = 0.0;
    }
}

fn check_values(values: &[f64], channels: usize, n_a: usize, mode: TransferMode) -> Result<()> {
    let invalid = |reason: String| Error::InvalidParameter {
        name: "values_a",
        reason,
    };
    if channels == 0 {
        return Err(Error::InvalidParameter {
            name: "channels",
            reason: "must be at least 1".into(),
        });
    }
    if Some(values.len()) != n_a.checked_mul(channels) {
        return Err(invalid(format!(
            "has {} values, A has {n_a} vertices x {channels} channels",
            values.len()
        )));
    }
    if let Some(i) = values.iter().position(|x| !x.is_finite()) {
        return Err(invalid(format!(
            "vertex {} channel {} is {} (values must be finite)",
            i / channels,
            i % channels,
            values[i]
        )));
    }
    if let TransferMode::Weights { .. } = mode {
        if let Some(i) = values.iter().position(|&x| x < 0.0) {
            return Err(invalid(format!(
                "vertex {} channel {} is {} (skin weights must be non-negative)",
                i / channels,
                i % channels,
                values[i]
            )));
        }
    }
    Ok(())
}
