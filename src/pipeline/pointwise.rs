//! The pointwise job: the regions and the point-to-point map of a pair on given eigenbases
//! (docs/design.md, step 13), and the verification of a region answer by maps (step 12.1).

use crate::maps::fmap::{p2p_to_fmap, ZoomOutParams};
use crate::maps::hypotheses::{self, Verdict};
use crate::maps::partial::{self, PartialReport, Partiality};
use crate::maps::placement::Guidance;
use crate::maps::pointwise::{pin_landmarks, PointwiseMap, PointwiseParams, Refinement};
use crate::pipeline::budget::Estimate;
use crate::pipeline::correspondence::Correspondence;
use crate::pipeline::pair::{run_pair, PairJob, PairShapes};
use crate::pipeline::Params;
use crate::progress::{check, polled, AsStage, Progress, Stage};
use crate::shape::Shape;
use crate::spectral::eigen::{EigenParams, Eigenbasis, ShapeBasis};
use crate::{Error, Result};
use faer::MatRef;

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
    /// What the job was estimated to take before it started ([`crate::pipeline::budget`]).
    pub estimate: Estimate,
    /// [`Shape::fingerprint`] of A and B: [`PointwiseCorrespondence::check_shapes`].
    pub fingerprints: [u64; 2],
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
        let job = PairJob {
            params,
            map: Some(pointwise),
        };
        let pair = run_pair(PairShapes::Two(a, b), job, progress)?;
        let map = pair
            .map
            .expect("a pair job with map parameters gives a map");
        Ok(PointwiseCorrespondence {
            regions: pair.regions,
            map,
            eigenbasis_a: pair.eigenbasis_s[0],
            eigenbasis_b: pair.eigenbasis_s[1],
            proxies: pair.proxies_s,
            total: pair.total_s,
            estimate: pair.estimate,
            fingerprints: [a.fingerprint(), b.fingerprint()],
        })
    }

    /// Checks that `a` and `b` are the shapes the map was computed from, in that order
    /// (their [`Shape::fingerprint`]s): a shape with the same vertex count but other
    /// positions or faces, or A and B swapped, is refused.
    pub fn check_shapes(&self, a: &Shape, b: &Shape) -> Result<()> {
        let [fa, fb] = self.fingerprints;
        let given = [a.fingerprint(), b.fingerprint()];
        if given == [fa, fb] {
            return Ok(());
        }
        let (name, shape, side) = if given[0] != fa {
            ("a", a, "A")
        } else {
            ("b", b, "B")
        };
        let hint = if given == [fb, fa] {
            ": A and B are swapped"
        } else {
            ""
        };
        Err(Error::InvalidParameter {
            name,
            reason: format!(
                "is not the shape {side} the pointwise map was computed from (it has {} \
                 vertices, but other positions or faces{hint}); pass the two shapes given to \
                 the pointwise map, in the same order",
                shape.n_vertices()
            ),
        })
    }

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

    /// The other answer: the runner-up hypothesis's map and one-to-one regions, with its
    /// verdict ([`Verdict::other`]), computed with this one (nothing is recomputed). None
    /// when no other hypothesis gives a different map.
    pub fn other_answer(&self) -> Option<PointwiseCorrespondence> {
        let verdict = self.map.verdict.as_ref()?.other()?;
        let p2p_ba = self.map.other_p2p_ba.clone()?;
        let mut other = self.clone();
        other.map.other_p2p_ba = Some(std::mem::replace(&mut other.map.p2p_ba, p2p_ba));
        other.map.fmap_ab = verdict.chosen().fmap_ab.clone();
        if let Some(coverage) = other.map.other_coverage.take() {
            other.map.other_coverage = Some(std::mem::replace(&mut other.map.coverage, coverage));
        }
        other.regions.matches_one_to_one = verdict.chosen().one_to_one.clone();
        other.regions.verdict = Some(verdict.clone());
        other.map.verdict = Some(verdict);
        Some(other)
    }
}

/// The eigensolver's parameters of a pointwise job: enough eigenpairs for the map and the
/// regions, computed once per shape.
pub fn basis_params(params: &Params, pointwise: &PointwiseParams) -> EigenParams {
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
    a: ShapeBasis<'_>,
    b: ShapeBasis<'_>,
    params: &Params,
    pointwise: &PointwiseParams,
    progress: &mut dyn Progress,
) -> Result<(Correspondence, PointwiseMap)> {
    let k = params.eigen.n_eigenpairs;
    let unverified = Params {
        verify_hypotheses: false,
        ..params.clone()
    };
    let (basis_a, basis_b) = (truncated(a.basis, k), truncated(b.basis, k));
    let mut regions = Correspondence::from_bases(
        ShapeBasis::new(a.shape, &basis_a),
        ShapeBasis::new(b.shape, &basis_b),
        &unverified,
        progress,
    )?;
    check(progress, Stage::PointwiseMap, 0.0)?;
    let pointwise = PointwiseParams {
        hypotheses: pointwise.hypotheses && params.verify_hypotheses,
        orientation: pointwise.orientation && params.verify_hypotheses,
        ..pointwise.clone()
    };
    let (partial, guidance) = partiality(a, b, params);
    let mut map = PointwiseMap::guided(
        a,
        b,
        Some(regions.matches_view()),
        &pointwise,
        &guidance,
        progress,
    )?;
    // A's image in B, when A is a part of B: of the chosen map and of the runner-up's.
    let (mut into_whole, mut other_into_whole) = (None, None);
    if let (Some(slope), Refinement::ZoomOut(zoomout)) =
        (guidance.part_slope, &pointwise.refinement)
    {
        // The chosen map grown again from its first eigenfunctions on the slanted diagonal:
        // on the generated lower cuts the quadrupeds' mean error fell from 0.057 to 0.015
        // (docs/partial.md).
        let (fmap_ab, p2p_ba) = polled(progress, Stage::PointwiseMap, (0.9, 0.95), |cancel| {
            partial::part_map((a, b), &map.p2p_ba, slope, zoomout, cancel)
        })?;
        (map.fmap_ab, map.p2p_ba) = (fmap_ab, p2p_ba);
        if partial.partiality == Partiality::AInB {
            let other_fmap_ab = (map.verdict.as_ref())
                .and_then(|v| Some(&v.scores[v.runner_up()?].fmap_ab))
                .filter(|_| map.other_p2p_ba.is_some());
            polled(progress, Stage::PointwiseMap, (0.95, 1.0), |cancel| {
                let into = |fmap: MatRef<'_, f64>| {
                    partial::part_into_whole((a, b), fmap, slope, zoomout, cancel)
                };
                let (p2p_ab, p2p_ba) = into(map.fmap_ab.as_ref())?;
                // The functional map of the map given, not of the one it was remade from.
                let (k_b, k_a) = (map.fmap_ab.nrows(), map.fmap_ab.ncols());
                let (phi_a, phi_b) = (a.basis.vectors.as_ref(), b.basis.vectors.as_ref());
                map.fmap_ab = p2p_to_fmap(&p2p_ba, phi_a, phi_b, &b.basis.mass, k_a, k_b);
                (into_whole, map.p2p_ba) = (Some(p2p_ab), p2p_ba);
                if let Some(fmap) = other_fmap_ab {
                    let (p2p_ab, p2p_ba) = into(fmap.as_ref())?;
                    (other_into_whole, map.other_p2p_ba) = (Some(p2p_ab), Some(p2p_ba));
                }
                Ok(())
            })?;
        }
        for p2p in std::iter::once(&mut map.p2p_ba).chain(map.other_p2p_ba.as_mut()) {
            pin_landmarks(p2p, &params.landmarks);
        }
    }
    map.coverage = partial::coverage(a, b, &map.p2p_ba, into_whole.as_deref());
    map.other_coverage = (map.other_p2p_ba.as_deref())
        .map(|p2p_ba| partial::coverage(a, b, p2p_ba, other_into_whole.as_deref()));
    map.partial = partial;
    if let Some(verdict) = &map.verdict {
        regions.matches_one_to_one =
            hypotheses::one_to_one_from_map(regions.matches_view(), &map.p2p_ba, &b.basis.mass);
        regions.verdict = Some(verdict.clone());
    }
    check(progress, Stage::PointwiseMap, 1.0)?;
    Ok((regions, map))
}

/// Whether B is a part of A (or A of B), from the shapes' open boundaries and areas
/// ([`partial::detect`]); a part and its whole are taken to be in the same units, as
/// Rodolà et al. do, so the slope of a part's map is the ratio of the two areas.
fn partiality(a: ShapeBasis<'_>, b: ShapeBasis<'_>, params: &Params) -> (PartialReport, Guidance) {
    let boundary = [
        partial::open_boundary(a.shape),
        partial::open_boundary(b.shape),
    ];
    let area_share = b.basis.input_area / a.basis.input_area;
    let report = partial::detect(params.partial, boundary, area_share);
    let guidance = Guidance {
        part_slope: (report.partiality != Partiality::Whole)
            .then(|| area_share.clamp(MIN_SLOPE, 1.0 / MIN_SLOPE)),
        ..params.guidance()
    };
    (report, guidance)
}

/// The smallest slope of a part's map: a part of a tenth of the whole's area (50 of A's
/// 100 eigenfunctions would leave B 5).
const MIN_SLOPE: f64 = 0.1;

/// Verifies the one-to-one answer of `regions` at the map level on the regions' own
/// eigenbases (ZoomOut up to their size): the hypotheses of [`hypotheses::candidates`] are
/// refined and judged, the one-to-one matches become those that agree best with the chosen
/// map ([`hypotheses::one_to_one_from_map`]) and the verdict is kept with them. Nothing
/// changes when there is a single hypothesis. Reported as [`Stage::SymmetryBreaking`].
pub fn verify_regions(
    a: ShapeBasis<'_>,
    b: ShapeBasis<'_>,
    regions: &mut Correspondence,
    guidance: &Guidance,
    progress: &mut dyn Progress,
) -> Result<()> {
    if regions.matches_one_to_one.is_empty() {
        return Ok(());
    }
    let n = a.basis.len().min(b.basis.len());
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
    let mut as_stage = AsStage {
        inner: progress,
        stage: Stage::SymmetryBreaking,
    };
    let map = PointwiseMap::guided(
        a,
        b,
        Some(regions.matches_view()),
        &params,
        guidance,
        &mut as_stage,
    )?;
    if let Some(verdict) = map.verdict {
        regions.matches_one_to_one =
            hypotheses::one_to_one_from_map(regions.matches_view(), &map.p2p_ba, &b.basis.mass);
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
