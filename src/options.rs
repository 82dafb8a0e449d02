//! Named options: the parameters of [`Params`] (region correspondence) and of
//! [`PointwiseParams`] (point-to-point map, names starting with `p2p_`) that the C API, the
//! Python binding and the add-ons set by name (`"k_min"`, `"gap_ratio"`,
//! `"p2p_fmap_size"`, ...). One table, so every front end offers the same options with the
//! same defaults, which come from `Params::default()` and `PointwiseParams::default()`.
//! [`Options`] holds a value for every option.
//!
//! A value is type-checked and range-checked here as far as the option alone allows
//! (integers non-negative and within range, choices among their listed values, floats
//! finite); the checks that involve several options (`k_min <= k_max`,
//! `p2p_fmap_size <= p2p_eigenpairs`) are [`Params::validate`]'s and
//! [`PointwiseParams::validate`]'s. Text front ends (the command line, `--set NAME=VALUE`)
//! read a value with [`parse_option_value`], which also knows the choices' names
//! (`p2p_refinement = icp`).

use crate::maps::fmap::ZoomOutParams;
use crate::maps::pointwise::{PointwiseParams, Refinement, RegionConstraints};
use crate::pipeline::Params;
use crate::{Error, Result};

/// The type of an option's value.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum OptionType {
    /// A non-negative integer.
    Int = 0,
    /// A finite floating-point number.
    Float = 1,
    /// A yes/no switch.
    Bool = 2,
}

/// A value read or written through [`Params::set_option`] and [`Params::option`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum OptionValue {
    /// The value of an [`OptionType::Int`] option.
    Int(i64),
    /// The value of an [`OptionType::Float`] option.
    Float(f64),
    /// The value of an [`OptionType::Bool`] option.
    Bool(bool),
}

impl OptionValue {
    /// The type of this value.
    pub fn option_type(&self) -> OptionType {
        match self {
            OptionValue::Int(_) => OptionType::Int,
            OptionValue::Float(_) => OptionType::Float,
            OptionValue::Bool(_) => OptionType::Bool,
        }
    }
}

/// Which parameters an option belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OptionGroup {
    /// The region correspondence ([`Params`]): used by every job.
    Regions,
    /// The point-to-point map ([`PointwiseParams`]): used only when a pointwise map is
    /// computed. The names start with `p2p_`.
    Pointwise,
}

/// One named option.
#[derive(Debug, Clone, Copy)]
pub struct OptionInfo {
    /// The name used by every front end.
    pub name: &'static str,
    /// The type of its value.
    pub option_type: OptionType,
    /// The parameters it sets.
    pub group: OptionGroup,
    /// One line: what it does.
    pub doc: &'static str,
    /// Smallest accepted value (integers and floats; 0 for a bool).
    pub min: f64,
    /// Largest accepted value: what the pipeline can do in memory and time (see
    /// docs/decisions.md, "Option ranges").
    pub max: f64,
}

impl OptionInfo {
    /// This option with the accepted range `[min, max]`.
    const fn range(self, min: f64, max: f64) -> OptionInfo {
        OptionInfo { min, max, ..self }
    }

    /// The accepted range as text, e.g. `[1, 100]`.
    pub fn range_text(&self) -> String {
        format!("[{}, {}]", number_text(self.min), number_text(self.max))
    }
}

/// A number as people read it: `100`, `0.5`, `1e-6`, `1e12`.
fn number_text(v: f64) -> String {
    if v != 0.0 && !(1e-3..1e9).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

const fn info(name: &'static str, option_type: OptionType, doc: &'static str) -> OptionInfo {
    OptionInfo {
        name,
        option_type,
        group: OptionGroup::Regions,
        doc,
        min: 0.0,
        max: 0.0,
    }
}

const fn p2p(name: &'static str, option_type: OptionType, doc: &'static str) -> OptionInfo {
    OptionInfo {
        name,
        option_type,
        group: OptionGroup::Pointwise,
        doc,
        min: 0.0,
        max: 0.0,
    }
}

/// The choices of `p2p_regions`, by value (0, 1, 2).
pub const P2P_REGIONS: [RegionConstraints; 3] = [
    RegionConstraints::None,
    RegionConstraints::OneToOne,
    RegionConstraints::Symmetric,
];

/// The names of `p2p_regions`' choices, by value (0, 1, 2).
pub const P2P_REGIONS_NAMES: [&str; 3] = ["none", "one-to-one", "symmetric"];

/// `p2p_refinement = 0`: the first functional map's vertex map, unrefined.
pub const P2P_REFINEMENT_NONE: i64 = 0;
/// `p2p_refinement = 1`: ZoomOut (`p2p_zoomout_end`, `p2p_zoomout_step`,
/// `p2p_zoomout_sample`).
pub const P2P_REFINEMENT_ZOOMOUT: i64 = 1;
/// `p2p_refinement = 2`: spectral ICP (`p2p_icp_iterations`).
pub const P2P_REFINEMENT_ICP: i64 = 2;

/// The names of `p2p_refinement`'s choices, by value (0, 1, 2).
pub const P2P_REFINEMENT_NAMES: [&str; 3] = ["none", "zoomout", "icp"];

/// Iterations of spectral ICP when it is chosen without more (`p2p_refinement = 2` or
/// `icp`): the default of `p2p_icp_iterations`.
pub const ICP_ITERATIONS: usize = 10;

use OptionType::{Bool, Float, Int};

/// Every named option, in a stable order (new options are appended).
pub const OPTIONS: &[OptionInfo] = &[
    info(
        "k_min",
        Int,
        "smallest number of joint clusters tried (paper: 5)",
    )
    .range(2.0, 100.0),
    info(
        "k_max",
        Int,
        "largest number of joint clusters tried (paper: 10)",
    )
    .range(2.0, 100.0),
    info(
        "kmeans_restarts",
        Int,
        "k-means++ starts per k; the lowest cost is kept",
    )
    .range(1.0, 1000.0),
    info(
        "max_regions",
        Int,
        "graphs with more regions than this are not accepted",
    )
    .range(1.0, 10_000.0),
    info(
        "min_region_area",
        Float,
        "regions below this fraction of the area are merged into a neighbour",
    )
    .range(0.0, 0.49),
    info(
        "seed",
        Int,
        "seed of every random choice (k-means++, eigensolver start, local search)",
    )
    .range(i64::MIN as f64, u64::MAX as f64),
    info("hks_times", Int, "number of heat kernel signature times").range(1.0, 100.0),
    info("hks_t_min", Float, "smallest HKS time (unit-area shape)").range(1e-6, 1e3),
    info("hks_t_max", Float, "largest HKS time (unit-area shape)").range(1e-6, 1e3),
    info("hks_log", Bool, "use the logarithm of the HKS").range(0.0, 1.0),
    info("eigenpairs", Int, "number of Laplacian eigenpairs").range(1.0, 1000.0),
    info(
        "threads",
        Int,
        "threads of the eigensolver (0: all cores); results do not depend on it",
    )
    .range(0.0, 1024.0),
    info(
        "sigma",
        Float,
        "width of the graph matching's Gaussian affinities",
    )
    .range(1e-3, 100.0),
    info(
        "histogram_bins",
        Int,
        "bins of the graph-distance histograms",
    )
    .range(1.0, 1000.0),
    info(
        "gap_ratio",
        Float,
        "a match scoring below ratio x the previous one ends the list",
    )
    .range(0.0, 1.0),
    info(
        "max_symmetry_order",
        Int,
        "largest number of matches per region",
    )
    .range(1.0, 64.0),
    info(
        "one_to_one",
        Bool,
        "break symmetries into a one-to-one region correspondence",
    )
    .range(0.0, 1.0),
    info(
        "exhaustive_limit",
        Int,
        "one-to-one: largest number of combinations searched exhaustively",
    )
    .range(0.0, 10_000_000.0),
    info(
        "symmetry_restarts",
        Int,
        "one-to-one: local-search restarts above that limit",
    )
    .range(0.0, 10_000.0),
    info(
        "hks_fallback",
        Bool,
        "second try with HKS from a smaller time when the first leaves area unmatched",
    )
    .range(0.0, 1.0),
    p2p(
        "p2p_eigenpairs",
        Int,
        "pointwise map: Laplacian eigenpairs per shape (the largest basis any step uses)",
    )
    .range(2.0, 1000.0),
    p2p(
        "p2p_fmap_size",
        Int,
        "pointwise map: size k of the first functional map (k x k)",
    )
    .range(2.0, 1000.0),
    p2p(
        "p2p_regions",
        Int,
        "pointwise map: region constraints: 0 none, 1 one-to-one (matches), 2 symmetric (groups)",
    )
    .range(0.0, 2.0),
    p2p(
        "p2p_region_distances",
        Bool,
        "pointwise map: also constrain by the distance from each matched region",
    )
    .range(0.0, 1.0),
    p2p(
        "p2p_wks",
        Bool,
        "pointwise map: also constrain by wave kernel signatures (100 energies)",
    )
    .range(0.0, 1.0),
    p2p(
        "p2p_descriptor_step",
        Int,
        "pointwise map: keep every n-th WKS energy",
    )
    .range(1.0, 100.0),
    p2p(
        "p2p_laplacian_weight",
        Float,
        "pointwise map: weight of the Laplacian commutativity term",
    )
    .range(0.0, 1e6),
    p2p(
        "p2p_descriptor_commutativity",
        Float,
        "pointwise map: weight of the descriptor commutativity term (0 = off)",
    )
    .range(0.0, 1e6),
    p2p(
        "p2p_orientation_term",
        Float,
        "pointwise map: weight of the orientation-preserving term (0 = off)",
    )
    .range(0.0, 1e6),
    p2p(
        "p2p_refinement",
        Int,
        "pointwise map: refinement: 0 none, 1 zoomout (ZoomOut), 2 icp (spectral ICP)",
    )
    .range(0.0, 2.0),
    p2p(
        "p2p_zoomout_end",
        Int,
        "pointwise map: ZoomOut's final basis size (at most p2p_eigenpairs)",
    )
    .range(1.0, 1000.0),
    p2p(
        "p2p_zoomout_step",
        Int,
        "pointwise map: eigenfunctions ZoomOut adds per iteration",
    )
    .range(1.0, 1000.0),
    p2p(
        "p2p_zoomout_sample",
        Int,
        "pointwise map: vertices per shape ZoomOut iterates on (0: all)",
    )
    .range(0.0, 100_000_000.0),
    p2p(
        "p2p_icp_iterations",
        Int,
        "pointwise map: largest number of spectral ICP iterations",
    )
    .range(0.0, 1000.0),
    p2p(
        "p2p_orientation",
        Bool,
        "pointwise map: verify the answer's mirror image as a hypothesis (orientable meshes)",
    )
    .range(0.0, 1.0),
    p2p(
        "p2p_hypotheses",
        Bool,
        "pointwise map: verify the symmetric groups and single-group alternatives as hypotheses",
    )
    .range(0.0, 1.0),
    info(
        "verify_hypotheses",
        Bool,
        "regions: choose among one-to-one hypotheses by their refined maps (and give a confidence)",
    )
    .range(0.0, 1.0),
    info(
        "proxy_above",
        Int,
        "dense shapes: a shape with more vertices runs on a proxy of about proxy_vertices (0: never)",
    )
    .range(0.0, 100_000_000.0),
    info(
        "proxy_vertices",
        Int,
        "dense shapes: about how many vertices a proxy has (64 or more, below proxy_above)",
    )
    .range(64.0, 100_000_000.0),
    info(
        "max_vertices",
        Int,
        "largest shape accepted, in vertices; a larger one is refused before any work",
    )
    .range(32.0, 100_000_000.0),
    info(
        "memory_limit_mib",
        Int,
        "memory ceiling of a job in MiB (0: the memory available); a job estimated above it is refused before any work",
    )
    .range(0.0, 16_777_216.0),
    info(
        "time_limit_s",
        Float,
        "time limit of a job in seconds (0: none); refused at once when estimated above it, stopped when it runs past it",
    )
    .range(0.0, 1e7),
];

/// The option called `name`.
pub fn option_info(name: &str) -> Result<&'static OptionInfo> {
    OPTIONS
        .iter()
        .find(|o| o.name == name)
        .ok_or_else(|| Error::UnknownOption {
            name: name.to_string(),
            known: OPTIONS
                .iter()
                .map(|o| o.name)
                .collect::<Vec<_>>()
                .join(", "),
        })
}

/// The names of the choices of option `name`, by value (`p2p_regions`, `p2p_refinement`);
/// `None` for an option that is not a choice.
pub fn option_choices(name: &str) -> Option<&'static [&'static str]> {
    match name {
        "p2p_regions" => Some(&P2P_REGIONS_NAMES),
        "p2p_refinement" => Some(&P2P_REFINEMENT_NAMES),
        _ => None,
    }
}

/// Reads a value of option `name` from text, by the option's type: an integer (a choice
/// also by its name, see [`option_choices`]; `seed` also as an unsigned 64-bit number), a
/// float, or a bool as `true`/`false`, `yes`/`no` or `1`/`0` (any case). Errors with
/// [`Error::UnknownOption`] for a name not in [`OPTIONS`] and with
/// [`Error::InvalidParameter`] saying what was expected for text that is none of those.
/// Only the text is checked: the range is [`Options::set_option`]'s.
pub fn parse_option_value(name: &str, text: &str) -> Result<OptionValue> {
    let info = option_info(name)?;
    let trimmed = text.trim();
    let lower = trimmed.to_ascii_lowercase();
    let parsed = match info.option_type {
        OptionType::Int => match option_choices(info.name) {
            Some(names) => names
                .iter()
                .position(|n| *n == lower)
                .map(|i| i as i64)
                .or_else(|| trimmed.parse().ok()),
            None if info.name == "seed" => trimmed
                .parse()
                .ok()
                .or_else(|| trimmed.parse::<u64>().ok().map(|v| v as i64)),
            None => trimmed.parse().ok(),
        }
        .map(OptionValue::Int),
        OptionType::Float => trimmed.parse().ok().map(OptionValue::Float),
        OptionType::Bool => match lower.as_str() {
            "true" | "yes" | "1" => Some(OptionValue::Bool(true)),
            "false" | "no" | "0" => Some(OptionValue::Bool(false)),
            _ => None,
        },
    };
    parsed.ok_or_else(|| {
        let expected = match (info.option_type, option_choices(info.name)) {
            (OptionType::Int, Some(names)) => {
                let listed: Vec<String> = names
                    .iter()
                    .enumerate()
                    .map(|(i, n)| format!("{n} ({i})"))
                    .collect();
                format!("one of {}", listed.join(", "))
            }
            (OptionType::Int, None) => "an integer".to_string(),
            (OptionType::Float, _) => "a number".to_string(),
            (OptionType::Bool, _) => "true or false (yes/no, 1/0)".to_string(),
        };
        Error::InvalidParameter {
            name: info.name,
            reason: format!("expected {expected}, got `{text}`"),
        }
    })
}

fn wrong_type(info: &OptionInfo, got: OptionType) -> Error {
    Error::InvalidParameter {
        name: info.name,
        reason: format!("is of type {:?}, but a {got:?} was given", info.option_type),
    }
}

fn out_of_range(info: &OptionInfo, value: impl std::fmt::Display) -> Error {
    Error::InvalidParameter {
        name: info.name,
        reason: format!("must lie in {}, got {value}", info.range_text()),
    }
}

/// An integer within the option's range.
fn to_usize(info: &OptionInfo, value: i64) -> Result<usize> {
    let in_range = (info.min..=info.max).contains(&(value as f64));
    match usize::try_from(value) {
        Ok(v) if in_range => Ok(v),
        _ => Err(out_of_range(info, value)),
    }
}

/// A finite float within the option's range.
fn to_finite(info: &OptionInfo, value: f64) -> Result<f64> {
    if !value.is_finite() {
        return Err(Error::InvalidParameter {
            name: info.name,
            reason: format!("must be finite, got {value}"),
        });
    }
    if !(info.min..=info.max).contains(&value) {
        return Err(out_of_range(info, number_text(value)));
    }
    Ok(value)
}

/// The option called `name`, of type `value` (if given) and of `group`.
fn checked_info(
    name: &str,
    value: Option<OptionValue>,
    group: OptionGroup,
) -> Result<&'static OptionInfo> {
    let info = option_info(name)?;
    if info.group != group {
        let holder = match info.group {
            OptionGroup::Regions => "Params",
            OptionGroup::Pointwise => "PointwiseParams",
        };
        return Err(Error::InvalidParameter {
            name: info.name,
            reason: format!("belongs to {holder}; set and read it through options::Options"),
        });
    }
    match value {
        Some(v) if v.option_type() != info.option_type => Err(wrong_type(info, v.option_type())),
        _ => Ok(info),
    }
}

/// Checks that every option of `group` read by `value_of` lies in its range (for values
/// set directly in the parameter structs, which [`Params::set_option`] did not see).
fn check_ranges(group: OptionGroup, value_of: impl Fn(&str) -> Result<OptionValue>) -> Result<()> {
    for info in OPTIONS
        .iter()
        .filter(|o| o.group == group && o.name != "seed")
    {
        match value_of(info.name)? {
            OptionValue::Int(v) => {
                to_usize(info, v)?;
            }
            OptionValue::Float(v) => {
                to_finite(info, v)?;
            }
            OptionValue::Bool(_) => {}
        }
    }
    Ok(())
}

impl Params {
    /// Checks that every option's value lies in its documented range
    /// ([`OptionInfo::min`], [`OptionInfo::max`]); called by [`Params::validate`].
    pub fn check_option_ranges(&self) -> Result<()> {
        check_ranges(OptionGroup::Regions, |name| self.option(name))
    }

    /// Sets the option `name` (one of [`OptionGroup::Regions`]). Errors with
    /// [`Error::UnknownOption`] for a name not in [`OPTIONS`], and with
    /// [`Error::InvalidParameter`] for a pointwise option (see [`Options`]), a value of the
    /// wrong type, a negative integer or a non-finite float. Nothing changes on error.
    pub fn set_option(&mut self, name: &str, value: OptionValue) -> Result<()> {
        let info = checked_info(name, Some(value), OptionGroup::Regions)?;
        match value {
            OptionValue::Int(v) => {
                // Seeds take the full 64 bits (reinterpreted), so any integer is a seed.
                if info.name == "seed" {
                    let seed = v as u64;
                    self.segmentation.seed = seed;
                    self.eigen.seed = seed;
                    self.symmetry.seed = seed;
                    return Ok(());
                }
                let v = to_usize(info, v)?;
                match info.name {
                    "k_min" => self.segmentation.k_min = v,
                    "k_max" => self.segmentation.k_max = v,
                    "kmeans_restarts" => self.segmentation.kmeans_restarts = v,
                    "max_regions" => self.segmentation.max_regions = v,
                    "hks_times" => self.hks.n_times = v,
                    "eigenpairs" => self.eigen.n_eigenpairs = v,
                    "threads" => self.eigen.threads = v,
                    "histogram_bins" => self.matching.histogram_bins = v,
                    "max_symmetry_order" => self.matching.max_symmetry_order = v,
                    "exhaustive_limit" => self.symmetry.exhaustive_limit = v,
                    "symmetry_restarts" => self.symmetry.restarts = v,
                    "max_vertices" => self.eigen.max_vertices = v,
                    "proxy_above" => self.multiresolution.above = v,
                    "proxy_vertices" => self.multiresolution.proxy_vertices = v,
                    "memory_limit_mib" => self.budget.memory_limit_mib = v as u64,
                    other => unreachable!("integer option {other} has no field"),
                }
            }
            OptionValue::Float(v) => {
                let v = to_finite(info, v)?;
                match info.name {
                    "min_region_area" => self.segmentation.min_region_area = v,
                    "hks_t_min" => self.hks.t_min = v,
                    "hks_t_max" => self.hks.t_max = v,
                    "sigma" => self.matching.sigma = v,
                    "gap_ratio" => self.matching.gap_ratio = v,
                    "time_limit_s" => self.budget.time_limit_s = v,
                    other => unreachable!("float option {other} has no field"),
                }
            }
            OptionValue::Bool(v) => match info.name {
                "hks_log" => self.hks.log = v,
                "one_to_one" => self.skip_one_to_one = !v,
                "hks_fallback" => {
                    self.fallback = v.then(|| self.fallback.clone().unwrap_or_default())
                }
                "verify_hypotheses" => self.verify_hypotheses = v,
                other => unreachable!("bool option {other} has no field"),
            },
        }
        Ok(())
    }

    /// The current value of the option `name` ([`Error::UnknownOption`] if there is none,
    /// [`Error::InvalidParameter`] for a pointwise option).
    pub fn option(&self, name: &str) -> Result<OptionValue> {
        let info = checked_info(name, None, OptionGroup::Regions)?;
        let int = |v: usize| OptionValue::Int(v as i64);
        Ok(match info.name {
            "k_min" => int(self.segmentation.k_min),
            "k_max" => int(self.segmentation.k_max),
            "kmeans_restarts" => int(self.segmentation.kmeans_restarts),
            "max_regions" => int(self.segmentation.max_regions),
            "min_region_area" => OptionValue::Float(self.segmentation.min_region_area),
            "seed" => OptionValue::Int(self.segmentation.seed as i64),
            "hks_times" => int(self.hks.n_times),
            "hks_t_min" => OptionValue::Float(self.hks.t_min),
            "hks_t_max" => OptionValue::Float(self.hks.t_max),
            "hks_log" => OptionValue::Bool(self.hks.log),
            "eigenpairs" => int(self.eigen.n_eigenpairs),
            "threads" => int(self.eigen.threads),
            "sigma" => OptionValue::Float(self.matching.sigma),
            "histogram_bins" => int(self.matching.histogram_bins),
            "gap_ratio" => OptionValue::Float(self.matching.gap_ratio),
            "max_symmetry_order" => int(self.matching.max_symmetry_order),
            "one_to_one" => OptionValue::Bool(!self.skip_one_to_one),
            "exhaustive_limit" => int(self.symmetry.exhaustive_limit),
            "symmetry_restarts" => int(self.symmetry.restarts),
            "hks_fallback" => OptionValue::Bool(self.fallback.is_some()),
            "verify_hypotheses" => OptionValue::Bool(self.verify_hypotheses),
            "max_vertices" => int(self.eigen.max_vertices),
            "proxy_above" => int(self.multiresolution.above),
            "proxy_vertices" => int(self.multiresolution.proxy_vertices),
            "memory_limit_mib" => int(self.budget.memory_limit_mib as usize),
            "time_limit_s" => OptionValue::Float(self.budget.time_limit_s),
            other => unreachable!("option {other} has no field"),
        })
    }
}

/// A value for every named option: the region correspondence's [`Params`] and the
/// pointwise map's [`PointwiseParams`] (what the C API's `sc_params` handle holds).
///
/// The settings of each refinement are kept apart from the choice of refinement, so options
/// may be set in any order: `p2p_zoomout_end` set while ICP is chosen is used once
/// `p2p_refinement` chooses ZoomOut. That is why the pointwise parameters are read through
/// [`Options::pointwise`] and changed only through [`Options::set_option`].
#[derive(Debug, Clone)]
pub struct Options {
    /// The region correspondence's parameters.
    pub params: Params,
    /// The pointwise map's parameters; `pointwise.refinement` is always built from the
    /// two fields below.
    pointwise: PointwiseParams,
    /// ZoomOut's settings, whichever refinement is chosen.
    zoomout: ZoomOutParams,
    /// Spectral ICP's iterations, whichever refinement is chosen.
    icp_iterations: usize,
}

impl Default for Options {
    fn default() -> Self {
        Options::new(Params::default(), PointwiseParams::default())
    }
}

impl Options {
    /// Options holding these parameters (the refinement's settings not in use take their
    /// defaults).
    pub fn new(params: Params, pointwise: PointwiseParams) -> Self {
        let zoomout = match &pointwise.refinement {
            Refinement::ZoomOut(z) => z.clone(),
            _ => ZoomOutParams::default(),
        };
        let icp_iterations = match pointwise.refinement {
            Refinement::Icp(n) => n,
            _ => ICP_ITERATIONS,
        };
        Options {
            params,
            pointwise,
            zoomout,
            icp_iterations,
        }
    }

    /// The pointwise map's parameters.
    pub fn pointwise(&self) -> &PointwiseParams {
        &self.pointwise
    }

    /// Checks both sets of parameters ([`Params::validate`], [`PointwiseParams::validate`]).
    pub fn validate(&self) -> Result<()> {
        self.params.validate()?;
        check_ranges(OptionGroup::Pointwise, |name| self.option(name))?;
        self.pointwise.validate()
    }

    /// Sets any option: errors as [`Params::set_option`] (without the pointwise one), and
    /// [`Error::InvalidParameter`] for a choice out of its list. Nothing changes on error.
    pub fn set_option(&mut self, name: &str, value: OptionValue) -> Result<()> {
        let info = option_info(name)?;
        if info.group == OptionGroup::Regions {
            return self.params.set_option(name, value);
        }
        let info = checked_info(name, Some(value), OptionGroup::Pointwise)?;
        let p = &mut self.pointwise;
        match value {
            OptionValue::Int(v) => {
                let choice = |n: usize| -> Result<usize> {
                    usize::try_from(v).ok().filter(|&i| i < n).ok_or_else(|| {
                        Error::InvalidParameter {
                            name: info.name,
                            reason: format!("must be one of 0 to {}, got {v}", n - 1),
                        }
                    })
                };
                match info.name {
                    "p2p_regions" => p.regions = P2P_REGIONS[choice(P2P_REGIONS.len())?],
                    "p2p_refinement" => {
                        p.refinement = match choice(3)? as i64 {
                            P2P_REFINEMENT_NONE => Refinement::None,
                            P2P_REFINEMENT_ZOOMOUT => Refinement::ZoomOut(self.zoomout.clone()),
                            _ => Refinement::Icp(self.icp_iterations),
                        }
                    }
                    _ => {
                        let v = to_usize(info, v)?;
                        match info.name {
                            "p2p_eigenpairs" => p.n_eigenpairs = v,
                            "p2p_fmap_size" => p.fmap_size = v,
                            "p2p_descriptor_step" => p.descriptor_step = v,
                            "p2p_zoomout_end" => self.zoomout.k_end = v,
                            "p2p_zoomout_step" => self.zoomout.step = v,
                            "p2p_zoomout_sample" => self.zoomout.sample_size = v,
                            "p2p_icp_iterations" => self.icp_iterations = v,
                            other => unreachable!("integer option {other} has no field"),
                        }
                        // Keep the chosen refinement's settings current.
                        match &mut p.refinement {
                            Refinement::ZoomOut(z) => *z = self.zoomout.clone(),
                            Refinement::Icp(n) => *n = self.icp_iterations,
                            Refinement::None => {}
                        }
                    }
                }
            }
            OptionValue::Float(v) => {
                // Every pointwise float option is a weight.
                let v = to_finite(info, v)?;
                if v < 0.0 {
                    return Err(Error::InvalidParameter {
                        name: info.name,
                        reason: format!("a weight must be >= 0, got {v}"),
                    });
                }
                match info.name {
                    "p2p_laplacian_weight" => p.laplacian_weight = v,
                    "p2p_descriptor_commutativity" => p.descriptor_commutativity = v,
                    "p2p_orientation_term" => p.orientation_term = v,
                    other => unreachable!("float option {other} has no field"),
                }
            }
            OptionValue::Bool(v) => match info.name {
                "p2p_region_distances" => p.region_distances = v,
                "p2p_wks" => p.wks = v.then(|| p.wks.clone().unwrap_or_default()),
                "p2p_orientation" => p.orientation = v,
                "p2p_hypotheses" => p.hypotheses = v,
                other => unreachable!("bool option {other} has no field"),
            },
        }
        Ok(())
    }

    /// The current value of any option ([`Error::UnknownOption`] if there is none).
    pub fn option(&self, name: &str) -> Result<OptionValue> {
        let info = option_info(name)?;
        if info.group == OptionGroup::Regions {
            return self.params.option(name);
        }
        let p = &self.pointwise;
        let int = |v: usize| OptionValue::Int(v as i64);
        Ok(match info.name {
            "p2p_eigenpairs" => int(p.n_eigenpairs),
            "p2p_fmap_size" => int(p.fmap_size),
            "p2p_regions" => int(P2P_REGIONS
                .iter()
                .position(|r| *r == p.regions)
                .expect("every region constraint has a value")),
            "p2p_region_distances" => OptionValue::Bool(p.region_distances),
            "p2p_wks" => OptionValue::Bool(p.wks.is_some()),
            "p2p_descriptor_step" => int(p.descriptor_step),
            "p2p_laplacian_weight" => OptionValue::Float(p.laplacian_weight),
            "p2p_descriptor_commutativity" => OptionValue::Float(p.descriptor_commutativity),
            "p2p_orientation_term" => OptionValue::Float(p.orientation_term),
            "p2p_refinement" => OptionValue::Int(match p.refinement {
                Refinement::None => P2P_REFINEMENT_NONE,
                Refinement::ZoomOut(_) => P2P_REFINEMENT_ZOOMOUT,
                Refinement::Icp(_) => P2P_REFINEMENT_ICP,
            }),
            "p2p_zoomout_end" => int(self.zoomout.k_end),
            "p2p_zoomout_step" => int(self.zoomout.step),
            "p2p_zoomout_sample" => int(self.zoomout.sample_size),
            "p2p_icp_iterations" => int(self.icp_iterations),
            "p2p_orientation" => OptionValue::Bool(p.orientation),
            "p2p_hypotheses" => OptionValue::Bool(p.hypotheses),
            other => unreachable!("option {other} has no field"),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectral::descriptors::WksParams;

    #[test]
    fn every_option_reads_back_what_was_set() {
        for (i, info) in OPTIONS.iter().enumerate() {
            let mut options = Options::default();
            let value = match info.option_type {
                // Choices take a valid value other than the default.
                OptionType::Int if matches!(info.name, "p2p_regions" | "p2p_refinement") => {
                    let OptionValue::Int(v) = options.option(info.name).unwrap() else {
                        panic!("{} is not an integer", info.name)
                    };
                    OptionValue::Int((v + 1) % 3)
                }
                OptionType::Int => {
                    OptionValue::Int((info.min as i64 + 1 + i as i64).min(info.max as i64))
                }
                OptionType::Float => {
                    OptionValue::Float(info.min + (info.max - info.min) / (2.0 + i as f64))
                }
                OptionType::Bool => {
                    let OptionValue::Bool(b) = options.option(info.name).unwrap() else {
                        panic!("{} is not a bool", info.name)
                    };
                    OptionValue::Bool(!b)
                }
            };
            assert_ne!(options.option(info.name).unwrap(), value, "{}", info.name);
            options.set_option(info.name, value).unwrap();
            assert_eq!(options.option(info.name).unwrap(), value, "{}", info.name);
            // Exactly this option changed: every other option still has its default.
            let defaults = Options::default();
            for other in OPTIONS.iter().filter(|o| o.name != info.name) {
                assert_eq!(
                    options.option(other.name).unwrap(),
                    defaults.option(other.name).unwrap(),
                    "setting {} changed {}",
                    info.name,
                    other.name
                );
            }
        }
    }

    #[test]
    fn names_are_unique_and_types_match_the_defaults() {
        let defaults = Options::default();
        for (i, info) in OPTIONS.iter().enumerate() {
            assert!(OPTIONS[..i].iter().all(|o| o.name != info.name));
            assert_eq!(
                defaults.option(info.name).unwrap().option_type(),
                info.option_type
            );
            assert_eq!(
                info.name.starts_with("p2p_"),
                info.group == OptionGroup::Pointwise,
                "{}",
                info.name
            );
        }
    }

    #[test]
    fn defaults_are_the_parameter_structs_defaults() {
        let options = Options::default();
        assert_eq!(options.pointwise(), &PointwiseParams::default());
        assert!(options.validate().is_ok());
        assert_eq!(
            options.option("hks_fallback").unwrap(),
            OptionValue::Bool(Params::default().fallback.is_some())
        );
    }

    #[test]
    fn bad_names_types_and_values_are_rejected_without_change() {
        let mut options = Options::default();
        assert!(matches!(
            options.set_option("k_mni", OptionValue::Int(3)),
            Err(Error::UnknownOption { .. })
        ));
        for (name, value) in [
            ("k_min", OptionValue::Float(3.0)),
            ("k_min", OptionValue::Int(-1)),
            ("gap_ratio", OptionValue::Float(f64::NAN)),
            ("gap_ratio", OptionValue::Bool(true)),
            ("one_to_one", OptionValue::Int(1)),
            ("p2p_regions", OptionValue::Int(3)),
            ("p2p_regions", OptionValue::Int(-1)),
            ("p2p_refinement", OptionValue::Int(3)),
            ("p2p_fmap_size", OptionValue::Int(-2)),
            ("p2p_fmap_size", OptionValue::Float(2.0)),
            ("p2p_laplacian_weight", OptionValue::Float(f64::INFINITY)),
            ("p2p_orientation_term", OptionValue::Float(-0.1)),
            ("p2p_descriptor_commutativity", OptionValue::Float(f64::NAN)),
            ("p2p_wks", OptionValue::Int(1)),
        ] {
            let before = format!("{options:?}");
            assert!(
                matches!(
                    options.set_option(name, value),
                    Err(Error::InvalidParameter { .. })
                ),
                "{name} = {value:?}"
            );
            assert_eq!(format!("{options:?}"), before);
        }
    }

    #[test]
    fn params_alone_refuse_pointwise_options() {
        let mut params = Params::default();
        let err = params
            .set_option("p2p_fmap_size", OptionValue::Int(30))
            .unwrap_err();
        assert!(err.to_string().contains("Options"), "{err}");
        assert!(params.option("p2p_fmap_size").is_err());
        assert_eq!(params.option("k_min").unwrap(), OptionValue::Int(5));
    }

    #[test]
    fn refinement_settings_survive_a_change_of_refinement_in_any_order() {
        let mut options = Options::default();
        let set = |o: &mut Options, name: &str, v: i64| o.set_option(name, OptionValue::Int(v));
        set(&mut options, "p2p_refinement", P2P_REFINEMENT_ICP).unwrap();
        set(&mut options, "p2p_zoomout_end", 60).unwrap();
        set(&mut options, "p2p_icp_iterations", 4).unwrap();
        assert_eq!(options.pointwise().refinement, Refinement::Icp(4));
        set(&mut options, "p2p_refinement", P2P_REFINEMENT_ZOOMOUT).unwrap();
        let expected = ZoomOutParams {
            k_end: 60,
            ..ZoomOutParams::default()
        };
        assert_eq!(
            options.pointwise().refinement,
            Refinement::ZoomOut(expected.clone())
        );
        set(&mut options, "p2p_zoomout_step", 2).unwrap();
        assert_eq!(
            options.pointwise().refinement,
            Refinement::ZoomOut(ZoomOutParams {
                step: 2,
                ..expected
            })
        );
        set(&mut options, "p2p_refinement", P2P_REFINEMENT_NONE).unwrap();
        assert_eq!(options.pointwise().refinement, Refinement::None);
        assert_eq!(
            options.option("p2p_zoomout_end").unwrap(),
            OptionValue::Int(60)
        );
        assert_eq!(
            options.option("p2p_icp_iterations").unwrap(),
            OptionValue::Int(4)
        );
        // Values valid alone but not together fail at use, not when set.
        set(&mut options, "p2p_fmap_size", 200).unwrap();
        assert!(matches!(
            options.validate(),
            Err(Error::InvalidParameter {
                name: "pointwise.fmap_size",
                ..
            })
        ));
    }

    #[test]
    fn choices_map_to_the_pointwise_params() {
        let mut options = Options::default();
        for (v, kind) in P2P_REGIONS.iter().enumerate() {
            options
                .set_option("p2p_regions", OptionValue::Int(v as i64))
                .unwrap();
            assert_eq!(options.pointwise().regions, *kind);
        }
        options
            .set_option("p2p_wks", OptionValue::Bool(true))
            .unwrap();
        assert_eq!(options.pointwise().wks, Some(WksParams::default()));
    }

    #[test]
    fn text_is_parsed_by_the_option_type() {
        let parse = |name: &str, text: &str| parse_option_value(name, text).unwrap();
        assert_eq!(parse("k_min", "7"), OptionValue::Int(7));
        assert_eq!(parse("k_min", " -1 "), OptionValue::Int(-1)); // the range is set_option's
        assert_eq!(parse("gap_ratio", "0.85"), OptionValue::Float(0.85));
        assert_eq!(parse("gap_ratio", "1"), OptionValue::Float(1.0));
        for (text, value) in [
            ("true", true),
            ("Yes", true),
            ("1", true),
            ("false", false),
            ("NO", false),
            ("0", false),
        ] {
            assert_eq!(
                parse("one_to_one", text),
                OptionValue::Bool(value),
                "{text}"
            );
        }
        assert_eq!(
            parse("seed", "18446744073709551615"),
            OptionValue::Int(u64::MAX as i64)
        );
        assert_eq!(parse("seed", "-7"), OptionValue::Int(-7));
    }

    #[test]
    fn choices_are_read_by_name_or_number() {
        for (names, option) in [
            (P2P_REGIONS_NAMES, "p2p_regions"),
            (P2P_REFINEMENT_NAMES, "p2p_refinement"),
        ] {
            assert_eq!(option_choices(option), Some(&names[..]));
            for (i, name) in names.iter().enumerate() {
                let by_name = parse_option_value(option, name).unwrap();
                assert_eq!(by_name, OptionValue::Int(i as i64), "{option} = {name}");
                assert_eq!(parse_option_value(option, &i.to_string()).unwrap(), by_name);
                assert_eq!(
                    parse_option_value(option, &name.to_uppercase()).unwrap(),
                    by_name
                );
            }
        }
        assert_eq!(option_choices("k_min"), None);
        let mut options = Options::default();
        let icp = parse_option_value("p2p_refinement", "icp").unwrap();
        options.set_option("p2p_refinement", icp).unwrap();
        assert_eq!(
            options.pointwise().refinement,
            Refinement::Icp(ICP_ITERATIONS)
        );
        let symmetric = parse_option_value("p2p_regions", "symmetric").unwrap();
        options.set_option("p2p_regions", symmetric).unwrap();
        assert_eq!(options.pointwise().regions, RegionConstraints::Symmetric);
    }

    #[test]
    fn bad_text_says_what_was_expected() {
        let reason = |name: &str, text: &str| match parse_option_value(name, text) {
            Err(Error::InvalidParameter { name: n, reason }) => {
                assert_eq!(n, name);
                reason
            }
            other => panic!("{name} = {text:?}: {other:?}"),
        };
        assert!(reason("k_min", "five").contains("an integer"));
        assert!(reason("k_min", "2.5").contains("`2.5`"));
        assert!(reason("gap_ratio", "high").contains("a number"));
        assert!(reason("one_to_one", "maybe").contains("true or false"));
        let choice = reason("p2p_refinement", "zoom");
        assert!(
            choice.contains("none (0), zoomout (1), icp (2)"),
            "{choice}"
        );
        assert!(reason("p2p_regions", "both").contains("one-to-one (1)"));
        assert!(matches!(
            parse_option_value("nope", "1"),
            Err(Error::UnknownOption { .. })
        ));
    }

    #[test]
    fn orientation_is_the_pointwise_params_switch() {
        let last = OPTIONS.last().unwrap();
        assert_eq!((last.name, last.option_type), ("time_limit_s", Float));
        assert!(Options::default().pointwise().hypotheses);
        let mut options = Options::default();
        assert_eq!(
            options.option("p2p_orientation").unwrap(),
            OptionValue::Bool(true)
        );
        options
            .set_option("p2p_orientation", OptionValue::Bool(false))
            .unwrap();
        assert!(!options.pointwise().orientation);
    }

    #[test]
    fn seed_takes_any_64_bit_value() {
        let mut params = Params::default();
        params.set_option("seed", OptionValue::Int(-7)).unwrap();
        assert_eq!(params.segmentation.seed, (-7i64) as u64);
        assert_eq!(params.option("seed").unwrap(), OptionValue::Int(-7));
    }
}
