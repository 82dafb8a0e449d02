//! Parameters: a handle holding every option, set and read by name. Defaults are
//! `Params::default()` and `PointwiseParams::default()`, the same as the command line's and
//! the add-ons'.

use std::ffi::{c_char, CString};
use std::sync::OnceLock;

use super::boundary::{
    boundary, boundary_value, check_out, free_handle, give_handle, handle, input_slice, input_str,
    write_output, Failure, FfiResult, ScStatus,
};
use crate::options::{option_info, OptionType, OptionValue, Options, OPTIONS};
use crate::pipeline::Params;

/// Every parameter of the method: the region correspondence's and (options named `p2p_*`)
/// the pointwise map's. Setters change it; use one handle from one thread while setting,
/// after which it may be shared for reading by concurrent `sc_match`, `sc_symmetry_detect`
/// and `sc_pointwise_map` calls. Free it with `sc_params_free`.
pub struct ScParams {
    pub(crate) options: Options,
}

/// An integer option (`sc_params_set_int`).
pub const SC_OPTION_INT: u32 = 0;
/// A floating-point option (`sc_params_set_double`).
pub const SC_OPTION_DOUBLE: u32 = 1;
/// A boolean option (`sc_params_set_bool`).
pub const SC_OPTION_BOOL: u32 = 2;

/// Option `placement`: use where the shapes stand only when it is informative (the default;
/// docs/placement.md).
pub const SC_PLACEMENT_AUTO: i64 = 0;
/// Option `placement`: never use where the shapes stand (the intrinsic answer).
pub const SC_PLACEMENT_IGNORE: i64 = 1;
/// Option `placement`: the shapes stand alike (one scene, one scanner rig); among the
/// consistent answers, the one that implies the least turn is taken.
pub const SC_PLACEMENT_TRUST: i64 = 2;
/// Option `partial`: B is taken as a part of A when measured so (the default;
/// docs/partial.md).
pub const SC_PARTIAL_AUTO: i64 = 0;
/// Option `partial`: both shapes are whole.
pub const SC_PARTIAL_OFF: i64 = 1;
/// Option `partial`: B is a part of A (a scan of one side, a body cut off by the field of
/// view).
pub const SC_PARTIAL_B_IN_A: i64 = 2;
/// Option `partial`: A is a part of B.
pub const SC_PARTIAL_A_IN_B: i64 = 3;
/// Most landmark pairs `sc_params_set_landmarks` accepts.
pub const SC_MAX_LANDMARKS: usize = 100;

/// New parameters with the documented defaults.
///
/// # Safety
/// `out_params` must be writable.
#[no_mangle]
pub unsafe extern "C" fn sc_params_new(out_params: *mut *mut ScParams) -> ScStatus {
    boundary(|| {
        check_out(out_params, "out_params")?;
        give_handle(
            out_params,
            ScParams {
                options: Options::default(),
            },
        )
    })
}

/// Frees parameters; NULL is a no-op. It drops the caller's reference: a call still using the
/// handle (freed from its progress callback, or on another thread) keeps the object alive
/// until that call returns.
///
/// # Safety
/// `params` must be NULL or live parameters, not passed to a call afterwards.
#[no_mangle]
pub unsafe extern "C" fn sc_params_free(params: *mut ScParams) {
    free_handle(params)
}

unsafe fn set(params: *mut ScParams, name: *const c_char, value: OptionValue) -> ScStatus {
    boundary(|| {
        let name = input_str(name, "name")?;
        let params = params.as_mut().ok_or_else(|| Failure::null("params"))?;
        let info = option_info(name)?;
        if info.option_type != value.option_type() {
            return Err(Failure::invalid(format!(
                "option `{name}` is {}; use sc_params_set_{}",
                type_name(info.option_type),
                setter_suffix(info.option_type)
            )));
        }
        Ok(params.options.set_option(name, value)?)
    })
}

unsafe fn get(
    params: *const ScParams,
    name: *const c_char,
    wanted: OptionType,
) -> FfiResult<OptionValue> {
    let name = input_str(name, "name")?;
    let params = handle(params, "params")?;
    let info = option_info(name)?;
    if info.option_type != wanted {
        return Err(Failure::invalid(format!(
            "option `{name}` is {}; use sc_params_get_{}",
            type_name(info.option_type),
            setter_suffix(info.option_type)
        )));
    }
    Ok(params.options.option(name)?)
}

/// Reads option `name` of type `wanted` into `*out_value` (nothing written on error).
unsafe fn get_into<T>(
    params: *const ScParams,
    name: *const c_char,
    out_value: *mut T,
    wanted: OptionType,
    extract: impl FnOnce(OptionValue) -> Option<T>,
) -> ScStatus {
    boundary(|| {
        let out = out_value
            .as_mut()
            .ok_or_else(|| Failure::null("out_value"))?;
        if let Some(value) = extract(get(params, name, wanted)?) {
            *out = value;
        }
        Ok(())
    })
}

fn type_name(t: OptionType) -> &'static str {
    match t {
        OptionType::Int => "an integer",
        OptionType::Float => "a double",
        OptionType::Bool => "a bool",
    }
}

fn setter_suffix(t: OptionType) -> &'static str {
    match t {
        OptionType::Int => "int",
        OptionType::Float => "double",
        OptionType::Bool => "bool",
    }
}

/// Sets an integer option by name (see `sc_option_name`). Errors:
/// `SC_STATUS_UNKNOWN_OPTION`, `SC_STATUS_INVALID_ARGUMENT` (the option is not an
/// integer), `SC_STATUS_INVALID_PARAMETER` (negative, or a choice such as `p2p_regions`
/// out of its list). Ranges that involve several options (k_min <= k_max,
/// p2p_fmap_size <= p2p_eigenpairs) are checked when the parameters are used. Options named
/// `p2p_*` only affect `sc_pointwise_map`.
///
/// # Safety
/// `params` must be live parameters; `name` a NUL-terminated string.
#[no_mangle]
pub unsafe extern "C" fn sc_params_set_int(
    params: *mut ScParams,
    name: *const c_char,
    value: i64,
) -> ScStatus {
    set(params, name, OptionValue::Int(value))
}

/// Sets a floating-point option by name (errors as `sc_params_set_int`; NaN and infinity
/// are `SC_STATUS_INVALID_PARAMETER`).
///
/// # Safety
/// `params` must be live parameters; `name` a NUL-terminated string.
#[no_mangle]
pub unsafe extern "C" fn sc_params_set_double(
    params: *mut ScParams,
    name: *const c_char,
    value: f64,
) -> ScStatus {
    set(params, name, OptionValue::Float(value))
}

/// Sets a boolean option by name (errors as `sc_params_set_int`).
///
/// # Safety
/// `params` must be live parameters; `name` a NUL-terminated string.
#[no_mangle]
pub unsafe extern "C" fn sc_params_set_bool(
    params: *mut ScParams,
    name: *const c_char,
    value: bool,
) -> ScStatus {
    set(params, name, OptionValue::Bool(value))
}

/// Reads an integer option into `*out_value`.
///
/// # Safety
/// `params` must be live parameters; `name` a NUL-terminated string; `out_value` writable.
#[no_mangle]
pub unsafe extern "C" fn sc_params_get_int(
    params: *const ScParams,
    name: *const c_char,
    out_value: *mut i64,
) -> ScStatus {
    get_into(params, name, out_value, OptionType::Int, |v| match v {
        OptionValue::Int(v) => Some(v),
        _ => None,
    })
}

/// Reads a floating-point option into `*out_value`.
///
/// # Safety
/// `params` must be live parameters; `name` a NUL-terminated string; `out_value` writable.
#[no_mangle]
pub unsafe extern "C" fn sc_params_get_double(
    params: *const ScParams,
    name: *const c_char,
    out_value: *mut f64,
) -> ScStatus {
    get_into(params, name, out_value, OptionType::Float, |v| match v {
        OptionValue::Float(v) => Some(v),
        _ => None,
    })
}

/// Reads a boolean option into `*out_value`.
///
/// # Safety
/// `params` must be live parameters; `name` a NUL-terminated string; `out_value` writable.
#[no_mangle]
pub unsafe extern "C" fn sc_params_get_bool(
    params: *const ScParams,
    name: *const c_char,
    out_value: *mut bool,
) -> ScStatus {
    get_into(params, name, out_value, OptionType::Bool, |v| match v {
        OptionValue::Bool(v) => Some(v),
        _ => None,
    })
}

/// Sets the landmarks: `n_pairs` pairs of vertices known to correspond, `pairs[2 i]` a vertex
/// of A (the first shape given to `sc_match` or `sc_pointwise_map`) and `pairs[2 i + 1]` its
/// partner on B, 0-based input indices (docs/placement.md). They replace those set before;
/// `n_pairs` 0 clears them (`pairs` may then be NULL). Every landmark of B maps exactly to its
/// partner in the pointwise map, and the region answer is chosen to agree with them: two
/// pairs on one side of a body settle every symmetric choice. They are copied.
///
/// Errors: `SC_STATUS_NULL_ARGUMENT` (`params`, or `pairs` with `n_pairs` above 0),
/// `SC_STATUS_INVALID_PARAMETER` (more than `SC_MAX_LANDMARKS` pairs). Checked against the
/// shapes when a job starts, where a failure is `SC_STATUS_INVALID_PARAMETER` with
/// `sc_last_error` naming the pair: a vertex past the end of its shape, one the repairs left
/// out, one vertex given two partners.
///
/// # Safety
/// `params` must be live parameters; `pairs` NULL or `2 * n_pairs` readable values.
#[no_mangle]
pub unsafe extern "C" fn sc_params_set_landmarks(
    params: *mut ScParams,
    pairs: *const u32,
    n_pairs: usize,
) -> ScStatus {
    boundary(|| {
        let params = params.as_mut().ok_or_else(|| Failure::null("params"))?;
        if n_pairs > SC_MAX_LANDMARKS {
            return Err(crate::Error::InvalidParameter {
                name: "landmarks",
                reason: format!(
                    "{n_pairs} pairs given, at most {SC_MAX_LANDMARKS} (SC_MAX_LANDMARKS) are \
                     accepted"
                ),
            }
            .into());
        }
        let flat = input_slice(pairs, 2 * n_pairs, "pairs")?;
        params.options.params.landmarks = flat.chunks_exact(2).map(|p| [p[0], p[1]]).collect();
        Ok(())
    })
}

/// Number of landmark pairs set (`sc_params_set_landmarks`); 0 for NULL.
///
/// # Safety
/// `params` must be NULL or live parameters.
#[no_mangle]
pub unsafe extern "C" fn sc_params_n_landmarks(params: *const ScParams) -> usize {
    boundary_value(0, || {
        Ok(handle(params, "params")?.options.params.landmarks.len())
    })
}

/// Copies the landmark pairs as `a0 b0 a1 b1 ...` (`2 * sc_params_n_landmarks` values, in
/// the order set) into `out_pairs` of `len` elements.
///
/// # Safety
/// `params` must be live parameters; `out_pairs` must point to `len` writable elements.
#[no_mangle]
pub unsafe extern "C" fn sc_params_landmarks(
    params: *const ScParams,
    out_pairs: *mut u32,
    len: usize,
) -> ScStatus {
    boundary(|| {
        let params = handle(params, "params")?;
        let flat: Vec<u32> = params
            .options
            .params
            .landmarks
            .iter()
            .flatten()
            .copied()
            .collect();
        write_output(out_pairs, len, &flat, "out_pairs")
    })
}

/// The C strings of one option: its name, its description and its choices' names.
struct OptionStrings {
    name: CString,
    doc: CString,
    choices: Vec<CString>,
}

fn option_strings() -> &'static [OptionStrings] {
    static STRINGS: OnceLock<Vec<OptionStrings>> = OnceLock::new();
    let c_string = |text: &str| CString::new(text).expect("the option table has no NUL");
    STRINGS.get_or_init(|| {
        OPTIONS
            .iter()
            .map(|o| OptionStrings {
                name: c_string(o.name),
                doc: c_string(o.doc),
                choices: o.choices.iter().map(|c| c_string(c)).collect(),
            })
            .collect()
    })
}

/// Number of options; they are numbered `0 .. sc_option_count() - 1` in a stable order
/// (new options are appended).
#[no_mangle]
pub extern "C" fn sc_option_count() -> usize {
    OPTIONS.len()
}

/// Name of option `index` (static; never free it), or NULL past the end.
#[no_mangle]
pub extern "C" fn sc_option_name(index: usize) -> *const c_char {
    option_strings()
        .get(index)
        .map_or(std::ptr::null(), |o| o.name.as_ptr())
}

/// One-line description of option `index` (static), or NULL past the end.
#[no_mangle]
pub extern "C" fn sc_option_doc(index: usize) -> *const c_char {
    option_strings()
        .get(index)
        .map_or(std::ptr::null(), |o| o.doc.as_ptr())
}

/// Name of value `value` of option `index` when the option chooses among named
/// alternatives (`p2p_regions`: `"none"`, `"one-to-one"`, `"symmetric"`; `p2p_refinement`:
/// `"none"`, `"zoomout"`, `"icp"`), the name the command line also takes; static, never
/// free it. NULL when the option is not a choice, or past its last value or the last
/// option: values are numbered from 0, so a loop up to the first NULL lists them.
#[no_mangle]
pub extern "C" fn sc_option_choice(index: usize, value: usize) -> *const c_char {
    option_strings()
        .get(index)
        .and_then(|o| o.choices.get(value))
        .map_or(std::ptr::null(), |name| name.as_ptr())
}

/// Type of option `index`: `SC_OPTION_INT`, `SC_OPTION_DOUBLE` or `SC_OPTION_BOOL`;
/// `UINT32_MAX` past the end.
#[no_mangle]
pub extern "C" fn sc_option_type(index: usize) -> u32 {
    OPTIONS
        .get(index)
        .map_or(u32::MAX, |o| match o.option_type {
            OptionType::Int => SC_OPTION_INT,
            OptionType::Float => SC_OPTION_DOUBLE,
            OptionType::Bool => SC_OPTION_BOOL,
        })
}

/// Smallest accepted value of option `index` (0 for a bool); NaN past the end. A value
/// outside `[sc_option_min, sc_option_max]` is refused with `SC_STATUS_INVALID_PARAMETER`.
#[no_mangle]
pub extern "C" fn sc_option_min(index: usize) -> f64 {
    OPTIONS.get(index).map_or(f64::NAN, |o| o.min)
}

/// Largest accepted value of option `index` (1 for a bool); NaN past the end.
#[no_mangle]
pub extern "C" fn sc_option_max(index: usize) -> f64 {
    OPTIONS.get(index).map_or(f64::NAN, |o| o.max)
}

/// The region parameters behind a nullable handle: NULL means the defaults.
pub(crate) unsafe fn params_or_default(params: *const ScParams) -> Params {
    params
        .as_ref()
        .map_or_else(Params::default, |p| p.options.params.clone())
}

/// Every option behind a nullable handle: NULL means the defaults.
pub(crate) unsafe fn options_or_default(params: *const ScParams) -> Options {
    params
        .as_ref()
        .map_or_else(Options::default, |p| p.options.clone())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::maps::placement::Placement;
    use crate::options::OPTIONS;

    #[test]
    fn header_partial_constants_match_the_option() {
        use crate::maps::partial::PartialOption;
        let option = OPTIONS.iter().find(|o| o.name == "partial").unwrap();
        for (value, name) in [
            (SC_PARTIAL_AUTO, "auto"),
            (SC_PARTIAL_OFF, "off"),
            (SC_PARTIAL_B_IN_A, "b_in_a"),
            (SC_PARTIAL_A_IN_B, "a_in_b"),
        ] {
            assert_eq!(option.choices[value as usize], name);
            assert_eq!(PartialOption::ALL[value as usize] as i64, value);
        }
    }

    #[test]
    fn header_placement_constants_match_the_option() {
        let option = OPTIONS.iter().find(|o| o.name == "placement").unwrap();
        for (value, placement) in [
            (SC_PLACEMENT_AUTO, Placement::Auto),
            (SC_PLACEMENT_IGNORE, Placement::Ignore),
            (SC_PLACEMENT_TRUST, Placement::Trust),
        ] {
            assert_eq!(Placement::ALL[value as usize], placement);
            assert_eq!(option.choices[value as usize], placement.name());
        }
    }

    #[test]
    fn header_landmark_limit_is_the_librarys() {
        assert_eq!(SC_MAX_LANDMARKS, crate::maps::landmarks::MAX_LANDMARKS);
    }
}
