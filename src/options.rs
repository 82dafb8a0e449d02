//! Named options: the parameters of [`Params`] that the C API, the Python binding and the
//! add-ons set by name (`"k_min"`, `"gap_ratio"`, ...). One table, so every front end offers
//! the same options with the same defaults, which come from `Params::default()`.
//!
//! A value is type-checked and range-checked here as far as the option alone allows
//! (integers non-negative and within range, floats finite); the checks that involve several
//! options (`k_min <= k_max`) are [`Params::validate`]'s.

use crate::correspondence::Params;
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
    Int(i64),
    Float(f64),
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

/// One named option.
#[derive(Debug, Clone, Copy)]
pub struct OptionInfo {
    /// The name used by every front end.
    pub name: &'static str,
    /// The type of its value.
    pub option_type: OptionType,
    /// One line: what it does.
    pub doc: &'static str,
}

const fn info(name: &'static str, option_type: OptionType, doc: &'static str) -> OptionInfo {
    OptionInfo {
        name,
        option_type,
        doc,
    }
}

use OptionType::{Bool, Float, Int};

/// Every named option, in a stable order (new options are appended).
pub const OPTIONS: &[OptionInfo] = &[
    info(
        "k_min",
        Int,
        "smallest number of joint clusters tried (paper: 5)",
    ),
    info(
        "k_max",
        Int,
        "largest number of joint clusters tried (paper: 10)",
    ),
    info(
        "kmeans_restarts",
        Int,
        "k-means++ starts per k; the lowest cost is kept",
    ),
    info(
        "max_regions",
        Int,
        "graphs with more regions than this are not accepted",
    ),
    info(
        "min_region_area",
        Float,
        "regions below this fraction of the area are merged into a neighbour",
    ),
    info(
        "seed",
        Int,
        "seed of every random choice (k-means++, eigensolver start, local search)",
    ),
    info("hks_times", Int, "number of heat kernel signature times"),
    info("hks_t_min", Float, "smallest HKS time (unit-area shape)"),
    info("hks_t_max", Float, "largest HKS time (unit-area shape)"),
    info("hks_log", Bool, "use the logarithm of the HKS"),
    info("eigenpairs", Int, "number of Laplacian eigenpairs"),
    info(
        "threads",
        Int,
        "threads of the eigensolver (0: all cores); results do not depend on it",
    ),
    info(
        "sigma",
        Float,
        "width of the graph matching's Gaussian affinities",
    ),
    info(
        "histogram_bins",
        Int,
        "bins of the graph-distance histograms",
    ),
    info(
        "gap_ratio",
        Float,
        "a match scoring below ratio x the previous one ends the list",
    ),
    info(
        "max_symmetry_order",
        Int,
        "largest number of matches per region",
    ),
    info(
        "one_to_one",
        Bool,
        "break symmetries into a one-to-one region correspondence",
    ),
    info(
        "exhaustive_limit",
        Int,
        "one-to-one: largest number of combinations searched exhaustively",
    ),
    info(
        "symmetry_restarts",
        Int,
        "one-to-one: local-search restarts above that limit",
    ),
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

fn wrong_type(info: &OptionInfo, got: OptionType) -> Error {
    Error::InvalidParameter {
        name: info.name,
        reason: format!("is of type {:?}, but a {got:?} was given", info.option_type),
    }
}

fn to_usize(info: &OptionInfo, value: i64) -> Result<usize> {
    usize::try_from(value).map_err(|_| Error::InvalidParameter {
        name: info.name,
        reason: format!("must be a non-negative integer, got {value}"),
    })
}

fn to_finite(info: &OptionInfo, value: f64) -> Result<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(Error::InvalidParameter {
            name: info.name,
            reason: format!("must be finite, got {value}"),
        })
    }
}

impl Params {
    /// Sets the option `name`. Errors with [`Error::UnknownOption`] for a name not in
    /// [`OPTIONS`], and with [`Error::InvalidParameter`] for a value of the wrong type, a
    /// negative integer or a non-finite float. Nothing changes on error.
    pub fn set_option(&mut self, name: &str, value: OptionValue) -> Result<()> {
        let info = option_info(name)?;
        if value.option_type() != info.option_type {
            return Err(wrong_type(info, value.option_type()));
        }
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
                    other => unreachable!("float option {other} has no field"),
                }
            }
            OptionValue::Bool(v) => match info.name {
                "hks_log" => self.hks.log = v,
                "one_to_one" => self.skip_one_to_one = !v,
                "hks_fallback" => {
                    self.fallback = v.then(|| self.fallback.clone().unwrap_or_default())
                }
                other => unreachable!("bool option {other} has no field"),
            },
        }
        Ok(())
    }

    /// The current value of the option `name` ([`Error::UnknownOption`] if there is none).
    pub fn option(&self, name: &str) -> Result<OptionValue> {
        let info = option_info(name)?;
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
            other => unreachable!("option {other} has no field"),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_option_reads_back_what_was_set() {
        for (i, info) in OPTIONS.iter().enumerate() {
            let mut params = Params::default();
            let value = match info.option_type {
                OptionType::Int => OptionValue::Int(3 + i as i64),
                OptionType::Float => OptionValue::Float(0.125 + i as f64),
                OptionType::Bool => {
                    let OptionValue::Bool(b) = params.option(info.name).unwrap() else {
                        panic!("{} is not a bool", info.name)
                    };
                    OptionValue::Bool(!b)
                }
            };
            assert_ne!(params.option(info.name).unwrap(), value, "{}", info.name);
            params.set_option(info.name, value).unwrap();
            assert_eq!(params.option(info.name).unwrap(), value, "{}", info.name);
            // Exactly this option changed: every other option still has its default.
            let defaults = Params::default();
            for other in OPTIONS.iter().filter(|o| o.name != info.name) {
                assert_eq!(
                    params.option(other.name).unwrap(),
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
        let defaults = Params::default();
        for (i, info) in OPTIONS.iter().enumerate() {
            assert!(OPTIONS[..i].iter().all(|o| o.name != info.name));
            assert_eq!(
                defaults.option(info.name).unwrap().option_type(),
                info.option_type
            );
        }
    }

    #[test]
    fn bad_names_types_and_values_are_rejected_without_change() {
        let mut params = Params::default();
        assert!(matches!(
            params.set_option("k_mni", OptionValue::Int(3)),
            Err(Error::UnknownOption { .. })
        ));
        for (name, value) in [
            ("k_min", OptionValue::Float(3.0)),
            ("k_min", OptionValue::Int(-1)),
            ("gap_ratio", OptionValue::Float(f64::NAN)),
            ("gap_ratio", OptionValue::Bool(true)),
            ("one_to_one", OptionValue::Int(1)),
        ] {
            let before = format!("{params:?}");
            assert!(
                matches!(
                    params.set_option(name, value),
                    Err(Error::InvalidParameter { .. })
                ),
                "{name} = {value:?}"
            );
            assert_eq!(format!("{params:?}"), before);
        }
    }

    #[test]
    fn seed_takes_any_64_bit_value() {
        let mut params = Params::default();
        params.set_option("seed", OptionValue::Int(-7)).unwrap();
        assert_eq!(params.segmentation.seed, (-7i64) as u64);
        assert_eq!(params.option("seed").unwrap(), OptionValue::Int(-7));
    }
}
