//! Step 1 (paper, section 4): rank alignment of the descriptors of both shapes.

use super::*;

/// Maps every column of `other` onto the values of `reference` at the same area-weighted
/// rank (paper, section 4, step 1): `T(beta) = alpha` with
/// `Area_ref(f <= alpha) = Area_other(g <= beta)`.
///
/// The rank of a value is the mid-rank `(mass strictly below + mass of its tie group / 2) /
/// total mass`; the reference's tie groups are knots at their mid-ranks and ranks between
/// knots are interpolated linearly (ranks outside the knots take the extreme values).
/// Equal values get equal outputs, a vertex of double mass counts double, zero-mass vertices
/// of `other` get a value too, and the result does not depend on the vertex order. A
/// column that is an increasing function of the reference (same masses) gives back the
/// reference's values exactly. Masses are clamped at 0; all-zero masses count as uniform.
///
/// # Panics
/// When the column counts differ or a mass slice does not match its matrix's rows.
pub fn rank_align(
    reference: MatRef<f64>,
    reference_mass: &[f64],
    other: MatRef<f64>,
    other_mass: &[f64],
) -> Mat<f64> {
    assert_eq!(
        reference.ncols(),
        other.ncols(),
        "rank_align: column counts differ"
    );
    assert_eq!(
        reference.nrows(),
        reference_mass.len(),
        "rank_align: reference mass"
    );
    assert_eq!(other.nrows(), other_mass.len(), "rank_align: other mass");
    let ref_w = normalised_weights(reference_mass);
    let other_w = normalised_weights(other_mass);
    let columns: Vec<Vec<f64>> = (0..other.ncols())
        .into_par_iter()
        .map(|j| {
            let ref_values: Vec<f64> = (0..reference.nrows()).map(|i| reference[(i, j)]).collect();
            let values: Vec<f64> = (0..other.nrows()).map(|i| other[(i, j)]).collect();
            align_column(&ref_values, &ref_w, &values, &other_w)
        })
        .collect();
    Mat::from_fn(other.nrows(), other.ncols(), |i, j| columns[j][i])
}

/// Weights clamped at 0 and normalised to sum 1 (uniform when they sum to 0 or are not
/// finite).
pub(super) fn normalised_weights(mass: &[f64]) -> Vec<f64> {
    let clean: Vec<f64> = mass
        .iter()
        .map(|&m| if m > 0.0 && m.is_finite() { m } else { 0.0 })
        .collect();
    // Summed in sorted order, so the total does not depend on the vertex order.
    let mut sorted = clean.clone();
    sorted.sort_by(f64::total_cmp);
    let total: f64 = sorted.iter().sum();
    if total > 0.0 && total.is_finite() {
        clean.iter().map(|m| m / total).collect()
    } else {
        vec![1.0 / mass.len().max(1) as f64; mass.len()]
    }
}

/// Tie groups of `values` in ascending order: (value, mid-rank, members).
fn tie_groups(values: &[f64], weights: &[f64]) -> Vec<(f64, f64, Vec<usize>)> {
    let mut order: Vec<usize> = (0..values.len()).collect();
    // (value, weight) orders ties canonically, so sums do not depend on the vertex order.
    order.sort_by(|&x, &y| {
        values[x]
            .total_cmp(&values[y])
            .then(weights[x].total_cmp(&weights[y]))
            .then(x.cmp(&y))
    });
    let mut groups = Vec::new();
    let mut below = 0.0;
    let mut start = 0;
    while start < order.len() {
        let value = values[order[start]];
        let mut end = start;
        let mut mass = 0.0;
        while end < order.len() && values[order[end]].total_cmp(&value).is_eq() {
            mass += weights[order[end]];
            end += 1;
        }
        groups.push((value, below + 0.5 * mass, order[start..end].to_vec()));
        below += mass;
        start = end;
    }
    groups
}

fn align_column(ref_values: &[f64], ref_w: &[f64], values: &[f64], weights: &[f64]) -> Vec<f64> {
    // Knots: the reference's tie groups of positive mass at their mid-ranks.
    let knots: Vec<(f64, f64)> = tie_groups(ref_values, ref_w)
        .into_iter()
        .filter(|(_, _, members)| members.iter().any(|&i| ref_w[i] > 0.0))
        .map(|(value, rank, _)| (rank, value))
        .collect();
    let mut out = vec![0.0; values.len()];
    let Some((&first, &last)) = knots.first().zip(knots.last()) else {
        return out;
    };
    let mut knot = 0;
    for (_, rank, members) in tie_groups(values, weights) {
        // Ranks ascend along the groups, so the knot search only moves forward.
        while knot + 1 < knots.len() && knots[knot + 1].0 <= rank {
            knot += 1;
        }
        let mapped = if rank <= first.0 {
            first.1
        } else if rank >= last.0 {
            last.1
        } else {
            let (r0, v0) = knots[knot];
            let (r1, v1) = knots[knot + 1];
            if rank == r0 {
                v0
            } else {
                v0 + (v1 - v0) * (rank - r0) / (r1 - r0)
            }
        };
        for i in members {
            out[i] = mapped;
        }
    }
    out
}
