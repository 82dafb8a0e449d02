//! Joint segmentation of two shapes and their shape graphs (paper, section 4; docs/design.md,
//! steps 6-9).
//!
//! 1. [`rank_align`]: every descriptor column of shape B is mapped onto the values of shape A
//!    at the same area-weighted rank (paper step 1).
//! 2. [`joint_kmeans`]: k-means on the stacked descriptors of both shapes, weighted by vertex
//!    area so that sampling density does not matter (paper step 2). Euclidean by default,
//!    city block (the authors') as an option: [`DEFAULT_METRIC`] says what was measured.
//! 3. [`shape_graph`]: a node for every connected region of every cluster, an edge from a
//!    region to every region its expanded region meets (grown over the vertices whose
//!    second nearest centroid is the region's, [`RegionExpansion`]) (paper step 3), with
//!    tiny fragments merged into a neighbour ([`DEFAULT_MIN_REGION_AREA`]).
//! 4. [`segment_pair`]: steps 1-3 for every k in a range, keeping the k whose two graphs have
//!    the most similar node-degree histograms (paper step 5).
//!
//! Everything is deterministic and independent of the number of threads: k-means works on
//! the points in a canonical order (sorted by descriptor value), so the result does not even
//! depend on the order of the input vertices.

use std::collections::{BTreeMap, HashMap};

use faer::{Mat, MatRef};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use crate::regions::graph::{ShapeGraph, UNREACHABLE};
use crate::shape::{DisjointSets, Shape};
use crate::{Error, Result};

/// Points per parallel work item. Fixed, so that nothing depends on the number of threads.
const CHUNK: usize = 1024;

/// Weights of the node degrees in the degree-histogram difference, in tenths: degree 1
/// counts 0.3 and degree 2 counts 0.2 (the authors' release), every other degree 1.0.
/// Integers so that ties are exact.
fn degree_weight_tenths(degree: usize) -> u64 {
    match degree {
        1 => 3,
        2 => 2,
        _ => 10,
    }
}

// ---------------------------------------------------------------------------------------
// Parameters and results
// ---------------------------------------------------------------------------------------

/// Distance of the joint k-means, also used for the nearest and second-nearest centroid
/// tests of the shape graph.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum KMeansMetric {
    /// City-block (L1) distance with weighted-median centroids: the authors' choice.
    CityBlock,
    /// Euclidean distance (squared distances in the cost) with weighted-mean centroids:
    /// the default ([`DEFAULT_METRIC`]).
    #[default]
    Euclidean,
}

/// Default k-means distance: Euclidean. Measured against the authors' city block on FAUST
/// (`tests/segmentation.rs`, `faust_metric_comparison` and `faust_figures`): the share of
/// A's area whose corresponding point on B lies in a region of the same joint cluster was
/// 0.975 vs 0.965 on 12 same-person pairs and 0.933 vs 0.913 on 12 different-person pairs
/// with the chosen k, higher at k = 5 on all of 5 pairs measured per k, and 0.804 vs 0.779
/// on point clouds with 1% noise, with about as many regions (18.6 vs 20.2 per shape).
pub const DEFAULT_METRIC: KMeansMetric = KMeansMetric::Euclidean;

/// How ties between k values with the same degree-histogram difference are broken.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum KTieBreak {
    /// The smallest k wins (docs/decisions.md, "k tie-break": accuracy falls as k grows; k = 5 was then
    /// chosen in 90 of 94 pairs).
    #[default]
    SmallestK,
    /// The authors' tie-break first: the sorted hop distances from the most central node
    /// of each graph, compared entry by entry; then the smallest k.
    HopDistancesThenSmallestK,
}

/// Which vertices the expanded region `R*` of a region `R` of cluster `c` may grow over.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum RegionExpansion {
    /// `R` plus the vertices of other clusters whose second nearest centroid is `c` (the
    /// authors' release; docs/decisions.md, "Region expansion"). Graphs follow the shape's structure: on a
    /// star, body - limb middle - limb tip; on FAUST bodies, trees (16-25 nodes, one edge
    /// fewer).
    #[default]
    SecondNearestBand,
    /// The paper's wording: every vertex whose first or second nearest centroid is `c`,
    /// other regions of cluster `c` included. Clusters in the middle of the descriptor
    /// range are everybody's second nearest, so their expanded regions spread over much of
    /// the shape and join many nodes (a star's limb middles are joined to every node; FAUST
    /// bodies get 41-54 edges on 16-25 nodes).
    FirstOrSecondNearest,
}

/// Parameters of [`shape_graph_with`].
#[derive(Debug, Clone, PartialEq)]
pub struct GraphParams {
    /// Distance for the nearest and second-nearest centroids (that of the k-means).
    pub metric: KMeansMetric,
    /// Connected regions below this fraction of the shape's area are merged into the
    /// neighbouring region they share most edges with; 0 keeps every region.
    pub min_region_area: f64,
    /// How expanded regions grow.
    pub expansion: RegionExpansion,
}

impl Default for GraphParams {
    fn default() -> Self {
        GraphParams {
            metric: DEFAULT_METRIC,
            min_region_area: DEFAULT_MIN_REGION_AREA,
            expansion: RegionExpansion::SecondNearestBand,
        }
    }
}

/// Parameters of [`joint_kmeans_with`].
#[derive(Debug, Clone, PartialEq)]
pub struct KMeansParams {
    /// Number of clusters.
    pub k: usize,
    /// Independent k-means++ starts; the one with the lowest weighted cost is kept
    /// (authors: 3).
    pub restarts: usize,
    /// Seed of the k-means++ sampling.
    pub seed: u64,
    /// Distance.
    pub metric: KMeansMetric,
    /// Lloyd iterations per start at most (the iteration stops earlier when no label
    /// changes).
    pub max_iterations: usize,
}

impl Default for KMeansParams {
    fn default() -> Self {
        KMeansParams {
            k: 5,
            restarts: 3,
            seed: 0x5eed,
            metric: DEFAULT_METRIC,
            max_iterations: DEFAULT_MAX_ITERATIONS,
        }
    }
}

/// Default cap on Lloyd iterations per k-means start.
pub const DEFAULT_MAX_ITERATIONS: usize = 100;

/// Default smallest region, as a fraction of the shape's area; smaller connected regions
/// are merged into a neighbour. Measured on FAUST (`tests/segmentation.rs`): the meshes have
/// no region below 0.009 at k = 5 (merging at 0.001-0.005 changes nothing; 0.01 starts
/// merging real parts at k >= 6). Point clouds with 1% noise have specks of 1e-5 to 4e-4
/// of the area that make graphs differ or fall apart; merging below 0.001-0.005 raised the
/// region consistency from 0.736 to about 0.78 (city block; Euclidean 0.804 at 0.002),
/// 0.01 lowered it to 0.705. 0.002 is about 14 vertices of a 6,890-vertex body.
pub const DEFAULT_MIN_REGION_AREA: f64 = 0.002;

/// Parameters of the joint segmentation. The defaults are the documented ones.
#[derive(Debug, Clone, PartialEq)]
pub struct SegmentationParams {
    /// Smallest number of clusters tried (paper: 5; the authors' code: 7).
    pub k_min: usize,
    /// Largest number of clusters tried (paper: 10; the authors' code: 8).
    pub k_max: usize,
    /// k-means restarts per k (authors: 3).
    pub kmeans_restarts: usize,
    /// Lloyd iterations per k-means start at most.
    pub kmeans_max_iterations: usize,
    /// Distance of the k-means ([`DEFAULT_METRIC`]; authors: city block).
    pub metric: KMeansMetric,
    /// Graphs with more nodes than this are not acceptable (authors: 60).
    pub max_regions: usize,
    /// Connected regions below this fraction of the shape's area are merged into the
    /// neighbouring region they share most edges with ([`DEFAULT_MIN_REGION_AREA`]).
    /// 0 keeps every region.
    pub min_region_area: f64,
    /// How expanded regions grow (the authors' second-nearest band).
    pub expansion: RegionExpansion,
    /// How ties in the degree-histogram difference are broken.
    pub tie_break: KTieBreak,
    /// Seed of the k-means++ sampling (the same seed is used for every k).
    pub seed: u64,
}

impl Default for SegmentationParams {
    /// k = 5..=10 (paper), 3 restarts (authors), Euclidean k-means ([`DEFAULT_METRIC`]),
    /// at most 60 regions (authors), fragments below [`DEFAULT_MIN_REGION_AREA`] merged,
    /// the authors' second-nearest band, ties towards the smaller k (docs/decisions.md, "Segmentation").
    fn default() -> Self {
        SegmentationParams {
            k_min: 5,
            k_max: 10,
            kmeans_restarts: 3,
            kmeans_max_iterations: DEFAULT_MAX_ITERATIONS,
            metric: DEFAULT_METRIC,
            max_regions: 60,
            min_region_area: DEFAULT_MIN_REGION_AREA,
            expansion: RegionExpansion::SecondNearestBand,
            tie_break: KTieBreak::SmallestK,
            seed: 0x5eed,
        }
    }
}

impl SegmentationParams {
    /// The graph parameters these imply.
    pub fn graph_params(&self) -> GraphParams {
        GraphParams {
            metric: self.metric,
            min_region_area: self.min_region_area,
            expansion: self.expansion,
        }
    }

    /// Checks every field's range.
    pub fn validate(&self) -> Result<()> {
        let bad = |name, reason: String| Err(Error::InvalidParameter { name, reason });
        if self.k_min < 2 || self.k_min > self.k_max {
            return bad(
                "segmentation.k_min/k_max",
                format!(
                    "need 2 <= k_min <= k_max, got k_min = {}, k_max = {}",
                    self.k_min, self.k_max
                ),
            );
        }
        if self.k_max > MAX_CLUSTERS {
            return bad(
                "segmentation.k_max",
                format!("at most {MAX_CLUSTERS} clusters, got {}", self.k_max),
            );
        }
        if self.kmeans_restarts == 0 {
            return bad("segmentation.kmeans_restarts", "must be at least 1".into());
        }
        if self.kmeans_max_iterations == 0 {
            return bad(
                "segmentation.kmeans_max_iterations",
                "must be at least 1".into(),
            );
        }
        if self.max_regions == 0 {
            return bad("segmentation.max_regions", "must be at least 1".into());
        }
        if !(self.min_region_area >= 0.0 && self.min_region_area < 0.5) {
            return bad(
                "segmentation.min_region_area",
                format!(
                    "must lie in [0, 0.5) (a fraction of the area), got {}",
                    self.min_region_area
                ),
            );
        }
        Ok(())
    }
}

/// Most clusters [`segment_pair`] accepts.
pub const MAX_CLUSTERS: usize = 1000;

/// Result of [`joint_kmeans`].
#[derive(Debug, Clone, PartialEq)]
pub struct JointClustering {
    /// Cluster of every vertex of shape A.
    pub labels_a: Vec<u32>,
    /// Cluster of every vertex of shape B.
    pub labels_b: Vec<u32>,
    /// One centroid per row (k x d), in lexicographic order of their coordinates.
    pub centroids: Mat<f64>,
    /// Weighted cost of the kept start: `sum_i w_i dist(x_i, c(i))` with both shapes'
    /// weights normalised to 1 (squared distance for [`KMeansMetric::Euclidean`]).
    pub cost: f64,
}

/// One k tried by [`segment_pair`].
#[derive(Debug, Clone, PartialEq)]
pub struct KCandidate {
    pub k: usize,
    pub n_nodes_a: usize,
    pub n_nodes_b: usize,
    pub connected_a: bool,
    pub connected_b: bool,
    /// Both graphs connected and within `max_regions`.
    pub acceptable: bool,
    /// Weighted degree-histogram difference, lower is more similar (0: equal histograms).
    pub score: f64,
    /// Difference of the sorted hop distances from the most central node of each graph.
    pub hop_difference: u64,
}

/// Result of [`segment_pair`].
#[derive(Debug, Clone)]
pub struct JointSegmentation {
    /// The chosen number of clusters.
    pub k: usize,
    pub graph_a: ShapeGraph,
    pub graph_b: ShapeGraph,
    /// The joint centroids of the chosen k (k x d, in the descriptor space of shape A).
    pub centroids: Mat<f64>,
    /// Every k tried, ascending.
    pub candidates: Vec<KCandidate>,
}

// ---------------------------------------------------------------------------------------
// Step 1: rank alignment
// ---------------------------------------------------------------------------------------

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
fn normalised_weights(mass: &[f64]) -> Vec<f64> {
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

// ---------------------------------------------------------------------------------------
// Step 2: joint k-means
// ---------------------------------------------------------------------------------------

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
    kmeans(&points, params)
}

/// The stacked points of both shapes in canonical order.
struct Points {
    d: usize,
    n_a: usize,
    /// Canonical position -> stacked index (A's rows, then B's).
    order: Vec<u32>,
    /// Rows in canonical order, row-major.
    data: Vec<f64>,
    /// Weights in canonical order (each shape's sum to 1).
    weight: Vec<f64>,
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
    fn new(a: MatRef<f64>, mass_a: &[f64], b: MatRef<f64>, mass_b: &[f64]) -> Points {
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
fn nearest(
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

fn kmeans(points: &Points, params: &KMeansParams) -> JointClustering {
    let (k, d, n) = (params.k, points.d, points.n());
    assert!(k >= 1, "joint k-means: k must be at least 1");
    assert!(
        params.restarts >= 1,
        "joint k-means: restarts must be at least 1"
    );
    let mut rng = ChaCha8Rng::seed_from_u64(params.seed);
    let mut best: Option<(f64, Vec<f64>, Vec<u32>)> = None;
    for _ in 0..params.restarts {
        let centroids = seed_centroids(points, k, params.metric, &mut rng);
        let (cost, centroids, labels) =
            lloyd(points, centroids, k, params.metric, params.max_iterations);
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
    JointClustering {
        labels_a: stacked,
        labels_b,
        centroids: Mat::from_fn(k, d, |c, j| centroids[rank[c] * d + j]),
        cost,
    }
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
) -> (f64, Vec<f64>, Vec<u32>) {
    let d = points.d;
    let mut state = Assignment::new(points, &centroids, metric);
    let mut medians: Option<Medians> = None;
    let mut moved: Vec<(u32, u32, u32)> = Vec::new();
    for _ in 0..max_iterations {
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

// ---------------------------------------------------------------------------------------
// Step 3: shape graph
// ---------------------------------------------------------------------------------------

/// The shape graph of one shape (paper, section 4, step 3; docs/design.md, step 8) with the
/// default [`GraphParams`]. See [`shape_graph_with`].
pub fn shape_graph(
    shape: &Shape,
    mass: &[f64],
    descriptors: MatRef<f64>,
    centroids: MatRef<f64>,
    labels: &[u32],
) -> ShapeGraph {
    shape_graph_with(
        shape,
        mass,
        descriptors,
        centroids,
        labels,
        &GraphParams::default(),
    )
}

/// The shape graph of one shape from its joint clustering.
///
/// - `labels[v]` is the cluster of input vertex `v` (its nearest centroid); `descriptors`
///   (rank-aligned, one row per input vertex) and `centroids` (k x d) give every vertex its
///   second nearest centroid under `params.metric`.
/// - A region is a connected set (over [`Shape::edges`]) of active vertices of one cluster.
///   Regions below `params.min_region_area` of the total mass are merged, smallest first, into the
///   neighbouring region they share most edges with (ties: the larger, then the lower
///   numbered); a merge that makes two regions of the absorbing cluster touch unites them.
///   Every remaining region is a node, numbered by its smallest vertex index.
/// - The expanded region `R*` of region `R` of cluster `c` is the connected set containing
///   `R` in `R` plus the vertices whose second nearest centroid is `c`
///   ([`RegionExpansion::SecondNearestBand`]), or among all vertices whose first or second
///   nearest centroid is `c` ([`RegionExpansion::FirstOrSecondNearest`]); `R` and `S` are
///   joined by an edge when `S` intersects `R*`. Edges are found on the regions before
///   merging and then contracted: a merged node's expanded region is the union of its
///   parts'.
/// - Unreferenced vertices take the node of their representative; node area is the sum of
///   mass (normalised to sum 1), node descriptor the mass-weighted mean descriptor.
///
/// # Panics
/// When a slice or matrix does not have one entry per input vertex, the centroids and
/// descriptors have different columns, or a label is not below the number of centroids.
pub fn shape_graph_with(
    shape: &Shape,
    mass: &[f64],
    descriptors: MatRef<f64>,
    centroids: MatRef<f64>,
    labels: &[u32],
    params: &GraphParams,
) -> ShapeGraph {
    let edges = shape.edges();
    let connectivity = Connectivity {
        active: shape.active_vertices(),
        representative: shape.representative(),
        edges: &edges,
    };
    build_graph(&connectivity, mass, descriptors, centroids, labels, params)
}

/// What the graph construction needs from a shape (edges computed once per pair).
struct Connectivity<'a> {
    active: &'a [u32],
    representative: &'a [u32],
    edges: &'a [(u32, u32)],
}

fn build_graph(
    conn: &Connectivity,
    mass: &[f64],
    descriptors: MatRef<f64>,
    centroids: MatRef<f64>,
    labels: &[u32],
    params: &GraphParams,
) -> ShapeGraph {
    let (metric, min_region_area) = (params.metric, params.min_region_area);
    let n = conn.representative.len();
    let (k, d) = (centroids.nrows(), centroids.ncols());
    assert_eq!(mass.len(), n, "shape graph: one mass per input vertex");
    assert_eq!(labels.len(), n, "shape graph: one label per input vertex");
    assert_eq!(
        descriptors.nrows(),
        n,
        "shape graph: one descriptor row per input vertex"
    );
    assert_eq!(
        descriptors.ncols(),
        d,
        "shape graph: descriptor and centroid columns differ"
    );
    let active = conn.active;
    assert!(
        active.iter().all(|&v| (labels[v as usize] as usize) < k),
        "shape graph: a label is not below the number of centroids ({k})"
    );
    let mass: Vec<f64> = mass
        .iter()
        .map(|&m| if m > 0.0 && m.is_finite() { m } else { 0.0 })
        .collect();

    // Second nearest centroid of every active vertex.
    let centroid_rows: Vec<f64> = (0..k)
        .flat_map(|c| (0..d).map(move |j| centroids[(c, j)]))
        .collect();
    let second_active: Vec<u32> = active
        .par_iter()
        .map(|&v| {
            if k < 2 {
                return u32::MAX;
            }
            let row: Vec<f64> = (0..d).map(|j| descriptors[(v as usize, j)]).collect();
            nearest(metric, &row, &centroid_rows, d, labels[v as usize] as usize).0
        })
        .collect();
    let mut second = vec![u32::MAX; n];
    for (&v, &s) in active.iter().zip(&second_active) {
        second[v as usize] = s;
    }

    // Regions: connected components of each cluster.
    let (mut regions, region_of) = Regions::components(n, active, conn.edges, labels, &mass);
    let first_vertex = regions.first_vertex.clone();
    let total_mass: f64 = regions.area.iter().sum();
    if min_region_area > 0.0 {
        regions.merge_fragments(min_region_area * total_mass);
    }

    // Nodes: the surviving regions, numbered by smallest vertex.
    let (survivors, node_of_region) = regions.nodes();
    let n_nodes = survivors.len();
    let node_cluster: Vec<u32> = survivors
        .iter()
        .map(|&r| regions.cluster[r as usize])
        .collect();
    let mut node_of = vec![u32::MAX; n];
    for &v in active {
        node_of[v as usize] = node_of_region[region_of[v as usize] as usize];
    }

    // Edges on the regions before fragments were merged, then contracted (a merged
    // node's expanded region is the union of its parts').
    let mut regions_of_cluster: Vec<Vec<u32>> = vec![Vec::new(); k];
    for (r, &c) in regions.cluster.iter().enumerate() {
        regions_of_cluster[c as usize].push(r as u32);
    }
    let region_edges = match params.expansion {
        RegionExpansion::SecondNearestBand => {
            band_edges(conn, labels, &second, &region_of, &regions_of_cluster)
        }
        RegionExpansion::FirstOrSecondNearest => first_or_second_edges(
            conn,
            labels,
            &second,
            &region_of,
            &regions_of_cluster,
            &first_vertex,
        ),
    };
    let mut graph_edges: Vec<(u32, u32)> = region_edges
        .into_iter()
        .map(|(r, s)| (node_of_region[r as usize], node_of_region[s as usize]))
        .filter(|(x, y)| x != y)
        .map(|(x, y)| (x.min(y), x.max(y)))
        .collect();
    graph_edges.sort_unstable();
    graph_edges.dedup();

    // Per input vertex: labels, areas and descriptors.
    let graph_labels: Vec<u32> = conn
        .representative
        .iter()
        .map(|&r| node_of[r as usize])
        .collect();
    let mut node_area = vec![0.0; n_nodes];
    let mut node_count = vec![0usize; n_nodes];
    let mut weighted = vec![vec![0.0; d]; n_nodes];
    let mut plain = vec![vec![0.0; d]; n_nodes];
    for (v, &node) in graph_labels.iter().enumerate() {
        let node = node as usize;
        node_area[node] += mass[v];
        node_count[node] += 1;
        for j in 0..d {
            weighted[node][j] += mass[v] * descriptors[(v, j)];
            plain[node][j] += descriptors[(v, j)];
        }
    }
    let node_descriptor: Vec<Vec<f64>> = (0..n_nodes)
        .map(|node| {
            if node_area[node] > 0.0 {
                weighted[node].iter().map(|x| x / node_area[node]).collect()
            } else {
                plain[node]
                    .iter()
                    .map(|x| x / node_count[node].max(1) as f64)
                    .collect()
            }
        })
        .collect();
    let total: f64 = node_area.iter().sum();
    if total > 0.0 {
        for a in &mut node_area {
            *a /= total;
        }
    } else {
        for (a, &count) in node_area.iter_mut().zip(&node_count) {
            *a = count as f64 / n as f64;
        }
    }
    ShapeGraph {
        labels: graph_labels,
        node_cluster,
        node_area,
        node_descriptor,
        edges: graph_edges,
    }
}

/// Region edges of [`RegionExpansion::SecondNearestBand`]: for every cluster `c`, the
/// connected pieces of the band (vertices not of cluster `c` whose second nearest centroid
/// is `c`); a region of cluster `c` touching a piece is joined to every region the piece
/// meets.
fn band_edges(
    conn: &Connectivity,
    labels: &[u32],
    second: &[u32],
    region_of: &[u32],
    regions_of_cluster: &[Vec<u32>],
) -> Vec<(u32, u32)> {
    let n = labels.len();
    let mut edges = Vec::new();
    for (c, cluster_regions) in regions_of_cluster.iter().enumerate() {
        if cluster_regions.is_empty() {
            continue;
        }
        let c = c as u32;
        let in_band = |v: u32| second[v as usize] == c && labels[v as usize] != c;
        let mut sets = DisjointSets::new(n);
        for &(u, v) in conn.edges {
            if in_band(u) && in_band(v) {
                sets.union(u as usize, v as usize);
            }
        }
        // (band piece, region of cluster c touching it)
        let mut attached: Vec<(usize, u32)> = Vec::new();
        for &(u, v) in conn.edges {
            for (x, y) in [(u, v), (v, u)] {
                if labels[x as usize] == c && in_band(y) {
                    attached.push((sets.find(y as usize), region_of[x as usize]));
                }
            }
        }
        attached.sort_unstable();
        attached.dedup();
        if attached.is_empty() {
            continue;
        }
        // (band piece, region it meets)
        let mut met: Vec<(usize, u32)> = conn
            .active
            .iter()
            .filter(|&&v| in_band(v))
            .map(|&v| (sets.find(v as usize), region_of[v as usize]))
            .collect();
        met.sort_unstable();
        met.dedup();
        let mut i = 0;
        for &(piece, region) in &attached {
            while i < met.len() && met[i].0 < piece {
                i += 1;
            }
            let mut j = i;
            while j < met.len() && met[j].0 == piece {
                edges.push((region, met[j].1));
                j += 1;
            }
        }
    }
    edges
}

/// Region edges of [`RegionExpansion::FirstOrSecondNearest`]: for every cluster `c`, the
/// connected pieces of the vertices whose first or second nearest centroid is `c`; every
/// region of cluster `c` is joined to every region its piece meets.
fn first_or_second_edges(
    conn: &Connectivity,
    labels: &[u32],
    second: &[u32],
    region_of: &[u32],
    regions_of_cluster: &[Vec<u32>],
    first_vertex: &[u32],
) -> Vec<(u32, u32)> {
    let n = labels.len();
    let mut edges = Vec::new();
    for (c, cluster_regions) in regions_of_cluster.iter().enumerate() {
        if cluster_regions.is_empty() {
            continue;
        }
        let c = c as u32;
        let eligible = |v: u32| labels[v as usize] == c || second[v as usize] == c;
        let mut sets = DisjointSets::new(n);
        for &(u, v) in conn.edges {
            if eligible(u) && eligible(v) {
                sets.union(u as usize, v as usize);
            }
        }
        let mut expanded: HashMap<usize, Vec<u32>> = HashMap::new();
        for &r in cluster_regions {
            let root = sets.find(first_vertex[r as usize] as usize);
            expanded.entry(root).or_default().push(r);
        }
        let mut met: Vec<(usize, u32)> = conn
            .active
            .iter()
            .filter(|&&v| eligible(v))
            .map(|&v| (sets.find(v as usize), region_of[v as usize]))
            .filter(|(root, _)| expanded.contains_key(root))
            .collect();
        met.sort_unstable();
        met.dedup();
        for (root, other) in met {
            for &r in &expanded[&root] {
                edges.push((r, other));
            }
        }
    }
    edges
}

/// Connected regions while fragments are merged (also the Reeb baseline's level components,
/// `shapecorr_eval::reeb`).
#[derive(Default)]
pub struct Regions {
    /// The cluster (Reeb: level interval) of each region.
    pub cluster: Vec<u32>,
    pub area: Vec<f64>,
    pub first_vertex: Vec<u32>,
    /// Neighbouring regions and the number of edges shared with each.
    pub neighbours: Vec<BTreeMap<u32, u32>>,
    /// The region this one was merged into (`u32::MAX`: still a region).
    pub absorbed_into: Vec<u32>,
}

impl Regions {
    /// The connected components, over `edges`, of the active vertices of each label: their
    /// label (`cluster`), area (sum of `mass`), smallest vertex and neighbours; with the
    /// region of every vertex (`u32::MAX` for inactive ones). Nothing is merged yet.
    pub fn components(
        n: usize,
        active: &[u32],
        edges: &[(u32, u32)],
        labels: &[u32],
        mass: &[f64],
    ) -> (Regions, Vec<u32>) {
        let mut sets = DisjointSets::new(n);
        for &(u, v) in edges {
            if labels[u as usize] == labels[v as usize] {
                sets.union(u as usize, v as usize);
            }
        }
        let mut region_of = vec![u32::MAX; n];
        let mut region_of_root: HashMap<usize, u32> = HashMap::new();
        let mut regions = Regions::default();
        for &v in active {
            let next = regions.cluster.len() as u32;
            let r = *region_of_root.entry(sets.find(v as usize)).or_insert(next);
            if r == next {
                regions.cluster.push(labels[v as usize]);
                regions.area.push(0.0);
                regions.first_vertex.push(v);
                regions.neighbours.push(BTreeMap::new());
                regions.absorbed_into.push(u32::MAX);
            }
            region_of[v as usize] = r;
            regions.area[r as usize] += mass[v as usize];
        }
        for &(u, v) in edges {
            let (ru, rv) = (region_of[u as usize], region_of[v as usize]);
            if ru != rv {
                *regions.neighbours[ru as usize].entry(rv).or_insert(0) += 1;
                *regions.neighbours[rv as usize].entry(ru).or_insert(0) += 1;
            }
        }
        (regions, region_of)
    }

    /// The regions that survived merging, numbered by smallest vertex (`survivors[node]` is
    /// the region of that node), and the node of every region (merged ones: their
    /// absorber's).
    pub fn nodes(&self) -> (Vec<u32>, Vec<u32>) {
        let mut survivors: Vec<u32> = (0..self.cluster.len() as u32)
            .filter(|&r| self.absorbed_into[r as usize] == u32::MAX)
            .collect();
        survivors.sort_by_key(|&r| self.first_vertex[r as usize]);
        let mut node_of_region = vec![u32::MAX; self.cluster.len()];
        for (node, &r) in survivors.iter().enumerate() {
            node_of_region[r as usize] = node as u32;
        }
        for r in 0..self.cluster.len() {
            node_of_region[r] = node_of_region[self.resolve(r as u32) as usize];
        }
        (survivors, node_of_region)
    }

    pub fn resolve(&self, mut r: u32) -> u32 {
        while self.absorbed_into[r as usize] != u32::MAX {
            r = self.absorbed_into[r as usize];
        }
        r
    }

    /// Merges regions below `threshold` area, smallest first, into the neighbour sharing
    /// most edges (ties: the larger, then the lower numbered); regions of the absorbing
    /// cluster that touched the fragment join too. A region without neighbours (a separate
    /// piece of the shape) stays.
    pub fn merge_fragments(&mut self, threshold: f64) {
        loop {
            let fragment = (0..self.cluster.len())
                .filter(|&r| {
                    self.absorbed_into[r] == u32::MAX
                        && self.area[r] < threshold
                        && !self.neighbours[r].is_empty()
                })
                .min_by(|&x, &y| self.area[x].total_cmp(&self.area[y]).then(x.cmp(&y)));
            let Some(fragment) = fragment else { break };
            let target = *self.neighbours[fragment]
                .iter()
                .max_by(|(&x, &cx), (&y, &cy)| {
                    cx.cmp(&cy)
                        .then(self.area[x as usize].total_cmp(&self.area[y as usize]))
                        .then(y.cmp(&x))
                })
                .expect("the fragment has neighbours")
                .0;
            let others: Vec<u32> = self.neighbours[fragment].keys().copied().collect();
            self.absorb(target, fragment as u32);
            // Regions of the target's cluster that touched the fragment now touch the
            // target: they are one connected region of that cluster.
            for other in others {
                if other != target
                    && self.absorbed_into[other as usize] == u32::MAX
                    && self.cluster[other as usize] == self.cluster[target as usize]
                {
                    self.absorb(target, other);
                }
            }
        }
    }

    fn absorb(&mut self, target: u32, absorbed: u32) {
        let (t, a) = (target as usize, absorbed as usize);
        self.absorbed_into[a] = target;
        self.area[t] += self.area[a];
        self.first_vertex[t] = self.first_vertex[t].min(self.first_vertex[a]);
        let moved = std::mem::take(&mut self.neighbours[a]);
        for (other, count) in moved {
            self.neighbours[other as usize].remove(&absorbed);
            if other != target {
                *self.neighbours[t].entry(other).or_insert(0) += count;
                *self.neighbours[other as usize].entry(target).or_insert(0) += count;
            }
        }
        self.neighbours[t].remove(&absorbed);
    }
}

// ---------------------------------------------------------------------------------------
// Steps 4-5: both shapes, every k, the choice of k
// ---------------------------------------------------------------------------------------

/// Both shapes' descriptors mapped onto one common distribution, the average of their two
/// area-weighted quantile functions: a value of A at area rank r becomes
/// `(value + Q_B(r)) / 2`, and likewise for B. The paper aligns B to A ([`rank_align`]);
/// aligning both to their average treats A and B alike, so swapping the shapes swaps the
/// result (tested), at the same accuracy.
pub fn rank_align_common(
    a: MatRef<f64>,
    mass_a: &[f64],
    b: MatRef<f64>,
    mass_b: &[f64],
) -> (Mat<f64>, Mat<f64>) {
    let a_on_b = rank_align(b, mass_b, a, mass_a);
    let b_on_a = rank_align(a, mass_a, b, mass_b);
    let average = |own: MatRef<f64>, other: &Mat<f64>| {
        Mat::from_fn(own.nrows(), own.ncols(), |i, j| {
            0.5 * (own[(i, j)] + other[(i, j)])
        })
    };
    (average(a, &a_on_b), average(b, &b_on_a))
}

/// Joint segmentation of two shapes (paper, section 4; docs/design.md, steps 6-9).
///
/// Both shapes' descriptors are rank-aligned to a common distribution
/// ([`rank_align_common`]); for every k in
/// `params.k_min..=params.k_max`: joint k-means ([`joint_kmeans_with`]) and both shape
/// graphs ([`shape_graph_with`]). A k is acceptable when both graphs are connected and have
/// at most `params.max_regions` nodes. Among the acceptable k (else among those with two
/// connected graphs, else among all) the one with the smallest weighted degree-histogram
/// difference wins ([`degree_histogram_difference`]); ties follow `params.tie_break`.
///
/// `mass_*` are the per-vertex masses (e.g. [`crate::Eigenbasis::mass`]), `desc_*` one
/// descriptor row per input vertex (e.g. HKS).
pub fn segment_pair(
    shape_a: &Shape,
    mass_a: &[f64],
    desc_a: MatRef<f64>,
    shape_b: &Shape,
    mass_b: &[f64],
    desc_b: MatRef<f64>,
    params: &SegmentationParams,
) -> Result<JointSegmentation> {
    segment_pair_with_progress(
        shape_a,
        mass_a,
        desc_a,
        shape_b,
        mass_b,
        desc_b,
        params,
        &mut crate::progress::NoProgress,
    )
}

/// As [`segment_pair`], reporting progress over the values of k and stopping with
/// [`Error::Cancelled`] when `progress` asks to. The k values run in parallel in batches of
/// the thread count, with a report (and a chance to cancel) between batches.
#[allow(clippy::too_many_arguments)]
pub fn segment_pair_with_progress(
    shape_a: &Shape,
    mass_a: &[f64],
    desc_a: MatRef<f64>,
    shape_b: &Shape,
    mass_b: &[f64],
    desc_b: MatRef<f64>,
    params: &SegmentationParams,
    progress: &mut dyn crate::progress::Progress,
) -> Result<JointSegmentation> {
    params.validate()?;
    validate_inputs("a", shape_a, mass_a, desc_a)?;
    validate_inputs("b", shape_b, mass_b, desc_b)?;
    if desc_a.ncols() != desc_b.ncols() {
        return Err(Error::InvalidParameter {
            name: "descriptors",
            reason: format!(
                "shape A has {} descriptor columns, shape B {}; use the same descriptor for both",
                desc_a.ncols(),
                desc_b.ncols()
            ),
        });
    }
    let (aligned_a, aligned_b) = rank_align_common(desc_a, mass_a, desc_b, mass_b);
    let points = Points::new(aligned_a.as_ref(), mass_a, aligned_b.as_ref(), mass_b);
    let positive = points.weight.iter().filter(|&&w| w > 0.0).count();
    if positive < params.k_max {
        return Err(Error::InvalidParameter {
            name: "segmentation.k_max",
            reason: format!(
                "k_max = {} but the two shapes have only {positive} vertices with mass",
                params.k_max
            ),
        });
    }
    let edges_a = shape_a.edges();
    let edges_b = shape_b.edges();
    let conn_a = Connectivity {
        active: shape_a.active_vertices(),
        representative: shape_a.representative(),
        edges: &edges_a,
    };
    let conn_b = Connectivity {
        active: shape_b.active_vertices(),
        representative: shape_b.representative(),
        edges: &edges_b,
    };
    let graph_params = params.graph_params();
    let all_k: Vec<usize> = (params.k_min..=params.k_max).collect();
    let batch = rayon::current_num_threads().max(1);
    let mut tried: Vec<(KCandidate, ShapeGraph, ShapeGraph, Mat<f64>)> = Vec::new();
    for (done, ks) in all_k.chunks(batch).enumerate() {
        let fraction = (done * batch) as f32 / all_k.len() as f32;
        crate::progress::check(progress, crate::progress::Stage::Segmentation, fraction)?;
        let results: Vec<(KCandidate, ShapeGraph, ShapeGraph, Mat<f64>)> = ks
            .par_iter()
            .map(|&k| {
                let clustering = kmeans(
                    &points,
                    &KMeansParams {
                        k,
                        restarts: params.kmeans_restarts,
                        seed: params.seed,
                        metric: params.metric,
                        max_iterations: params.kmeans_max_iterations,
                    },
                );
                let centroids = clustering.centroids.as_ref();
                let (graph_a, graph_b) = rayon::join(
                    || {
                        build_graph(
                            &conn_a,
                            mass_a,
                            aligned_a.as_ref(),
                            centroids,
                            &clustering.labels_a,
                            &graph_params,
                        )
                    },
                    || {
                        build_graph(
                            &conn_b,
                            mass_b,
                            aligned_b.as_ref(),
                            centroids,
                            &clustering.labels_b,
                            &graph_params,
                        )
                    },
                );
                let candidate = compare_graphs(k, &graph_a, &graph_b, params.max_regions);
                (candidate, graph_a, graph_b, clustering.centroids)
            })
            .collect();
        tried.extend(results);
    }
    let chosen = choose_k(
        &tried.iter().map(|t| t.0.clone()).collect::<Vec<_>>(),
        params.tie_break,
    );
    let candidates = tried.iter().map(|t| t.0.clone()).collect();
    let (candidate, graph_a, graph_b, centroids) = tried
        .into_iter()
        .nth(chosen)
        .expect("choose_k returns an index of the candidates");
    Ok(JointSegmentation {
        k: candidate.k,
        graph_a,
        graph_b,
        centroids,
        candidates,
    })
}

fn validate_inputs(
    which: &'static str,
    shape: &Shape,
    mass: &[f64],
    desc: MatRef<f64>,
) -> Result<()> {
    let n = shape.n_vertices();
    let name = if which == "a" {
        "shape_a inputs"
    } else {
        "shape_b inputs"
    };
    let bad = |reason: String| Err(Error::InvalidParameter { name, reason });
    if mass.len() != n || desc.nrows() != n {
        return bad(format!(
            "the shape has {n} vertices but {} masses and {} descriptor rows; pass one per input vertex",
            mass.len(),
            desc.nrows()
        ));
    }
    if desc.ncols() == 0 {
        return bad("the descriptors have no columns".into());
    }
    if let Some(i) = mass.iter().position(|m| !(m.is_finite() && *m >= 0.0)) {
        return bad(format!(
            "mass of vertex {i} is {}; masses must be finite and >= 0",
            mass[i]
        ));
    }
    if !(mass.iter().sum::<f64>() > 0.0) {
        return bad("all masses are zero".into());
    }
    for v in 0..n {
        for j in 0..desc.ncols() {
            let x = desc[(v, j)];
            if !x.is_finite() {
                return bad(format!(
                    "descriptor ({v}, {j}) is {x}; descriptors must be finite"
                ));
            }
        }
    }
    Ok(())
}

/// Degree histograms, connectivity and sizes of two graphs.
pub fn compare_graphs(k: usize, a: &ShapeGraph, b: &ShapeGraph, max_regions: usize) -> KCandidate {
    let (connected_a, connected_b) = (a.is_connected(), b.is_connected());
    let (n_nodes_a, n_nodes_b) = (a.n_nodes(), b.n_nodes());
    KCandidate {
        k,
        n_nodes_a,
        n_nodes_b,
        connected_a,
        connected_b,
        acceptable: connected_a
            && connected_b
            && n_nodes_a <= max_regions
            && n_nodes_b <= max_regions,
        score: degree_histogram_difference(a, b),
        hop_difference: hop_difference(&hop_signature(a), &hop_signature(b)),
    }
}

/// `sum_d w_d |h_A(d) - h_B(d)|` over node degrees d, with `w_1 = 0.3`, `w_2 = 0.2` and
/// `w_d = 1` otherwise (the authors' weights); 0 when the histograms are equal.
pub fn degree_histogram_difference(a: &ShapeGraph, b: &ShapeGraph) -> f64 {
    degree_difference_tenths(a, b) as f64 / 10.0
}

fn degree_difference_tenths(a: &ShapeGraph, b: &ShapeGraph) -> u64 {
    let histogram = |g: &ShapeGraph| {
        let mut h: Vec<i64> = Vec::new();
        for degree in g.degrees() {
            if h.len() <= degree {
                h.resize(degree + 1, 0);
            }
            h[degree] += 1;
        }
        h
    };
    let (ha, hb) = (histogram(a), histogram(b));
    (0..ha.len().max(hb.len()))
        .map(|d| {
            let diff = ha.get(d).copied().unwrap_or(0) - hb.get(d).copied().unwrap_or(0);
            degree_weight_tenths(d) * diff.unsigned_abs()
        })
        .sum()
}

/// Sorted hop distances from the most central node (smallest eccentricity, then smallest
/// distance sum, then largest area, then lowest number); unreachable counts as `n_nodes`.
fn hop_signature(g: &ShapeGraph) -> Vec<u32> {
    let n = g.n_nodes();
    if n == 0 {
        return Vec::new();
    }
    let hops: Vec<Vec<u32>> = g
        .hop_distances()
        .into_iter()
        .map(|row| {
            row.into_iter()
                .map(|h| if h == UNREACHABLE { n as u32 } else { h })
                .collect()
        })
        .collect();
    let centre = (0..n)
        .min_by(|&x, &y| {
            let ecc = |i: usize| hops[i].iter().max().copied().unwrap_or(0);
            let sum = |i: usize| hops[i].iter().map(|&h| h as u64).sum::<u64>();
            ecc(x)
                .cmp(&ecc(y))
                .then(sum(x).cmp(&sum(y)))
                .then(g.node_area[y].total_cmp(&g.node_area[x]))
                .then(x.cmp(&y))
        })
        .expect("n > 0");
    let mut signature = hops[centre].clone();
    signature.sort_unstable();
    signature
}

/// Entry-by-entry difference of two sorted hop signatures; an entry missing from the
/// shorter one counts its value plus one.
fn hop_difference(a: &[u32], b: &[u32]) -> u64 {
    (0..a.len().max(b.len()))
        .map(|i| match (a.get(i), b.get(i)) {
            (Some(&x), Some(&y)) => x.abs_diff(y) as u64,
            (Some(&x), None) | (None, Some(&x)) => x as u64 + 1,
            (None, None) => 0,
        })
        .sum()
}

/// Index of the chosen candidate (see [`segment_pair`]).
fn choose_k(candidates: &[KCandidate], tie_break: KTieBreak) -> usize {
    let pool: Vec<usize> = {
        let acceptable: Vec<usize> = (0..candidates.len())
            .filter(|&i| candidates[i].acceptable)
            .collect();
        let connected: Vec<usize> = (0..candidates.len())
            .filter(|&i| candidates[i].connected_a && candidates[i].connected_b)
            .collect();
        if !acceptable.is_empty() {
            acceptable
        } else if !connected.is_empty() {
            connected
        } else {
            (0..candidates.len()).collect()
        }
    };
    let key = |i: usize| {
        let c = &candidates[i];
        let tenths = (c.score * 10.0).round() as u64;
        let hops = match tie_break {
            KTieBreak::SmallestK => 0,
            KTieBreak::HopDistancesThenSmallestK => c.hop_difference,
        };
        (tenths, hops, c.k)
    };
    pool.into_iter()
        .min_by_key(|&i| key(i))
        .expect("at least one k is tried")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params(min_region_area: f64) -> GraphParams {
        GraphParams {
            min_region_area,
            ..GraphParams::default()
        }
    }

    fn path(n: u32) -> (Vec<u32>, Vec<(u32, u32)>) {
        ((0..n).collect(), (0..n - 1).map(|i| (i, i + 1)).collect())
    }

    #[test]
    fn band_expansion_does_not_leak_through_other_regions_of_the_cluster() {
        // A path with descriptor values 1 1 0 0 1 1 2 2 and centroids 0, 1, 2: regions
        // A = {0,1} (cluster 1), B = {2,3} (0), C = {4,5} (1), D = {6,7} (2). Cluster 1 is
        // every other vertex's second nearest, so the paper's first-or-second set of
        // cluster 1 is the whole path and joins A to D; the band does not.
        let (active, edges) = path(8);
        let conn = Connectivity {
            active: &active,
            representative: &active,
            edges: &edges,
        };
        let values = [1.0, 1.0, 0.0, 0.0, 1.0, 1.0, 2.0, 2.0];
        let labels = [1, 1, 0, 0, 1, 1, 2, 2];
        let descriptors = Mat::from_fn(8, 1, |i, _| values[i]);
        let centroids = Mat::from_fn(3, 1, |c, _| c as f64);
        let graph = |expansion| {
            build_graph(
                &conn,
                &[0.125; 8],
                descriptors.as_ref(),
                centroids.as_ref(),
                &labels,
                &GraphParams {
                    min_region_area: 0.0,
                    expansion,
                    ..GraphParams::default()
                },
            )
        };
        let band = graph(RegionExpansion::SecondNearestBand);
        assert_eq!(band.node_cluster, vec![1, 0, 1, 2]);
        assert_eq!(band.edges, vec![(0, 1), (1, 2), (2, 3)]);
        let paper = graph(RegionExpansion::FirstOrSecondNearest);
        assert_eq!(paper.edges, vec![(0, 1), (0, 2), (0, 3), (1, 2), (2, 3)]);
    }

    fn column(values: &[f64]) -> Mat<f64> {
        Mat::from_fn(values.len(), 1, |i, _| values[i])
    }

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

    #[test]
    fn rank_align_interpolates_between_reference_knots() {
        // Reference 0, 10 with equal mass: knots at ranks 0.25 and 0.75. Other: four equal
        // points at ranks 0.125, 0.375, 0.625, 0.875.
        let aligned = rank_align(
            column(&[0.0, 10.0]).as_ref(),
            &[0.5, 0.5],
            column(&[1.0, 2.0, 3.0, 4.0]).as_ref(),
            &[0.25; 4],
        );
        let got: Vec<f64> = (0..4).map(|i| aligned[(i, 0)]).collect();
        assert_eq!(got, vec![0.0, 2.5, 7.5, 10.0]);
    }

    #[test]
    fn fragments_merge_into_the_neighbour_sharing_most_edges() {
        // A path of 10 vertices: clusters 0 0 0 0 1 0 0 2 2 2; vertex 4 is a fragment
        // between two regions of cluster 0, which then unite.
        let active: Vec<u32> = (0..10).collect();
        let edges: Vec<(u32, u32)> = (0..9).map(|i| (i, i + 1)).collect();
        let conn = Connectivity {
            active: &active,
            representative: &active,
            edges: &edges,
        };
        let labels = [0, 0, 0, 0, 1, 0, 0, 2, 2, 2];
        let descriptors = Mat::from_fn(10, 1, |i, _| labels[i] as f64);
        let centroids = Mat::from_fn(3, 1, |c, _| c as f64);
        let mass = vec![0.1; 10];
        let keep = build_graph(
            &conn,
            &mass,
            descriptors.as_ref(),
            centroids.as_ref(),
            &labels,
            &params(0.0),
        );
        assert_eq!(keep.n_nodes(), 4);
        let merged = build_graph(
            &conn,
            &mass,
            descriptors.as_ref(),
            centroids.as_ref(),
            &labels,
            &params(0.15),
        );
        assert_eq!(merged.n_nodes(), 2);
        assert_eq!(merged.labels, vec![0, 0, 0, 0, 0, 0, 0, 1, 1, 1]);
        assert_eq!(merged.node_cluster, vec![0, 2]);
        assert_eq!(merged.edges, vec![(0, 1)]);
        assert!((merged.node_area[0] - 0.7).abs() < 1e-12);
    }

    #[test]
    fn edges_come_from_second_nearest_overlap() {
        // A path 0..6 with descriptors 0, 0, 1, 1, 3, 3 and centroids 0, 1, 3: region of
        // cluster 0 {0,1}, cluster 1 {2,3}, cluster 2 {4,5}. Second nearest of 0..1 is 1,
        // of 2..3 is 0, of 4..5 is 1: so 0-1 and 1-2 are joined, 0-2 is not.
        let active: Vec<u32> = (0..6).collect();
        let edges: Vec<(u32, u32)> = (0..5).map(|i| (i, i + 1)).collect();
        let conn = Connectivity {
            active: &active,
            representative: &active,
            edges: &edges,
        };
        let values = [0.0, 0.0, 1.0, 1.0, 3.0, 3.0];
        let labels = [0, 0, 1, 1, 2, 2];
        let descriptors = Mat::from_fn(6, 1, |i, _| values[i]);
        let centroids = Mat::from_fn(3, 1, |c, _| [0.0, 1.0, 3.0][c]);
        let g = build_graph(
            &conn,
            &[1.0 / 6.0; 6],
            descriptors.as_ref(),
            centroids.as_ref(),
            &labels,
            &params(0.0),
        );
        assert_eq!(g.edges, vec![(0, 1), (1, 2)]);
        assert_eq!(g.degrees(), vec![1, 2, 1]);
    }

    #[test]
    fn choice_of_k_prefers_acceptable_then_small_k() {
        let cand = |k, acceptable, connected, score| KCandidate {
            k,
            n_nodes_a: 10,
            n_nodes_b: 10,
            connected_a: connected,
            connected_b: connected,
            acceptable,
            score,
            hop_difference: 10 - k as u64,
        };
        let list = vec![
            cand(5, true, true, 0.5),
            cand(6, true, true, 0.0),
            cand(7, true, true, 0.0),
        ];
        assert_eq!(choose_k(&list, KTieBreak::SmallestK), 1);
        assert_eq!(choose_k(&list, KTieBreak::HopDistancesThenSmallestK), 2);
        let none = vec![
            cand(5, false, false, 0.0),
            cand(6, false, true, 2.0),
            cand(7, false, true, 1.0),
        ];
        assert_eq!(choose_k(&none, KTieBreak::SmallestK), 2);
        assert_eq!(degree_weight_tenths(1) + degree_weight_tenths(2), 5);
    }
}
