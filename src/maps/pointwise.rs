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

use crate::maps::fmap::{
    fmap_to_p2p, icp_refine, multiplication_operators, orientation_operators, p2p_to_fmap, project,
    slanted, solve_fmap_commuting, zoomout_on_samples, zoomout_sloped, Commutativity,
    ZoomOutParams,
};
pub use crate::maps::hypotheses::orientation_score;
use crate::maps::hypotheses::{self, Decision, HypothesisKind, RegionGroups, Verdict};
use crate::maps::landmarks::{landmark_error, Landmark};
use crate::maps::partial::{Coverage, PartialReport};
use crate::maps::placement::{self, Guidance, Placement};
use crate::progress::{polled, Cancel, Progress, Stage};
use crate::regions::RegionMatches;
use crate::shape::{Shape, ShapeKind};
use crate::spectral::descriptors::{hks, wks, HksParams, WksParams};
use crate::spectral::eigen::{Eigenbasis, ShapeBasis};
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
    /// Used on orientable meshes and on point clouds whose orientation is trusted (faces
    /// taken as [`Shape::oriented_triangles`]; 0 = off).
    pub orientation_term: f64,
    /// Refinement of the first map.
    pub refinement: Refinement,
    /// On orientable meshes and point clouds, also verify the mirror image of the one-to-one
    /// region answer (another choice in every symmetric group) as a hypothesis.
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
    /// The final functional map from A to B (`k x k`; `k_b x k_a` on the slanted diagonal
    /// for a part, [`crate::maps::partial`]).
    pub fmap_ab: Mat<f64>,
    /// The region hypotheses verified at the map level, the chosen one and its confidence
    /// (None when there was one hypothesis only).
    pub verdict: Option<Verdict>,
    /// The runner-up's map ([`Verdict::runner_up`]), for the user who takes the other
    /// answer; None when there is none.
    pub other_p2p_ba: Option<Vec<u32>>,
    /// Seconds of the first functional map and of its refinement.
    pub timings: PointwiseTimings,
    /// Whether B was taken as a part of A (or A of B), and what was measured
    /// ([`crate::maps::partial`]).
    pub partial: PartialReport,
    /// Which vertices of A and of B have a counterpart ([`crate::maps::partial::coverage`]);
    /// empty until the job sets it.
    pub coverage: Coverage,
    /// The same for the runner-up's map (`other_p2p_ba`); None when there is none.
    pub other_coverage: Option<Coverage>,
}

impl PointwiseMap {
    /// The pointwise map between two shapes whose eigenbases are given (each with at least
    /// `params.n_eigenpairs` pairs, or all the shape has), with the region correspondence
    /// `regions` (needed unless `params.regions` is `None`). Reports progress as `stage`
    /// from the caller's thread, every [`crate::progress::POLL_INTERVAL`], and stops within
    /// a fraction of a second when it cancels: every loop inside checks the cancel.
    pub fn from_bases(
        a: ShapeBasis<'_>,
        b: ShapeBasis<'_>,
        regions: Option<RegionMatches<'_>>,
        params: &PointwiseParams,
        progress: &mut dyn Progress,
    ) -> Result<PointwiseMap> {
        PointwiseMap::guided(a, b, regions, params, &Guidance::default(), progress)
    }

    /// [`PointwiseMap::from_bases`] with what the user knows beyond the shapes' geometry
    /// (`guidance`: the placement's use, landmarks as vertices of these shapes).
    pub fn guided(
        a: ShapeBasis<'_>,
        b: ShapeBasis<'_>,
        regions: Option<RegionMatches<'_>>,
        params: &PointwiseParams,
        guidance: &Guidance,
        progress: &mut dyn Progress,
    ) -> Result<PointwiseMap> {
        polled(progress, Stage::PointwiseMap, (0.0, 1.0), |cancel| {
            PointwiseMap::solve(a, b, regions, (params, guidance), cancel)
        })
    }

    /// [`PointwiseMap::from_bases`] on the calling thread, polling `cancel`.
    fn solve(
        side_a: ShapeBasis<'_>,
        side_b: ShapeBasis<'_>,
        regions: Option<RegionMatches<'_>>,
        (params, guidance): (&PointwiseParams, &Guidance),
        cancel: &Cancel,
    ) -> Result<PointwiseMap> {
        let ShapeBasis {
            shape: a,
            basis: basis_a,
        } = side_a;
        let ShapeBasis {
            shape: b,
            basis: basis_b,
        } = side_b;
        params.validate()?;
        let started = Instant::now();
        let k = params.fmap_size.min(basis_a.len()).min(basis_b.len());
        let groups = constraint_groups(regions, params.regions)?;
        // Both shapes' oriented faces (a cloud's: its local triangles; None where not
        // orientable or trusted): the orientation term and the mirror decision need them.
        // A one-to-one region answer may be the mirror image of the truth (paper, section
        // 5.2): on orientable meshes, its mirror image is a second candidate. So it is with
        // a point cloud: its cost rarely tells the two apart, but where the shapes stand may
        // (a half-turned answer's mirror image is the map with no turn; docs/scans.md,
        // "Point clouds").
        let faces = if params.orientation || params.orientation_term > 0.0 {
            a.oriented_triangles().zip(b.oriented_triangles())
        } else {
            None
        };
        let (mut kinds, candidates) = hypotheses_to_verify(
            (side_a, side_b, faces.is_some()),
            (regions, groups),
            params,
            guidance,
        );
        let candidate_refs: Vec<&[(Vec<u32>, Vec<u32>)]> =
            candidates.iter().map(Vec::as_slice).collect();
        let orientation_faces = faces
            .as_ref()
            .filter(|_| params.orientation_term > 0.0)
            .map(|(fa, fb)| (fa.as_slice(), fb.as_slice()));
        let features = Features::new(
            side_a,
            side_b,
            regions,
            &candidate_refs,
            orientation_faces,
            (params, &guidance.landmarks),
            k,
        )?;
        cancel.check()?;
        cancel.set_fraction(0.2);
        let mut fmaps = (0..candidates.len())
            .into_par_iter()
            .map(|c| features.solve(c, (basis_a, basis_b), params, cancel))
            .collect::<Result<Vec<_>>>()?;
        // Hypotheses are verified: the shapes' placement gives one more.
        if fmaps.len() > 1 && guidance.placement != Placement::Ignore {
            let area = |basis: &Eigenbasis| basis.mass.iter().sum::<f64>();
            let p2p = placement::nearest_in_frame(
                (a, &basis_a.mass, area(basis_a)),
                (b, &basis_b.mass, area(basis_b)),
            );
            let (phi_a, phi_b) = (basis_a.vectors.as_ref(), basis_b.vectors.as_ref());
            fmaps.push(p2p_to_fmap(&p2p, phi_a, phi_b, &basis_b.mass, k, k));
            kinds.push(HypothesisKind::Placement);
        }
        let slope = part_slope(params, guidance);
        if slope != 1.0 {
            fmaps = fmaps.iter().map(|f| slanted(f.as_ref(), slope)).collect();
        }
        cancel.set_fraction(0.4);
        let t_fmap = started.elapsed().as_secs_f64();
        let t = Instant::now();
        let (fmap_ab, mut p2p_ba, verdict) = if fmaps.len() > 1 {
            let (verdict, chosen_map) = verified(
                (side_a, side_b, faces.as_ref()),
                (kinds, &candidates, regions),
                &fmaps,
                (params, guidance, k),
                cancel,
            )?;
            cancel.set_fraction(0.8);
            let (fmap_ab, p2p_ba) = match &params.refinement {
                // The chosen map is already refined on the samples.
                Refinement::ZoomOut(_) => {
                    let fmap = verdict.scores[verdict.chosen].fmap_ab.clone();
                    let p2p = match chosen_map {
                        Some(p2p) => p2p,
                        None => fmap_to_p2p(
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
                    (params, k, slope),
                    cancel,
                )?,
            };
            (fmap_ab, p2p_ba, Some(verdict))
        } else {
            let (fmap_ab, p2p_ba) =
                refine(&fmaps[0], (basis_a, basis_b), (params, k, slope), cancel)?;
            (fmap_ab, p2p_ba, None)
        };
        let mut other_p2p_ba = runner_up_map(verdict.as_ref(), (basis_a, basis_b), cancel)?;
        for map in std::iter::once(&mut p2p_ba).chain(other_p2p_ba.as_mut()) {
            pin_landmarks(map, &guidance.landmarks);
        }
        Ok(PointwiseMap {
            p2p_ba,
            other_p2p_ba,
            fmap_ab,
            verdict,
            timings: PointwiseTimings {
                fmap: t_fmap,
                refinement: t.elapsed().as_secs_f64(),
            },
            partial: PartialReport::default(),
            coverage: Coverage::default(),
            other_coverage: None,
        })
    }
}

/// The hypotheses the map is solved for, with their region groups: the region answer's
/// ([`hypotheses::candidates`]; only the answer when the regions were verified already or
/// not one-to-one), and with landmarks the landmarks' own, which has no region group.
fn hypotheses_to_verify(
    (side_a, side_b, oriented): (ShapeBasis<'_>, ShapeBasis<'_>, bool),
    (regions, groups): (Option<RegionMatches<'_>>, RegionGroups),
    params: &PointwiseParams,
    guidance: &Guidance,
) -> (Vec<HypothesisKind>, Vec<RegionGroups>) {
    let kinds_and_groups: Vec<(HypothesisKind, RegionGroups)> = match regions {
        // Regions verified already: their answer is the only hypothesis.
        Some(regions) if params.regions == RegionConstraints::OneToOne && !regions.verified => {
            let is_cloud = |s: &Shape| s.kind() == ShapeKind::PointCloud;
            let with_mirror = params.orientation
                && (oriented || is_cloud(side_a.shape) || is_cloud(side_b.shape));
            if params.hypotheses {
                hypotheses::candidates(side_a, side_b, regions, with_mirror)
            } else if with_mirror {
                hypotheses::candidates(side_a, side_b, regions, true)
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
    let (mut kinds, mut candidates): (Vec<HypothesisKind>, Vec<RegionGroups>) =
        kinds_and_groups.into_iter().unzip();
    // Hypotheses are verified: the landmarks give one more, free of the region answer.
    if kinds.len() > 1 && !guidance.landmarks.is_empty() {
        kinds.push(HypothesisKind::Landmarks);
        candidates.push(Vec::new());
    }
    (kinds, candidates)
}

/// The slope of the maps' slanted diagonal: the guidance's for a part refined by ZoomOut
/// (spectral ICP needs a square map), else 1.
fn part_slope(params: &PointwiseParams, guidance: &Guidance) -> f64 {
    match (&params.refinement, guidance.part_slope) {
        (Refinement::ZoomOut(_), Some(slope)) => slope,
        _ => 1.0,
    }
}

/// The runner-up's vertex map ([`Verdict::runner_up`]); None when there is none.
fn runner_up_map(
    verdict: Option<&Verdict>,
    (basis_a, basis_b): (&Eigenbasis, &Eigenbasis),
    cancel: &Cancel,
) -> Result<Option<Vec<u32>>> {
    let Some((verdict, h)) = verdict.and_then(|v| Some((v, v.runner_up()?))) else {
        return Ok(None);
    };
    let (phi_a, phi_b) = (basis_a.vectors.as_ref(), basis_b.vectors.as_ref());
    fmap_to_p2p(verdict.scores[h].fmap_ab.as_ref(), phi_a, phi_b, cancel).map(Some)
}

/// The region constraints of the map: the groups of matched regions (none for
/// [`RegionConstraints::None`]).
fn constraint_groups(
    regions: Option<RegionMatches<'_>>,
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
            name: "p2p_regions",
            reason: format!(
                "the region correspondence has no {} match to constrain the map; use another \
                 p2p_regions (symmetric, or none with p2p_wks)",
                if kind == RegionConstraints::OneToOne {
                    "one-to-one"
                } else {
                    "symmetric"
                }
            ),
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
    (params, k, slope): (&PointwiseParams, usize, f64),
    cancel: &Cancel,
) -> Result<(Mat<f64>, Vec<u32>)> {
    let (phi_a, phi_b) = (basis_a.vectors.as_ref(), basis_b.vectors.as_ref());
    let bases = (
        (phi_a, basis_a.mass.as_slice()),
        (phi_b, basis_b.mass.as_slice()),
    );
    match &params.refinement {
        Refinement::None => {
            let p2p = fmap_to_p2p(fmap.as_ref(), phi_a, phi_b, cancel)?;
            Ok((fmap.clone(), p2p))
        }
        Refinement::ZoomOut(z) => {
            let z = clamped(z, (basis_a, basis_b), k);
            zoomout_sloped(fmap.as_ref(), bases, &z, slope, cancel)
        }
        Refinement::Icp(iterations) => {
            let sample_size = ZoomOutParams::default().sample_size;
            icp_refine(fmap.as_ref(), bases, (*iterations, sample_size), cancel)
        }
    }
}

/// Every landmark of B sent to its partner on A.
pub fn pin_landmarks(p2p_ba: &mut [u32], landmarks: &[Landmark]) {
    for &[la, lb] in landmarks {
        if let Some(image) = p2p_ba.get_mut(lb as usize) {
            *image = la;
        }
    }
}

/// The hypotheses' functional maps `fmaps` refined by ZoomOut on the same samples and
/// judged by [`hypotheses::energies`], then by the shapes' placement and the landmarks
/// (`guidance`): the verdict. `candidates`: the region groups of each region hypothesis
/// (the placement's hypothesis comes after them).
#[allow(clippy::type_complexity)]
fn verified(
    (side_a, side_b, faces): (
        ShapeBasis<'_>,
        ShapeBasis<'_>,
        Option<&hypotheses::OrientedFaces>,
    ),
    (kinds, candidates, regions): (
        Vec<HypothesisKind>,
        &[RegionGroups],
        Option<RegionMatches<'_>>,
    ),
    fmaps: &[Mat<f64>],
    (params, guidance, k): (&PointwiseParams, &Guidance, usize),
    cancel: &Cancel,
) -> Result<(Verdict, Option<Vec<u32>>)> {
    let (a, basis_a, basis_b) = (side_a.shape, side_a.basis, side_b.basis);
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
        .map(|fmap| {
            let slope = part_slope(params, guidance);
            zoomout_on_samples(fmap.as_ref(), bases, &decision, slope, cancel)
        })
        .collect::<Result<Vec<_>>>()?;
    cancel.check()?;
    let energies = hypotheses::energies(side_a, side_b, faces, &sampled);
    let sample_maps: Vec<&[u32]> = sampled.iter().map(|s| s.p2p_ba.as_slice()).collect();
    let sample_fmaps = sampled.iter().map(|s| s.fmap_ab.clone()).collect();
    let mut verdict = hypotheses::choose(
        kinds,
        energies,
        sample_fmaps,
        &sample_maps,
        (a.vertices(), basis_a.input_area),
    );
    let scale_a = 1.0 / basis_a.input_area.sqrt();
    for (h, (score, s)) in verdict.scores.iter_mut().zip(&sampled).enumerate() {
        score.rotation = placement::implied_rotation(
            a.vertices(),
            side_b.shape.vertices(),
            &s.sample_b.vertices,
            &s.p2p_ba,
        );
        score.turn_degrees = placement::turn_degrees(&score.rotation);
        score.landmark_error = landmark_error(
            &guidance.landmarks,
            s.fmap_ab.as_ref(),
            (phi_a, phi_b),
            (a.vertices(), scale_a),
        );
        score.one_to_one = match (&score.kind, candidates.get(h), regions) {
            (HypothesisKind::Symmetric, _, _) => Vec::new(),
            (HypothesisKind::Placement | HypothesisKind::Landmarks, _, Some(regions)) => {
                hypotheses::one_to_one_from_samples(
                    regions,
                    (Some(&s.sample_b.vertices), &s.sample_b.weights),
                    &s.p2p_ba,
                )
            }
            (_, Some(groups), _) => groups
                .iter()
                .filter_map(|(ga, gb)| Some((*ga.first()?, *gb.first()?)))
                .collect(),
            _ => Vec::new(),
        };
    }
    if guidance.placement != Placement::Ignore {
        verdict.apply_placement(guidance.placement);
    }
    if !guidance.landmarks.is_empty() {
        verdict.apply_landmarks();
    }
    // A close call is decided at full resolution, where a mesh's orientation is known and a
    // cloud's coverage is (unless the placement or the landmarks decided).
    let mut chosen_map = None;
    if let (Some(rival), Decision::Cost) = (verdict.close_call(), verdict.decided_by) {
        cancel.check()?;
        let convert =
            |h: usize| fmap_to_p2p(verdict.scores[h].fmap_ab.as_ref(), phi_a, phi_b, cancel);
        let (chosen_p2p, rival_p2p) = (convert(verdict.chosen)?, convert(rival)?);
        // A cloud's local triangles do not settle a close call: a wrong map can keep more
        // of them than the right one (docs/scans.md, "Point clouds").
        let is_cloud = |s: &Shape| s.kind() == ShapeKind::PointCloud;
        let faces = faces.filter(|_| !is_cloud(a) && !is_cloud(side_b.shape));
        let consistency = (
            hypotheses::full_consistency(a, faces, &chosen_p2p),
            hypotheses::full_consistency(a, faces, &rival_p2p),
        );
        let changed = verdict.settle(rival, consistency);
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
        (params, landmarks): (&PointwiseParams, &[u32]),
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
        if !landmarks.is_empty() {
            // Each landmark's distance function: the same descriptor on both shapes.
            let sources = Mat::from_fn(shape.n_vertices(), landmarks.len(), |v, l| {
                if landmarks[l] as usize == v {
                    1.0
                } else {
                    0.0
                }
            });
            let distances = distance_functions(shape, basis, sources.as_ref());
            features.point_coef.push(project(
                basis.vectors.as_ref(),
                &basis.mass,
                k,
                distances.as_ref(),
            ));
            let (m, o) = operators(distances.as_ref());
            features.point_multiplication.extend(m);
            features.point_orientation.extend(o);
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
        side_a: ShapeBasis<'_>,
        side_b: ShapeBasis<'_>,
        regions: Option<RegionMatches<'_>>,
        candidates: &[&[(Vec<u32>, Vec<u32>)]],
        orientation_faces: Option<FacePair<'_>>,
        (params, landmarks): (&PointwiseParams, &[Landmark]),
        k: usize,
    ) -> Result<Features> {
        let ShapeBasis {
            shape: a,
            basis: basis_a,
        } = side_a;
        let ShapeBasis {
            shape: b,
            basis: basis_b,
        } = side_b;
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
        let (landmarks_a, landmarks_b): (Vec<u32>, Vec<u32>) =
            landmarks.iter().map(|&[la, lb]| (la, lb)).unzip();
        let side = |shape, basis, labels, sets: &[Vec<u32>], landmarks: &[u32], faces| {
            SideFeatures::new(
                shape,
                basis,
                labels,
                sets,
                (params, landmarks),
                k,
                multiplication,
                faces,
            )
        };
        let labels_a = regions.map(|r| (r.labels_a, r.n_regions_a));
        let labels_b = regions.map(|r| (r.labels_b, r.n_regions_b));
        Ok(Features {
            a: side(
                a,
                basis_a,
                labels_a,
                &sets_a,
                &landmarks_a,
                orientation_faces.map(|f| f.0),
            )?,
            b: side(
                b,
                basis_b,
                labels_b,
                &sets_b,
                &landmarks_b,
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
        solve_fmap_commuting(
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

/// The corresponding region sets that constrain the map: one pair per one-to-one match,
/// or one per group of symmetric matches (the connected components of their bipartite
/// graph, [`crate::regions::symmetry::bipartite_groups`]).
pub fn region_groups(regions: RegionMatches<'_>, kind: RegionConstraints) -> RegionGroups {
    match kind {
        RegionConstraints::None => Vec::new(),
        RegionConstraints::OneToOne => regions
            .one_to_one
            .iter()
            .map(|&(i, j)| (vec![i], vec![j]))
            .collect(),
        RegionConstraints::Symmetric => crate::regions::symmetry::bipartite_groups(regions.matches),
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
