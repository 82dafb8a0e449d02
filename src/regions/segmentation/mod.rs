//! Joint segmentation of two shapes and their shape graphs (paper, section 4; docs/design.md,
//! steps 6-9).
//!
//! 1. [`rank_align_common`]: every descriptor column of both shapes is mapped onto one
//!    common distribution, the average of their area-weighted quantile functions (the
//!    paper's step 1 maps B onto A: [`rank_align`]).
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

mod kmeans;
mod rank;
mod shape_graph;
#[cfg(test)]
mod tests;

pub use kmeans::{joint_kmeans, joint_kmeans_with};
use kmeans::{nearest, Points};
use rank::normalised_weights;
pub use rank::rank_align;
use shape_graph::{build_graph, Connectivity};
pub use shape_graph::{shape_graph, shape_graph_with, Regions};

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
/// (`tests/it/segmentation.rs`, `faust_metric_comparison` and `faust_figures`): the share of
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
    /// Keeps the struct open to new fields: build it with `..Default::default()`.
    #[doc(hidden)]
    pub non_exhaustive: crate::NonExhaustive,
}

impl Default for GraphParams {
    fn default() -> Self {
        GraphParams {
            metric: DEFAULT_METRIC,
            min_region_area: DEFAULT_MIN_REGION_AREA,
            expansion: RegionExpansion::SecondNearestBand,
            non_exhaustive: crate::NonExhaustive(()),
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
    /// Keeps the struct open to new fields: build it with `..Default::default()`.
    #[doc(hidden)]
    pub non_exhaustive: crate::NonExhaustive,
}

impl Default for KMeansParams {
    fn default() -> Self {
        KMeansParams {
            k: 5,
            restarts: 3,
            seed: 0x5eed,
            metric: DEFAULT_METRIC,
            max_iterations: DEFAULT_MAX_ITERATIONS,
            non_exhaustive: crate::NonExhaustive(()),
        }
    }
}

/// Default cap on Lloyd iterations per k-means start.
pub const DEFAULT_MAX_ITERATIONS: usize = 100;

/// Default smallest region, as a fraction of the shape's area; smaller connected regions
/// are merged into a neighbour. Measured on FAUST (`tests/it/segmentation.rs`): the meshes have
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
    /// Keeps the struct open to new fields: build it with `..Default::default()`.
    #[doc(hidden)]
    pub non_exhaustive: crate::NonExhaustive,
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
            non_exhaustive: crate::NonExhaustive(()),
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
            ..Default::default()
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
    /// The number of joint clusters.
    pub k: usize,
    /// Nodes (regions) of A's shape graph.
    pub n_nodes_a: usize,
    /// Nodes (regions) of B's shape graph.
    pub n_nodes_b: usize,
    /// Whether A's shape graph is connected.
    pub connected_a: bool,
    /// Whether B's shape graph is connected.
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
    /// A's shape graph at that k.
    pub graph_a: ShapeGraph,
    /// B's shape graph at that k.
    pub graph_b: ShapeGraph,
    /// The joint centroids of the chosen k (k x d, in the descriptor space of shape A).
    pub centroids: Mat<f64>,
    /// Every k tried, ascending.
    pub candidates: Vec<KCandidate>,
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
/// Reports progress over the values of k and stops with [`Error::Cancelled`] when
/// `progress` asks to: the k values run in parallel in batches of the thread count, with a
/// report (and a chance to cancel) between batches.
pub fn segment_pair(
    a: Described<'_>,
    b: Described<'_>,
    params: &SegmentationParams,
    progress: &mut dyn crate::progress::Progress,
) -> Result<JointSegmentation> {
    let (shape_a, mass_a, desc_a) = (a.shape, a.mass, a.descriptors);
    let (shape_b, mass_b, desc_b) = (b.shape, b.mass, b.descriptors);
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
    let tried = crate::progress::polled(
        progress,
        crate::progress::Stage::Segmentation,
        (0.0, 1.0),
        |cancel| {
            let try_k = |k: usize| -> Result<Tried> {
                let kmeans_params = KMeansParams {
                    k,
                    restarts: params.kmeans_restarts,
                    seed: params.seed,
                    metric: params.metric,
                    max_iterations: params.kmeans_max_iterations,
                    ..Default::default()
                };
                let clustering = kmeans::kmeans(&points, &kmeans_params, cancel)?;
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
                Ok((candidate, graph_a, graph_b, clustering.centroids))
            };
            let batch = rayon::current_num_threads().max(1);
            let mut tried: Vec<Tried> = Vec::new();
            for (done, ks) in all_k.chunks(batch).enumerate() {
                cancel.set_fraction((done * batch) as f32 / all_k.len() as f32);
                let results: Result<Vec<Tried>> = ks.par_iter().map(|&k| try_k(k)).collect();
                tried.extend(results?);
            }
            Ok(tried)
        },
    )?;
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
/// One shape as the joint segmentation reads it.
#[derive(Debug, Clone, Copy)]
pub struct Described<'a> {
    /// The shape (its edges or neighbour graph make the regions connected).
    pub shape: &'a Shape,
    /// Per-vertex masses (e.g. [`crate::Eigenbasis::mass`]).
    pub mass: &'a [f64],
    /// One descriptor row per input vertex (e.g. HKS).
    pub descriptors: MatRef<'a, f64>,
}

/// One value of k tried: its scores, both graphs and the centroids.
type Tried = (KCandidate, ShapeGraph, ShapeGraph, Mat<f64>);

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
