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
            mean.fill(0.0);
            for (&v, &w) in point.vertices.iter().zip(&point.weights) {
                if w > 0.0 {
                    mean.iter_mut().zip(row(v)).for_each(|(m, x)| *m += w * x);
                }
            }
            if let TransferMode::Weights { max_influences } = mode {
                keep_largest(&mut mean, max_influences);
                let total: f64 = mean.iter().sum();
                if total > 0.0 {
                    mean.iter_mut().for_each(|w| *w /= total);
                }
            }
            out.extend_from_slice(&mean);
        }
        Ok(out)
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
