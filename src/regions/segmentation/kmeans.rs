//! Step 2 (paper, section 4): joint k-means on the stacked descriptors, weighted by area.

use super::*;
use crate::progress::Cancel;

/// Weighted k-means on the stacked rows of `a` and `b` (paper, section 4, step 2) with the
/// default distance [`DEFAULT_METRIC`] (the authors use city block with 3 restarts; pass
/// [`KMeansParams::metric`] to [`joint_kmeans_with`] for it). See [`joint_kmeans_with`].
pub fn joint_kmeans(
    a: MatRef<f64>,
    mass_a: &[f64],
    b: MatRef<f64>,
    mass_b: &[f64],
    k: usize,
    restarts: usize,
    seed: u64,
) -> JointClustering {
    joint_kmeans_with(
        a,
        mass_a,
        b,
        mass_b,
        &KMeansParams {
            k,
            restarts,
            seed,
            ..KMeansParams::default()
        },
    )
}

/// Weighted k-means on the stacked rows of `a` and `b`.
///
/// Each shape's masses are normalised to sum 1, so both shapes weigh the same and sampling
/// density does not matter; zero-mass rows are assigned but do not move centroids.
/// k-means++ seeding (`ChaCha8Rng::seed_from_u64(seed)`, probability `w_i D(x_i)` for city
/// block and `w_i D(x_i)^2` for Euclidean), Lloyd iterations until no label changes (at most
/// `max_iterations`), a cluster left without mass re-seeded at the point of largest
/// weighted cost, the best of `restarts` starts by weighted cost. City block updates each
/// centroid to the per-dimension weighted (lower) median, Euclidean to the weighted mean.
/// Ties go to the lowest centroid index; centroids are returned in lexicographic order.
/// The points are processed in a canonical order (sorted rows), so the result does not
/// depend on the row order of `a` or `b`, nor on the number of threads.
///
/// # Panics
/// When the column counts differ, a mass slice does not match, `k` or `restarts` is 0.
pub fn joint_kmeans_with(
    a: MatRef<f64>,
    mass_a: &[f64],
    b: MatRef<f64>,
    mass_b: &[f64],
    params: &KMeansParams,
) -> JointClustering {
    let points = Points::new(a, mass_a, b, mass_b);
    kmeans(&points, params, &Cancel::default()).expect("a default Cancel is never set")
}

/// The stacked points of both shapes in canonical order.
pub(super) struct Points {
    d: usize,
    n_a: usize,
    /// Canonical position -> stacked index (A's rows, then B's).
    order: Vec<u32>,
    /// Rows in canonical order, row-major.
    data: Vec<f64>,
    /// Weights in canonical order (each shape's sum to 1).
    pub(super) weight: Vec<f64>,
    /// The weights in units of 2^-40 ([`WEIGHT_SCALE`]): sums of them are exact, so weighted
    /// medians do not depend on the order of summation.
    int_weight: Vec<u64>,
    /// Per dimension, the positive-weight points in ascending value (for weighted medians).
    by_dim: Vec<DimOrder>,
}

/// Fixed-point scale of the integer weights used for weighted medians (a FAUST vertex has
/// a mass of about 2^-13, so the rounding is far below anything that matters).
const WEIGHT_SCALE: f64 = (1u64 << 40) as f64;

struct DimOrder {
    values: Vec<f64>,
    int_weights: Vec<u64>,
    positions: Vec<u32>,
    /// Index in this order of every canonical position (`u32::MAX`: not listed).
    rank: Vec<u32>,
}

impl Points {
    pub(super) fn new(a: MatRef<f64>, mass_a: &[f64], b: MatRef<f64>, mass_b: &[f64]) -> Points {
        assert_eq!(a.ncols(), b.ncols(), "joint k-means: column counts differ");
        assert_eq!(a.nrows(), mass_a.len(), "joint k-means: mass_a length");
        assert_eq!(b.nrows(), mass_b.len(), "joint k-means: mass_b length");
        let d = a.ncols();
        let (n_a, n_b) = (a.nrows(), b.nrows());
        let n = n_a + n_b;
        let mut stacked = vec![0.0; n * d];
        for j in 0..d {
            for i in 0..n_a {
                stacked[i * d + j] = a[(i, j)];
            }
            for i in 0..n_b {
                stacked[(n_a + i) * d + j] = b[(i, j)];
            }
        }
        let mut stacked_weight = normalised_weights(mass_a);
        stacked_weight.extend(normalised_weights(mass_b));
        let row = |s: usize| &stacked[s * d..(s + 1) * d];
        let mut order: Vec<u32> = (0..n as u32).collect();
        // Stable sort: identical points keep the stacked order, and they are interchangeable.
        order.par_sort_by(|&x, &y| {
            let (x, y) = (x as usize, y as usize);
            row(x)
                .iter()
                .zip(row(y))
                .map(|(p, q)| p.total_cmp(q))
                .find(|o| o.is_ne())
                .unwrap_or(std::cmp::Ordering::Equal)
                .then(stacked_weight[x].total_cmp(&stacked_weight[y]))
        });
        let mut data = Vec::with_capacity(n * d);
        for &s in &order {
            data.extend_from_slice(row(s as usize));
        }
        let weight: Vec<f64> = order.iter().map(|&s| stacked_weight[s as usize]).collect();
        let int_weight: Vec<u64> = weight
            .iter()
            .map(|&w| (w * WEIGHT_SCALE).round() as u64)
            .collect();
        let by_dim = (0..d)
            .into_par_iter()
            .map(|j| {
                // (order-preserving bits of the value, position): unique keys, so the
                // unstable sort is deterministic.
                let mut keyed: Vec<(u64, u32)> = (0..n as u32)
                    .filter(|&p| int_weight[p as usize] > 0)
                    .map(|p| (total_order_bits(data[p as usize * d + j]), p))
                    .collect();
                keyed.sort_unstable();
                let positions: Vec<u32> = keyed.into_iter().map(|(_, p)| p).collect();
                let mut rank = vec![u32::MAX; n];
                for (r, &p) in positions.iter().enumerate() {
                    rank[p as usize] = r as u32;
                }
                DimOrder {
                    values: positions
                        .iter()
                        .map(|&p| data[p as usize * d + j])
                        .collect(),
                    int_weights: positions.iter().map(|&p| int_weight[p as usize]).collect(),
                    positions,
                    rank,
                }
            })
            .collect();
        Points {
            d,
            n_a,
            order,
            data,
            weight,
            int_weight,
            by_dim,
        }
    }

    fn n(&self) -> usize {
        self.weight.len()
    }

    fn row(&self, p: usize) -> &[f64] {
        &self.data[p * self.d..(p + 1) * self.d]
    }
}

/// Bits of `x` whose unsigned order is `f64::total_cmp`'s order.
fn total_order_bits(x: f64) -> u64 {
    let bits = x.to_bits();
    if bits >> 63 == 1 {
        !bits
    } else {
        bits | (1 << 63)
    }
}

/// City-block distance, or squared Euclidean distance; stops early (returning something
/// `>= bound`) once the partial sum reaches `bound`.
#[inline]
fn distance_bounded(metric: KMeansMetric, x: &[f64], c: &[f64], bound: f64) -> f64 {
    let mut sum = 0.0;
    match metric {
        KMeansMetric::CityBlock => {
            for (chunk_x, chunk_c) in x.chunks(4).zip(c.chunks(4)) {
                for (p, q) in chunk_x.iter().zip(chunk_c) {
                    sum += (p - q).abs();
                }
                if sum >= bound {
                    return sum;
                }
            }
        }
        KMeansMetric::Euclidean => {
            for (chunk_x, chunk_c) in x.chunks(4).zip(c.chunks(4)) {
                for (p, q) in chunk_x.iter().zip(chunk_c) {
                    sum += (p - q) * (p - q);
                }
                if sum >= bound {
                    return sum;
                }
            }
        }
    }
    sum
}

/// Nearest centroid (lowest index on ties) and its distance; `skip` is left out.
#[inline]
pub(super) fn nearest(
    metric: KMeansMetric,
    x: &[f64],
    centroids: &[f64],
    d: usize,
    skip: usize,
) -> (u32, f64) {
    let mut best = (u32::MAX, f64::INFINITY);
    for (c, centroid) in centroids.chunks_exact(d).enumerate() {
        if c == skip {
            continue;
        }
        let dist = distance_bounded(metric, x, centroid, best.1);
        if dist < best.1 || best.0 == u32::MAX {
            best = (c as u32, dist);
        }
    }
    best
}

/// Draws an index with probability proportional to `scores` (None when they sum to 0).
fn sample(scores: &[f64], rng: &mut ChaCha8Rng) -> Option<usize> {
    let total: f64 = scores.iter().sum();
    if !(total > 0.0 && total.is_finite()) {
        return None;
    }
    let target = rng.random::<f64>() * total;
    let mut acc = 0.0;
    let mut last_positive = None;
    for (i, &s) in scores.iter().enumerate() {
        if s > 0.0 {
            acc += s;
            last_positive = Some(i);
            if acc > target {
                return Some(i);
            }
        }
    }
    last_positive
}

/// Weighted k-means with k-means++ seeding and `params.restarts` restarts (the best kept);
/// stops with [`crate::Error::Cancelled`] between Lloyd iterations once `cancel` is set.
pub(super) fn kmeans(
    points: &Points,
    params: &KMeansParams,
    cancel: &Cancel,
) -> crate::Result<JointClustering> {
    let (k, d, n) = (params.k, points.d, points.n());
    assert!(k >= 1, "joint k-means: k must be at least 1");
    assert!(
        params.restarts >= 1,
        "joint k-means: restarts must be at least 1"
    );
    let mut rng = ChaCha8Rng::seed_from_u64(params.seed);
    let mut best: Option<(f64, Vec<f64>, Vec<u32>)> = None;
    for _ in 0..params.restarts {
        cancel.check()?;
        let centroids = seed_centroids(points, k, params.metric, &mut rng);
        let (cost, centroids, labels) = lloyd(
            points,
            centroids,
            k,
            params.metric,
            params.max_iterations,
            cancel,
        );
        cancel.check()?;
        if best.as_ref().is_none_or(|(c, _, _)| cost < *c) {
            best = Some((cost, centroids, labels));
        }
    }
    let (cost, centroids, labels) = best.expect("at least one restart");
    // Centroids in lexicographic order, so cluster numbers mean something stable.
    let mut rank: Vec<usize> = (0..k).collect();
    rank.sort_by(|&x, &y| {
        centroids[x * d..(x + 1) * d]
            .iter()
            .zip(&centroids[y * d..(y + 1) * d])
            .map(|(p, q)| p.total_cmp(q))
            .find(|o| o.is_ne())
            .unwrap_or(std::cmp::Ordering::Equal)
            .then(x.cmp(&y))
    });
    let mut new_id = vec![0u32; k];
    for (new, &old) in rank.iter().enumerate() {
        new_id[old] = new as u32;
    }
    let mut stacked = vec![0u32; n];
    for (p, &s) in points.order.iter().enumerate() {
        stacked[s as usize] = new_id[labels[p] as usize];
    }
    let labels_b = stacked.split_off(points.n_a);
    Ok(JointClustering {
        labels_a: stacked,
        labels_b,
        centroids: Mat::from_fn(k, d, |c, j| centroids[rank[c] * d + j]),
        cost,
    })
}

/// k-means++ seeding (row-major k x d centroids).
fn seed_centroids(
    points: &Points,
    k: usize,
    metric: KMeansMetric,
    rng: &mut ChaCha8Rng,
) -> Vec<f64> {
    let d = points.d;
    let n = points.n();
    let mut centroids = Vec::with_capacity(k * d);
    let first = sample(&points.weight, rng).unwrap_or(0);
    centroids.extend_from_slice(points.row(first));
    let mut closest = vec![f64::INFINITY; n];
    for c in 1..=k {
        let newest = centroids[(c - 1) * d..c * d].to_vec();
        closest
            .par_chunks_mut(CHUNK)
            .enumerate()
            .for_each(|(chunk, out)| {
                for (i, slot) in out.iter_mut().enumerate() {
                    let p = chunk * CHUNK + i;
                    let dist = distance_bounded(metric, points.row(p), &newest, f64::INFINITY);
                    *slot = slot.min(dist);
                }
            });
        if c == k {
            break;
        }
        let scores: Vec<f64> = closest
            .iter()
            .zip(&points.weight)
            .map(|(&dist, &w)| w * dist)
            .collect();
        // All positive-weight points already coincide with a centroid: repeat the first.
        let next = sample(&scores, rng).unwrap_or(first);
        centroids.extend_from_slice(points.row(next));
    }
    centroids
}

/// Distance in the metric itself (city block, or Euclidean without the square), for the
/// triangle-inequality bounds.
#[inline]
fn metric_distance(metric: KMeansMetric, x: &[f64], c: &[f64]) -> f64 {
    match metric {
        KMeansMetric::CityBlock => distance_bounded(metric, x, c, f64::INFINITY),
        KMeansMetric::Euclidean => distance_bounded(metric, x, c, f64::INFINITY).sqrt(),
    }
}

/// Nearest centroid (lowest index on ties) with the metric distances to the nearest and the
/// second nearest.
#[inline]
fn two_nearest(metric: KMeansMetric, x: &[f64], centroids: &[f64], d: usize) -> (u32, f64, f64) {
    let (mut best, mut d1, mut d2) = (0u32, f64::INFINITY, f64::INFINITY);
    for (c, centroid) in centroids.chunks_exact(d).enumerate() {
        let dist = metric_distance(metric, x, centroid);
        if dist < d1 {
            d2 = d1;
            d1 = dist;
            best = c as u32;
        } else if dist < d2 {
            d2 = dist;
        }
    }
    (best, d1, d2)
}

/// Relative safety margin on the bounds, so that rounding in them never skips a point
/// whose nearest centroid changed (ties within it are recomputed exactly).
const BOUND_MARGIN: f64 = 1e-12;

/// Per-point state of Hamerly's accelerated Lloyd iteration: the label, an upper bound on
/// the distance to the assigned centroid and a lower bound on the distance to every other.
struct Assignment {
    labels: Vec<u32>,
    upper: Vec<f64>,
    lower: Vec<f64>,
}

impl Assignment {
    /// Exact nearest centroids of every point.
    fn new(points: &Points, centroids: &[f64], metric: KMeansMetric) -> Assignment {
        let n = points.n();
        let mut state = Assignment {
            labels: vec![0; n],
            upper: vec![0.0; n],
            lower: vec![0.0; n],
        };
        let d = points.d;
        state
            .labels
            .par_chunks_mut(CHUNK)
            .zip(state.upper.par_chunks_mut(CHUNK))
            .zip(state.lower.par_chunks_mut(CHUNK))
            .enumerate()
            .for_each(|(chunk, ((labels, upper), lower))| {
                for i in 0..labels.len() {
                    let p = chunk * CHUNK + i;
                    let (c, d1, d2) = two_nearest(metric, points.row(p), centroids, d);
                    labels[i] = c;
                    upper[i] = d1;
                    lower[i] = d2;
                }
            });
        state
    }

    /// Re-assigns after the centroids moved by `moves` (metric distances); a point is
    /// re-examined only when its bounds no longer prove its label (Hamerly 2010). Returns
    /// the points that changed cluster as (position, old, new), by position.
    fn update(
        &mut self,
        points: &Points,
        centroids: &[f64],
        metric: KMeansMetric,
        moves: &[f64],
    ) -> Vec<(u32, u32, u32)> {
        let (d, k) = (points.d, moves.len());
        // Half the distance from every centroid to its nearest other centroid.
        let half_gap: Vec<f64> = (0..k)
            .map(|c| {
                (0..k)
                    .filter(|&o| o != c)
                    .map(|o| {
                        metric_distance(
                            metric,
                            &centroids[c * d..(c + 1) * d],
                            &centroids[o * d..(o + 1) * d],
                        )
                    })
                    .fold(f64::INFINITY, f64::min)
                    * 0.5
            })
            .collect();
        let (mut first, mut second) = ((0usize, 0.0f64), 0.0f64);
        for (c, &m) in moves.iter().enumerate() {
            if m > first.1 {
                second = first.1;
                first = (c, m);
            } else if m > second {
                second = m;
            }
        }
        self.labels
            .par_chunks_mut(CHUNK)
            .zip(self.upper.par_chunks_mut(CHUNK))
            .zip(self.lower.par_chunks_mut(CHUNK))
            .enumerate()
            .map(|(chunk, ((labels, upper), lower))| {
                let mut moved = Vec::new();
                for i in 0..labels.len() {
                    let p = chunk * CHUNK + i;
                    let a = labels[i] as usize;
                    upper[i] += moves[a];
                    lower[i] -= if a == first.0 { second } else { first.1 };
                    let bound = half_gap[a].max(lower[i]);
                    if upper[i] * (1.0 + BOUND_MARGIN) < bound {
                        continue;
                    }
                    let x = points.row(p);
                    upper[i] = metric_distance(metric, x, &centroids[a * d..(a + 1) * d]);
                    if upper[i] * (1.0 + BOUND_MARGIN) < bound {
                        continue;
                    }
                    let (c, d1, d2) = two_nearest(metric, x, centroids, d);
                    if c as usize != a {
                        moved.push((p as u32, a as u32, c));
                    }
                    labels[i] = c;
                    upper[i] = d1;
                    lower[i] = d2;
                }
                moved
            })
            .collect::<Vec<_>>()
            .concat()
    }
}

/// Lloyd iterations from `centroids`; returns (weighted cost, centroids, labels), the
/// labels being the nearest centroids of the returned centroids.
fn lloyd(
    points: &Points,
    mut centroids: Vec<f64>,
    k: usize,
    metric: KMeansMetric,
    max_iterations: usize,
    cancel: &Cancel,
) -> (f64, Vec<f64>, Vec<u32>) {
    let d = points.d;
    let mut state = Assignment::new(points, &centroids, metric);
    let mut medians: Option<Medians> = None;
    let mut moved: Vec<(u32, u32, u32)> = Vec::new();
    for _ in 0..max_iterations {
        if cancel.check().is_err() {
            break; // the caller sees the cancel and drops this result
        }
        let previous = centroids.clone();
        update(
            points,
            &mut centroids,
            k,
            metric,
            &state,
            &moved,
            &mut medians,
        );
        let moves: Vec<f64> = (0..k)
            .map(|c| {
                metric_distance(
                    metric,
                    &previous[c * d..(c + 1) * d],
                    &centroids[c * d..(c + 1) * d],
                )
            })
            .collect();
        moved = state.update(points, &centroids, metric, &moves);
        if moved.is_empty() {
            break;
        }
    }
    // Exact cost of the final assignment (squared distances for Euclidean).
    let labels = state.labels;
    let cost: Vec<f64> = labels
        .par_chunks(CHUNK)
        .enumerate()
        .map(|(chunk, labels)| {
            let mut sum = 0.0;
            for (i, &c) in labels.iter().enumerate() {
                let p = chunk * CHUNK + i;
                let c = c as usize;
                sum += points.weight[p]
                    * distance_bounded(
                        metric,
                        points.row(p),
                        &centroids[c * d..(c + 1) * d],
                        f64::INFINITY,
                    );
            }
            sum
        })
        .collect();
    (cost.iter().sum(), centroids, labels)
}

/// Weighted (lower) medians of every cluster in every dimension, kept up to date as points
/// change cluster: per dimension and cluster, the index in the sorted order of the median
/// point and the integer weight of the cluster's points up to and including it.
struct Medians {
    /// `at[j][c]`: index of cluster c's median in dimension j's order (`u32::MAX`: none).
    at: Vec<Vec<u32>>,
    /// `below[j][c]`: weight of cluster c's points at or before `at[j][c]`.
    below: Vec<Vec<u64>>,
}

impl Medians {
    /// From scratch: one pass over every dimension's order.
    fn new(points: &Points, labels: &[u32], totals: &[u64]) -> Medians {
        let k = totals.len();
        let (at, below): (Vec<Vec<u32>>, Vec<Vec<u64>>) = points
            .by_dim
            .par_iter()
            .map(|dim| {
                let mut at = vec![u32::MAX; k];
                let mut acc = vec![0u64; k];
                let mut left = totals.iter().filter(|&&t| t > 0).count();
                for (r, (&p, &w)) in dim.positions.iter().zip(&dim.int_weights).enumerate() {
                    if left == 0 {
                        break;
                    }
                    let c = labels[p as usize] as usize;
                    if at[c] != u32::MAX {
                        continue;
                    }
                    acc[c] += w;
                    if 2 * acc[c] >= totals[c] && totals[c] > 0 {
                        at[c] = r as u32;
                        left -= 1;
                    }
                }
                (at, acc)
            })
            .unzip();
        Medians { at, below }
    }

    /// After the points in `moved` (position, old, new) changed cluster, moves every
    /// median along its order to where the cumulative weight reaches half the cluster's.
    /// Returns false when some cluster has no median to move from (then rebuild).
    fn update(
        &mut self,
        points: &Points,
        labels: &[u32],
        totals: &[u64],
        moved: &[(u32, u32, u32)],
    ) -> bool {
        let k = totals.len();
        let mut touched = vec![false; k];
        for &(_, old, new) in moved {
            touched[old as usize] = true;
            touched[new as usize] = true;
        }
        if (0..k).any(|c| touched[c] && totals[c] > 0 && self.at[0][c] == u32::MAX) {
            return false;
        }
        self.at
            .par_iter_mut()
            .zip(self.below.par_iter_mut())
            .zip(points.by_dim.par_iter())
            .for_each(|((at, below), dim)| {
                for &(p, old, new) in moved {
                    let r = dim.rank[p as usize];
                    if r == u32::MAX {
                        continue; // zero weight
                    }
                    let w = dim.int_weights[r as usize];
                    if at[old as usize] != u32::MAX && r <= at[old as usize] {
                        below[old as usize] -= w;
                    }
                    if at[new as usize] != u32::MAX && r <= at[new as usize] {
                        below[new as usize] += w;
                    }
                }
                for c in (0..k).filter(|&c| touched[c]) {
                    if totals[c] == 0 {
                        at[c] = u32::MAX;
                        below[c] = 0;
                        continue;
                    }
                    let member = |r: usize| labels[dim.positions[r] as usize] as usize == c;
                    let mut r = at[c] as usize;
                    // Forward until half the weight is reached (the cluster's last point
                    // reaches all of it).
                    while 2 * below[c] < totals[c] {
                        r += 1;
                        while !member(r) {
                            r += 1;
                        }
                        below[c] += dim.int_weights[r];
                    }
                    // Backward while the previous point of the cluster still reaches half.
                    loop {
                        let own = if member(r) { dim.int_weights[r] } else { 0 };
                        let before = below[c] - own;
                        if 2 * before < totals[c] {
                            break;
                        }
                        let mut q = r;
                        while q > 0 && !member(q - 1) {
                            q -= 1;
                        }
                        // Points of the cluster before r weigh `before` >= half > 0, so a
                        // previous one exists.
                        r = q - 1;
                        below[c] = before;
                    }
                    at[c] = r as u32;
                }
            });
        true
    }

    /// The median value of cluster c in dimension j.
    fn value(&self, points: &Points, j: usize, c: usize) -> f64 {
        points.by_dim[j].values[self.at[j][c] as usize]
    }
}

/// Centroid update: weighted (lower) medians for city block, kept up to date from the
/// points `moved` since the last update; weighted means for Euclidean. Clusters without
/// weight are re-seeded at the points of largest weighted distance bound (ties: lowest
/// position).
fn update(
    points: &Points,
    centroids: &mut [f64],
    k: usize,
    metric: KMeansMetric,
    state: &Assignment,
    moved: &[(u32, u32, u32)],
    medians: &mut Option<Medians>,
) {
    let d = points.d;
    let labels = &state.labels;
    let mut totals = vec![0u64; k];
    let mut cluster_weight = vec![0.0; k];
    for ((&c, &w), &iw) in labels.iter().zip(&points.weight).zip(&points.int_weight) {
        totals[c as usize] += iw;
        cluster_weight[c as usize] += w;
    }
    match metric {
        KMeansMetric::CityBlock => {
            let current = match medians.take() {
                Some(mut m) => {
                    if m.update(points, labels, &totals, moved) {
                        m
                    } else {
                        Medians::new(points, labels, &totals)
                    }
                }
                None => Medians::new(points, labels, &totals),
            };
            for c in (0..k).filter(|&c| totals[c] > 0) {
                for j in 0..d {
                    centroids[c * d + j] = current.value(points, j, c);
                }
            }
            *medians = Some(current);
        }
        KMeansMetric::Euclidean => {
            let mut sums = vec![0.0; k * d];
            for (p, (&w, &c)) in points.weight.iter().zip(labels.iter()).enumerate() {
                let c = c as usize;
                if w > 0.0 {
                    for (s, x) in sums[c * d..(c + 1) * d].iter_mut().zip(points.row(p)) {
                        *s += w * x;
                    }
                }
            }
            for c in (0..k).filter(|&c| cluster_weight[c] > 0.0) {
                for j in 0..d {
                    centroids[c * d + j] = sums[c * d + j] / cluster_weight[c];
                }
            }
        }
    }
    let empty: Vec<usize> = (0..k)
        .filter(|&c| !(cluster_weight[c] > 0.0) || totals[c] == 0)
        .collect();
    if empty.is_empty() {
        return;
    }
    // Re-seed at the points contributing most to the cost (ties: lowest position).
    let bound = &state.upper;
    let mut candidates: Vec<usize> = (0..points.n())
        .filter(|&p| points.int_weight[p] > 0 && bound[p] > 0.0)
        .collect();
    candidates.sort_by(|&x, &y| {
        (points.weight[y] * bound[y])
            .total_cmp(&(points.weight[x] * bound[x]))
            .then(x.cmp(&y))
    });
    for (c, &p) in empty.iter().zip(&candidates) {
        centroids[c * d..(c + 1) * d].copy_from_slice(points.row(p));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::regions::segmentation::tests::column;

    #[test]
    fn weighted_median_update_picks_the_lower_weighted_median() {
        // One cluster, one dimension: values 0, 1, 2, 10 with weights 0.1, 0.1, 0.3, 0.5
        // (each shape's weights sum to 1, so use shape A only and an empty B).
        let a = column(&[10.0, 0.0, 2.0, 1.0]);
        let b = Mat::<f64>::zeros(0, 1);
        let points = Points::new(a.as_ref(), &[0.5, 0.1, 0.3, 0.1], b.as_ref(), &[]);
        let state = Assignment {
            labels: vec![0u32; 4],
            upper: vec![0.0; 4],
            lower: vec![0.0; 4],
        };
        let mut centroid = vec![0.0];
        update(
            &points,
            &mut centroid,
            1,
            KMeansMetric::CityBlock,
            &state,
            &[],
            &mut None,
        );
        // Cumulative weights 0.1, 0.2, 0.5 (reaches half at value 2).
        assert_eq!(centroid[0], 2.0);
        update(
            &points,
            &mut centroid,
            1,
            KMeansMetric::Euclidean,
            &state,
            &[],
            &mut None,
        );
        assert!((centroid[0] - (0.1 * 0.0 + 0.1 * 1.0 + 0.3 * 2.0 + 0.5 * 10.0)).abs() < 1e-12);
    }

    #[test]
    fn incremental_medians_equal_medians_from_scratch() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let (n, d, k) = (600, 3, 5);
        // Few distinct values (ties) and some zero masses.
        let a = Mat::from_fn(n, d, |_, _| (rng.random::<f64>() * 40.0).floor());
        let mass: Vec<f64> = (0..n)
            .map(|i| {
                if i % 17 == 0 {
                    0.0
                } else {
                    rng.random::<f64>()
                }
            })
            .collect();
        let b = Mat::<f64>::zeros(0, d);
        let points = Points::new(a.as_ref(), &mass, b.as_ref(), &[]);
        let totals_of = |labels: &[u32]| {
            let mut totals = vec![0u64; k];
            for (&c, &w) in labels.iter().zip(&points.int_weight) {
                totals[c as usize] += w;
            }
            totals
        };
        let mut labels: Vec<u32> = (0..n).map(|_| rng.random_range(0..k as u32)).collect();
        let mut medians = Medians::new(&points, &labels, &totals_of(&labels));
        for round in 0..30 {
            let mut moved = Vec::new();
            for _ in 0..(1 + round * 7) {
                let p = rng.random_range(0..n);
                let new = rng.random_range(0..k as u32);
                if new != labels[p] && !moved.iter().any(|&(q, _, _)| q == p as u32) {
                    moved.push((p as u32, labels[p], new));
                    labels[p] = new;
                }
            }
            moved.sort_unstable();
            let totals = totals_of(&labels);
            assert!(medians.update(&points, &labels, &totals, &moved));
            let fresh = Medians::new(&points, &labels, &totals);
            for j in 0..d {
                for c in 0..k {
                    assert_eq!(medians.at[j][c], fresh.at[j][c], "round {round}");
                    assert_eq!(medians.below[j][c], fresh.below[j][c]);
                }
            }
        }
    }

    #[test]
    fn empty_clusters_are_reseeded_at_the_costliest_point() {
        let a = column(&[0.0, 1.0, 5.0, 9.0]);
        let b = Mat::<f64>::zeros(0, 1);
        let points = Points::new(a.as_ref(), &[0.25; 4], b.as_ref(), &[]);
        // Everything in cluster 0 (centroid at 0); cluster 1 empty.
        let state = Assignment {
            labels: vec![0u32; 4],
            upper: vec![0.0, 1.0, 5.0, 9.0],
            lower: vec![f64::INFINITY; 4],
        };
        let mut centroids = vec![0.0, 100.0];
        update(
            &points,
            &mut centroids,
            2,
            KMeansMetric::CityBlock,
            &state,
            &[],
            &mut None,
        );
        assert_eq!(centroids[1], 9.0);
    }
}
