//! The method's parameters, with the documented defaults (docs/design.md; each default's
//! measurement: docs/decisions.md). The command line, the C API and the add-ons read their
//! defaults from here.

use crate::maps::landmarks::Landmark;
use crate::maps::partial::PartialOption;
use crate::maps::placement::{Guidance, Placement};
use crate::pipeline::budget::Budget;
use crate::pipeline::multiresolution::Multiresolution;
use crate::regions::matching::MatchingParams;
use crate::regions::segmentation::SegmentationParams;
use crate::regions::symmetry::SymmetryParams;
use crate::spectral::descriptors::HksParams;
use crate::spectral::eigen::EigenParams;
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
    /// in docs/decisions.md, "Hypotheses verified at the map level".
    pub verify_hypotheses: bool,
    /// Dense shapes run on proxies ([`crate::pipeline::multiresolution`]): above 12K vertices, proxies
    /// of about 8K.
    pub multiresolution: Multiresolution,
    /// The job's memory ceiling and time limit, checked from an estimate before any work
    /// and the time limit enforced while it runs ([`crate::pipeline::budget`]).
    pub budget: Budget,
    /// How the shapes' placement in space is used to choose among the verified hypotheses
    /// (docs/placement.md): `Auto` only when it is informative.
    pub placement: Placement,
    /// Pairs of vertices known to correspond (A's vertex, B's vertex; input indices), 0 to
    /// [`crate::maps::landmarks::MAX_LANDMARKS`] ([`crate::maps::landmarks`]). Checked
    /// against the shapes when the job starts.
    pub landmarks: Vec<Landmark>,
    /// Whether one shape is a part of the other (docs/partial.md): `Auto` takes B as a part
    /// of A when the first map leaves much of A uncovered and B has more open boundary.
    pub partial: PartialOption,
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
            placement: Placement::Auto,
            partial: PartialOption::Auto,
            landmarks: Vec::new(),
            non_exhaustive: crate::NonExhaustive(()),
        }
    }
}

impl Params {
    /// What the user knows beyond the shapes' geometry, for the map stages.
    pub fn guidance(&self) -> Guidance {
        Guidance {
            placement: self.placement,
            landmarks: self.landmarks.clone(),
            part_slope: None,
        }
    }

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
