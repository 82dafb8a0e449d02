//! The Reeb-graph baseline of the paper's Table 1 (section 6.2, last column): the shape
//! graph replaced by a discretised Reeb graph of one scalar function, the heat kernel
//! signature at a single time, matched with the same graph matcher
//! ([`shapecorr::regions::matching::match_graphs`]) and the same one-to-one step
//! ([`shapecorr::regions::symmetry::one_to_one`]) as the main method.
//!
//! Construction ([`reeb_graph`]), the usual discrete Reeb graph (Mapper without overlap):
//! 1. `f` = HKS at time `t` ([`ReebParams::hks_time`]) on the unit-area shape
//!    ([`hks_function`]).
//! 2. The range of `f` is cut into `levels` intervals at **area-weighted quantiles**
//!    ([`level_boundaries`]), so every interval holds the same area. Equal-width intervals
//!    were not chosen: the HKS is small and flat on the torso and rises steeply towards the
//!    extremities, so equal widths would put the body in one interval and spend the others
//!    on finger tips and noise; quantiles also make the graph independent of any monotone
//!    rescaling of `f` (raw or log HKS give the same graph). By default each shape is cut at
//!    its own quantiles: that is exactly the paper's own order of work, rank alignment of B
//!    onto A (paper step 1, [`shapecorr::regions::segmentation::rank_align`]) followed by joint
//!    clustering, since joint quantiles of rank-aligned values are each shape's own
//!    quantiles. Joint quantiles of the raw values ([`ReebParams::joint_levels`]) measured
//!    worse on FAUST (9 pairs, 8 levels: symmetric accuracy 0.696 vs 0.822) and on TOSCA
//!    (4 pairs: two fell to 0.000 and 0.001 against 0.730 and 0.822): the HKS of two
//!    people, poses or meshes differ in distribution, so the same values cut them
//!    differently.
//! 3. A node for every connected component (over [`Shape::edges`]: mesh edges, or the
//!    symmetric kNN graph of a point cloud) of the vertices whose value lies in one
//!    interval; two nodes are adjacent when a vertex edge joins them.
//! 4. Components below [`ReebParams::min_area_fraction`] of the area (specks where a level
//!    boundary grazes a saddle or a bump, most of them a handful of vertices) are merged,
//!    smallest first, into the neighbour they share most edges with; when that makes two
//!    components of the absorbing level touch, they become one node (it is now one
//!    connected set of that level), as [`shapecorr::regions::segmentation`] does with k-means fragments.

use std::time::Instant;

use shapecorr::pipeline::multiresolution::Working;
use shapecorr::pipeline::{one_to_one_matches, Correspondence, Params, Timings};
use shapecorr::regions::graph::ShapeGraph;
use shapecorr::regions::matching::match_graphs;
use shapecorr::regions::segmentation::{compare_graphs, Regions};
use shapecorr::shape::Shape;
use shapecorr::spectral::descriptors::{hks, HksParams};
use shapecorr::spectral::eigen::Eigenbasis;
use shapecorr::spectral::eigen::ShapeBasis;
use shapecorr::{Error, Result};

/// HKS time of the baseline on the unit-area shape (the crate's HKS convention: absolute
/// times after scaling the shape to unit area, [`shapecorr::spectral::descriptors`]).
pub const DEFAULT_HKS_TIME: f64 = 0.1;

/// Default number of level intervals, chosen to give the segment count of the paper's
/// Reeb graphs (Table 1: 25.9 on FAUST, 20.7 on TOSCA, 6.2 on SCAPE). Measured on FAUST
/// (tr_reg_000, 009, 010, 019, 020, 029, 030, 039, 040, 049; `tests/it/reeb.rs`,
/// `faust_reeb_baseline`): 5 levels give 15-17 nodes per shape, 6 levels 19-20, 8 levels
/// 26-28, 10 levels 32-35. TOSCA (cat0/1, dog0/1, horse0/5, centaur0/1): 8 levels give
/// 28-34 nodes, 6 levels 20-27.
pub const DEFAULT_LEVELS: usize = 8;

/// Default smallest component, as a fraction of the area (the value of
/// [`shapecorr::regions::segmentation::DEFAULT_MIN_REGION_AREA`]: about 14 vertices of a 6,890-vertex
/// body). Clean meshes have no such specks (the ten FAUST shapes above: the same node
/// counts with 0, 0.002 and 0.005 at 5-10 levels but one shape at 6 levels with 0.005);
/// noisy point clouds have many (`tests/it/reeb.rs`, `merging_tames_a_noisy_point_cloud`).
pub const DEFAULT_MIN_AREA_FRACTION: f64 = 0.002;

/// Most level intervals accepted (a guard against a graph the matcher cannot handle).
pub const MAX_LEVELS: usize = 1000;

/// Parameters of the Reeb-graph baseline.
#[derive(Debug, Clone, PartialEq)]
pub struct ReebParams {
    /// Time of the single HKS on the unit-area shape ([`DEFAULT_HKS_TIME`], paper 0.1).
    pub hks_time: f64,
    /// Number of level intervals of equal area ([`DEFAULT_LEVELS`]).
    pub levels: usize,
    /// Components below this fraction of the shape's area are merged into a neighbour
    /// ([`DEFAULT_MIN_AREA_FRACTION`]); 0 keeps every component.
    pub min_area_fraction: f64,
    /// Cut both shapes of a pair at the quantiles of their raw values taken together;
    /// `false` (default) cuts each shape at its own quantiles, the same as joint quantiles
    /// after the paper's rank alignment (module docs).
    pub joint_levels: bool,
}

impl Default for ReebParams {
    fn default() -> Self {
        ReebParams {
            hks_time: DEFAULT_HKS_TIME,
            levels: DEFAULT_LEVELS,
            min_area_fraction: DEFAULT_MIN_AREA_FRACTION,
            joint_levels: false,
        }
    }
}

impl ReebParams {
    /// Checks every field's range.
    pub fn validate(&self) -> Result<()> {
        let bad = |name, reason: String| Err(Error::InvalidParameter { name, reason });
        if !(self.hks_time > 0.0 && self.hks_time.is_finite()) {
            return bad(
                "reeb.hks_time",
                format!("must be positive and finite, got {}", self.hks_time),
            );
        }
        if self.levels == 0 || self.levels > MAX_LEVELS {
            return bad(
                "reeb.levels",
                format!("must lie in 1..={MAX_LEVELS}, got {}", self.levels),
            );
        }
        check_min_area(self.min_area_fraction)
    }
}

fn check_min_area(fraction: f64) -> Result<()> {
    if !(0.0..0.5).contains(&fraction) {
        return Err(Error::InvalidParameter {
            name: "reeb.min_area_fraction",
            reason: format!("must lie in [0, 0.5) (a fraction of the area), got {fraction}"),
        });
    }
    Ok(())
}

/// The heat kernel signature at the single time `t`, one value per input vertex:
/// `HKS(x, t) = sum_i exp(-lambda_i t) phi_i(x)^2` (raw, not log: the level quantiles do
/// not depend on a monotone rescaling).
pub fn hks_function(basis: &Eigenbasis, t: f64) -> Result<Vec<f64>> {
    let params = HksParams {
        n_times: 1,
        t_min: t,
        t_max: t,
        log: false,
        ..Default::default()
    };
    let column = hks(basis, &params)?;
    Ok((0..column.nrows()).map(|v| column[(v, 0)]).collect())
}

/// The `levels - 1` interior boundaries (ascending) that cut the values of one or more
/// shapes into `levels` intervals of equal area: `shapes` are `(values, mass)` per input
/// vertex; every shape's mass is normalised to 1, so every shape counts alike. Boundary `i`
/// is the smallest value with at least `i / levels` of the total weight strictly below it;
/// a vertex lies in interval `#{boundaries <= value}` ([`level_of`]).
///
/// Errors ([`Error::InvalidParameter`]): no shape, `levels` outside `1..=`[`MAX_LEVELS`],
/// slices of different lengths, a non-finite value or a negative or non-finite mass, or a
/// shape without mass.
pub fn level_boundaries(shapes: &[(&[f64], &[f64])], levels: usize) -> Result<Vec<f64>> {
    let bad = |reason: String| {
        Err(Error::InvalidParameter {
            name: "reeb.level_boundaries",
            reason,
        })
    };
    if shapes.is_empty() {
        return bad("no shape given".into());
    }
    if levels == 0 || levels > MAX_LEVELS {
        return bad(format!("levels must lie in 1..={MAX_LEVELS}, got {levels}"));
    }
    let mut weighted: Vec<(f64, f64)> = Vec::new();
    for (index, &(values, mass)) in shapes.iter().enumerate() {
        if let Err(e) = check_values(values, mass, values.len()) {
            return bad(format!("shape {index}: {e}"));
        }
        let total: f64 = mass.iter().sum();
        if !(total > 0.0) {
            return bad(format!("shape {index} has no mass"));
        }
        weighted.extend(
            values
                .iter()
                .zip(mass)
                .filter(|(_, &m)| m > 0.0)
                .map(|(&f, &m)| (f, m / total)),
        );
    }
    weighted.sort_by(|x, y| x.0.total_cmp(&y.0));
    let total = shapes.len() as f64;
    let mut boundaries = Vec::with_capacity(levels - 1);
    let mut below = 0.0;
    let mut next = 1;
    // Walk the distinct values; `below` is the weight strictly below the current one.
    for group in weighted.chunk_by(|x, y| x.0 == y.0) {
        let value = group[0].0;
        while next < levels && below >= total * next as f64 / levels as f64 {
            boundaries.push(value);
            next += 1;
        }
        below += group.iter().map(|w| w.1).sum::<f64>();
    }
    // Round-off can leave the last boundaries unplaced: put them above every value.
    let top = weighted.last().map_or(0.0, |w| w.0);
    while boundaries.len() < levels - 1 {
        boundaries.push(next_up(top));
    }
    Ok(boundaries)
}

/// The smallest float above `x` (finite `x`).
fn next_up(x: f64) -> f64 {
    if x == 0.0 {
        f64::MIN_POSITIVE
    } else if x > 0.0 {
        f64::from_bits(x.to_bits() + 1)
    } else {
        f64::from_bits(x.to_bits() - 1)
    }
}

/// Interval of `value` among ascending `boundaries`: the number of boundaries `<= value`.
pub fn level_of(value: f64, boundaries: &[f64]) -> u32 {
    boundaries.partition_point(|&b| b <= value) as u32
}

/// Checks one value and one finite, non-negative mass per vertex, as a reason string.
fn check_values(values: &[f64], mass: &[f64], n: usize) -> std::result::Result<(), String> {
    if values.len() != n || mass.len() != n {
        return Err(format!(
            "need one value and one mass per vertex ({n}), got {} values and {} masses",
            values.len(),
            mass.len()
        ));
    }
    if let Some(v) = values.iter().position(|f| !f.is_finite()) {
        return Err(format!("value of vertex {v} is {}", values[v]));
    }
    if let Some(v) = mass.iter().position(|m| !(*m >= 0.0 && m.is_finite())) {
        return Err(format!("mass of vertex {v} is {}", mass[v]));
    }
    Ok(())
}

/// The discretised Reeb graph of `values` on `shape` (module docs): a node for every
/// connected component of the active vertices of one interval of `boundaries` (ascending;
/// [`level_boundaries`]), components below `min_area_fraction` of the total mass merged into
/// a neighbour, an edge between nodes joined by a vertex edge.
///
/// In the returned [`ShapeGraph`]: `labels` per input vertex (unreferenced vertices take
/// their representative's node), nodes numbered by their smallest vertex; `node_cluster`
/// is the node's interval (that of the component that absorbed the others, for a merged
/// node);
/// `node_area` sums to 1; `node_descriptor` is the one-entry area-weighted mean of `values`.
///
/// Errors ([`Error::InvalidParameter`]): slices not one per input vertex, non-finite
/// values or mass, no mass at all, boundaries not finite and ascending, or
/// `min_area_fraction` outside `[0, 0.5)`.
pub fn reeb_graph(
    shape: &Shape,
    mass: &[f64],
    values: &[f64],
    boundaries: &[f64],
    min_area_fraction: f64,
) -> Result<ShapeGraph> {
    let bad = |reason: String| Error::InvalidParameter {
        name: "reeb.reeb_graph",
        reason,
    };
    let n = shape.n_vertices();
    check_values(values, mass, n).map_err(bad)?;
    if boundaries.iter().any(|b| !b.is_finite()) || boundaries.windows(2).any(|w| w[0] > w[1]) {
        return Err(bad(format!(
            "boundaries must be finite and ascending, got {boundaries:?}"
        )));
    }
    check_min_area(min_area_fraction)?;
    let active = shape.active_vertices();
    let total_mass: f64 = active.iter().map(|&v| mass[v as usize]).sum();
    if !(total_mass > 0.0) {
        return Err(bad("the shape's vertices have no mass".into()));
    }
    let level: Vec<u32> = values.iter().map(|&f| level_of(f, boundaries)).collect();

    // Components of every interval.
    let edges = shape.edges();
    let (mut parts, part_of) = Regions::components(n, active, &edges, &level, mass);
    if min_area_fraction > 0.0 {
        parts.merge_fragments(min_area_fraction * total_mass);
    }

    // Nodes: surviving parts numbered by smallest vertex.
    let (survivors, node_of_part) = parts.nodes();
    let n_nodes = survivors.len();
    let labels: Vec<u32> = shape
        .representative()
        .iter()
        .map(|&r| node_of_part[part_of[r as usize] as usize])
        .collect();

    let mut graph_edges: Vec<(u32, u32)> = edges
        .iter()
        .map(|&(u, v)| (labels[u as usize], labels[v as usize]))
        .filter(|(x, y)| x != y)
        .map(|(x, y)| (x.min(y), x.max(y)))
        .collect();
    graph_edges.sort_unstable();
    graph_edges.dedup();

    let mut node_area = vec![0.0; n_nodes];
    let mut weighted_value = vec![0.0; n_nodes];
    for (v, &node) in labels.iter().enumerate() {
        node_area[node as usize] += mass[v];
        weighted_value[node as usize] += mass[v] * values[v];
    }
    let node_descriptor = (0..n_nodes)
        .map(|i| vec![weighted_value[i] / node_area[i].max(f64::MIN_POSITIVE)])
        .collect();
    for area in &mut node_area {
        *area /= total_mass;
    }
    Ok(ShapeGraph {
        labels,
        node_cluster: survivors
            .iter()
            .map(|&p| parts.cluster[p as usize])
            .collect(),
        node_area,
        node_descriptor,
        edges: graph_edges,
    })
}

/// The Reeb graph of one shape alone: HKS at `params.hks_time`, cut at the shape's own
/// quantiles into `params.levels` intervals ([`reeb_graph`]).
pub fn shape_reeb_graph(
    shape: &Shape,
    basis: &Eigenbasis,
    params: &ReebParams,
) -> Result<ShapeGraph> {
    params.validate()?;
    check_basis(shape, basis, "basis")?;
    let f = hks_function(basis, params.hks_time)?;
    let boundaries = level_boundaries(&[(&f, &basis.mass)], params.levels)?;
    reeb_graph(
        shape,
        &basis.mass,
        &f,
        &boundaries,
        params.min_area_fraction,
    )
}

fn check_basis(shape: &Shape, basis: &Eigenbasis, name: &'static str) -> Result<()> {
    let n = shape.n_vertices();
    if basis.vectors.nrows() != n || basis.mass.len() != n || basis.is_empty() {
        return Err(Error::InvalidParameter {
            name,
            reason: format!(
                "the eigenbasis has {} rows, {} masses and {} eigenpairs; the shape has {n} vertices \
                 (compute the eigenbasis of this shape)",
                basis.vectors.nrows(),
                basis.mass.len(),
                basis.len()
            ),
        });
    }
    Ok(())
}

/// The Reeb-graph baseline between two shapes (paper section 6.2, Table 1 "Reeb"): the
/// Reeb graphs of the HKS at `reeb.hks_time` ([`reeb_graph`], each shape cut at its own
/// quantiles, or at joint ones with `reeb.joint_levels`), matched by [`match_graphs`] with `params.matching`, then
/// made one-to-one by [`one_to_one`] with `params.symmetry` (unless
/// `params.skip_one_to_one`), exactly as in [`Correspondence::from_bases`].
///
/// The result's fields: `k` is the number of levels; `candidates` holds that single
/// "candidate" with both graphs' sizes, connectivity and degree-histogram difference
/// (`acceptable` against `params.segmentation.max_regions`, reported, not enforced);
/// `timings.descriptors` is the HKS, `timings.segmentation` the Reeb graphs,
/// the eigenbasis times are 0 (the bases are given). `params.hks`, the rest of
/// `params.segmentation` and `params.fallback` belong to the main method and are not used.
pub fn reeb_correspondence(
    a: &Shape,
    basis_a: &Eigenbasis,
    b: &Shape,
    basis_b: &Eigenbasis,
    reeb: &ReebParams,
    params: &Params,
) -> Result<Correspondence> {
    reeb.validate()?;
    params.matching.validate()?;
    check_basis(a, basis_a, "basis_a")?;
    check_basis(b, basis_b, "basis_b")?;
    let started = Instant::now();
    let mut timings = Timings::default();

    let t = Instant::now();
    let f_a = hks_function(basis_a, reeb.hks_time)?;
    let f_b = hks_function(basis_b, reeb.hks_time)?;
    timings.descriptors = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let (bounds_a, bounds_b) = if reeb.joint_levels {
        let joint = level_boundaries(&[(&f_a, &basis_a.mass), (&f_b, &basis_b.mass)], reeb.levels)?;
        (joint.clone(), joint)
    } else {
        (
            level_boundaries(&[(&f_a, &basis_a.mass)], reeb.levels)?,
            level_boundaries(&[(&f_b, &basis_b.mass)], reeb.levels)?,
        )
    };
    let graph_a = reeb_graph(a, &basis_a.mass, &f_a, &bounds_a, reeb.min_area_fraction)?;
    let graph_b = reeb_graph(b, &basis_b.mass, &f_b, &bounds_b, reeb.min_area_fraction)?;
    timings.segmentation = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let matching = match_graphs(&graph_a, &graph_b, &params.matching)?;
    timings.matching = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let matches_one_to_one = one_to_one_matches(
        (ShapeBasis::new(a, basis_a), &graph_a),
        (ShapeBasis::new(b, basis_b), &graph_b),
        &matching.matches,
        params,
    )?;
    timings.one_to_one = t.elapsed().as_secs_f64();
    timings.total = started.elapsed().as_secs_f64();

    let candidate = compare_graphs(
        reeb.levels,
        &graph_a,
        &graph_b,
        params.segmentation.max_regions,
    );
    Ok(Correspondence {
        k: reeb.levels,
        graph_a,
        graph_b,
        matches: matching.matches,
        matches_one_to_one,
        candidates: vec![candidate],
        timings,
        verdict: None,
        estimate: None,
        working: [a, b].map(|s| Working::of(s, None)),
    })
}
