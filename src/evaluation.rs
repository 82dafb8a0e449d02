//! Scores of a region correspondence against a ground-truth vertex map (docs/design.md, step 15,
//! paper section 6.2).
//!
//! Ground truth is a list of vertex pairs `(vertex of A, vertex of B)` (every vertex for
//! registered shapes, a sample for remeshed benchmarks). A pair counts as correct when B's
//! vertex lies in a region matched to A's vertex's region; pairs are weighted by the area of
//! A's vertex. Large regions make accuracy easy, so the coverage (how much of B's area a
//! vertex of A is matched to) is always reported beside it.

/// Scores of one correspondence.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct RegionScores {
    /// Accuracy of the symmetric (many-to-many) matches.
    pub symmetric: f64,
    /// Accuracy of the one-to-one matches against the ground truth.
    pub one_to_one: f64,
    /// Accuracy of the one-to-one matches allowing a global left/right flip (the better of
    /// the ground truth and the ground truth composed with the mirror map); None without a
    /// mirror map.
    pub one_to_one_flip: Option<f64>,
    /// Area-weighted mean fraction of B's area that a vertex of A is matched to
    /// (symmetric matches; unmatched vertices count 0).
    pub coverage: f64,
    /// Area fraction of A in regions without any symmetric match.
    pub unmatched: f64,
    /// Number of regions of A.
    pub n_regions_a: usize,
    /// Number of regions of B.
    pub n_regions_b: usize,
}

/// Area-weighted fraction of ground-truth pairs `(x, y)` with `y`'s region matched to `x`'s.
pub fn region_accuracy(
    labels_a: &[u32],
    labels_b: &[u32],
    mass_a: &[f64],
    n_regions_a: usize,
    n_regions_b: usize,
    matches: &[(u32, u32)],
    ground_truth: &[(u32, u32)],
) -> f64 {
    let mut matched = vec![false; n_regions_a * n_regions_b];
    for &(i, j) in matches {
        matched[i as usize * n_regions_b + j as usize] = true;
    }
    let (mut right, mut total) = (0.0, 0.0);
    for &(x, y) in ground_truth {
        let w = mass_a[x as usize];
        total += w;
        let (ra, rb) = (labels_a[x as usize] as usize, labels_b[y as usize] as usize);
        if matched[ra * n_regions_b + rb] {
            right += w;
        }
    }
    if total > 0.0 {
        right / total
    } else {
        0.0
    }
}

/// [`score`] of a computed correspondence (its regions and both kinds of matches), with the
/// vertex masses of A and B.
pub fn score_correspondence(
    result: &crate::pipeline::Correspondence,
    mass_a: &[f64],
    mass_b: &[f64],
    ground_truth: &[(u32, u32)],
    ground_truth_flipped: Option<&[(u32, u32)]>,
) -> RegionScores {
    score(
        result.regions_a(),
        result.regions_b(),
        mass_a,
        mass_b,
        &result.matches,
        &result.matches_one_to_one,
        ground_truth,
        ground_truth_flipped,
    )
}

/// All scores of a correspondence. `mirror_b[v]` is the mirror image of B's vertex v.
#[allow(clippy::too_many_arguments)]
pub fn score(
    labels_a: &[u32],
    labels_b: &[u32],
    mass_a: &[f64],
    mass_b: &[f64],
    matches: &[(u32, u32)],
    matches_one_to_one: &[(u32, u32)],
    ground_truth: &[(u32, u32)],
    ground_truth_flipped: Option<&[(u32, u32)]>,
) -> RegionScores {
    let n_a = labels_a.iter().map(|&r| r as usize + 1).max().unwrap_or(0);
    let n_b = labels_b.iter().map(|&r| r as usize + 1).max().unwrap_or(0);
    let accuracy = |m: &[(u32, u32)], gt: &[(u32, u32)]| {
        region_accuracy(labels_a, labels_b, mass_a, n_a, n_b, m, gt)
    };
    let symmetric = accuracy(matches, ground_truth);
    let one_to_one = accuracy(matches_one_to_one, ground_truth);
    let one_to_one_flip =
        ground_truth_flipped.map(|flipped| one_to_one.max(accuracy(matches_one_to_one, flipped)));

    let mut area_b = vec![0.0; n_b];
    for (v, &r) in labels_b.iter().enumerate() {
        area_b[r as usize] += mass_b[v];
    }
    let total_b: f64 = area_b.iter().sum();
    let mut matched_area = vec![0.0; n_a];
    for &(i, j) in matches {
        matched_area[i as usize] += area_b[j as usize] / total_b.max(f64::MIN_POSITIVE);
    }
    let (mut coverage, mut unmatched, mut total_a) = (0.0, 0.0, 0.0);
    for (v, &r) in labels_a.iter().enumerate() {
        let w = mass_a[v];
        total_a += w;
        coverage += w * matched_area[r as usize];
        if matched_area[r as usize] == 0.0 {
            unmatched += w;
        }
    }
    let total_a = total_a.max(f64::MIN_POSITIVE);
    RegionScores {
        symmetric,
        one_to_one,
        one_to_one_flip,
        coverage: coverage / total_a,
        unmatched: unmatched / total_a,
        n_regions_a: n_a,
        n_regions_b: n_b,
    }
}

/// Geodesic distances on A between pairs of its vertices `(source, target)`, divided by
/// `sqrt(area of A)` (the paper's normalisation): one heat-method solve per distinct
/// source, so every map scored against the same ground truth shares the solves.
pub fn normalised_geodesic_distances(
    heat_a: &crate::geodesic::HeatGeodesics,
    input_area_a: f64,
    pairs: &[(u32, u32)],
) -> crate::Result<Vec<f64>> {
    let mut order: Vec<usize> = (0..pairs.len()).collect();
    order.sort_by_key(|&i| pairs[i].0);
    let scale = 1.0 / input_area_a.sqrt();
    let mut out = vec![0.0; pairs.len()];
    let mut start = 0;
    while start < order.len() {
        let source = pairs[order[start]].0;
        let end = start
            + order[start..]
                .iter()
                .take_while(|&&i| pairs[i].0 == source)
                .count();
        let field = heat_a.distances(&[source])?;
        for &i in &order[start..end] {
            out[i] = field[pairs[i].1 as usize] * scale;
        }
        start = end;
    }
    Ok(out)
}

/// Geodesic errors of pointwise maps from B to A against ground-truth pairs
/// `(vertex of A, vertex of B)`: for each map and each pair `(x, y)`, the normalised
/// geodesic distance on A from `x` to `p2p_ba[y]`.
pub fn pointwise_errors(
    heat_a: &crate::geodesic::HeatGeodesics,
    input_area_a: f64,
    truth: &[(u32, u32)],
    maps_ba: &[&[u32]],
) -> crate::Result<Vec<Vec<f64>>> {
    let mut pairs = Vec::with_capacity(truth.len() * maps_ba.len());
    for map in maps_ba {
        if let Some(&(_, y)) = truth.iter().find(|&&(_, y)| y as usize >= map.len()) {
            return Err(crate::Error::InvalidParameter {
                name: "map",
                reason: format!(
                    "the map has {} entries but the ground truth names vertex {y} of B",
                    map.len()
                ),
            });
        }
        pairs.extend(truth.iter().map(|&(x, y)| (x, map[y as usize])));
    }
    let distances = normalised_geodesic_distances(heat_a, input_area_a, &pairs)?;
    Ok(distances
        .chunks(truth.len().max(1))
        .map(|c| c.to_vec())
        .take(maps_ba.len())
        .collect())
}

/// Summary of one map's geodesic errors.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ErrorSummary {
    /// Mean normalised geodesic error.
    pub mean: f64,
    /// Fraction of pairs with error at most 0.05.
    pub within_005: f64,
    /// Fraction of pairs with error at most 0.10.
    pub within_010: f64,
}

impl ErrorSummary {
    /// Summary of one map's normalised geodesic errors (all zeros for none).
    pub fn of(errors: &[f64]) -> ErrorSummary {
        let n = errors.len().max(1) as f64;
        let within = |t: f64| errors.iter().filter(|&&e| e <= t).count() as f64 / n;
        ErrorSummary {
            mean: errors.iter().sum::<f64>() / n,
            within_005: within(0.05),
            within_010: within(0.10),
        }
    }
}

/// The cumulative error curve: for each threshold, the fraction of errors at most it.
pub fn error_curve(errors: &[f64], thresholds: &[f64]) -> Vec<f64> {
    let mut sorted = errors.to_vec();
    sorted.sort_by(f64::total_cmp);
    let n = sorted.len().max(1) as f64;
    thresholds
        .iter()
        .map(|&t| sorted.partition_point(|&e| e <= t) as f64 / n)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accuracy_counts_area_of_pairs_landing_in_matched_regions() {
        // A: 4 vertices in regions 0,0,1,1; B: regions 1,1,0,0 (swapped); identity truth.
        let labels_a = [0, 0, 1, 1];
        let labels_b = [1, 1, 0, 0];
        let mass = [0.1, 0.2, 0.3, 0.4];
        let truth: Vec<(u32, u32)> = (0..4).map(|i| (i, i)).collect();
        let right = [(0, 1), (1, 0)];
        assert_eq!(
            region_accuracy(&labels_a, &labels_b, &mass, 2, 2, &right, &truth),
            1.0
        );
        let half = [(0, 1)];
        let acc = region_accuracy(&labels_a, &labels_b, &mass, 2, 2, &half, &truth);
        assert!((acc - 0.3).abs() < 1e-12);
        let wrong = [(0, 0), (1, 1)];
        assert_eq!(
            region_accuracy(&labels_a, &labels_b, &mass, 2, 2, &wrong, &truth),
            0.0
        );
    }

    #[test]
    fn coverage_and_unmatched() {
        let labels_a = [0, 0, 1, 1];
        let labels_b = [0, 0, 1, 1];
        let mass = [0.25; 4];
        let truth: Vec<(u32, u32)> = (0..4).map(|i| (i, i)).collect();
        // Region 0 matched to both regions of B, region 1 unmatched.
        let s = score(
            &labels_a,
            &labels_b,
            &mass,
            &mass,
            &[(0, 0), (0, 1)],
            &[(0, 0)],
            &truth,
            None,
        );
        assert!((s.coverage - 0.5).abs() < 1e-12);
        assert!((s.unmatched - 0.5).abs() < 1e-12);
        assert!((s.symmetric - 0.5).abs() < 1e-12);
        assert_eq!(s.one_to_one_flip, None);
    }
}
