//! The region correspondence of two shapes (docs/design.md, steps 1-12).
//!
//! [`Correspondence::compute`] runs the pair job ([`crate::pipeline::pair`]); on given
//! eigenbases, [`Correspondence::from_bases`] runs: HKS of each shape -> rank alignment and
//! joint segmentation over a range of k, with the two shape graphs
//! ([`crate::regions::segmentation`]) -> spectral graph matching into a symmetric region
//! correspondence ([`crate::regions::matching`]) -> symmetry breaking into a one-to-one
//! correspondence ([`crate::regions::symmetry`]), verified by maps
//! ([`crate::pipeline::pointwise::verify_regions`]). Every per-vertex output is indexed by
//! the caller's vertices.

use std::time::Instant;

use crate::colors::region_colors;
use crate::geodesic::region_distance_matrix;
use crate::maps::hypotheses::Verdict;
use crate::pipeline::budget::Estimate;
use crate::pipeline::multiresolution::Working;
use crate::pipeline::pair::{run_pair, PairJob, PairShapes};
use crate::pipeline::params::{HksFallback, Params};
use crate::pipeline::pointwise::verify_regions;
use crate::progress::{check, NoProgress, Progress, Stage};
use crate::regions::graph::ShapeGraph;
use crate::regions::matching::{match_graphs, overlong_lists, GraphMatching, MatchingParams};
use crate::regions::segmentation::{segment_pair, Described, JointSegmentation, KCandidate};
use crate::regions::symmetry::one_to_one;
use crate::regions::RegionMatches;
use crate::shape::Shape;
use crate::spectral::descriptors::{hks, HksParams};
use crate::spectral::eigen::{Eigenbasis, ShapeBasis};
use crate::{Error, Result};

/// Seconds spent in each stage.
#[derive(Debug, Clone, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Timings {
    /// Eigenbasis of shape A (0 when the bases were given, [`Correspondence::from_bases`]).
    pub eigenbasis_a: f64,
    /// Eigenbasis of shape B (0 when the bases were given, [`Correspondence::from_bases`]).
    pub eigenbasis_b: f64,
    /// HKS descriptors of both shapes, the fallback try included.
    pub descriptors: f64,
    /// Joint segmentation and shape graphs, the fallback try included.
    pub segmentation: f64,
    /// Spectral graph matching, the fallback try included.
    pub matching: f64,
    /// Symmetry breaking into the one-to-one matches, their verification included.
    pub one_to_one: f64,
    /// Building the proxies of dense shapes (or refined copies of low-poly meshes) and
    /// bringing the answers back to every input vertex (0 when both shapes ran as they are,
    /// [`Params::multiresolution`]).
    pub proxies: f64,
    /// Whole call, from [`Correspondence::compute`] or [`Correspondence::from_bases`].
    pub total: f64,
}

/// A region correspondence between shapes A and B.
#[derive(Debug, Clone)]
pub struct Correspondence {
    /// The number of joint clusters chosen.
    pub k: usize,
    /// Shape graph of A; `graph_a.labels` is the region of every vertex of A.
    pub graph_a: ShapeGraph,
    /// Shape graph of B.
    pub graph_b: ShapeGraph,
    /// Symmetric (many-to-many) matches `(region of A, region of B)`, sorted.
    pub matches: Vec<(u32, u32)>,
    /// One-to-one matches, a subset of `matches` (a global left/right flip is not an error).
    pub matches_one_to_one: Vec<(u32, u32)>,
    /// The values of k that were tried, with their graphs' sizes and scores.
    pub candidates: Vec<KCandidate>,
    /// Seconds per stage.
    pub timings: Timings,
    /// The one-to-one hypotheses verified at the map level and the confidence of the
    /// answer ([`Params::verify_hypotheses`]; None when off or when there was no choice).
    pub verdict: Option<Verdict>,
    /// What the job was estimated to take before it started (None from
    /// [`Correspondence::from_bases`], which the budget does not see).
    pub estimate: Option<Estimate>,
    /// What the pipeline ran on for A and B: the input, a proxy or a refined copy
    /// ([`Params::multiresolution`]).
    pub working: [Working; 2],
}

impl Correspondence {
    /// Region correspondence between two shapes with the given parameters (the pair job,
    /// [`run_pair`]).
    pub fn compute(
        a: &Shape,
        b: &Shape,
        params: &Params,
        progress: &mut dyn Progress,
    ) -> Result<Correspondence> {
        let job = PairJob { params, map: None };
        Ok(run_pair(PairShapes::Two(a, b), job, progress)?.regions)
    }

    /// As [`Correspondence::compute`], with eigenbases computed beforehand (an eigenbasis is
    /// computed once per shape and reused for every pair it is in).
    pub fn from_bases(
        side_a: ShapeBasis<'_>,
        side_b: ShapeBasis<'_>,
        params: &Params,
        progress: &mut dyn Progress,
    ) -> Result<Correspondence> {
        params.validate()?;
        let (basis_a, basis_b) = (side_a.basis, side_b.basis);
        let started = Instant::now();
        let mut timings = Timings::default();

        let (segmentation, matching) =
            segment_and_match(side_a, side_b, &params.hks, params, &mut timings, progress)?;
        let (segmentation, matching) = match &params.fallback {
            Some(fallback) => {
                let own = self_score(&segmentation, &matching, basis_a, basis_b);
                if own.needs_fallback(fallback) {
                    let alt_hks = HksParams {
                        t_min: fallback.hks_t_min,
                        ..params.hks.clone()
                    };
                    let (seg2, match2) = segment_and_match(
                        side_a,
                        side_b,
                        &alt_hks,
                        params,
                        &mut timings,
                        progress,
                    )?;
                    if self_score(&seg2, &match2, basis_a, basis_b).key() < own.key() {
                        (seg2, match2)
                    } else {
                        (segmentation, matching)
                    }
                } else {
                    (segmentation, matching)
                }
            }
            None => (segmentation, matching),
        };

        if matching.matches.is_empty() {
            return Err(no_match(&segmentation, &matching, params));
        }
        check(progress, Stage::SymmetryBreaking, 0.0)?;
        let t = Instant::now();
        let matches_one_to_one = one_to_one_matches(
            (side_a, &segmentation.graph_a),
            (side_b, &segmentation.graph_b),
            &matching.matches,
            params,
        )?;
        let mut result = Correspondence {
            k: segmentation.k,
            graph_a: segmentation.graph_a,
            graph_b: segmentation.graph_b,
            matches: matching.matches,
            matches_one_to_one,
            candidates: segmentation.candidates,
            timings,
            verdict: None,
            estimate: None,
            working: [side_a.shape, side_b.shape].map(|s| Working::of(s, None)),
        };
        if params.verify_hypotheses && !params.skip_one_to_one {
            verify_regions(side_a, side_b, &mut result, &params.guidance(), progress)?;
        }
        result.timings.one_to_one = t.elapsed().as_secs_f64();
        check(progress, Stage::SymmetryBreaking, 1.0)?;
        result.timings.total = started.elapsed().as_secs_f64();
        Ok(result)
    }

    /// The confidence of the one-to-one answer in [0, 1] (None when it was not verified).
    pub fn confidence(&self) -> Option<f64> {
        self.verdict.as_ref().map(|v| v.confidence)
    }

    /// The other answer: the runner-up hypothesis's one-to-one matches with its verdict
    /// ([`Verdict::other`]; nothing is recomputed). None when no other hypothesis gives a
    /// different map.
    pub fn other_answer(&self) -> Option<Correspondence> {
        let verdict = self.verdict.as_ref()?.other()?;
        let mut other = self.clone();
        other.matches_one_to_one = verdict.chosen().one_to_one.clone();
        other.verdict = Some(verdict);
        Some(other)
    }

    /// The regions and matches as the map stages read them.
    pub fn matches_view(&self) -> RegionMatches<'_> {
        RegionMatches {
            labels_a: &self.graph_a.labels,
            n_regions_a: self.graph_a.n_nodes(),
            labels_b: &self.graph_b.labels,
            n_regions_b: self.graph_b.n_nodes(),
            matches: &self.matches,
            one_to_one: &self.matches_one_to_one,
            verified: self.verdict.is_some(),
        }
    }

    /// Region of every vertex of A.
    pub fn regions_a(&self) -> &[u32] {
        &self.graph_a.labels
    }

    /// Region of every vertex of B.
    pub fn regions_b(&self) -> &[u32] {
        &self.graph_b.labels
    }

    /// Per-vertex colours of A and B ([`region_colors`]): by the one-to-one matches when
    /// `one_to_one` is true, else by the symmetric matches (a symmetric group shares one
    /// colour).
    pub fn vertex_colors(&self, one_to_one: bool) -> (Vec<[u8; 3]>, Vec<[u8; 3]>) {
        let pairs = if one_to_one {
            &self.matches_one_to_one
        } else {
            &self.matches
        };
        region_colors(
            &self.graph_a.labels,
            self.graph_a.n_nodes(),
            &self.graph_b.labels,
            self.graph_b.n_nodes(),
            pairs,
        )
    }
}

/// The error of a matching that paired no region of A with one of B: an answer with no
/// match is no correspondence (every colour grey, nothing to constrain a map), so it fails,
/// naming `gap_ratio` and `max_symmetry_order` when the candidate lists were too long for
/// them ([`overlong_lists`]).
fn no_match(seg: &JointSegmentation, m: &GraphMatching, params: &Params) -> Error {
    let (n_a, n_b) = (seg.graph_a.n_nodes(), seg.graph_b.n_nodes());
    let p = &params.matching;
    let overlong = overlong_lists(&m.scores, (n_a, n_b), p.gap_ratio, p.max_symmetry_order);
    let found = format!(
        "no region of A was matched to one of B (k = {}, {n_a} and {n_b} regions)",
        seg.k
    );
    if overlong > 0 {
        Error::InvalidParameter {
            name: "gap_ratio",
            reason: format!(
                "{found}: {overlong} of the {} regions had more than max_symmetry_order = {} \
                 candidates within a factor gap_ratio = {:?} of each other, so none was kept; \
                 use a gap_ratio nearer 1 (default {}) or a larger max_symmetry_order \
                 (default {})",
                n_a + n_b,
                p.max_symmetry_order,
                p.gap_ratio,
                MatchingParams::default().gap_ratio,
                MatchingParams::default().max_symmetry_order,
            ),
        }
    } else {
        Error::Numerical {
            stage: "graph matching",
            reason: format!(
                "{found}: the two shape graphs agree on no region; check that the shapes are \
                 of one kind, or try other k_min and k_max"
            ),
        }
    }
}

/// Self-consistency of one segmentation and matching (no ground truth).
#[derive(Debug, Clone, Copy)]
struct SelfScore {
    /// Area fraction in regions without a symmetric match, mean of A and B.
    unmatched: f64,
    /// Degree-histogram difference of the chosen k (0: equal histograms).
    degree_difference: f64,
}

impl SelfScore {
    fn needs_fallback(&self, fallback: &HksFallback) -> bool {
        self.unmatched > fallback.max_unmatched || self.degree_difference > 0.0
    }

    /// Lower is better.
    fn key(&self) -> f64 {
        self.unmatched + 0.1 * self.degree_difference
    }
}

fn self_score(
    seg: &JointSegmentation,
    m: &GraphMatching,
    basis_a: &Eigenbasis,
    basis_b: &Eigenbasis,
) -> SelfScore {
    let unmatched = |labels: &[u32], mass: &[f64], n: usize, side: bool| {
        let mut matched = vec![false; n];
        for &(i, j) in &m.matches {
            matched[if side { j } else { i } as usize] = true;
        }
        let total: f64 = mass.iter().sum();
        let lost: f64 = labels
            .iter()
            .zip(mass)
            .filter(|(&r, _)| !matched[r as usize])
            .map(|(_, &w)| w)
            .sum();
        lost / total.max(f64::MIN_POSITIVE)
    };
    let ua = unmatched(
        &seg.graph_a.labels,
        &basis_a.mass,
        seg.graph_a.n_nodes(),
        false,
    );
    let ub = unmatched(
        &seg.graph_b.labels,
        &basis_b.mass,
        seg.graph_b.n_nodes(),
        true,
    );
    let degree = seg
        .candidates
        .iter()
        .find(|c| c.k == seg.k)
        .map(|c| c.score)
        .unwrap_or(0.0);
    SelfScore {
        unmatched: 0.5 * (ua + ub),
        degree_difference: degree,
    }
}

/// Descriptors, joint segmentation and graph matching with the given HKS parameters.
fn segment_and_match(
    ShapeBasis {
        shape: a,
        basis: basis_a,
    }: ShapeBasis<'_>,
    ShapeBasis {
        shape: b,
        basis: basis_b,
    }: ShapeBasis<'_>,
    hks_params: &HksParams,
    params: &Params,
    timings: &mut Timings,
    progress: &mut dyn Progress,
) -> Result<(JointSegmentation, GraphMatching)> {
    check(progress, Stage::Descriptors, 0.0)?;
    let t = Instant::now();
    let desc_a = hks(basis_a, hks_params)?;
    // Symmetry detection passes the same basis twice: compute its HKS once.
    let desc_b = if std::ptr::eq(basis_a, basis_b) {
        desc_a.clone()
    } else {
        hks(basis_b, hks_params)?
    };
    timings.descriptors += t.elapsed().as_secs_f64();

    check(progress, Stage::Segmentation, 0.0)?;
    let t = Instant::now();
    let segmentation = segment_pair(
        Described {
            shape: a,
            mass: &basis_a.mass,
            descriptors: desc_a.as_ref(),
        },
        Described {
            shape: b,
            mass: &basis_b.mass,
            descriptors: desc_b.as_ref(),
        },
        &params.segmentation,
        progress,
    )?;
    timings.segmentation += t.elapsed().as_secs_f64();

    check(progress, Stage::Matching, 0.0)?;
    let t = Instant::now();
    let matching = match_graphs(
        &segmentation.graph_a,
        &segmentation.graph_b,
        &params.matching,
    )?;
    timings.matching += t.elapsed().as_secs_f64();
    Ok((segmentation, matching))
}

/// The one-to-one step (paper section 5.2) on symmetric `matches` between the regions of
/// `graph_a` and `graph_b`: region-to-region distances on each shape, then
/// [`one_to_one`]; empty when `params.skip_one_to_one`. Shared by the main method and the
/// Reeb baseline (`shapecorr_eval::reeb`).
pub fn one_to_one_matches(
    (a, graph_a): (ShapeBasis<'_>, &ShapeGraph),
    (b, graph_b): (ShapeBasis<'_>, &ShapeGraph),
    matches: &[(u32, u32)],
    params: &Params,
) -> Result<Vec<(u32, u32)>> {
    if params.skip_one_to_one {
        return Ok(Vec::new());
    }
    let distances = |side: ShapeBasis<'_>, graph: &ShapeGraph| {
        let (shape, basis) = (side.shape, side.basis);
        region_distance_matrix(
            shape,
            &basis.mass,
            &graph.labels,
            graph.n_nodes(),
            1.0 / basis.input_area.sqrt(),
        )
    };
    let (d_a, d_b) = (distances(a, graph_a), distances(b, graph_b));
    one_to_one(matches, d_a.as_ref(), d_b.as_ref(), &params.symmetry)
}

/// Convenience: [`Correspondence::compute`] with default parameters and no progress.
pub fn correspond(a: &Shape, b: &Shape) -> Result<Correspondence> {
    Correspondence::compute(a, b, &Params::default(), &mut NoProgress)
}
