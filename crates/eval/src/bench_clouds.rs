//! The paper's point-cloud protocol (section 6.3, Figure "pointclouds"): region matching
//! when one or both shapes of a pair are sampled as (noisy) point clouds.
//!
//! For every sampling density (6000, 3000, 1500, 500 points) and noise level (0, 1%, 2% of
//! the shape width), repeated over trials: sample the surface uniformly by area
//! ([`sample_cloud`]), match mesh A to cloud B ("mesh-to-cloud") or cloud A to cloud B
//! ("cloud-to-cloud"), carry each cloud's regions back to its mesh through the nearest mesh
//! vertex of every point ([`transfer_labels`]) and score against the meshes' ground truth
//! with the region accuracy of [`shapecorr::evaluation`], leaving out mesh vertices no point
//! lands on ([`score_transferred`]). [`cloud_table`] and [`cloud_figure`] summarise.

use std::collections::BTreeSet;
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::datasets::Pair;
use crate::plot::{line_chart_png, Chart, Rendered, Series};
use shapecorr::evaluation::region_accuracy;
use shapecorr::pipeline::{Correspondence, Params};
use shapecorr::progress::NoProgress;
use shapecorr::shape::neighbors::PointTree;
use shapecorr::shape::{Shape, ShapeKind, MIN_VERTICES};
use shapecorr::spectral::eigen::Eigenbasis;
use shapecorr::spectral::eigen::ShapeBasis;
use shapecorr::spectral::laplacian::Laplacian;
use shapecorr::synth::{sample_points, FigureMesh};
use shapecorr::{Error, Result};

/// Mode name: A stays a mesh, B is sampled as a cloud.
pub const MESH_TO_CLOUD: &str = "mesh-to-cloud";
/// Mode name: both shapes are sampled as clouds.
pub const CLOUD_TO_CLOUD: &str = "cloud-to-cloud";
/// The modes in the order [`cloud_trials`] runs them.
pub const MODES: [&str; 2] = [MESH_TO_CLOUD, CLOUD_TO_CLOUD];

/// Mixed into a cloud's seed for the noise generator, so that the noise does not reuse the
/// random numbers that placed the points.
const NOISE_SEED_MIX: u64 = 0x6e6f_6973_6521_0001;

/// The protocol's grid of runs: every density x noise level, `trials` times.
#[derive(Debug, Clone, PartialEq)]
pub struct CloudProtocol {
    /// Points per sampled cloud (paper: 6000, 3000, 1500, 500).
    pub densities: Vec<usize>,
    /// Noise bound as a fraction of the shape width, see [`sample_cloud`] (paper: 0, 1%, 2%).
    pub noise: Vec<f64>,
    /// Repetitions of every (mode, density, noise), with different clouds (paper: 4).
    pub trials: usize,
    /// Base seed; every cloud's seed derives from it ([`cloud_seed`]).
    pub seed: u64,
}

impl Default for CloudProtocol {
    fn default() -> Self {
        CloudProtocol {
            densities: vec![6000, 3000, 1500, 500],
            noise: vec![0.0, 0.01, 0.02],
            trials: 4,
            seed: 0,
        }
    }
}

impl CloudProtocol {
    /// Checks the protocol before any work: at least one density, each at least
    /// [`MIN_VERTICES`]; at least one noise level, each finite and in `[0, 1)`; at least one
    /// trial.
    pub fn validate(&self) -> Result<()> {
        if self.densities.is_empty() {
            return Err(Error::InvalidParameter {
                name: "densities",
                reason: "give at least one number of points".into(),
            });
        }
        if let Some(&d) = self.densities.iter().find(|&&d| d < MIN_VERTICES) {
            return Err(Error::InvalidParameter {
                name: "densities",
                reason: format!("a cloud needs at least {MIN_VERTICES} points, got {d}"),
            });
        }
        if self.noise.is_empty() {
            return Err(Error::InvalidParameter {
                name: "noise",
                reason: "give at least one noise level (0 for none)".into(),
            });
        }
        if let Some(&n) = self
            .noise
            .iter()
            .find(|n| !(n.is_finite() && (0.0..1.0).contains(*n)))
        {
            return Err(Error::InvalidParameter {
                name: "noise",
                reason: format!(
                    "noise is a fraction of the shape width in [0, 1) (0.01 = 1%), got {n}"
                ),
            });
        }
        if self.trials == 0 {
            return Err(Error::InvalidParameter {
                name: "trials",
                reason: "must be at least 1".into(),
            });
        }
        Ok(())
    }
}

/// Width of a shape for the noise bound: the largest extent of its axis-aligned bounding box
/// (a standing body's height). Smaller than [`Shape::width`], the box's diagonal.
pub fn largest_extent(points: &[[f64; 3]]) -> f64 {
    let (lo, hi) = shapecorr::shape::bounding_box(points);
    (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max)
}

/// A sampled cloud with what it was made from.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceSample {
    /// The noise-free points on the mesh surface.
    pub surface: Vec<[f64; 3]>,
    /// The points after noise: `points[i] = surface[i] + offset`, every coordinate of the
    /// offset uniform in `[-noise * width, noise * width]`.
    pub points: Vec<[f64; 3]>,
    /// For every point, the mesh vertex nearest to it (to the noisy point).
    pub nearest_vertex: Vec<u32>,
    /// The width the noise was scaled by ([`largest_extent`] of the mesh).
    pub width: f64,
}

/// Samples `n_points` points uniformly by area on the surface of `mesh` (triangles chosen
/// with probability proportional to area, uniform barycentric position inside; the
/// sampler of [`shapecorr::synth::sample_points`]), shifts every coordinate of every point by
/// an independent uniform amount in `[-noise * width, noise * width]` with
/// `width` = [`largest_extent`] of the mesh (paper: "shifting every vertex by up to 0%,
/// 1% or 2% of the shape width in every direction"), and finds each noisy point's nearest
/// mesh vertex (among the vertices used by a face). Deterministic for a given `seed`.
///
/// Errors: `InvalidParameter` when `mesh` is a point cloud, `n_points` is 0 or `noise` is
/// negative or not finite.
pub fn sample_surface(
    mesh: &Shape,
    n_points: usize,
    noise: f64,
    seed: u64,
) -> Result<SurfaceSample> {
    if mesh.kind() != ShapeKind::Mesh {
        return Err(Error::InvalidParameter {
            name: "mesh",
            reason: "sampling needs a triangle mesh, got a point cloud".into(),
        });
    }
    if !(noise.is_finite() && noise >= 0.0) {
        return Err(Error::InvalidParameter {
            name: "noise",
            reason: format!("must be a finite fraction >= 0 of the shape width, got {noise}"),
        });
    }
    let figure = FigureMesh {
        vertices: mesh.vertices().to_vec(),
        triangles: mesh.triangles().to_vec(),
    };
    let surface = sample_points(&figure, n_points, 0.0, seed)?.points;
    let active = mesh.active_vertices();
    let width = largest_extent(
        &active
            .iter()
            .map(|&v| mesh.vertices()[v as usize])
            .collect::<Vec<_>>(),
    );
    let bound = noise * width;
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ NOISE_SEED_MIX);
    let points: Vec<[f64; 3]> = surface
        .iter()
        .map(|p| {
            if bound > 0.0 {
                p.map(|c| c + bound * (2.0 * rng.random::<f64>() - 1.0))
            } else {
                *p
            }
        })
        .collect();
    let active_points: Vec<[f64; 3]> = active
        .iter()
        .map(|&v| mesh.vertices()[v as usize])
        .collect();
    let tree = PointTree::new(&active_points);
    let nearest_vertex = points.iter().map(|p| active[tree.nearest(p)]).collect();
    Ok(SurfaceSample {
        surface,
        points,
        nearest_vertex,
        width,
    })
}

/// [`sample_surface`] as a point-cloud [`Shape`], with every point's nearest mesh vertex.
///
/// Errors as [`sample_surface`], and as [`Shape::point_cloud`] (fewer than
/// [`MIN_VERTICES`] points).
pub fn sample_cloud(
    mesh: &Shape,
    n_points: usize,
    noise: f64,
    seed: u64,
) -> Result<(Shape, Vec<u32>)> {
    let sample = sample_surface(mesh, n_points, noise, seed)?;
    Ok((Shape::point_cloud(sample.points)?, sample.nearest_vertex))
}

/// Carries a cloud's region labels to its mesh: every mesh vertex that at least one point
/// maps to (`nearest_vertex[p]`) takes the label of the nearest of those points (ties: the
/// lowest point index); a vertex no point maps to gets `None` and is left out of the scores.
/// `mesh_vertices` only gives the distances.
pub fn transfer_labels(
    mesh_vertices: &[[f64; 3]],
    cloud_points: &[[f64; 3]],
    nearest_vertex: &[u32],
    cloud_labels: &[u32],
) -> Vec<Option<u32>> {
    let mut best: Vec<Option<(f64, u32)>> = vec![None; mesh_vertices.len()];
    for ((p, &v), &label) in cloud_points.iter().zip(nearest_vertex).zip(cloud_labels) {
        let q = mesh_vertices[v as usize];
        let d = (0..3).map(|k| (p[k] - q[k]).powi(2)).sum::<f64>();
        let slot = &mut best[v as usize];
        // Strictly closer only: among equal distances the first (lowest index) point stays.
        if slot.is_none_or(|(d_best, _)| d < d_best) {
            *slot = Some((d, label));
        }
    }
    best.into_iter()
        .map(|b| b.map(|(_, label)| label))
        .collect()
}

/// Region accuracies of a correspondence whose labels may leave vertices out.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TransferredScores {
    /// Accuracy of the symmetric matches (the paper's figure).
    pub symmetric: f64,
    /// Accuracy of the one-to-one matches.
    pub one_to_one: f64,
    /// The better of the one-to-one accuracies against the ground truth and the mirrored
    /// ground truth; None without a mirrored ground truth.
    pub one_to_one_flip: Option<f64>,
    /// Fraction of the ground-truth pairs scored (both ends labelled); with the identity
    /// ground truth of registered shapes, the fraction of mesh vertices scored.
    pub covered: f64,
}

/// Scores region labels on meshes A and B (`None`: vertex left out) against ground-truth
/// pairs `(vertex of A, vertex of B)`, weighted by A's vertex masses `mass_a`: a pair counts
/// only when both of its vertices are labelled, and is then right when B's region is matched
/// to A's ([`region_accuracy`], with the correspondence's own region counts, since regions
/// that no mesh vertex received are still matched). The flipped ground truth is filtered the
/// same way.
#[allow(clippy::too_many_arguments)]
pub fn score_transferred(
    labels_a: &[Option<u32>],
    labels_b: &[Option<u32>],
    n_regions_a: usize,
    n_regions_b: usize,
    mass_a: &[f64],
    matches: &[(u32, u32)],
    matches_one_to_one: &[(u32, u32)],
    truth: &[(u32, u32)],
    flipped: Option<&[(u32, u32)]>,
) -> TransferredScores {
    let covered_pairs = |pairs: &[(u32, u32)]| -> Vec<(u32, u32)> {
        pairs
            .iter()
            .copied()
            .filter(|&(x, y)| labels_a[x as usize].is_some() && labels_b[y as usize].is_some())
            .collect()
    };
    // Left-out vertices take label 0; no kept pair refers to them.
    let plain_a: Vec<u32> = labels_a.iter().map(|l| l.unwrap_or(0)).collect();
    let plain_b: Vec<u32> = labels_b.iter().map(|l| l.unwrap_or(0)).collect();
    let accuracy = |m: &[(u32, u32)], gt: &[(u32, u32)]| {
        region_accuracy(&plain_a, &plain_b, mass_a, n_regions_a, n_regions_b, m, gt)
    };
    let kept = covered_pairs(truth);
    let one_to_one = accuracy(matches_one_to_one, &kept);
    TransferredScores {
        symmetric: accuracy(matches, &kept),
        one_to_one,
        one_to_one_flip: flipped
            .map(|f| one_to_one.max(accuracy(matches_one_to_one, &covered_pairs(f)))),
        covered: kept.len() as f64 / truth.len().max(1) as f64,
    }
}

/// One run of the protocol on one pair.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct CloudTrial {
    pub source: String,
    pub target: String,
    pub category: String,
    /// [`MESH_TO_CLOUD`] or [`CLOUD_TO_CLOUD`].
    pub mode: String,
    /// Points per sampled cloud.
    pub density: usize,
    /// Noise bound, fraction of the shape width.
    pub noise: f64,
    /// Repetition index, from 0.
    pub trial: usize,
    /// Accuracy of the symmetric matches, on the mesh vertices covered by the clouds.
    pub symmetric: f64,
    pub one_to_one: f64,
    pub one_to_one_flip: Option<f64>,
    /// Fraction of the ground-truth pairs scored (see [`TransferredScores::covered`]).
    pub covered: f64,
    pub n_regions_a: usize,
    pub n_regions_b: usize,
    /// Seconds for the trial as if run alone: sampling, both eigenbases (in mesh-to-cloud,
    /// mesh A's eigenbasis is computed once per call and its time added to every trial),
    /// the matching and the scoring.
    pub seconds: f64,
}

/// The seed of one sampled cloud: a 64-bit FNV-1a hash (stable across Rust versions and
/// platforms) of the protocol seed, the pair's names, the side sampled (`"A"` or `"B"`), the
/// density, the noise level's bits and the trial. The mode is left out on purpose: the B
/// cloud of a trial is the same in both modes, so the modes differ only by A's sampling.
pub fn cloud_seed(
    protocol_seed: u64,
    source: &str,
    target: &str,
    side: &str,
    density: usize,
    noise: f64,
    trial: usize,
) -> u64 {
    let mut h = Fnv1a::new();
    h.write(&protocol_seed.to_le_bytes());
    for s in [source, target, side] {
        h.write(&(s.len() as u64).to_le_bytes());
        h.write(s.as_bytes());
    }
    h.write(&(density as u64).to_le_bytes());
    h.write(&noise.to_bits().to_le_bytes());
    h.write(&(trial as u64).to_le_bytes());
    h.0
}

/// 64-bit FNV-1a.
struct Fnv1a(u64);

impl Fnv1a {
    fn new() -> Self {
        Fnv1a(0xcbf2_9ce4_8422_2325)
    }

    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 ^= u64::from(b);
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
}

/// Lumped mass of every input vertex of `shape` (0 for unreferenced vertices).
fn vertex_masses(shape: &Shape) -> Result<Vec<f64>> {
    let laplacian = Laplacian::new(shape)?;
    let mut mass = vec![0.0; shape.n_vertices()];
    for (row, &v) in shape.active_vertices().iter().enumerate() {
        mass[v as usize] = laplacian.mass[row];
    }
    Ok(mass)
}

/// Runs the protocol on one pair of meshes `a` and `b` with ground-truth pairs `truth`
/// `(vertex of A, vertex of B)` (and `flipped`, the mirrored ground truth, for the
/// flip-tolerant score): for each mode of [`MODES`], density, noise level and trial, in that
/// order, unless `skip(mode, density, noise, trial)` (to resume an interrupted run).
/// Mesh-to-cloud samples B; cloud-to-cloud samples both, and carries both clouds' regions back
/// to their meshes. Each trial is scored with [`score_transferred`] (A's vertex masses as
/// weights) and given to `report` as soon as it is done.
///
/// Errors: an invalid `protocol` or `params`, shapes that are not meshes, ground truth out of
/// range, or any failure of the sampling or the correspondence.
#[allow(clippy::too_many_arguments)]
pub fn cloud_trials(
    pair: &Pair,
    a: &Shape,
    b: &Shape,
    truth: &[(u32, u32)],
    flipped: Option<&[(u32, u32)]>,
    protocol: &CloudProtocol,
    params: &Params,
    skip: &dyn Fn(&str, usize, f64, usize) -> bool,
    report: &mut dyn FnMut(&CloudTrial),
) -> Result<Vec<CloudTrial>> {
    protocol.validate()?;
    params.validate()?;
    for (name, shape) in [("a", a), ("b", b)] {
        if shape.kind() != ShapeKind::Mesh {
            return Err(Error::InvalidParameter {
                name,
                reason: "the protocol samples meshes; got a point cloud".into(),
            });
        }
    }
    for pairs in std::iter::once(truth).chain(flipped) {
        if let Some(&(x, y)) = pairs
            .iter()
            .find(|&&(x, y)| x as usize >= a.n_vertices() || y as usize >= b.n_vertices())
        {
            return Err(Error::InvalidParameter {
                name: "truth",
                reason: format!(
                    "pair ({x}, {y}) is out of range for shapes of {} and {} vertices",
                    a.n_vertices(),
                    b.n_vertices()
                ),
            });
        }
    }
    let mass_a = vertex_masses(a)?;
    // Mesh A's eigenbasis, shared by the mesh-to-cloud trials, with its seconds.
    let mut basis_a: Option<(Eigenbasis, f64)> = None;
    let mut results = Vec::new();
    for mode in MODES {
        for &density in &protocol.densities {
            for &noise in &protocol.noise {
                for trial in 0..protocol.trials {
                    if skip(mode, density, noise, trial) {
                        continue;
                    }
                    let seed = |side: &str| {
                        cloud_seed(
                            protocol.seed,
                            &pair.source,
                            &pair.target,
                            side,
                            density,
                            noise,
                            trial,
                        )
                    };
                    let started = Instant::now();
                    let cloud_b = sample_surface(b, density, noise, seed("B"))?;
                    let shape_b = Shape::point_cloud(cloud_b.points.clone())?;
                    let (result, labels_a, extra_seconds) = if mode == MESH_TO_CLOUD {
                        if basis_a.is_none() {
                            let t = Instant::now();
                            let basis = Eigenbasis::compute(a, &params.eigen, &mut NoProgress)?;
                            basis_a = Some((basis, t.elapsed().as_secs_f64()));
                        }
                        let (basis, t_a) = basis_a.as_ref().expect("computed above");
                        let basis_b =
                            Eigenbasis::compute(&shape_b, &params.eigen, &mut NoProgress)?;
                        let result = Correspondence::from_bases(
                            ShapeBasis::new(a, basis),
                            ShapeBasis::new(&shape_b, &basis_b),
                            params,
                            &mut NoProgress,
                        )?;
                        let labels: Vec<Option<u32>> =
                            result.regions_a().iter().map(|&r| Some(r)).collect();
                        (result, labels, *t_a)
                    } else {
                        let cloud_a = sample_surface(a, density, noise, seed("A"))?;
                        let shape_a = Shape::point_cloud(cloud_a.points.clone())?;
                        let result =
                            Correspondence::compute(&shape_a, &shape_b, params, &mut NoProgress)?;
                        let labels = transfer_labels(
                            a.vertices(),
                            &cloud_a.points,
                            &cloud_a.nearest_vertex,
                            result.regions_a(),
                        );
                        (result, labels, 0.0)
                    };
                    let labels_b = transfer_labels(
                        b.vertices(),
                        &cloud_b.points,
                        &cloud_b.nearest_vertex,
                        result.regions_b(),
                    );
                    let (n_a, n_b) = (result.graph_a.n_nodes(), result.graph_b.n_nodes());
                    let scores = score_transferred(
                        &labels_a,
                        &labels_b,
                        n_a,
                        n_b,
                        &mass_a,
                        &result.matches,
                        &result.matches_one_to_one,
                        truth,
                        flipped,
                    );
                    let outcome = CloudTrial {
                        source: pair.source.clone(),
                        target: pair.target.clone(),
                        category: pair.category.clone(),
                        mode: mode.to_string(),
                        density,
                        noise,
                        trial,
                        symmetric: scores.symmetric,
                        one_to_one: scores.one_to_one,
                        one_to_one_flip: scores.one_to_one_flip,
                        covered: scores.covered,
                        n_regions_a: n_a,
                        n_regions_b: n_b,
                        seconds: started.elapsed().as_secs_f64() + extra_seconds,
                    };
                    report(&outcome);
                    results.push(outcome);
                }
            }
        }
    }
    Ok(results)
}

/// Short name of a mode for legends: "MTC" and "PC" as in the paper's figure.
fn mode_label(mode: &str) -> &str {
    match mode {
        MESH_TO_CLOUD => "MTC",
        CLOUD_TO_CLOUD => "PC",
        other => other,
    }
}

/// The distinct modes (in [`MODES`] order, unknown ones after), noise levels (ascending) and
/// densities (descending, as the paper lists them) of `results`.
fn axes(results: &[CloudTrial]) -> (Vec<String>, Vec<f64>, Vec<usize>) {
    let mut modes: Vec<String> = Vec::new();
    for m in MODES
        .iter()
        .map(|m| m.to_string())
        .chain(results.iter().map(|r| r.mode.clone()))
    {
        if results.iter().any(|r| r.mode == m) && !modes.contains(&m) {
            modes.push(m);
        }
    }
    let mut noise: Vec<f64> = results.iter().map(|r| r.noise).collect();
    noise.sort_by(f64::total_cmp);
    noise.dedup();
    let densities: BTreeSet<usize> = results.iter().map(|r| r.density).collect();
    (modes, noise, densities.into_iter().rev().collect())
}

/// A value read from a trial (None where the trial lacks it).
type Measure = dyn Fn(&CloudTrial) -> Option<f64>;

/// Mean of `f` over the trials of (mode, noise, density); None when there are none or `f`
/// is None for one of them.
fn cell(
    results: &[CloudTrial],
    mode: &str,
    noise: f64,
    density: usize,
    f: &Measure,
) -> Option<f64> {
    let values: Option<Vec<f64>> = results
        .iter()
        .filter(|r| r.mode == mode && r.noise == noise && r.density == density)
        .map(f)
        .collect();
    let values = values?;
    (!values.is_empty()).then(|| values.iter().sum::<f64>() / values.len() as f64)
}

/// The results as markdown: two tables (mean symmetric accuracy, then mean one-to-one
/// accuracy with flips allowed), rows = (mode, noise), columns = densities, cells = mean over
/// pairs and trials; then the mean covered fraction and seconds per trial, and the
/// mesh-to-mesh accuracy of the same pairs when given.
pub fn cloud_table(results: &[CloudTrial], mesh_accuracy: Option<f64>) -> String {
    let (modes, noise, densities) = axes(results);
    let mut out = String::new();
    let tables: [(&str, &Measure); 2] = [
        ("symmetric accuracy", &|r| Some(r.symmetric)),
        ("one-to-one accuracy (flip ok)", &|r| r.one_to_one_flip),
    ];
    for (title, f) in tables {
        let _ = write!(out, "| {title} | noise |");
        for d in &densities {
            let _ = write!(out, " {d} |");
        }
        let _ = writeln!(out);
        let _ = writeln!(out, "|---|---|{}", "---|".repeat(densities.len()));
        for mode in &modes {
            for &n in &noise {
                let _ = write!(out, "| {mode} | {:.0}% |", 100.0 * n);
                for &d in &densities {
                    match cell(results, mode, n, d, f) {
                        Some(v) => {
                            let _ = write!(out, " {v:.3} |");
                        }
                        None => {
                            let _ = write!(out, " n/a |");
                        }
                    }
                }
                let _ = writeln!(out);
            }
        }
        let _ = writeln!(out);
    }
    let n = results.len().max(1) as f64;
    let _ = writeln!(
        out,
        "{} trials; mean fraction of ground-truth pairs scored {:.3}; {:.2} s per trial",
        results.len(),
        results.iter().map(|r| r.covered).sum::<f64>() / n,
        results.iter().map(|r| r.seconds).sum::<f64>() / n,
    );
    if let Some(m) = mesh_accuracy {
        let _ = writeln!(out, "mesh-to-mesh symmetric accuracy: {m:.3}");
    }
    out
}

/// The paper's figure as a PNG at `path`: x = points per cloud, y = mean symmetric accuracy,
/// one line per (mode, noise) labelled like "MTC 1%" / "PC 2%", and the mesh-to-mesh
/// accuracy as a flat two-point line "mesh" when given. The y axis runs from the lowest
/// value (rounded down to 0.1) to 1.
///
/// Errors: `InvalidParameter` when `results` is empty or there are more lines than
/// [`crate::plot::PALETTE`] has colours; as [`line_chart_png`] otherwise.
pub fn cloud_figure(
    path: &Path,
    results: &[CloudTrial],
    mesh_accuracy: Option<f64>,
) -> Result<Rendered> {
    if results.is_empty() {
        return Err(Error::InvalidParameter {
            name: "results",
            reason: "no trials to draw".into(),
        });
    }
    let (modes, noise, densities) = axes(results);
    let (d_min, d_max) = (
        *densities.last().expect("results is not empty") as f64,
        densities[0] as f64,
    );
    let mut series = Vec::new();
    for mode in &modes {
        for &n in &noise {
            let points: Vec<(f64, f64)> = densities
                .iter()
                .rev()
                .filter_map(|&d| {
                    cell(results, mode, n, d, &|r| Some(r.symmetric)).map(|v| (d as f64, v))
                })
                .collect();
            if !points.is_empty() {
                series.push(Series {
                    label: format!("{} {:.0}%", mode_label(mode), 100.0 * n),
                    points,
                });
            }
        }
    }
    // A single density still gets an x range of some width.
    let pad = ((d_max - d_min) * 0.05).max(0.05 * d_max).max(1.0);
    let x_range = (d_min - pad, d_max + pad);
    if let Some(m) = mesh_accuracy {
        series.push(Series {
            label: "mesh".into(),
            points: vec![(x_range.0, m), (x_range.1, m)],
        });
    }
    let lowest = series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.1))
        .fold(1.0, f64::min);
    let y_low = ((lowest * 10.0).floor() / 10.0).clamp(0.0, 0.9);
    line_chart_png(
        path,
        &Chart {
            title: "Region matching on point clouds",
            x_label: "number of points",
            y_label: "accuracy (symmetric)",
            x_range,
            y_range: (y_low, 1.0),
        },
        &series,
    )
}
