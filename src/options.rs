//! Named options: the parameters of [`Params`] (region correspondence) and of
//! [`PointwiseParams`] (point-to-point map, names starting with `p2p_`) that the C API, the
//! Python binding and the add-ons set by name (`"k_min"`, `"gap_ratio"`,
//! `"p2p_fmap_size"`, ...). One table, so every front end offers the same options with the
//! same defaults, which come from `Params::default()` and `PointwiseParams::default()`.
//! [`Options`] holds a value for every option.
//!
//! Each option is declared once, in [`OPTIONS`]: its name, description, range, choices and
//! the field it reads and writes; getting, setting and checking by name all go through that
//! entry. A value is type-checked and range-checked here as far as the option alone allows
//! (integers within range, choices among their listed values, floats finite); the checks
//! that involve several options (`k_min <= k_max`, `p2p_fmap_size <= p2p_eigenpairs`) are
//! [`Params::validate`]'s and [`PointwiseParams::validate`]'s. Text front ends (the command
//! line, `--set NAME=VALUE`) read a value with [`parse_option_value`], which also knows the
//! choices' names (`p2p_refinement = icp`).

use std::fmt;

use crate::maps::fmap::ZoomOutParams;
use crate::maps::partial::{PartialOption, PARTIAL_NAMES};
use crate::maps::placement::{Placement, PLACEMENT_NAMES};
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
    /// docs/decisions.md, "Option ranges"; 1 for a bool).
    pub max: f64,
    /// For an integer that chooses among named alternatives (`p2p_regions`,
    /// `p2p_refinement`), their names by value (0, 1, ...); empty for other options.
    pub choices: &'static [&'static str],
    /// The field the option reads and writes.
    access: Access,
}

impl OptionInfo {
    /// This option with the accepted range `[min, max]`.
    const fn range(self, min: f64, max: f64) -> OptionInfo {
        OptionInfo { min, max, ..self }
    }

    /// This integer option as a choice among `names`, by value (range `[0, n - 1]`).
    const fn with_choices(self, names: &'static [&'static str]) -> OptionInfo {
        OptionInfo {
            choices: names,
            ..self.range(0.0, (names.len() - 1) as f64)
        }
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

/// The choices as text: `none (0), zoomout (1), icp (2)`.
fn choices_text(names: &[&str]) -> String {
    let listed: Vec<String> = names
        .iter()
        .enumerate()
        .map(|(i, n)| format!("{n} ({i})"))
        .collect();
    listed.join(", ")
}

/// How an option reads and writes the parameters of type `T` that hold it: a getter and a
/// setter of the option's type. The setter gets a value already checked against the
/// option's range, so it only stores it.
enum Field<T> {
    Int(fn(&T) -> i64, fn(&mut T, i64)),
    Float(fn(&T) -> f64, fn(&mut T, f64)),
    Bool(fn(&T) -> bool, fn(&mut T, bool)),
}

// Function pointers are `Copy` whatever `T` is (a derive would ask `T: Copy`).
impl<T> Clone for Field<T> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<T> Copy for Field<T> {}

impl<T> Field<T> {
    const fn option_type(&self) -> OptionType {
        match self {
            Field::Int(..) => OptionType::Int,
            Field::Float(..) => OptionType::Float,
            Field::Bool(..) => OptionType::Bool,
        }
    }

    /// The current value in `holder`.
    fn read(self, holder: &T) -> OptionValue {
        match self {
            Field::Int(get, _) => OptionValue::Int(get(holder)),
            Field::Float(get, _) => OptionValue::Float(get(holder)),
            Field::Bool(get, _) => OptionValue::Bool(get(holder)),
        }
    }

    /// Checks `value` (type and range of `info`) and stores it in `holder`; nothing changes
    /// on error.
    fn write(self, info: &OptionInfo, holder: &mut T, value: OptionValue) -> Result<()> {
        match (self, value) {
            (Field::Int(_, set), OptionValue::Int(v)) => set(holder, checked_int(info, v)?),
            (Field::Float(_, set), OptionValue::Float(v)) => set(holder, checked_float(info, v)?),
            (Field::Bool(_, set), OptionValue::Bool(v)) => set(holder, v),
            _ => return Err(wrong_type(info, value.option_type())),
        }
        Ok(())
    }
}

/// Which parameters hold an option, and its field there.
#[derive(Clone, Copy)]
enum Access {
    /// A field of [`Params`].
    Regions(Field<Params>),
    /// A field of [`Options`] (the pointwise parameters and the refinements' settings).
    Pointwise(Field<Options>),
}

impl fmt::Debug for Access {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Access::Regions(_) => "Params field",
            Access::Pointwise(_) => "Options field",
        })
    }
}

/// An integer field set by an option: the option's `i64` and back. The value is in the
/// option's range (non-negative but for `seed`, whose bits are kept), so nothing is lost.
trait IntField {
    fn to_option(self) -> i64;
    fn from_option(value: i64) -> Self;
}

impl IntField for usize {
    fn to_option(self) -> i64 {
        self as i64
    }
    fn from_option(value: i64) -> Self {
        value as usize
    }
}

impl IntField for u64 {
    fn to_option(self) -> i64 {
        self as i64
    }
    fn from_option(value: i64) -> Self {
        value as u64
    }
}

/// The [`Field`] of the plain field `$($path).+` of `$holder`, of option type `Int`,
/// `Float` or `Bool` (the field's Rust type must match: `usize`/`u64`, `f64`, `bool`).
macro_rules! field {
    ($holder:ty, Int, $($path:ident).+) => {
        Field::Int(
            |p: &$holder| IntField::to_option(p.$($path).+),
            |p: &mut $holder, v| p.$($path).+ = IntField::from_option(v),
        )
    };
    ($holder:ty, Float, $($path:ident).+) => {
        Field::Float(|p: &$holder| p.$($path).+, |p: &mut $holder, v| p.$($path).+ = v)
    };
    ($holder:ty, Bool, $($path:ident).+) => {
        Field::Bool(|p: &$holder| p.$($path).+, |p: &mut $holder, v| p.$($path).+ = v)
    };
}

/// An option of the region correspondence ([`Params`]).
const fn regions(name: &'static str, doc: &'static str, field: Field<Params>) -> OptionInfo {
    entry(name, doc, OptionGroup::Regions, Access::Regions(field))
}

/// An option of the pointwise map (held by [`Options`]).
const fn p2p(name: &'static str, doc: &'static str, field: Field<Options>) -> OptionInfo {
    entry(name, doc, OptionGroup::Pointwise, Access::Pointwise(field))
}

const fn entry(
    name: &'static str,
    doc: &'static str,
    group: OptionGroup,
    access: Access,
) -> OptionInfo {
    let option_type = match &access {
        Access::Regions(field) => field.option_type(),
        Access::Pointwise(field) => field.option_type(),
    };
    OptionInfo {
        name,
        option_type,
        group,
        doc,
        min: 0.0,
        // A bool is 0 or 1; integers and floats give their range.
        max: if matches!(option_type, OptionType::Bool) {
            1.0
        } else {
            0.0
        },
        choices: &[],
        access,
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

/// The value of `p2p_regions` for `regions` (its index in [`P2P_REGIONS`]).
fn regions_value(regions: &RegionConstraints) -> i64 {
    match regions {
        RegionConstraints::None => 0,
        RegionConstraints::OneToOne => 1,
        RegionConstraints::Symmetric => 2,
    }
}

/// Every named option, in a stable order (new options are appended).
pub const OPTIONS: &[OptionInfo] = &[
    regions(
        "k_min",
        "smallest number of joint clusters tried (paper: 5)",
        field!(Params, Int, segmentation.k_min),
    )
    .range(2.0, 100.0),
    regions(
        "k_max",
        "largest number of joint clusters tried (paper: 10)",
        field!(Params, Int, segmentation.k_max),
    )
    .range(2.0, 100.0),
    regions(
        "kmeans_restarts",
        "k-means++ starts per k; the lowest cost is kept",
        field!(Params, Int, segmentation.kmeans_restarts),
    )
    .range(1.0, 1000.0),
    regions(
        "max_regions",
        "graphs with more regions than this are not accepted",
        field!(Params, Int, segmentation.max_regions),
    )
    .range(1.0, 10_000.0),
    regions(
        "min_region_area",
        "regions below this fraction of the area are merged into a neighbour",
        field!(Params, Float, segmentation.min_region_area),
    )
    .range(0.0, 0.49),
    // Any 64-bit value is a seed (a negative one is read as its unsigned bits), used by
    // every random choice.
    regions(
        "seed",
        "seed of every random choice (k-means++, eigensolver start, local search)",
        Field::Int(
            |p: &Params| p.segmentation.seed.to_option(),
            |p: &mut Params, v| {
                let seed = u64::from_option(v);
                p.segmentation.seed = seed;
                p.eigen.seed = seed;
                p.symmetry.seed = seed;
            },
        ),
    )
    .range(i64::MIN as f64, u64::MAX as f64),
    regions(
        "hks_times",
        "number of heat kernel signature times",
        field!(Params, Int, hks.n_times),
    )
    .range(1.0, 100.0),
    regions(
        "hks_t_min",
        "smallest HKS time (unit-area shape)",
        field!(Params, Float, hks.t_min),
    )
    .range(1e-6, 1e3),
    regions(
        "hks_t_max",
        "largest HKS time (unit-area shape)",
        field!(Params, Float, hks.t_max),
    )
    .range(1e-6, 1e3),
    regions(
        "hks_log",
        "use the logarithm of the HKS",
        field!(Params, Bool, hks.log),
    ),
    regions(
        "eigenpairs",
        "number of Laplacian eigenpairs",
        field!(Params, Int, eigen.n_eigenpairs),
    )
    .range(1.0, 1000.0),
    regions(
        "threads",
        "threads of the eigensolver (0: all cores); results do not depend on it",
        field!(Params, Int, eigen.threads),
    )
    .range(0.0, 1024.0),
    regions(
        "sigma",
        "width of the graph matching's Gaussian affinities",
        field!(Params, Float, matching.sigma),
    )
    .range(1e-3, 100.0),
    regions(
        "histogram_bins",
        "bins of the graph-distance histograms",
        field!(Params, Int, matching.histogram_bins),
    )
    .range(1.0, 1000.0),
    regions(
        "gap_ratio",
        "a match scoring below ratio x the previous one ends the list",
        field!(Params, Float, matching.gap_ratio),
    )
    .range(0.0, 1.0),
    regions(
        "max_symmetry_order",
        "largest number of matches per region",
        field!(Params, Int, matching.max_symmetry_order),
    )
    .range(1.0, 64.0),
    regions(
        "one_to_one",
        "break symmetries into a one-to-one region correspondence",
        Field::Bool(
            |p: &Params| !p.skip_one_to_one,
            |p: &mut Params, v| p.skip_one_to_one = !v,
        ),
    ),
    regions(
        "exhaustive_limit",
        "one-to-one: largest number of combinations searched exhaustively",
        field!(Params, Int, symmetry.exhaustive_limit),
    )
    .range(0.0, 10_000_000.0),
    regions(
        "symmetry_restarts",
        "one-to-one: local-search restarts above that limit",
        field!(Params, Int, symmetry.restarts),
    )
    .range(0.0, 10_000.0),
    regions(
        "hks_fallback",
        "second try with HKS from a smaller time when the first leaves area unmatched",
        Field::Bool(
            |p: &Params| p.fallback.is_some(),
            |p: &mut Params, v| p.fallback = v.then(|| p.fallback.clone().unwrap_or_default()),
        ),
    ),
    p2p(
        "p2p_eigenpairs",
        "pointwise map: Laplacian eigenpairs per shape (the largest basis any step uses)",
        field!(Options, Int, pointwise.n_eigenpairs),
    )
    .range(2.0, 1000.0),
    p2p(
        "p2p_fmap_size",
        "pointwise map: size k of the first functional map (k x k)",
        field!(Options, Int, pointwise.fmap_size),
    )
    .range(2.0, 1000.0),
    p2p(
        "p2p_regions",
        "pointwise map: region constraints: 0 none, 1 one-to-one (matches), 2 symmetric (groups)",
        Field::Int(
            |o: &Options| regions_value(&o.pointwise.regions),
            |o: &mut Options, v| o.pointwise.regions = P2P_REGIONS[v as usize],
        ),
    )
    .with_choices(&P2P_REGIONS_NAMES),
    p2p(
        "p2p_region_distances",
        "pointwise map: also constrain by the distance from each matched region",
        field!(Options, Bool, pointwise.region_distances),
    ),
    p2p(
        "p2p_wks",
        "pointwise map: also constrain by wave kernel signatures (100 energies)",
        Field::Bool(
            |o: &Options| o.pointwise.wks.is_some(),
            |o: &mut Options, v| {
                o.pointwise.wks = v.then(|| o.pointwise.wks.clone().unwrap_or_default())
            },
        ),
    ),
    p2p(
        "p2p_descriptor_step",
        "pointwise map: keep every n-th WKS energy",
        field!(Options, Int, pointwise.descriptor_step),
    )
    .range(1.0, 100.0),
    p2p(
        "p2p_laplacian_weight",
        "pointwise map: weight of the Laplacian commutativity term",
        field!(Options, Float, pointwise.laplacian_weight),
    )
    .range(0.0, 1e6),
    p2p(
        "p2p_descriptor_commutativity",
        "pointwise map: weight of the descriptor commutativity term (0 = off)",
        field!(Options, Float, pointwise.descriptor_commutativity),
    )
    .range(0.0, 1e6),
    p2p(
        "p2p_orientation_term",
        "pointwise map: weight of the orientation-preserving term (0 = off)",
        field!(Options, Float, pointwise.orientation_term),
    )
    .range(0.0, 1e6),
    // The refinements' settings are kept apart from the choice ([`Options`]).
    p2p(
        "p2p_refinement",
        "pointwise map: refinement: 0 none, 1 zoomout (ZoomOut), 2 icp (spectral ICP)",
        Field::Int(
            |o: &Options| match o.pointwise.refinement {
                Refinement::None => P2P_REFINEMENT_NONE,
                Refinement::ZoomOut(_) => P2P_REFINEMENT_ZOOMOUT,
                Refinement::Icp(_) => P2P_REFINEMENT_ICP,
            },
            |o: &mut Options, v| {
                o.pointwise.refinement = match v {
                    P2P_REFINEMENT_NONE => Refinement::None,
                    P2P_REFINEMENT_ZOOMOUT => Refinement::ZoomOut(o.zoomout.clone()),
                    _ => Refinement::Icp(o.icp_iterations),
                }
            },
        ),
    )
    .with_choices(&P2P_REFINEMENT_NAMES),
    p2p(
        "p2p_zoomout_end",
        "pointwise map: ZoomOut's final basis size (at most p2p_eigenpairs)",
        field!(Options, Int, zoomout.k_end),
    )
    .range(1.0, 1000.0),
    p2p(
        "p2p_zoomout_step",
        "pointwise map: eigenfunctions ZoomOut adds per iteration",
        field!(Options, Int, zoomout.step),
    )
    .range(1.0, 1000.0),
    p2p(
        "p2p_zoomout_sample",
        "pointwise map: vertices per shape ZoomOut iterates on (0: all)",
        field!(Options, Int, zoomout.sample_size),
    )
    .range(0.0, 100_000_000.0),
    p2p(
        "p2p_icp_iterations",
        "pointwise map: largest number of spectral ICP iterations",
        field!(Options, Int, icp_iterations),
    )
    .range(0.0, 1000.0),
    p2p(
        "p2p_orientation",
        "pointwise map: verify the answer's mirror image as a hypothesis (orientable meshes, point clouds)",
        field!(Options, Bool, pointwise.orientation),
    ),
    p2p(
        "p2p_hypotheses",
        "pointwise map: verify the symmetric groups and single-group alternatives as hypotheses",
        field!(Options, Bool, pointwise.hypotheses),
    ),
    regions(
        "verify_hypotheses",
        "regions: choose among one-to-one hypotheses by their refined maps (and give a confidence)",
        field!(Params, Bool, verify_hypotheses),
    ),
    regions(
        "proxy_above",
        "dense shapes: a shape with more vertices runs on a proxy of about proxy_vertices (0: never)",
        field!(Params, Int, multiresolution.above),
    )
    .range(0.0, 100_000_000.0),
    regions(
        "proxy_vertices",
        "dense shapes: about how many vertices a proxy has (64 or more, below proxy_above)",
        field!(Params, Int, multiresolution.proxy_vertices),
    )
    .range(64.0, 100_000_000.0),
    regions(
        "refine_below",
        "low-poly meshes: one with fewer vertices runs on a refined copy of at least this many (0: never)",
        field!(Params, Int, multiresolution.refine_below),
    )
    .range(0.0, 100_000.0),
    regions(
        "max_vertices",
        "largest shape accepted, in vertices; a larger one is refused before any work",
        field!(Params, Int, eigen.max_vertices),
    )
    .range(32.0, 100_000_000.0),
    regions(
        "memory_limit_mib",
        "memory ceiling of a job in MiB (0: the memory available); a job estimated above it is refused before any work",
        field!(Params, Int, budget.memory_limit_mib),
    )
    .range(0.0, 16_777_216.0),
    regions(
        "time_limit_s",
        "time limit of a job in seconds (0: none); refused at once when estimated above it, stopped when it runs past it",
        field!(Params, Float, budget.time_limit_s),
    )
    .range(0.0, 1e7),
    regions(
        "placement",
        "use where the shapes stand to choose among the answers: 0 auto (when informative), 1 ignore, 2 trust",
        Field::Int(
            |p: &Params| p.placement as i64,
            |p: &mut Params, v| p.placement = Placement::ALL[v as usize],
        ),
    )
    .with_choices(&PLACEMENT_NAMES),
    regions(
        "partial",
        "whether one shape is a part of the other: 0 auto (measured), 1 off (both whole), 2 b_in_a, 3 a_in_b",
        Field::Int(
            |p: &Params| p.partial as i64,
            |p: &mut Params, v| p.partial = PartialOption::ALL[v as usize],
        ),
    )
    .with_choices(&PARTIAL_NAMES),
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

/// The names of the choices of option `name`, by value (`p2p_regions`, `p2p_refinement`;
/// [`OptionInfo::choices`]); `None` for an option that is not a choice.
pub fn option_choices(name: &str) -> Option<&'static [&'static str]> {
    option_info(name)
        .ok()
        .map(|info| info.choices)
        .filter(|choices| !choices.is_empty())
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
    // An option whose range reaches past i64 (`seed`) also takes unsigned 64-bit text.
    let unsigned = info.max > i64::MAX as f64;
    let parsed = match info.option_type {
        OptionType::Int => info
            .choices
            .iter()
            .position(|n| *n == lower)
            .map(|i| i as i64)
            .or_else(|| trimmed.parse().ok())
            .or_else(|| {
                unsigned
                    .then(|| trimmed.parse::<u64>().ok().map(|v| v as i64))
                    .flatten()
            })
            .map(OptionValue::Int),
        OptionType::Float => trimmed.parse().ok().map(OptionValue::Float),
        OptionType::Bool => match lower.as_str() {
            "true" | "yes" | "1" => Some(OptionValue::Bool(true)),
            "false" | "no" | "0" => Some(OptionValue::Bool(false)),
            _ => None,
        },
    };
    parsed.ok_or_else(|| {
        let expected = match info.option_type {
            OptionType::Int if !info.choices.is_empty() => {
                format!("one of {}", choices_text(info.choices))
            }
            OptionType::Int => "an integer".to_string(),
            OptionType::Float => "a number".to_string(),
            OptionType::Bool => "true or false (yes/no, 1/0)".to_string(),
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

/// An integer within the option's range (a choice: one of its values).
fn checked_int(info: &OptionInfo, value: i64) -> Result<i64> {
    if !info.choices.is_empty() && usize::try_from(value).map_or(true, |v| v >= info.choices.len())
    {
        return Err(Error::InvalidParameter {
            name: info.name,
            reason: format!("must be one of {}, got {value}", choices_text(info.choices)),
        });
    }
    if !(info.min..=info.max).contains(&(value as f64)) {
        return Err(out_of_range(info, value));
    }
    Ok(value)
}

/// A finite float within the option's range.
fn checked_float(info: &OptionInfo, value: f64) -> Result<f64> {
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

/// Checks that a value read from the parameters lies in the option's range (for values set
/// directly in the parameter structs, which `set_option` did not see).
fn check_range(info: &OptionInfo, value: OptionValue) -> Result<()> {
    match value {
        OptionValue::Int(v) => checked_int(info, v).map(drop),
        OptionValue::Float(v) => checked_float(info, v).map(drop),
        OptionValue::Bool(_) => Ok(()),
    }
}

/// The error for an option of the pointwise map asked of [`Params`] alone.
fn held_by_options(info: &OptionInfo) -> Error {
    Error::InvalidParameter {
        name: info.name,
        reason: "belongs to PointwiseParams; set and read it through options::Options".to_string(),
    }
}

impl Params {
    /// Checks that every option's value lies in its documented range
    /// ([`OptionInfo::min`], [`OptionInfo::max`]); called by [`Params::validate`].
    pub fn check_option_ranges(&self) -> Result<()> {
        OPTIONS.iter().try_for_each(|info| match info.access {
            Access::Regions(field) => check_range(info, field.read(self)),
            Access::Pointwise(_) => Ok(()),
        })
    }

    /// Sets the option `name` (one of [`OptionGroup::Regions`]). Errors with
    /// [`Error::UnknownOption`] for a name not in [`OPTIONS`], and with
    /// [`Error::InvalidParameter`] for a pointwise option (see [`Options`]), a value of the
    /// wrong type or out of the option's range. Nothing changes on error.
    pub fn set_option(&mut self, name: &str, value: OptionValue) -> Result<()> {
        let info = option_info(name)?;
        match info.access {
            Access::Regions(field) => field.write(info, self, value),
            Access::Pointwise(_) => Err(held_by_options(info)),
        }
    }

    /// The current value of the option `name` ([`Error::UnknownOption`] if there is none,
    /// [`Error::InvalidParameter`] for a pointwise option).
    pub fn option(&self, name: &str) -> Result<OptionValue> {
        let info = option_info(name)?;
        match info.access {
            Access::Regions(field) => Ok(field.read(self)),
            Access::Pointwise(_) => Err(held_by_options(info)),
        }
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
        OPTIONS.iter().try_for_each(|info| match info.access {
            Access::Regions(_) => Ok(()),
            Access::Pointwise(field) => check_range(info, field.read(self)),
        })?;
        self.pointwise.validate()
    }

    /// Sets any option: errors as [`Params::set_option`] (without the pointwise one), and
    /// [`Error::InvalidParameter`] for a choice out of its list. Nothing changes on error.
    pub fn set_option(&mut self, name: &str, value: OptionValue) -> Result<()> {
        let info = option_info(name)?;
        match info.access {
            Access::Regions(field) => field.write(info, &mut self.params, value),
            Access::Pointwise(field) => {
                field.write(info, self, value)?;
                // Keep the chosen refinement's settings current.
                match &mut self.pointwise.refinement {
                    Refinement::ZoomOut(z) => *z = self.zoomout.clone(),
                    Refinement::Icp(n) => *n = self.icp_iterations,
                    Refinement::None => {}
                }
                Ok(())
            }
        }
    }

    /// The current value of any option ([`Error::UnknownOption`] if there is none).
    pub fn option(&self, name: &str) -> Result<OptionValue> {
        let info = option_info(name)?;
        Ok(match info.access {
            Access::Regions(field) => field.read(&self.params),
            Access::Pointwise(field) => field.read(self),
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
                OptionType::Int if !info.choices.is_empty() => {
                    let OptionValue::Int(v) = options.option(info.name).unwrap() else {
                        panic!("{} is not an integer", info.name)
                    };
                    OptionValue::Int((v + 1) % info.choices.len() as i64)
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
    fn choices_are_declared_in_the_table_with_their_range() {
        let choices: Vec<(&str, &[&str])> = OPTIONS
            .iter()
            .filter(|o| !o.choices.is_empty())
            .map(|o| (o.name, o.choices))
            .collect();
        assert_eq!(
            choices,
            [
                ("p2p_regions", &P2P_REGIONS_NAMES[..]),
                ("p2p_refinement", &P2P_REFINEMENT_NAMES[..]),
                ("placement", &PLACEMENT_NAMES[..]),
                ("partial", &PARTIAL_NAMES[..])
            ]
        );
        for info in OPTIONS.iter().filter(|o| !o.choices.is_empty()) {
            assert_eq!(info.option_type, OptionType::Int);
            assert_eq!((info.min, info.max), (0.0, info.choices.len() as f64 - 1.0));
            let err = Options::default()
                .set_option(info.name, OptionValue::Int(info.choices.len() as i64))
                .unwrap_err();
            assert!(
                err.to_string()
                    .contains(&format!("{} (0)", info.choices[0])),
                "{err}"
            );
        }
        for info in OPTIONS.iter().filter(|o| o.option_type == OptionType::Bool) {
            assert_eq!((info.min, info.max), (0.0, 1.0), "{}", info.name);
        }
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
        assert_eq!((last.name, last.option_type), ("partial", OptionType::Int));
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
