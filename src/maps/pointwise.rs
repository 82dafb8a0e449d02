//! Point-to-point maps from region correspondences (docs/design.md, step 13, paper section 6.4):
//! the matched regions' indicator functions (optionally heat-diffused, optionally with WKS
//! or HKS) constrain a functional map, which is converted to a vertex map and refined by
//! ZoomOut (beyond the paper). See [`crate::maps::fmap`] for the building blocks.
//!
//! Direction: the output `p2p_ba[v]` is the vertex of A matched to vertex `v` of B
//! (`map_b_to_a.txt`); `fmap_ab` maps functions on A to functions on B.

use std::time::Instant;

use faer::Mat;
use rayon::prelude::*;

use crate::correspondence::{Correspondence, Params};
use crate::maps::fmap::{
    fmap_to_p2p, icp_refine, multiplication_operators, orientation_operators, project,
    solve_fmap_commuting, zoomout, zoomout_on_samples, Commutativity, SampledZoomOut,
    ZoomOutParams,
};
use crate::progress::{check, Progress, Stage};
use crate::shape::Shape;
use crate::spectral::descriptors::{hks, wks, HksParams, WksParams};
use crate::spectral::eigen::{EigenParams, Eigenbasis};
use crate::{Error, Result};

/// Which region matches constrain the functional map.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RegionConstraints {
    /// No region constraint (descriptors only).
    None,
    /// One indicator pair per one-to-one match (the paper's SEGS).
    OneToOne,
    /// One indicator pair per group of symmetric matches (connected component of the
    /// bipartite match graph: the union of its regions on each side; the paper's SYM).
    Symmetric,
}

/// How the first functional map is refined.
#[derive(Debug, Clone, PartialEq)]
pub enum Refinement {
    /// The first functional map's vertex map, unrefined.
    None,
    /// ZoomOut (Melzi et al. 2019) up to `k_end` eigenfunctions.
    ZoomOut(ZoomOutParams),
    /// Spectral ICP (Ovsjanikov et al. 2012) for at most this many iterations.
    Icp(usize),
}

/// Parameters of the pointwise map. The defaults are the documented ones.
#[derive(Debug, Clone, PartialEq)]
pub struct PointwiseParams {
    /// Eigenpairs computed per shape (the largest basis any stage uses; region matching
    /// uses the first [`Params::eigen`]`.n_eigenpairs` of them).
    pub n_eigenpairs: usize,
    /// Size of the first functional map (k x k).
    pub fmap_size: usize,
    /// Region constraints.
    pub regions: RegionConstraints,
    /// Heat-diffusion times of the region indicators on the unit-area shape (0 = the plain
    /// indicator); each time adds one descriptor per region pair.
    pub region_times: Vec<f64>,
    /// Also constrain the map by each region set's distance function (edge-graph geodesic
    /// distance from the set, on the unit-area shape).
    pub region_distances: bool,
    /// WKS descriptors (the paper's WKS and WKS + SEGS), every `descriptor_step`-th energy.
    pub wks: Option<WksParams>,
    /// HKS descriptors (the paper's HKS), every `descriptor_step`-th time.
    pub hks: Option<HksParams>,
    /// Keep every n-th WKS/HKS column (pyFM's `subsample_step`).
    pub descriptor_step: usize,
    /// Weight of the Laplacian commutativity term (eigenvalue differences normalised).
    pub laplacian_weight: f64,
    /// Weight of the descriptor commutativity term (Nogneng and Ovsjanikov 2017): the map
    /// commutes with multiplication by every undiffused descriptor (0 = off).
    pub descriptor_commutativity: f64,
    /// Weight of the orientation-preserving term (Ren et al. 2018): the map commutes with
    /// every undiffused descriptor's orientation operator `g -> <n x grad f, grad g>`.
    /// Used on orientable meshes (faces taken as [`Shape::oriented_triangles`]), not on
    /// point clouds (0 = off).
    pub orientation_term: f64,
    /// Refinement of the first map.
    pub refinement: Refinement,
    /// For orientable meshes, choose between the one-to-one region answer and its mirror
    /// image (another choice in every symmetric group): both are solved (with the
    /// orientation term) and refined by ZoomOut on the samples, and the map with the larger
    /// product of A's samples reached and B's sample triangles keeping their orientation
    /// wins; only the winner is converted at full resolution.
    pub orientation: bool,
}

impl Default for PointwiseParams {
    fn default() -> Self {
        PointwiseParams {
            n_eigenpairs: 100,
            fmap_size: 40,
            regions: RegionConstraints::OneToOne,
            region_times: vec![0.0],
            region_distances: true,
            wks: None,
            hks: None,
            descriptor_step: 5,
            laplacian_weight: 1.0,
            descriptor_commutativity: 0.0,
            orientation_term: 0.003,
            refinement: Refinement::ZoomOut(ZoomOutParams::default()),
            orientation: true,
        }
    }
}

impl PointwiseParams {
    /// Checks every field's range.
    pub fn validate(&self) -> Result<()> {
        let bad = |name, reason: String| Err(Error::InvalidParameter { name, reason });
        if self.fmap_size < 2 || self.fmap_size > self.n_eigenpairs {
            return bad(
                "pointwise.fmap_size",
                format!(
                    "need 2 <= fmap_size <= n_eigenpairs ({}), got {}",
                    self.n_eigenpairs, self.fmap_size
                ),
            );
        }
        if self
            .region_times
            .iter()
            .any(|t| !(*t >= 0.0 && t.is_finite()))
        {
            return bad(
                "pointwise.region_times",
                format!("need finite times >= 0, got {:?}", self.region_times),
            );
        }
        if self.regions != RegionConstraints::None && self.region_times.is_empty() {
            return bad(
                "pointwise.region_times",
                "region constraints need at least one time".into(),
            );
        }
        if self.regions == RegionConstraints::None && self.wks.is_none() && self.hks.is_none() {
            return bad(
                "pointwise.descriptors",
                "choose regions, WKS or HKS (none given)".into(),
            );
        }
        if self.descriptor_step == 0 {
            return bad("pointwise.descriptor_step", "must be at least 1".into());
        }
        for (name, weight) in [
            (
                "pointwise.descriptor_commutativity",
                self.descriptor_commutativity,
            ),
            ("pointwise.orientation_term", self.orientation_term),
            ("pointwise.laplacian_weight", self.laplacian_weight),
        ] {
            if !(weight >= 0.0 && weight.is_finite()) {
                return bad(name, format!("must be finite and >= 0, got {weight}"));
            }
        }
        match &self.refinement {
            Refinement::ZoomOut(z)
                if z.step == 0 || z.k_end < self.fmap_size || z.k_end > self.n_eigenpairs =>
            {
                bad(
                    "pointwise.zoomout",
                    format!(
                        "need step >= 1 and fmap_size ({}) <= k_end ({}) <= n_eigenpairs ({})",
                        self.fmap_size, z.k_end, self.n_eigenpairs
                    ),
                )
            }
            _ => Ok(()),
        }
    }
}

/// Seconds per stage of the pointwise map.
#[derive(Debug, Clone, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PointwiseTimings {
    /// Descriptors and the first functional map.
    pub fmap: f64,
    /// Its conversion to a vertex map and the refinement.
    pub refinement: f64,
}

/// A point-to-point map from B to A.
#[derive(Debug, Clone)]
pub struct PointwiseMap {
    /// `p2p_ba[v]`: the vertex of A matched to vertex `v` of B.
    pub p2p_ba: Vec<u32>,
    /// The final functional map from A to B (`k x k`).
    pub fmap_ab: Mat<f64>,
    /// Seconds of the first functional map and of its refinement.
    pub timings: PointwiseTimings,
}

impl PointwiseMap {
    /// The pointwise map between two shapes whose eigenbases are given (each with at least
    /// `params.n_eigenpairs` pairs, or all the shape has), with the region correspondence
    /// `regions` (needed unless `params.regions` is `None`).
    pub fn from_bases(
        a: &Shape,
        basis_a: &Eigenbasis,
        b: &Shape,
        basis_b: &Eigenbasis,
        regions: Option<&Correspondence>,
        params: &PointwiseParams,
    ) -> Result<PointwiseMap> {
        params.validate()?;
        let started = Instant::now();
        let k = params.fmap_size.min(basis_a.len()).min(basis_b.len());
        let groups = constraint_groups(regions, params.regions)?;
        // Both shapes' faces consistently oriented (None for point clouds and
        // non-orientable surfaces): the orientation term and the mirror decision need them.
        // A one-to-one region answer may be the mirror image of the truth (paper, section
        // 5.2): on orientable meshes, its mirror image is a second candidate.
        let faces = if params.orientation || params.orientation_term > 0.0 {
            a.oriented_triangles().zip(b.oriented_triangles())
        } else {
            None
        };
        let mirror = match (regions, params.regions, &faces) {
            (Some(regions), RegionConstraints::OneToOne, Some(_)) if params.orientation => {
                Some(mirrored_groups(a, basis_a, b, basis_b, regions)).filter(|m| *m != groups)
            }
            _ => None,
        };
        let candidates: Vec<&[(Vec<u32>, Vec<u32>)]> = std::iter::once(groups.as_slice())
            .chain(mirror.as_deref())
            .collect();
        let orientation_faces = faces
            .as_ref()
            .filter(|_| params.orientation_term > 0.0)
            .map(|(fa, fb)| (fa.as_slice(), fb.as_slice()));
        let features = Features::new(
            (a, basis_a),
            (b, basis_b),
            regions,
            &candidates,
            orientation_faces,
            params,
            k,
        )?;
        let fmaps = (0..candidates.len())
            .map(|c| features.solve(c, basis_a, basis_b, params))
            .collect::<Result<Vec<_>>>()?;
        let t_fmap = started.elapsed().as_secs_f64();
        let t = Instant::now();
        let (fmap_ab, p2p_ba) = match &faces {
            Some(faces) if fmaps.len() > 1 => {
                let bases = (basis_a, basis_b);
                orientation_winner((a, b), bases, faces, &fmaps, params, k)?
            }
            _ => refine(&fmaps[0], (basis_a, basis_b), params, k)?,
        };
        Ok(PointwiseMap {
            p2p_ba,
            fmap_ab,
            timings: PointwiseTimings {
                fmap: t_fmap,
                refinement: t.elapsed().as_secs_f64(),
            },
        })
    }
}

/// The region constraints of the map: the groups of matched regions (none for
/// [`RegionConstraints::None`]).
fn constraint_groups(
    regions: Option<&Correspondence>,
    kind: RegionConstraints,
) -> Result<Vec<(Vec<u32>, Vec<u32>)>> {
    if kind == RegionConstraints::None {
        return Ok(Vec::new());
    }
    let regions = regions.ok_or(Error::InvalidParameter {
        name: "regions",
        reason: "region constraints need a region correspondence".into(),
    })?;
    let groups = region_groups(regions, kind);
    if groups.is_empty() {
        return Err(Error::InvalidParameter {
            name: "regions",
            reason: "the region correspondence has no match to constrain the map".into(),
        });
    }
    Ok(groups)
}

/// ZoomOut's settings up to what both bases have, and at least the first map's size `k`.
fn clamped(
    z: &ZoomOutParams,
    (basis_a, basis_b): (&Eigenbasis, &Eigenbasis),
    k: usize,
) -> ZoomOutParams {
    ZoomOutParams {
        k_end: z.k_end.min(basis_a.len()).min(basis_b.len()).max(k),
        ..z.clone()
    }
}

/// The chosen refinement of one functional map: the refined map and its vertex map.
fn refine(
    fmap: &Mat<f64>,
    (basis_a, basis_b): (&Eigenbasis, &Eigenbasis),
    params: &PointwiseParams,
    k: usize,
) -> Result<(Mat<f64>, Vec<u32>)> {
    let (phi_a, phi_b) = (basis_a.vectors.as_ref(), basis_b.vectors.as_ref());
    match &params.refinement {
        Refinement::None => Ok((fmap.clone(), fmap_to_p2p(fmap.as_ref(), phi_a, phi_b))),
        Refinement::ZoomOut(z) => zoomout(
            fmap.as_ref(),
            phi_a,
            &basis_a.mass,
            phi_b,
            &basis_b.mass,
            &clamped(z, (basis_a, basis_b), k),
        ),
        Refinement::Icp(iterations) => icp_refine(
            fmap.as_ref(),
            phi_a,
            &basis_a.mass,
            phi_b,
            &basis_b.mass,
            *iterations,
            ZoomOutParams::default().sample_size,
        ),
    }
}

/// The candidate functional maps `fmaps` (the answer and its mirror image) decided by
/// orientation on consistently oriented meshes (`faces` of A and B), refined: the final map
/// and its vertex map.
fn orientation_winner(
    (a, b): (&Shape, &Shape),
    (basis_a, basis_b): (&Eigenbasis, &Eigenbasis),
    (faces_a, faces_b): &(Vec<[u32; 3]>, Vec<[u32; 3]>),
    fmaps: &[Mat<f64>],
    params: &PointwiseParams,
    k: usize,
) -> Result<(Mat<f64>, Vec<u32>)> {
    let (phi_a, phi_b) = (basis_a.vectors.as_ref(), basis_b.vectors.as_ref());
    // The answer and its mirror image, each refined by ZoomOut on the samples.
    // The orientation term makes the candidate whose regions agree with the
    // orientation a consistent map, and the other a compromise that folds part
    // of the shape onto itself or turns it over: it reaches fewer of A's
    // samples, or keeps the orientation of fewer triangles. Only the winner is
    // converted at full resolution.
    let decision = match &params.refinement {
        Refinement::ZoomOut(z) => z.clone(),
        _ => ZoomOutParams::default(),
    };
    let mut sampled = fmaps
        .iter()
        .map(|fmap| {
            zoomout_on_samples(
                fmap.as_ref(),
                phi_a,
                &basis_a.mass,
                phi_b,
                &basis_b.mass,
                &clamped(&decision, (basis_a, basis_b), k),
            )
        })
        .collect::<Result<Vec<_>>>()?;
    // Every candidate ran on the same samples (fixed seeds).
    let triangles_b = sample_triangles(
        b.vertices(),
        &vertex_normals(b.vertices(), faces_b),
        &sampled[0].sample_b.vertices,
    );
    let normals_a = vertex_normals(a.vertices(), faces_a);
    let score: Vec<f64> = sampled
        .iter()
        .map(|s| sample_consistency((a.vertices(), &normals_a), &triangles_b, s))
        .collect();
    let mut best = argmax(&score);
    let runner_up = (0..score.len())
        .filter(|&c| c != best)
        .map(|c| score[c])
        .fold(0.0, f64::max);
    // A close call is decided at full resolution: every candidate converted,
    // A's vertices reached times B's triangles keeping their orientation.
    let mut full: Vec<Option<Vec<u32>>> = vec![None; sampled.len()];
    if score[best] < CLOSE_CALL * runner_up {
        let full_score: Vec<f64> = sampled
            .iter()
            .zip(&mut full)
            .map(|(s, slot)| {
                let p2p = fmap_to_p2p(s.fmap_ab.as_ref(), phi_a, phi_b);
                let covered = covered_vertices(&p2p, a.n_vertices()) as f64;
                let kept = orientation_kept((a.vertices(), &normals_a), faces_b, &p2p);
                *slot = Some(p2p);
                covered * kept.unwrap_or(0.0)
            })
            .collect();
        best = argmax(&full_score);
    }
    Ok(match &params.refinement {
        Refinement::ZoomOut(_) => {
            let fmap = sampled.swap_remove(best).fmap_ab;
            let p2p = full
                .swap_remove(best)
                .unwrap_or_else(|| fmap_to_p2p(fmap.as_ref(), phi_a, phi_b));
            (fmap, p2p)
        }
        _ => refine(&fmaps[best], (basis_a, basis_b), params, k)?,
    })
}

/// Number of distinct vertices of A that the map reaches.
fn covered_vertices(p2p_ba: &[u32], n_a: usize) -> usize {
    let mut hit = vec![false; n_a];
    for &v in p2p_ba {
        hit[v as usize] = true;
    }
    hit.into_iter().filter(|&h| h).count()
}

/// The index of the largest score (the first among equals).
fn argmax(scores: &[f64]) -> usize {
    (1..scores.len()).fold(0, |best, c| if scores[c] > scores[best] { c } else { best })
}

/// The mirror decision is a close call when the winner's sample score is below this many
/// times the runner-up's; it is then made at full resolution. On 74 FAUST and TOSCA pairs
/// the sample and the full-resolution decisions agreed, the closest sample margin 0.2%
/// (six TOSCA pairs within 5%, no FAUST pair).
const CLOSE_CALL: f64 = 1.05;

/// Descriptor columns of one shape, computed once for every region set any candidate uses.
struct SideFeatures {
    /// Per region set: its coefficient columns (first `k`): the indicator diffused for each
    /// of `region_times`, then the distance function when asked for.
    set_coef: Vec<Mat<f64>>,
    /// Per region set: the multiplication and orientation operators of its undiffused
    /// functions (when the terms are on).
    set_multiplication: Vec<Vec<Mat<f64>>>,
    set_orientation: Vec<Vec<Mat<f64>>>,
    /// WKS and HKS columns (the same for every candidate).
    point_coef: Vec<Mat<f64>>,
    point_multiplication: Vec<Mat<f64>>,
    point_orientation: Vec<Mat<f64>>,
}

impl SideFeatures {
    #[allow(clippy::too_many_arguments)]
    fn new(
        shape: &Shape,
        basis: &Eigenbasis,
        labels: Option<(&[u32], usize)>,
        sets: &[Vec<u32>],
        params: &PointwiseParams,
        k: usize,
        with_multiplication: bool,
        oriented_faces: Option<&[[u32; 3]]>,
    ) -> Result<SideFeatures> {
        let operators = |functions: faer::MatRef<'_, f64>| -> (Vec<Mat<f64>>, Vec<Mat<f64>>) {
            let multiplication = if with_multiplication {
                multiplication_operators(basis.vectors.as_ref(), &basis.mass, k, functions)
            } else {
                Vec::new()
            };
            let orientation = oriented_faces.map_or(Vec::new(), |faces| {
                orientation_operators(basis.vectors.as_ref(), k, faces, functions)
            });
            (multiplication, orientation)
        };
        let mut features = SideFeatures {
            set_coef: Vec::new(),
            set_multiplication: Vec::new(),
            set_orientation: Vec::new(),
            point_coef: Vec::new(),
            point_multiplication: Vec::new(),
            point_orientation: Vec::new(),
        };
        if let (Some((labels, n_regions)), false) = (labels, sets.is_empty()) {
            let indicators = indicators(labels, n_regions, sets);
            let distances = params
                .region_distances
                .then(|| distance_functions(shape, basis, indicators.as_ref()));
            let diffused: Vec<Mat<f64>> = params
                .region_times
                .iter()
                .map(|&t| diffused(basis, k, indicators.as_ref(), t))
                .collect();
            let projected_distances = distances
                .as_ref()
                .map(|d| project(basis.vectors.as_ref(), &basis.mass, k, d.as_ref()));
            // Each set's undiffused functions side by side: its indicator, then its distance.
            let per_set = 1 + usize::from(distances.is_some());
            let functions = Mat::from_fn(shape.n_vertices(), sets.len() * per_set, |v, j| {
                match (j % per_set, &distances) {
                    (1, Some(d)) => d[(v, j / per_set)],
                    _ => indicators[(v, j / per_set)],
                }
            });
            let (multiplication, orientation) = operators(functions.as_ref());
            let chunk = |ops: &[Mat<f64>], s: usize| {
                ops.get(s * per_set..(s + 1) * per_set)
                    .map_or(Vec::new(), <[Mat<f64>]>::to_vec)
            };
            for s in 0..sets.len() {
                let mut columns: Vec<faer::ColRef<'_, f64>> =
                    diffused.iter().map(|c| c.col(s)).collect();
                columns.extend(projected_distances.as_ref().map(|d| d.col(s)));
                features
                    .set_coef
                    .push(Mat::from_fn(k, columns.len(), |i, j| columns[j][i]));
                features.set_multiplication.push(chunk(&multiplication, s));
                features.set_orientation.push(chunk(&orientation, s));
            }
        }
        let point = [
            params.wks.as_ref().map(|w| wks(basis, w)),
            params.hks.as_ref().map(|h| hks(basis, h)),
        ];
        for descriptor in point.into_iter().flatten() {
            let chosen = every_column(&descriptor?, params.descriptor_step);
            features.point_coef.push(project(
                basis.vectors.as_ref(),
                &basis.mass,
                k,
                chosen.as_ref(),
            ));
            let (m, o) = operators(chosen.as_ref());
            features.point_multiplication.extend(m);
            features.point_orientation.extend(o);
        }
        Ok(features)
    }
}

/// Both shapes' consistently oriented faces (A's, then B's).
type FacePair<'a> = (&'a [[u32; 3]], &'a [[u32; 3]]);

/// The descriptors of both shapes for every candidate set of region groups.
struct Features {
    a: SideFeatures,
    b: SideFeatures,
    /// For every candidate, each group's set index on A and on B.
    candidates: Vec<Vec<(usize, usize)>>,
}

impl Features {
    /// `orientation_faces`: both shapes' consistently oriented faces when the orientation
    /// term is on.
    fn new(
        (a, basis_a): (&Shape, &Eigenbasis),
        (b, basis_b): (&Shape, &Eigenbasis),
        regions: Option<&Correspondence>,
        candidates: &[&[(Vec<u32>, Vec<u32>)]],
        orientation_faces: Option<FacePair<'_>>,
        params: &PointwiseParams,
        k: usize,
    ) -> Result<Features> {
        let (mut sets_a, mut sets_b) = (Vec::new(), Vec::new());
        let index = |sets: &mut Vec<Vec<u32>>, set: &Vec<u32>| {
            sets.iter().position(|s| s == set).unwrap_or_else(|| {
                sets.push(set.clone());
                sets.len() - 1
            })
        };
        let pairs: Vec<Vec<(usize, usize)>> = candidates
            .iter()
            .map(|groups| {
                groups
                    .iter()
                    .map(|(ga, gb)| (index(&mut sets_a, ga), index(&mut sets_b, gb)))
                    .collect()
            })
            .collect();
        let multiplication = params.descriptor_commutativity > 0.0;
        let side = |shape, basis, labels, sets: &[Vec<u32>], faces| {
            SideFeatures::new(shape, basis, labels, sets, params, k, multiplication, faces)
        };
        let labels_a = regions.map(|r| (r.regions_a(), r.graph_a.n_nodes()));
        let labels_b = regions.map(|r| (r.regions_b(), r.graph_b.n_nodes()));
        Ok(Features {
            a: side(
                a,
                basis_a,
                labels_a,
                &sets_a,
                orientation_faces.map(|f| f.0),
            )?,
            b: side(
                b,
                basis_b,
                labels_b,
                &sets_b,
                orientation_faces.map(|f| f.1),
            )?,
            candidates: pairs,
        })
    }

    /// The functional map of candidate `c`.
    fn solve(
        &self,
        c: usize,
        basis_a: &Eigenbasis,
        basis_b: &Eigenbasis,
        params: &PointwiseParams,
    ) -> Result<Mat<f64>> {
        let pairs = &self.candidates[c];
        let gather = |side: &SideFeatures, a_side: bool| {
            let sets = || pairs.iter().map(move |&(i, j)| if a_side { i } else { j });
            let coef: Vec<Mat<f64>> = sets()
                .map(|s| side.set_coef[s].clone())
                .chain(side.point_coef.iter().cloned())
                .collect();
            let multiplication: Vec<Mat<f64>> = sets()
                .flat_map(|s| side.set_multiplication[s].iter().cloned())
                .chain(side.point_multiplication.iter().cloned())
                .collect();
            let orientation: Vec<Mat<f64>> = sets()
                .flat_map(|s| side.set_orientation[s].iter().cloned())
                .chain(side.point_orientation.iter().cloned())
                .collect();
            (normalised_columns(&coef), multiplication, orientation)
        };
        let (coef_a, multiplication_a, orientation_a) = gather(&self.a, true);
        let (coef_b, multiplication_b, orientation_b) = gather(&self.b, false);
        solve_fmap_commuting(
            coef_a.as_ref(),
            coef_b.as_ref(),
            &basis_a.values,
            &basis_b.values,
            params.laplacian_weight,
            &[
                Commutativity {
                    operators_a: &multiplication_a,
                    operators_b: &multiplication_b,
                    weight: params.descriptor_commutativity,
                },
                Commutativity {
                    operators_a: &orientation_a,
                    operators_b: &orientation_b,
                    weight: params.orientation_term,
                },
            ],
        )
    }
}

/// Small triangles of B's samples: each sample with its two nearest samples, as positions
/// in `samples_b`, and whether it turns counter-clockwise about B's vertex normals
/// (degenerate ones left out).
fn sample_triangles(
    vb: &[[f64; 3]],
    normals_b: &[[f64; 3]],
    samples_b: &[u32],
) -> Vec<([usize; 3], bool)> {
    let points: Vec<[f64; 3]> = samples_b.iter().map(|&v| vb[v as usize]).collect();
    let tree = crate::shape::neighbors::PointTree::new(&points);
    let mut triangles = Vec::with_capacity(points.len());
    for (s, p) in points.iter().enumerate() {
        let near: Vec<usize> = tree
            .nearest_k(p, 3)
            .into_iter()
            .map(|(j, _)| j)
            .filter(|&j| j != s)
            .take(2)
            .collect();
        if let [j, l] = near[..] {
            let corners = [s, j, l];
            let turn = signed_turn(vb, corners.map(|c| samples_b[c] as usize), normals_b);
            if turn != 0.0 {
                triangles.push((corners, turn > 0.0));
            }
        }
    }
    triangles
}

/// How consistent a map refined on samples is, without converting it at full resolution:
/// the fraction of A's sample vertices that B's samples reach, times the fraction of B's
/// [`sample_triangles`] whose image keeps its orientation (judged by A's vertex normals of
/// its oriented faces). A map that folds part of the shape onto itself reaches fewer
/// samples; one that turns part of it over reverses more triangles.
fn sample_consistency(
    (va, normals_a): (&[[f64; 3]], &[[f64; 3]]),
    triangles_b: &[([usize; 3], bool)],
    sampled: &SampledZoomOut,
) -> f64 {
    let coverage = covered_vertices(&sampled.p2p_ba, va.len()) as f64
        / sampled.sample_a.vertices.len().max(1) as f64;
    let (mut kept, mut total) = (0usize, 0usize);
    for (corners, counter_clockwise) in triangles_b {
        let images = corners.map(|c| sampled.p2p_ba[c] as usize);
        let turn = signed_turn(va, images, normals_a);
        if turn != 0.0 {
            total += 1;
            if (turn > 0.0) == *counter_clockwise {
                kept += 1;
            }
        }
    }
    coverage * kept as f64 / total.max(1) as f64
}

/// Fraction of B's triangles whose image under `p2p_ba` keeps its orientation on A
/// (the mapped triangle's normal agrees with A's vertex normals there), both shapes' faces
/// taken as [`Shape::oriented_triangles`]; `None` when either shape is a point cloud or
/// not orientable, or no triangle maps to a proper triangle.
pub fn orientation_score(a: &Shape, b: &Shape, p2p_ba: &[u32]) -> Option<f64> {
    let normals_a = vertex_normals(a.vertices(), &a.oriented_triangles()?);
    orientation_kept((a.vertices(), &normals_a), &b.oriented_triangles()?, p2p_ba)
}

/// [`orientation_score`] with A's vertex normals ([`vertex_normals`] of its oriented faces)
/// and B's oriented faces given.
fn orientation_kept(
    (va, normals_a): (&[[f64; 3]], &[[f64; 3]]),
    triangles_b: &[[u32; 3]],
    p2p_ba: &[u32],
) -> Option<f64> {
    let (mut kept, mut total) = (0usize, 0usize);
    for t in triangles_b {
        let turn = signed_turn(va, t.map(|v| p2p_ba[v as usize] as usize), normals_a);
        if turn != 0.0 {
            total += 1;
            if turn > 0.0 {
                kept += 1;
            }
        }
    }
    (total > 0).then(|| kept as f64 / total as f64)
}

/// Area-weighted vertex normals (not normalised) of oriented faces.
fn vertex_normals(vertices: &[[f64; 3]], faces: &[[u32; 3]]) -> Vec<[f64; 3]> {
    let mut normals = vec![[0.0; 3]; vertices.len()];
    for t in faces {
        let [p, q, r] = t.map(|v| vertices[v as usize]);
        let n = crate::shape::cross(&crate::shape::sub(&q, &p), &crate::shape::sub(&r, &p));
        for &v in t {
            for c in 0..3 {
                normals[v as usize][c] += n[c];
            }
        }
    }
    normals
}

/// The triangle of three vertices, seen against their summed vertex normals: positive when it
/// turns counter-clockwise about them, negative when clockwise, 0 when two corners coincide.
fn signed_turn(vertices: &[[f64; 3]], c: [usize; 3], normals: &[[f64; 3]]) -> f64 {
    if c[0] == c[1] || c[1] == c[2] || c[0] == c[2] {
        return 0.0;
    }
    let [p, q, r] = c.map(|v| vertices[v]);
    let n = crate::shape::cross(&crate::shape::sub(&q, &p), &crate::shape::sub(&r, &p));
    let reference: [f64; 3] =
        std::array::from_fn(|i| normals[c[0]][i] + normals[c[1]][i] + normals[c[2]][i]);
    crate::shape::dot(&n, &reference)
}

/// Largest number of alternative matchings (besides the current one) enumerated for one
/// symmetric group when looking for the mirror-image answer (a 4x4 group of two left/right
/// pairs has 23); a group with more keeps its current matching.
const MIRROR_OPTIONS_CAP: usize = 5040;

/// The mirror image of the one-to-one answer: in every symmetric group with a choice, a
/// different matching of the same size (for a left/right pair: the swap), the groups chosen
/// together to minimise the distortion of region distances
/// ([`crate::regions::symmetry::distortion_energy`]) by a few sweeps of coordinate descent. A region
/// may keep its partner: a centaur's group of two arms and a middle region mirrors by
/// swapping the arms only (requiring every pair to change, as this did before, left such
/// groups no true mirror, and the centaurs' maps mirrored). Returned as one-to-one groups;
/// equal to `groups` when no group has a choice.
fn mirrored_groups(
    a: &Shape,
    basis_a: &Eigenbasis,
    b: &Shape,
    basis_b: &Eigenbasis,
    regions: &Correspondence,
) -> Vec<(Vec<u32>, Vec<u32>)> {
    let current = &regions.matches_one_to_one;
    let mut fixed: Vec<(u32, u32)> = Vec::new();
    let mut choices: Vec<Vec<Vec<(u32, u32)>>> = Vec::new();
    for (ra, rb) in crate::regions::symmetry::bipartite_groups(&regions.matches) {
        let in_group = |p: &(u32, u32)| ra.binary_search(&p.0).is_ok();
        let mut mine: Vec<(u32, u32)> = current.iter().copied().filter(in_group).collect();
        mine.sort_unstable();
        let edges: Vec<(u32, u32)> = regions.matches.iter().copied().filter(in_group).collect();
        let (options, complete) =
            crate::regions::symmetry::max_matchings(&ra, &rb, &edges, MIRROR_OPTIONS_CAP + 1);
        // Each option lists its pairs by ascending A region, as `mine` does.
        let full: Vec<Vec<(u32, u32)>> = options
            .into_iter()
            .filter(|m| m.len() == mine.len() && *m != mine)
            .collect();
        if ra.len() + rb.len() <= 2 || full.is_empty() || !complete {
            fixed.extend(mine);
        } else {
            choices.push(full);
        }
    }
    if choices.is_empty() {
        return current.iter().map(|&(i, j)| (vec![i], vec![j])).collect();
    }
    let d_a = crate::geodesic::region_distance_matrix(
        a,
        &basis_a.mass,
        regions.regions_a(),
        regions.graph_a.n_nodes(),
        1.0 / basis_a.input_area.sqrt(),
    );
    let d_b = crate::geodesic::region_distance_matrix(
        b,
        &basis_b.mass,
        regions.regions_b(),
        regions.graph_b.n_nodes(),
        1.0 / basis_b.input_area.sqrt(),
    );
    let assemble = |pick: &[usize]| {
        let mut pairs = fixed.clone();
        for (g, &o) in pick.iter().enumerate() {
            pairs.extend(&choices[g][o]);
        }
        pairs
    };
    let energy = |pick: &[usize]| {
        crate::regions::symmetry::distortion_energy(&assemble(pick), d_a.as_ref(), d_b.as_ref())
    };
    let mut pick = vec![0usize; choices.len()];
    for _sweep in 0..4 {
        let mut changed = false;
        for g in 0..choices.len() {
            let mut best = (energy(&pick), pick[g]);
            for o in 0..choices[g].len() {
                let mut trial = pick.clone();
                trial[g] = o;
                let e = energy(&trial);
                if e < best.0 - 1e-12 {
                    best = (e, o);
                }
            }
            if best.1 != pick[g] {
                pick[g] = best.1;
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    let mut pairs = assemble(&pick);
    pairs.sort_unstable();
    pairs.into_iter().map(|(i, j)| (vec![i], vec![j])).collect()
}

/// Everything from two shapes: eigenbases, region correspondence, pointwise map.
#[derive(Debug, Clone)]
pub struct PointwiseCorrespondence {
    /// The region correspondence the map is built on.
    pub regions: Correspondence,
    /// The point-to-point map from B to A.
    pub map: PointwiseMap,
    /// Seconds of A's eigenbasis.
    pub eigenbasis_a: f64,
    /// Seconds of B's eigenbasis.
    pub eigenbasis_b: f64,
    /// Seconds of the whole call.
    pub total: f64,
}

impl PointwiseCorrespondence {
    /// Region correspondence and pointwise map of two shapes. Each eigenbasis is computed
    /// once, with `pointwise.n_eigenpairs` pairs; region matching uses its first
    /// `params.eigen.n_eigenpairs`.
    pub fn compute(
        a: &Shape,
        b: &Shape,
        params: &Params,
        pointwise: &PointwiseParams,
        progress: &mut dyn Progress,
    ) -> Result<PointwiseCorrespondence> {
        params.validate()?;
        pointwise.validate()?;
        let started = Instant::now();
        let eigen = EigenParams {
            n_eigenpairs: pointwise.n_eigenpairs.max(params.eigen.n_eigenpairs),
            ..params.eigen.clone()
        };
        let basis_a = Eigenbasis::compute_with_progress(a, &eigen, progress)?;
        let eigenbasis_a = started.elapsed().as_secs_f64();
        let t = Instant::now();
        let basis_b = Eigenbasis::compute_with_progress(b, &eigen, progress)?;
        let eigenbasis_b = t.elapsed().as_secs_f64();
        let regions = Correspondence::from_bases(
            a,
            &truncated(&basis_a, params.eigen.n_eigenpairs),
            b,
            &truncated(&basis_b, params.eigen.n_eigenpairs),
            params,
            progress,
        )?;
        check(progress, Stage::PointwiseMap, 0.0)?;
        let map = PointwiseMap::from_bases(a, &basis_a, b, &basis_b, Some(&regions), pointwise)?;
        check(progress, Stage::PointwiseMap, 1.0)?;
        Ok(PointwiseCorrespondence {
            regions,
            map,
            eigenbasis_a,
            eigenbasis_b,
            total: started.elapsed().as_secs_f64(),
        })
    }
}

/// The first `k` eigenpairs of a basis (a copy; the eigenvectors of a larger solve agree
/// with a smaller one's to round-off).
pub fn truncated(basis: &Eigenbasis, k: usize) -> Eigenbasis {
    let k = k.min(basis.len());
    Eigenbasis {
        values: basis.values[..k].to_vec(),
        vectors: basis.vectors.subcols(0, k).to_owned(),
        mass: basis.mass.clone(),
        input_area: basis.input_area,
    }
}

/// The corresponding region sets that constrain the map: one pair per one-to-one match,
/// or one per group of symmetric matches (the connected components of their bipartite
/// graph, [`crate::regions::symmetry::bipartite_groups`]).
pub fn region_groups(
    regions: &Correspondence,
    kind: RegionConstraints,
) -> Vec<(Vec<u32>, Vec<u32>)> {
    match kind {
        RegionConstraints::None => Vec::new(),
        RegionConstraints::OneToOne => regions
            .matches_one_to_one
            .iter()
            .map(|&(i, j)| (vec![i], vec![j]))
            .collect(),
        RegionConstraints::Symmetric => {
            crate::regions::symmetry::bipartite_groups(&regions.matches)
        }
    }
}

/// Indicator functions of region sets (one column per set).
fn indicators(labels: &[u32], n_regions: usize, sets: &[Vec<u32>]) -> Mat<f64> {
    let mut member = vec![vec![false; n_regions]; sets.len()];
    for (m, set) in member.iter_mut().zip(sets) {
        for &r in set {
            m[r as usize] = true;
        }
    }
    Mat::from_fn(labels.len(), sets.len(), |v, s| {
        if member[s][labels[v] as usize] {
            1.0
        } else {
            0.0
        }
    })
}

/// For every indicator column, the edge-graph distance from the vertices where it is 1
/// (unit-area shape; unreachable vertices take the largest finite distance).
fn distance_functions(
    shape: &Shape,
    basis: &Eigenbasis,
    indicators: faer::MatRef<'_, f64>,
) -> Mat<f64> {
    let graph = crate::geodesic::EdgeGraph::new(shape, 1.0 / basis.input_area.sqrt());
    let columns: Vec<Vec<f64>> = (0..indicators.ncols())
        .into_par_iter()
        .map(|g| {
            let sources: Vec<u32> = (0..indicators.nrows())
                .filter(|&v| indicators[(v, g)] > 0.0)
                .map(|v| v as u32)
                .collect();
            let mut d = graph.distances(&sources);
            let finite = d
                .iter()
                .copied()
                .filter(|x| x.is_finite())
                .fold(0.0, f64::max);
            for x in &mut d {
                if !x.is_finite() {
                    *x = finite;
                }
            }
            d
        })
        .collect();
    Mat::from_fn(indicators.nrows(), columns.len(), |v, g| columns[g][v])
}

/// Coefficients of the functions after heat diffusion for time `t`: `exp(-lambda_i t)`
/// times the projection.
fn diffused(basis: &Eigenbasis, k: usize, functions: faer::MatRef<'_, f64>, t: f64) -> Mat<f64> {
    let mut coef = project(basis.vectors.as_ref(), &basis.mass, k, functions);
    for i in 0..coef.nrows() {
        let decay = (-basis.values[i].max(0.0) * t).exp();
        for j in 0..coef.ncols() {
            coef[(i, j)] *= decay;
        }
    }
    coef
}

/// Every `step`-th descriptor column.
fn every_column(descriptors: &Mat<f64>, step: usize) -> Mat<f64> {
    let columns: Vec<usize> = (0..descriptors.ncols()).step_by(step).collect();
    Mat::from_fn(descriptors.nrows(), columns.len(), |i, j| {
        descriptors[(i, columns[j])]
    })
}

/// The coefficient blocks side by side, each column scaled to unit norm (the M-norm of
/// the projected function), so that no descriptor dominates by its scale.
fn normalised_columns(blocks: &[Mat<f64>]) -> Mat<f64> {
    let k = blocks.first().map_or(0, |b| b.nrows());
    let columns: Vec<faer::ColRef<'_, f64>> = blocks
        .iter()
        .flat_map(|b| (0..b.ncols()).map(move |j| b.col(j)))
        .collect();
    Mat::from_fn(k, columns.len(), |i, j| {
        let norm = columns[j].norm_l2();
        if norm > 0.0 {
            columns[j][i] / norm
        } else {
            0.0
        }
    })
}
