//! The whole job behind one call: two shapes in, their regions and the region
//! correspondence out (docs/design.md, steps 1-12 and 14).
//!
//! `Correspondence::compute(&a, &b, &params, &mut progress)` runs: eigenbasis and HKS of each
//! shape -> rank alignment and joint segmentation over a range of k, with the two shape
//! graphs ([`crate::regions::segmentation`]) -> spectral graph matching into a symmetric region
//! correspondence ([`crate::regions::matching`]) -> symmetry breaking into a one-to-one
//! correspondence ([`crate::regions::symmetry`]). Every per-vertex output is indexed by the caller's
//! vertices.

use std::time::Instant;

use crate::budget::{regions_job, Budget, Job};
use crate::colors::{palette, region_colors, UNMATCHED_COLOR};
use crate::geodesic::region_distance_matrix;
use crate::maps::hypotheses::Verdict;
use crate::multiresolution::{lift_regions, working, Multiresolution};
use crate::progress::{check, NoProgress, Progress, Stage};
use crate::regions::graph::ShapeGraph;
use crate::regions::matching::{match_graphs, MatchingParams};
use crate::regions::segmentation::{segment_pair_with_progress, KCandidate, SegmentationParams};
use crate::regions::symmetry::{one_to_one, SymmetryParams};
use crate::shape::Shape;
use crate::spectral::descriptors::{hks, HksParams};
use crate::spectral::eigen::{EigenParams, Eigenbasis};
use crate::Result;

/// Every parameter of the method, with the documented defaults. The command line, the C API
/// and the add-ons all take their defaults from here.
#[derive(Debug, Clone)]
pub struct Params {
    /// Laplacian eigenbasis ([`REGION_EIGENPAIRS`] = 50 eigenpairs).
    pub eigen: EigenParams,
    /// Heat kernel signature (15 times in [0.03, 0.25], raw).
    pub hks: HksParams,
    /// Rank alignment, joint k-means, shape graphs and the choice of k.
    pub segmentation: SegmentationParams,
    /// Spectral graph matching and discretisation.
    pub matching: MatchingParams,
    /// Symmetry breaking.
    pub symmetry: SymmetryParams,
    /// Skip the one-to-one step (then `matches_one_to_one` is empty).
    pub skip_one_to_one: bool,
    /// Second try with HKS from a smaller time for pairs whose first result leaves area
    /// unmatched or whose graphs' degree histograms differ; the try with the better
    /// self-consistency (unmatched area + 0.1 x degree-histogram difference) is kept.
    /// Measured (squared one-to-one cost): FAUST 126 pairs symmetric 0.951 -> 0.953,
    /// one-to-one with flip 0.947 -> 0.949, worst pair 0.748 -> 0.869 (tr_reg_056 ->
    /// tr_reg_027, whose first try leaves 18% of the area unmatched; tr_reg_059 -> tr_reg_041
    /// 0.801 -> 0.923); two pairs change. A smaller t_min for every pair instead hurt remeshed
    /// TOSCA (0.940, one pair 0.013). `None` turns it off.
    pub fallback: Option<HksFallback>,
    /// Choose the one-to-one matches among hypotheses (the answer, its mirror image, the
    /// symmetric groups, single-group alternatives) by their maps refined on the regions'
    /// eigenbasis ([`crate::maps::hypotheses`]), and give the answer a confidence. Measured
    /// in docs/decisions.md (issue 18).
    pub verify_hypotheses: bool,
    /// Dense shapes run on proxies ([`crate::multiresolution`]): above 12K vertices, proxies
    /// of about 8K.
    pub multiresolution: Multiresolution,
    /// The job's memory ceiling and time limit, checked from an estimate before any work
    /// and the time limit enforced while it runs ([`crate::budget`]).
    pub budget: Budget,
    /// Keeps the struct open to new fields: build it with `..Default::default()`.
    #[doc(hidden)]
    pub non_exhaustive: crate::NonExhaustive,
}

/// Eigenpairs for region matching. The HKS at t >= 0.03 only needs the eigenvalues with
/// non-negligible exp(-lambda t): measured on FAUST tr_reg_000 and TOSCA david0, 50 eigenpairs
/// give the HKS within 1e-7 (relative) of 100 (30: 1e-4), at half the eigensolver's time.
pub const REGION_EIGENPAIRS: usize = 50;

impl Default for Params {
    fn default() -> Self {
        Params {
            eigen: EigenParams {
                n_eigenpairs: REGION_EIGENPAIRS,
                ..Default::default()
            },
            hks: HksParams::default(),
            segmentation: SegmentationParams::default(),
            matching: MatchingParams::default(),
            symmetry: SymmetryParams::default(),
            skip_one_to_one: false,
            fallback: Some(HksFallback::default()),
            verify_hypotheses: true,
            multiresolution: Multiresolution::default(),
            budget: Budget::default(),
            non_exhaustive: crate::NonExhaustive(()),
        }
    }
}

impl Params {
    /// Checks every parameter's range before any work starts, so a bad value fails at once
    /// with [`crate::Error::InvalidParameter`] instead of after the eigensolver.
    pub fn validate(&self) -> Result<()> {
        self.check_option_ranges()?;
        self.eigen.validate()?;
        self.hks.validate()?;
        self.segmentation.validate()?;
        self.matching.validate()?;
        self.multiresolution.validate()?;
        if let Some(fallback) = &self.fallback {
            if !(fallback.hks_t_min > 0.0 && fallback.hks_t_min <= self.hks.t_max) {
                return Err(crate::Error::InvalidParameter {
                    name: "fallback.hks_t_min",
                    reason: format!(
                        "need 0 < t_min <= hks.t_max = {}, got {}",
                        self.hks.t_max, fallback.hks_t_min
                    ),
                });
            }
            if !(0.0..=1.0).contains(&fallback.max_unmatched) {
                return Err(crate::Error::InvalidParameter {
                    name: "fallback.max_unmatched",
                    reason: format!("must lie in [0, 1], got {}", fallback.max_unmatched),
                });
            }
        }
        Ok(())
    }
}

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
    /// Building the proxies of dense shapes and bringing the answers back to every input
    /// vertex (0 when both shapes ran at full resolution, [`Params::multiresolution`]).
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
}

impl Correspondence {
    /// Region correspondence between two shapes with the given parameters.
    pub fn compute(
        a: &Shape,
        b: &Shape,
        params: &Params,
        progress: &mut dyn Progress,
    ) -> Result<Correspondence> {
        params.validate()?;
        params.budget.check(&Correspondence::job(a, b, params))?;
        params.budget.run(progress, |progress| {
            let started = Instant::now();
            let proxies = params
                .multiresolution
                .proxies([a, b], &params.eigen, progress)?;
            let built = started.elapsed().as_secs_f64();
            let [proxy_a, proxy_b] = &proxies;
            let (working_a, working_b) = (working(a, proxy_a), working(b, proxy_b));
            let mut result =
                Correspondence::compute_within(working_a, working_b, params, progress)?;
            let t = Instant::now();
            lift_regions(&mut result, [proxy_a.as_ref(), proxy_b.as_ref()]);
            if proxy_a.is_some() || proxy_b.is_some() {
                result.timings.proxies = built + t.elapsed().as_secs_f64();
            }
            result.timings.total = started.elapsed().as_secs_f64();
            Ok(result)
        })
    }

    /// What [`Correspondence::compute`] will do on these shapes, for [`Budget::check`].
    pub fn job(a: &Shape, b: &Shape, params: &Params) -> Job {
        let verify = params.verify_hypotheses && !params.skip_one_to_one;
        let sizes = [a, b].map(|s| params.multiresolution.working_size(s));
        regions_job(sizes, &params.eigen, verify)
    }

    /// [`Correspondence::compute`] once the budget has accepted the job.
    fn compute_within(
        a: &Shape,
        b: &Shape,
        params: &Params,
        progress: &mut dyn Progress,
    ) -> Result<Correspondence> {
        let started = Instant::now();
        let ([basis_a, basis_b], [t_a, t_b]) = Eigenbasis::pair((a, b), &params.eigen, progress)?;
        let mut result = Correspondence::from_bases(a, &basis_a, b, &basis_b, params, progress)?;
        result.timings.eigenbasis_a = t_a;
        result.timings.eigenbasis_b = t_b;
        result.timings.total = started.elapsed().as_secs_f64();
        Ok(result)
    }

    /// As [`Correspondence::compute`], with eigenbases computed beforehand (an eigenbasis is
    /// computed once per shape and reused for every pair it is in).
    pub fn from_bases(
        a: &Shape,
        basis_a: &Eigenbasis,
        b: &Shape,
        basis_b: &Eigenbasis,
        params: &Params,
        progress: &mut dyn Progress,
    ) -> Result<Correspondence> {
        params.validate()?;
        let started = Instant::now();
        let mut timings = Timings::default();

        let (segmentation, matching) = segment_and_match(
            a,
            basis_a,
            b,
            basis_b,
            &params.hks,
            params,
            &mut timings,
            progress,
        )?;
        let (segmentation, matching) = match &params.fallback {
            Some(fallback) => {
                let own = self_score(&segmentation, &matching, basis_a, basis_b);
                if own.needs_fallback(fallback) {
                    let alt_hks = HksParams {
                        t_min: fallback.hks_t_min,
                        ..params.hks.clone()
                    };
                    let (seg2, match2) = segment_and_match(
                        a,
                        basis_a,
                        b,
                        basis_b,
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

        check(progress, Stage::SymmetryBreaking, 0.0)?;
        let t = Instant::now();
        let matches_one_to_one = one_to_one_matches(
            (a, basis_a, &segmentation.graph_a),
            (b, basis_b, &segmentation.graph_b),
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
        };
        if params.verify_hypotheses && !params.skip_one_to_one {
            let (a, b) = ((a, basis_a), (b, basis_b));
            crate::maps::pointwise::verify_regions(a, b, &mut result, progress)?;
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

/// A second try with another HKS time range for pairs whose result looks doubtful by a
/// score that needs no ground truth ([`Params::fallback`]).
#[derive(Debug, Clone, PartialEq)]
pub struct HksFallback {
    /// Smallest HKS time of the second try (the other HKS parameters are kept).
    pub hks_t_min: f64,
    /// The second try runs when more than this fraction of the area (mean of A and B) is in
    /// regions without a symmetric match, or when the chosen k's degree histograms differ.
    pub max_unmatched: f64,
    /// Keeps the struct open to new fields: build it with `..Default::default()`.
    #[doc(hidden)]
    pub non_exhaustive: crate::NonExhaustive,
}

impl Default for HksFallback {
    fn default() -> Self {
        HksFallback {
            hks_t_min: 0.015,
            max_unmatched: 0.02,
            non_exhaustive: crate::NonExhaustive(()),
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
    seg: &crate::regions::segmentation::JointSegmentation,
    m: &crate::regions::matching::GraphMatching,
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
#[allow(clippy::too_many_arguments)]
fn segment_and_match(
    a: &Shape,
    basis_a: &Eigenbasis,
    b: &Shape,
    basis_b: &Eigenbasis,
    hks_params: &HksParams,
    params: &Params,
    timings: &mut Timings,
    progress: &mut dyn Progress,
) -> Result<(
    crate::regions::segmentation::JointSegmentation,
    crate::regions::matching::GraphMatching,
)> {
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
    let segmentation = segment_pair_with_progress(
        a,
        &basis_a.mass,
        desc_a.as_ref(),
        b,
        &basis_b.mass,
        desc_b.as_ref(),
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

/// Symmetric regions of one shape, found by matching the shape to itself (docs/design.md, step 14).
#[derive(Debug, Clone)]
pub struct Symmetry {
    /// The shape graph; `graph.labels` is the region of every vertex.
    pub graph: ShapeGraph,
    /// Groups of mutually symmetric regions (each sorted; groups sorted by first region).
    /// A region without a symmetric partner forms a group of its own.
    pub groups: Vec<Vec<u32>>,
    /// The self-matches found, `(region, region)`.
    pub matches: Vec<(u32, u32)>,
}

impl Symmetry {
    /// Self-symmetry groups of a shape.
    pub fn detect(shape: &Shape, params: &Params, progress: &mut dyn Progress) -> Result<Symmetry> {
        params.validate()?;
        let n = shape.active_vertices().len();
        params
            .budget
            .check(&regions_job([n, n], &params.eigen, false))?;
        params.budget.run(progress, |progress| {
            let basis = Eigenbasis::compute_with_progress(shape, &params.eigen, progress)?;
            Symmetry::from_basis(shape, &basis, params, progress)
        })
    }

    /// As [`Symmetry::detect`] with the eigenbasis given.
    pub fn from_basis(
        shape: &Shape,
        basis: &Eigenbasis,
        params: &Params,
        progress: &mut dyn Progress,
    ) -> Result<Symmetry> {
        let params = Params {
            skip_one_to_one: true,
            fallback: None,
            ..params.clone()
        };
        let pair = Correspondence::from_bases(shape, basis, shape, basis, &params, progress)?;
        let n = pair.graph_a.n_nodes();
        // Union-find over the self-matches; every region is its own group at first.
        let mut sets = crate::shape::DisjointSets::new(n);
        for &(i, j) in &pair.matches {
            sets.union(i as usize, j as usize);
        }
        let mut by_root: std::collections::BTreeMap<usize, Vec<u32>> = Default::default();
        for region in 0..n {
            by_root
                .entry(sets.find(region))
                .or_default()
                .push(region as u32);
        }
        let mut groups: Vec<Vec<u32>> = by_root.into_values().collect();
        groups.sort();
        Ok(Symmetry {
            graph: pair.graph_a,
            groups,
            matches: pair.matches,
        })
    }
}

impl Symmetry {
    /// Per-vertex colours: the regions of a group of two or more share a colour (one colour
    /// per group), regions without a symmetric partner are [`UNMATCHED_COLOR`].
    pub fn vertex_colors(&self) -> Vec<[u8; 3]> {
        let mut region_colour = vec![UNMATCHED_COLOR; self.graph.n_nodes()];
        for (index, group) in self.groups.iter().filter(|g| g.len() > 1).enumerate() {
            for &region in group {
                region_colour[region as usize] = palette(index);
            }
        }
        self.graph
            .labels
            .iter()
            .map(|&r| region_colour[r as usize])
            .collect()
    }
}

/// The one-to-one step (paper section 5.2) on symmetric `matches` between the regions of
/// `graph_a` and `graph_b`: region-to-region distances on each shape, then
/// [`one_to_one`]; empty when `params.skip_one_to_one`. Shared by the main method and the
/// Reeb baseline (`shapecorr_eval::reeb`).
pub fn one_to_one_matches(
    (a, basis_a, graph_a): (&Shape, &Eigenbasis, &ShapeGraph),
    (b, basis_b, graph_b): (&Shape, &Eigenbasis, &ShapeGraph),
    matches: &[(u32, u32)],
    params: &Params,
) -> Result<Vec<(u32, u32)>> {
    if params.skip_one_to_one {
        return Ok(Vec::new());
    }
    let distances = |shape: &Shape, basis: &Eigenbasis, graph: &ShapeGraph| {
        region_distance_matrix(
            shape,
            &basis.mass,
            &graph.labels,
            graph.n_nodes(),
            1.0 / basis.input_area.sqrt(),
        )
    };
    let (d_a, d_b) = (
        distances(a, basis_a, graph_a),
        distances(b, basis_b, graph_b),
    );
    one_to_one(matches, d_a.as_ref(), d_b.as_ref(), &params.symmetry)
}

/// Convenience: [`Correspondence::compute`] with default parameters and no progress.
pub fn correspond(a: &Shape, b: &Shape) -> Result<Correspondence> {
    Correspondence::compute(a, b, &Params::default(), &mut NoProgress)
}
