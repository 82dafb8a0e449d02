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
    fmap_to_p2p_cancellable, icp_refine_cancellable, multiplication_operators,
    orientation_operators, project, solve_fmap_commuting_cancellable, zoomout_cancellable,
    zoomout_on_samples_cancellable, Commutativity, ZoomOutParams,
};
pub use crate::maps::hypotheses::orientation_score;
use crate::maps::hypotheses::{self, HypothesisKind, RegionGroups, Verdict};
use crate::multiresolution::{lift_map, lift_regions, working};
use crate::progress::{check, polled, Cancel, Progress, Stage};
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
    /// On orientable meshes, also verify the mirror image of the one-to-one region answer
    /// (another choice in every symmetric group) as a hypothesis.
    pub orientation: bool,
    /// Verify more region hypotheses than the answer (and its mirror image): the symmetric
    /// groups and the best single-group alternatives ([`hypotheses::candidates`]). Every
    /// hypothesis is solved and refined by ZoomOut on the samples; the map of lowest
    /// [`hypotheses::MapEnergy::cost`] wins, and only it is converted at full resolution.
    pub hypotheses: bool,
    /// Keeps the struct open to new fields: build it with `..Default::default()`.
    #[doc(hidden)]
    pub non_exhaustive: crate::NonExhaustive,
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
            hypotheses: true,
            non_exhaustive: crate::NonExhaustive(()),
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
    /// The region hypotheses verified at the map level, the chosen one and its confidence
    /// (None when there was one hypothesis only).
    pub verdict: Option<Verdict>,
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
        let cancel = Cancel::default();
        PointwiseMap::from_bases_cancellable((a, basis_a), (b, basis_b), regions, params, &cancel)
    }

    /// As [`PointwiseMap::from_bases`], reporting progress to `progress` as `stage` (from
    /// the caller's thread, every [`crate::progress::POLL_INTERVAL`]) and stopping within a
    /// fraction of a second when it cancels: every loop inside checks the cancel (issue 19).
    pub fn from_bases_with_progress(
        (a, basis_a): (&Shape, &Eigenbasis),
        (b, basis_b): (&Shape, &Eigenbasis),
        regions: Option<&Correspondence>,
        params: &PointwiseParams,
        (progress, stage): (&mut dyn Progress, Stage),
    ) -> Result<PointwiseMap> {
        polled(progress, stage, (0.0, 1.0), |cancel| {
            PointwiseMap::from_bases_cancellable(
                (a, basis_a),
                (b, basis_b),
                regions,
                params,
                cancel,
            )
        })
    }

    fn from_bases_cancellable(
        (a, basis_a): (&Shape, &Eigenbasis),
        (b, basis_b): (&Shape, &Eigenbasis),
        regions: Option<&Correspondence>,
        params: &PointwiseParams,
        cancel: &Cancel,
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
        let kinds_and_groups: Vec<(HypothesisKind, RegionGroups)> = match regions {
            // Regions verified already ([`verify_regions`]): their answer is the hypothesis.
            Some(regions)
                if params.regions == RegionConstraints::OneToOne && regions.verdict.is_none() =>
            {
                let with_mirror = params.orientation && faces.is_some();
                if params.hypotheses {
                    hypotheses::candidates((a, basis_a), (b, basis_b), regions, with_mirror)
                } else if with_mirror {
                    hypotheses::candidates((a, basis_a), (b, basis_b), regions, true)
                        .into_iter()
                        .filter(|(kind, _)| {
                            matches!(kind, HypothesisKind::Answer | HypothesisKind::Mirror)
                        })
                        .collect()
                } else {
                    vec![(HypothesisKind::Answer, groups)]
                }
            }
            _ => vec![(HypothesisKind::Answer, groups)],
        };
        let (kinds, candidates): (Vec<HypothesisKind>, Vec<RegionGroups>) =
            kinds_and_groups.into_iter().unzip();
        let candidate_refs: Vec<&[(Vec<u32>, Vec<u32>)]> =
            candidates.iter().map(Vec::as_slice).collect();
        let orientation_faces = faces
            .as_ref()
            .filter(|_| params.orientation_term > 0.0)
            .map(|(fa, fb)| (fa.as_slice(), fb.as_slice()));
        let features = Features::new(
            (a, basis_a),
            (b, basis_b),
            regions,
            &candidate_refs,
            orientation_faces,
            params,
            k,
        )?;
        cancel.check()?;
        cancel.set_fraction(0.2);
        let fmaps = (0..candidates.len())
            .into_par_iter()
            .map(|c| features.solve(c, (basis_a, basis_b), params, cancel))
            .collect::<Result<Vec<_>>>()?;
        cancel.set_fraction(0.4);
        let t_fmap = started.elapsed().as_secs_f64();
        let t = Instant::now();
        let (fmap_ab, p2p_ba, verdict) = if fmaps.len() > 1 {
            let (verdict, chosen_map) = verified(
                (a, basis_a),
                (b, basis_b),
                faces.as_ref(),
                kinds,
                &fmaps,
                (params, k),
                cancel,
            )?;
            cancel.set_fraction(0.8);
            let (fmap_ab, p2p_ba) = match &params.refinement {
                // The chosen map is already refined on the samples.
                Refinement::ZoomOut(_) => {
                    let fmap = verdict.scores[verdict.chosen].fmap_ab.clone();
                    let p2p = match chosen_map {
                        Some(p2p) => p2p,
                        None => fmap_to_p2p_cancellable(
                            fmap.as_ref(),
                            basis_a.vectors.as_ref(),
                            basis_b.vectors.as_ref(),
                            cancel,
                        )?,
                    };
                    (fmap, p2p)
                }
                _ => refine(
                    &fmaps[verdict.chosen],
                    (basis_a, basis_b),
                    (params, k),
                    cancel,
                )?,
            };
            (fmap_ab, p2p_ba, Some(verdict))
        } else {
            let (fmap_ab, p2p_ba) = refine(&fmaps[0], (basis_a, basis_b), (params, k), cancel)?;
            (fmap_ab, p2p_ba, None)
        };
        Ok(PointwiseMap {
            p2p_ba,
            fmap_ab,
            verdict,
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
    (params, k): (&PointwiseParams, usize),
    cancel: &Cancel,
) -> Result<(Mat<f64>, Vec<u32>)> {
    let (phi_a, phi_b) = (basis_a.vectors.as_ref(), basis_b.vectors.as_ref());
    let bases = (
        (phi_a, basis_a.mass.as_slice()),
        (phi_b, basis_b.mass.as_slice()),
    );
    match &params.refinement {
        Refinement::None => {
            let p2p = fmap_to_p2p_cancellable(fmap.as_ref(), phi_a, phi_b, cancel)?;
            Ok((fmap.clone(), p2p))
        }
        Refinement::ZoomOut(z) => {
            let z = clamped(z, (basis_a, basis_b), k);
            zoomout_cancellable(fmap.as_ref(), bases, &z, cancel)
        }
        Refinement::Icp(iterations) => {
            let sample_size = ZoomOutParams::default().sample_size;
            icp_refine_cancellable(fmap.as_ref(), bases, (*iterations, sample_size), cancel)
        }
    }
}

/// The hypotheses' functional maps `fmaps` refined by ZoomOut on the same samples and
/// judged by [`hypotheses::energies`]: the verdict.
fn verified(
    (a, basis_a): (&Shape, &Eigenbasis),
    (b, basis_b): (&Shape, &Eigenbasis),
    faces: Option<&hypotheses::OrientedFaces>,
    kinds: Vec<HypothesisKind>,
    fmaps: &[Mat<f64>],
    (params, k): (&PointwiseParams, usize),
    cancel: &Cancel,
) -> Result<(Verdict, Option<Vec<u32>>)> {
    let (phi_a, phi_b) = (basis_a.vectors.as_ref(), basis_b.vectors.as_ref());
    let bases = (
        (phi_a, basis_a.mass.as_slice()),
        (phi_b, basis_b.mass.as_slice()),
    );
    let decision = match &params.refinement {
        Refinement::ZoomOut(z) => z.clone(),
        _ => ZoomOutParams::default(),
    };
    let decision = clamped(&decision, (basis_a, basis_b), k);
    let sampled = fmaps
        .par_iter()
        .map(|fmap| zoomout_on_samples_cancellable(fmap.as_ref(), bases, &decision, cancel))
        .collect::<Result<Vec<_>>>()?;
    cancel.check()?;
    let energies = hypotheses::energies((a, basis_a), (b, basis_b), faces, &sampled);
    let sample_maps: Vec<&[u32]> = sampled.iter().map(|s| s.p2p_ba.as_slice()).collect();
    let sample_fmaps = sampled.iter().map(|s| s.fmap_ab.clone()).collect();
    let mut verdict = hypotheses::choose(
        kinds,
        energies,
        sample_fmaps,
        &sample_maps,
        (a.vertices(), basis_a.input_area),
    );
    // A close call is decided at full resolution, where the meshes' orientation is known.
    let mut chosen_map = None;
    if let (Some(rival), Some(faces)) = (verdict.close_call(), faces) {
        cancel.check()?;
        let convert = |h: usize| {
            fmap_to_p2p_cancellable(verdict.scores[h].fmap_ab.as_ref(), phi_a, phi_b, cancel)
        };
        let (chosen_p2p, rival_p2p) = (convert(verdict.chosen)?, convert(rival)?);
        let consistency = (
            hypotheses::full_consistency(a, faces, &chosen_p2p),
            hypotheses::full_consistency(a, faces, &rival_p2p),
        );
        let changed = verdict.settle(
            rival,
            consistency,
            &sample_maps,
            (a.vertices(), basis_a.input_area),
        );
        chosen_map = Some(if changed { rival_p2p } else { chosen_p2p });
    }
    Ok((verdict, chosen_map))
}

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
        (basis_a, basis_b): (&Eigenbasis, &Eigenbasis),
        params: &PointwiseParams,
        cancel: &Cancel,
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
        solve_fmap_commuting_cancellable(
            coef_a.as_ref(),
            coef_b.as_ref(),
            (&basis_a.values, &basis_b.values, params.laplacian_weight),
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
            cancel,
        )
    }
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
    /// Seconds of building the proxies of dense shapes and bringing the regions and the map
    /// back to every input vertex (0 at full resolution, [`Params::multiresolution`]).
    pub proxies: f64,
    /// Seconds of the whole call.
    pub total: f64,
}

impl PointwiseCorrespondence {
    /// The verdict behind the answer: the map's own when it verified hypotheses, else the
    /// regions'.
    pub fn verdict(&self) -> Option<&Verdict> {
        self.map.verdict.as_ref().or(self.regions.verdict.as_ref())
    }

    /// The confidence of the answer in [0, 1] ([`PointwiseCorrespondence::verdict`]; None
    /// when nothing was verified).
    pub fn confidence(&self) -> Option<f64> {
        self.verdict().map(|v| v.confidence)
    }
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
        let eigen = basis_params(params, pointwise);
        params
            .budget
            .check(&PointwiseCorrespondence::job(a, b, params, pointwise))?;
        params.budget.run(progress, |progress| {
            let started = Instant::now();
            let proxies = params.multiresolution.proxies([a, b], &eigen, progress)?;
            let built = started.elapsed().as_secs_f64();
            let [proxy_a, proxy_b] = &proxies;
            let (working_a, working_b) = (working(a, proxy_a), working(b, proxy_b));
            let mut result = PointwiseCorrespondence::compute_within(
                (working_a, working_b),
                &eigen,
                params,
                pointwise,
                progress,
            )?;
            let t = Instant::now();
            lift_regions(&mut result.regions, [proxy_a.as_ref(), proxy_b.as_ref()]);
            result.map.p2p_ba = lift_map((a, proxy_a), (b, proxy_b), &result.map.p2p_ba, progress)?;
            if proxy_a.is_some() || proxy_b.is_some() {
                result.proxies = built + t.elapsed().as_secs_f64();
            }
            result.regions.timings.proxies = result.proxies;
            result.total = started.elapsed().as_secs_f64();
            Ok(result)
        })
    }

    /// What [`PointwiseCorrespondence::compute`] will do on these shapes, for
    /// [`crate::budget::Budget::check`]: the chosen map converted at full resolution, and a
    /// close call's rival too when the hypotheses are verified.
    pub fn job(
        a: &Shape,
        b: &Shape,
        params: &Params,
        pointwise: &PointwiseParams,
    ) -> crate::budget::Job {
        let eigen = basis_params(params, pointwise);
        let size = match &pointwise.refinement {
            Refinement::ZoomOut(z) => z.k_end,
            _ => pointwise.fmap_size,
        };
        let sizes = [a, b].map(|s| params.multiresolution.working_size(s));
        crate::budget::Job {
            conversions: if params.verify_hypotheses { 3 } else { 1 },
            conversion_size: size.min(eigen.n_eigenpairs),
            ..crate::budget::regions_job(sizes, &eigen, false)
        }
    }

    /// [`PointwiseCorrespondence::compute`] once the budget has accepted the job.
    fn compute_within(
        (a, b): (&Shape, &Shape),
        eigen: &EigenParams,
        params: &Params,
        pointwise: &PointwiseParams,
        progress: &mut dyn Progress,
    ) -> Result<PointwiseCorrespondence> {
        let started = Instant::now();
        let ([basis_a, basis_b], [eigenbasis_a, eigenbasis_b]) =
            Eigenbasis::pair((a, b), eigen, progress)?;
        let (regions, map) =
            regions_and_map((a, &basis_a), (b, &basis_b), params, pointwise, progress)?;
        Ok(PointwiseCorrespondence {
            regions,
            map,
            eigenbasis_a,
            eigenbasis_b,
            proxies: 0.0,
            total: started.elapsed().as_secs_f64(),
        })
    }
}

/// The eigensolver's parameters of a pointwise job: enough eigenpairs for the map and the
/// regions, computed once per shape.
pub(crate) fn basis_params(params: &Params, pointwise: &PointwiseParams) -> EigenParams {
    EigenParams {
        n_eigenpairs: pointwise.n_eigenpairs.max(params.eigen.n_eigenpairs),
        ..params.eigen.clone()
    }
}

/// The regions (on the first `params.eigen.n_eigenpairs` of the bases) and the map (on all of
/// them). With `params.verify_hypotheses`, the hypotheses are verified once, by the map on
/// its larger basis (on FAUST_r, verifying on the regions' 50 eigenpairs failed 15 of 126
/// pairs, on the map's 100 one: docs/tails.md), and the regions follow the chosen map
/// ([`hypotheses::one_to_one_from_map`]) and carry its verdict.
pub fn regions_and_map(
    (a, basis_a): (&Shape, &Eigenbasis),
    (b, basis_b): (&Shape, &Eigenbasis),
    params: &Params,
    pointwise: &PointwiseParams,
    progress: &mut dyn Progress,
) -> Result<(Correspondence, PointwiseMap)> {
    let k = params.eigen.n_eigenpairs;
    let unverified = Params {
        verify_hypotheses: false,
        ..params.clone()
    };
    let mut regions = Correspondence::from_bases(
        a,
        &truncated(basis_a, k),
        b,
        &truncated(basis_b, k),
        &unverified,
        progress,
    )?;
    check(progress, Stage::PointwiseMap, 0.0)?;
    let pointwise = PointwiseParams {
        hypotheses: pointwise.hypotheses && params.verify_hypotheses,
        orientation: pointwise.orientation && params.verify_hypotheses,
        ..pointwise.clone()
    };
    let map = PointwiseMap::from_bases_with_progress(
        (a, basis_a),
        (b, basis_b),
        Some(&regions),
        &pointwise,
        (progress, Stage::PointwiseMap),
    )?;
    if let Some(verdict) = &map.verdict {
        regions.matches_one_to_one =
            hypotheses::one_to_one_from_map(&regions, &map.p2p_ba, &basis_b.mass);
        regions.verdict = Some(verdict.clone());
    }
    check(progress, Stage::PointwiseMap, 1.0)?;
    Ok((regions, map))
}

/// Verifies the one-to-one answer of `regions` at the map level on the regions' own
/// eigenbases (ZoomOut up to their size): the hypotheses of [`hypotheses::candidates`] are
/// refined and judged, the one-to-one matches become those that agree best with the chosen
/// map ([`hypotheses::one_to_one_from_map`]) and the verdict is kept with them. Nothing
/// changes when there is a single hypothesis.
pub fn verify_regions(
    (a, basis_a): (&Shape, &Eigenbasis),
    (b, basis_b): (&Shape, &Eigenbasis),
    regions: &mut Correspondence,
    progress: &mut dyn Progress,
) -> Result<()> {
    if regions.matches_one_to_one.is_empty() {
        return Ok(());
    }
    let n = basis_a.len().min(basis_b.len());
    let defaults = PointwiseParams::default();
    let params = PointwiseParams {
        n_eigenpairs: n,
        fmap_size: defaults.fmap_size.min(n),
        refinement: Refinement::ZoomOut(ZoomOutParams {
            k_end: n,
            ..Default::default()
        }),
        ..defaults
    };
    let map = PointwiseMap::from_bases_with_progress(
        (a, basis_a),
        (b, basis_b),
        Some(regions),
        &params,
        (progress, Stage::SymmetryBreaking),
    )?;
    if let Some(verdict) = map.verdict {
        regions.matches_one_to_one =
            hypotheses::one_to_one_from_map(regions, &map.p2p_ba, &basis_b.mass);
        regions.verdict = Some(verdict);
    }
    Ok(())
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
