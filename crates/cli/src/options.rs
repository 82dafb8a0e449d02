//! The method's options on the command line, generated from the library's option table
//! ([`shapecorr::options::OPTIONS`], the one the C API, Python, Blender and MeshLab use):
//! one flag per option, named as the option with `-` for `_` (`k_min` is `--k-min 5`,
//! `one_to_one` is `--one-to-one false`), with the table's doc as its help and its value
//! read by the table's type ([`parse_option_value`]: choices also by name); plus
//! `--set NAME=VALUE` (repeatable, table spelling), applied after the flags. Defaults are
//! the library's ([`Options::default`]).
//!
//! `match`, `symmetry` and `bench regions` take the region options ([`RegionOptions`]);
//! `p2p` and `bench p2p` take both groups and `--region-times` ([`PointwiseOptions`]).

use std::ffi::OsStr;

use clap::builder::TypedValueParser;
use clap::error::ErrorKind;
use clap::{Arg, ArgAction, ArgMatches, Args, Command, FromArgMatches};
use shapecorr::options::{
    option_choices, option_info, parse_option_value, OptionGroup, OptionInfo, OptionType,
    OptionValue, Options, OPTIONS,
};
use shapecorr::{Error, Params, PointwiseParams};

/// The options of `match`, `symmetry` and `bench regions`: the region group.
pub type RegionOptions = OptionArgs<false>;
/// The options of `p2p` and `bench p2p`: both groups, and `--region-times`.
pub type PointwiseOptions = OptionArgs<true>;

const SET: &str = "set";
const REGION_TIMES: &str = "region_times";

/// The options given on the command line: a flag per option of [`OptionGroup::Regions`]
/// (and, with `POINTWISE`, of [`OptionGroup::Pointwise`]) and `--set NAME=VALUE`. Each
/// value was parsed and range-checked alone when the command line was read; the checks
/// across options are [`OptionArgs::options`]'.
#[derive(Clone, Debug, Default)]
pub struct OptionArgs<const POINTWISE: bool> {
    /// The values given: the flags (in the table's order), then `--set` (in command-line
    /// order), so a `--set` wins over a flag.
    values: Vec<(&'static str, OptionValue)>,
    /// `--region-times` (only with `POINTWISE`): a list, which the table cannot hold.
    region_times: Option<Vec<f64>>,
}

/// The flag of option `name`: `k_min` is `k-min`.
pub fn flag_name(name: &str) -> String {
    name.replace('_', "-")
}

impl<const POINTWISE: bool> OptionArgs<POINTWISE> {
    /// Whether this command takes `info`.
    fn takes(info: &OptionInfo) -> bool {
        POINTWISE || info.group == OptionGroup::Regions
    }

    /// The options this command takes, in the table's order.
    pub fn table() -> impl Iterator<Item = &'static OptionInfo> {
        OPTIONS.iter().filter(|o| Self::takes(o))
    }

    /// Every option: the library's defaults with the values given set, checked together
    /// ([`Options::validate`]).
    pub fn options(&self) -> Result<Options, Error> {
        let mut options = Options::default();
        for &(name, value) in &self.values {
            options.set_option(name, value)?;
        }
        options.validate()?;
        Ok(options)
    }

    /// The region correspondence's parameters.
    pub fn params(&self) -> Result<Params, Error> {
        Ok(self.options()?.params)
    }
}

impl PointwiseOptions {
    /// Every option, and the pointwise map's parameters with `--region-times`.
    pub fn pointwise(&self) -> Result<(Options, PointwiseParams), Error> {
        let options = self.options()?;
        let mut pointwise = options.pointwise().clone();
        if let Some(times) = &self.region_times {
            pointwise.region_times = times.clone();
        }
        pointwise.validate()?;
        Ok((options, pointwise))
    }
}

fn heading(group: OptionGroup) -> &'static str {
    match group {
        OptionGroup::Regions => "Region options (the library's option table)",
        OptionGroup::Pointwise => "Pointwise-map options (the library's option table)",
    }
}

fn value_name(info: &OptionInfo) -> String {
    match (info.option_type, option_choices(info.name)) {
        (OptionType::Int, Some(names)) => names.join("|"),
        (OptionType::Int, None) => "INT".to_string(),
        (OptionType::Float, _) => "NUMBER".to_string(),
        (OptionType::Bool, _) => "true|false".to_string(),
    }
}

/// A value as the command line spells it (a choice by its name).
pub fn value_text(name: &str, value: OptionValue) -> String {
    match value {
        OptionValue::Int(v) => option_choices(name)
            .and_then(|names| usize::try_from(v).ok().and_then(|i| names.get(i)))
            .map_or_else(|| v.to_string(), |n| n.to_string()),
        OptionValue::Float(v) => v.to_string(),
        OptionValue::Bool(v) => v.to_string(),
    }
}

fn help(info: &OptionInfo) -> String {
    let default = Options::default()
        .option(info.name)
        .map(|v| value_text(info.name, v))
        .unwrap_or_default();
    match info.option_type {
        OptionType::Bool => format!("{} [default: {default}]", info.doc),
        _ if info.name == "seed" => format!("{} [default: {default}]", info.doc),
        _ => format!(
            "{} [default: {default}] [range: {}]",
            info.doc,
            info.range_text()
        ),
    }
}

fn invalid(cmd: &Command, message: String) -> clap::Error {
    let mut cmd = cmd.clone();
    cmd.error(ErrorKind::ValueValidation, message)
}

/// A value of one option, checked alone: parsed by its type and accepted by
/// [`Options::set_option`].
fn checked_value(name: &'static str, text: &str) -> Result<OptionValue, Error> {
    let value = parse_option_value(name, text)?;
    Options::default().set_option(name, value)?;
    Ok(value)
}

/// Reads the value of one option's flag.
#[derive(Clone)]
struct ValueParser(&'static OptionInfo);

impl TypedValueParser for ValueParser {
    type Value = OptionValue;

    fn parse_ref(
        &self,
        cmd: &Command,
        arg: Option<&Arg>,
        value: &OsStr,
    ) -> Result<OptionValue, clap::Error> {
        let text = value.to_string_lossy();
        checked_value(self.0.name, &text).map_err(|e| {
            let arg = arg.map_or_else(|| flag_name(self.0.name), |a| a.to_string());
            invalid(cmd, format!("invalid value '{text}' for '{arg}': {e}"))
        })
    }
}

/// Reads `--set NAME=VALUE` for a command that takes the pointwise options or not.
#[derive(Clone)]
struct SetParser<const POINTWISE: bool>;

impl<const POINTWISE: bool> SetParser<POINTWISE> {
    fn parse(text: &str) -> Result<(&'static str, OptionValue), String> {
        let Some((name, value)) = text.split_once('=') else {
            return Err("expected NAME=VALUE (an option of the table, e.g. k_max=8)".into());
        };
        let name = name.trim();
        let known = || {
            OptionArgs::<POINTWISE>::table()
                .map(|o| o.name)
                .collect::<Vec<_>>()
                .join(", ")
        };
        let info = match option_info(name) {
            Ok(info) if OptionArgs::<POINTWISE>::takes(info) => info,
            Ok(info) => {
                return Err(format!(
                    "option `{}` is the pointwise map's (p2p, bench p2p); this command \
                     takes: {}",
                    info.name,
                    known()
                ))
            }
            Err(_) => {
                let hint = option_info(&name.replace('-', "_"))
                    .map_or(String::new(), |o| format!(" (did you mean `{}`?)", o.name));
                return Err(format!(
                    "unknown option `{name}`{hint}; this command takes: {}",
                    known()
                ));
            }
        };
        checked_value(info.name, value)
            .map(|v| (info.name, v))
            .map_err(|e| e.to_string())
    }
}

impl<const POINTWISE: bool> TypedValueParser for SetParser<POINTWISE> {
    type Value = (&'static str, OptionValue);

    fn parse_ref(
        &self,
        cmd: &Command,
        _arg: Option<&Arg>,
        value: &OsStr,
    ) -> Result<Self::Value, clap::Error> {
        let text = value.to_string_lossy();
        Self::parse(&text)
            .map_err(|e| invalid(cmd, format!("invalid value '{text}' for '--set': {e}")))
    }
}

impl<const POINTWISE: bool> Args for OptionArgs<POINTWISE> {
    fn augment_args(cmd: Command) -> Command {
        let mut cmd = Self::table().fold(cmd, |cmd, info| {
            cmd.arg(
                Arg::new(info.name)
                    .long(flag_name(info.name))
                    .value_name(value_name(info))
                    .help(help(info))
                    .help_heading(heading(info.group))
                    .action(ArgAction::Set)
                    .allow_negative_numbers(true)
                    .value_parser(ValueParser(info)),
            )
        });
        if POINTWISE {
            cmd = cmd.arg(
                Arg::new(REGION_TIMES)
                    .long("region-times")
                    .value_name("TIMES")
                    .help(
                        "pointwise map: diffusion times of the region indicators, comma \
                         separated [default: 0] (command line only: a list has no entry in \
                         the option table)",
                    )
                    .help_heading(heading(OptionGroup::Pointwise))
                    .action(ArgAction::Set)
                    .value_delimiter(',')
                    .value_parser(clap::value_parser!(f64)),
            );
        }
        let last = if POINTWISE {
            OptionGroup::Pointwise
        } else {
            OptionGroup::Regions
        };
        cmd.arg(
            Arg::new(SET)
                .long(SET)
                .value_name("NAME=VALUE")
                .help(
                    "set any of the options above by its table name (k_max=8), after the \
                     flags; repeatable",
                )
                .help_heading(heading(last))
                .action(ArgAction::Append)
                .value_parser(SetParser::<POINTWISE>),
        )
    }

    fn augment_args_for_update(cmd: Command) -> Command {
        Self::augment_args(cmd)
    }
}

impl<const POINTWISE: bool> FromArgMatches for OptionArgs<POINTWISE> {
    fn from_arg_matches(matches: &ArgMatches) -> Result<Self, clap::Error> {
        let mut args = Self::default();
        args.update_from_arg_matches(matches)?;
        Ok(args)
    }

    fn update_from_arg_matches(&mut self, matches: &ArgMatches) -> Result<(), clap::Error> {
        for info in Self::table() {
            if let Some(&value) = matches.get_one::<OptionValue>(info.name) {
                self.values.push((info.name, value));
            }
        }
        if let Some(sets) = matches.get_many::<(&'static str, OptionValue)>(SET) {
            self.values.extend(sets.copied());
        }
        if POINTWISE {
            if let Some(times) = matches.get_many::<f64>(REGION_TIMES) {
                self.region_times = Some(times.copied().collect());
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(clap::Parser)]
    struct Regions {
        #[command(flatten)]
        options: RegionOptions,
    }

    #[derive(clap::Parser)]
    struct Pointwise {
        #[command(flatten)]
        options: PointwiseOptions,
    }

    fn regions(args: &[&str]) -> Result<Options, String> {
        use clap::Parser;
        let parsed = Regions::try_parse_from(std::iter::once("t").chain(args.iter().copied()))
            .map_err(|e| e.to_string())?;
        parsed.options.options().map_err(|e| e.to_string())
    }

    fn pointwise(args: &[&str]) -> Result<(Options, PointwiseParams), String> {
        use clap::Parser;
        let parsed = Pointwise::try_parse_from(std::iter::once("t").chain(args.iter().copied()))
            .map_err(|e| e.to_string())?;
        parsed.options.pointwise().map_err(|e| e.to_string())
    }

    #[test]
    fn nothing_given_is_the_library_defaults() {
        let options = regions(&[]).unwrap();
        let defaults = Options::default();
        for info in OPTIONS {
            assert_eq!(
                options.option(info.name).unwrap(),
                defaults.option(info.name).unwrap()
            );
        }
        let (_, p) = pointwise(&[]).unwrap();
        assert_eq!(p, PointwiseParams::default());
    }

    #[test]
    fn flags_and_set_reach_the_params() {
        let options = regions(&[
            "--k-min",
            "4",
            "--gap-ratio",
            "0.8",
            "--one-to-one",
            "no",
            "--set",
            "k_max=7",
        ])
        .unwrap();
        let p = &options.params;
        assert_eq!((p.segmentation.k_min, p.segmentation.k_max), (4, 7));
        assert_eq!(p.matching.gap_ratio, 0.8);
        assert!(p.skip_one_to_one);
        // Seeds take any 64-bit integer, negative ones too.
        let options = regions(&["--seed", "-7"]).unwrap();
        assert_eq!(options.params.segmentation.seed, (-7i64) as u64);
        // --set comes after the flags, whatever the order on the command line.
        let options = regions(&["--set", "k_max=6", "--k-max", "9"]).unwrap();
        assert_eq!(options.params.segmentation.k_max, 6);
        let (options, p) = pointwise(&[
            "--p2p-refinement",
            "icp",
            "--p2p-regions",
            "symmetric",
            "--p2p-orientation",
            "false",
            "--set",
            "p2p_fmap_size=30",
            "--region-times",
            "0,0.5",
            "--k-min",
            "6",
        ])
        .unwrap();
        assert_eq!(options.params.segmentation.k_min, 6);
        assert_eq!(
            p.refinement,
            shapecorr::maps::pointwise::Refinement::Icp(shapecorr::options::ICP_ITERATIONS)
        );
        assert_eq!(
            p.regions,
            shapecorr::maps::pointwise::RegionConstraints::Symmetric
        );
        assert!(!p.orientation);
        assert_eq!(p.fmap_size, 30);
        assert_eq!(p.region_times, vec![0.0, 0.5]);
    }

    #[test]
    fn bad_values_name_the_flag_or_option() {
        for (args, expected) in [
            (&["--k-min", "five"][..], "--k-min"),
            (&["--k-min", "-1"], "must lie in [2, 100], got -1"),
            (&["--one-to-one", "maybe"], "true or false"),
            (&["--set", "nope=1"], "`nope`"),
            (&["--set", "k-max=3"], "did you mean `k_max`"),
            (&["--set", "k_max"], "NAME=VALUE"),
            (&["--set", "p2p_fmap_size=30"], "pointwise"),
            (&["--p2p-fmap-size", "30"], "--p2p-fmap-size"),
            (&["--k-min", "8", "--k-max", "5"], "k_min"),
        ] {
            let error = regions(args).unwrap_err();
            assert!(error.contains(expected), "{args:?}: {error}");
        }
        let error = pointwise(&["--p2p-refinement", "zoom"]).unwrap_err();
        assert!(error.contains("zoomout (1)"), "{error}");
        let error = pointwise(&["--p2p-fmap-size", "200"]).unwrap_err();
        assert!(error.contains("fmap_size"), "{error}");
    }

    #[test]
    fn every_option_of_the_command_has_a_flag() {
        let cmd = Pointwise::augment_args(Command::new("t"));
        for info in OPTIONS {
            let long = flag_name(info.name);
            assert!(
                cmd.get_arguments()
                    .any(|a| a.get_long() == Some(long.as_str())),
                "{long}"
            );
        }
        let cmd = Regions::augment_args(Command::new("t"));
        let longs: Vec<&str> = cmd.get_arguments().filter_map(|a| a.get_long()).collect();
        let expected: Vec<String> = RegionOptions::table()
            .map(|o| flag_name(o.name))
            .chain(["set".to_string()])
            .collect();
        assert_eq!(longs, expected);
    }
}
