//! The panic boundary, status codes, the last-error message and the pointer checks every
//! exported function goes through.

use std::cell::RefCell;
use std::ffi::{c_char, CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::Arc;

use crate::Error;

/// Status of every fallible call. The numbers never change meaning; new codes are added.
#[repr(u32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ScStatus {
    /// Success.
    Ok = 0,
    /// A required pointer argument was NULL.
    NullArgument = 1,
    /// An argument is invalid: a count that does not fit, a misaligned pointer, a string
    /// that is not UTF-8, an unknown side or match kind, an option of another type.
    InvalidArgument = 2,
    /// An output buffer is shorter than the size its `_n_` query gives.
    BufferTooSmall = 3,
    /// An option name that does not exist (see `sc_option_name`).
    UnknownOption = 4,
    /// A vertex coordinate is NaN or infinite.
    NonFiniteCoordinate = 10,
    /// A face refers to a vertex index past the end.
    FaceIndexOutOfRange = 11,
    /// A face has fewer than three corners.
    FaceTooSmall = 12,
    /// Too few (referenced) vertices: the shape is empty or tiny.
    TooFewVertices = 13,
    /// The shape has no area (every face degenerate, all points coincide).
    ZeroArea = 14,
    /// A parameter value is out of its range (or two disagree, e.g. k_min > k_max).
    InvalidParameter = 15,
    /// A file could not be read or parsed.
    FileError = 16,
    /// A numerical method failed (factorisation or eigensolver).
    NumericalFailure = 17,
    /// The progress callback returned false.
    Cancelled = 18,
    /// The job is too big for a limit: refused before any work by its estimate
    /// (`memory_limit_mib`, `time_limit_s`, `max_vertices`, the memory available) or
    /// stopped when it ran past `time_limit_s`. `sc_last_error` names the limit, the
    /// estimate and what to do.
    ResourceLimit = 19,
    /// An internal error (a bug in shapecorr): the call was stopped safely; please report
    /// the message of `sc_last_error`.
    Panic = 100,
}

impl ScStatus {
    fn text(self) -> &'static CStr {
        match self {
            ScStatus::Ok => c"success",
            ScStatus::NullArgument => c"a required pointer argument is NULL",
            ScStatus::InvalidArgument => c"invalid argument",
            ScStatus::BufferTooSmall => c"output buffer too small",
            ScStatus::UnknownOption => c"unknown option name",
            ScStatus::NonFiniteCoordinate => c"a vertex coordinate is NaN or infinite",
            ScStatus::FaceIndexOutOfRange => c"a face refers to a vertex that does not exist",
            ScStatus::FaceTooSmall => c"a face has fewer than three corners",
            ScStatus::TooFewVertices => c"too few vertices",
            ScStatus::ZeroArea => c"the shape has zero area",
            ScStatus::InvalidParameter => c"invalid parameter value",
            ScStatus::FileError => c"file could not be read",
            ScStatus::NumericalFailure => c"numerical failure",
            ScStatus::Cancelled => c"cancelled by the progress callback",
            ScStatus::ResourceLimit => {
                c"the job exceeds a resource limit (memory, time or shape size)"
            }
            ScStatus::Panic => c"internal error (a bug in shapecorr)",
        }
    }

    const ALL: [ScStatus; 16] = [
        ScStatus::Ok,
        ScStatus::NullArgument,
        ScStatus::InvalidArgument,
        ScStatus::BufferTooSmall,
        ScStatus::UnknownOption,
        ScStatus::NonFiniteCoordinate,
        ScStatus::FaceIndexOutOfRange,
        ScStatus::FaceTooSmall,
        ScStatus::TooFewVertices,
        ScStatus::ZeroArea,
        ScStatus::InvalidParameter,
        ScStatus::FileError,
        ScStatus::NumericalFailure,
        ScStatus::Cancelled,
        ScStatus::ResourceLimit,
        ScStatus::Panic,
    ];
}

/// A short static description of a status code (`"unknown status"` for a number that is
/// not a status). Never free it.
#[no_mangle]
pub extern "C" fn sc_status_str(status: u32) -> *const c_char {
    ScStatus::ALL
        .iter()
        .find(|s| **s as u32 == status)
        .map_or(c"unknown status", |s| s.text())
        .as_ptr()
}

thread_local! {
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

/// The message of the last failed call on this thread (what was received and how to fix
/// it), or `""` if none failed yet. Valid until the next failed call on the same thread;
/// never free it. Successful calls leave it unchanged.
#[no_mangle]
pub extern "C" fn sc_last_error() -> *const c_char {
    LAST_ERROR.with(|m| m.borrow().as_ptr())
}

fn set_last_error(message: &str) {
    let message = CString::new(message.replace('\0', " ")).unwrap_or_default();
    LAST_ERROR.with(|m| *m.borrow_mut() = message);
}

/// A failed call: its status and the message for [`sc_last_error`].
#[derive(Debug)]
pub(crate) struct Failure {
    pub status: ScStatus,
    pub message: String,
}

impl Failure {
    pub fn new(status: ScStatus, message: impl Into<String>) -> Self {
        Failure {
            status,
            message: message.into(),
        }
    }

    pub fn null(name: &str) -> Self {
        Failure::new(
            ScStatus::NullArgument,
            format!("`{name}` is NULL; pass a valid pointer"),
        )
    }

    pub fn invalid(message: impl Into<String>) -> Self {
        Failure::new(ScStatus::InvalidArgument, message)
    }
}

impl From<Error> for Failure {
    fn from(error: Error) -> Self {
        let status = match error.innermost() {
            Error::NonFiniteCoordinate { .. } => ScStatus::NonFiniteCoordinate,
            Error::FaceIndexOutOfRange { .. } => ScStatus::FaceIndexOutOfRange,
            Error::FaceTooSmall { .. } => ScStatus::FaceTooSmall,
            Error::TooFewVertices { .. } => ScStatus::TooFewVertices,
            Error::ZeroArea { .. } => ScStatus::ZeroArea,
            Error::InvalidParameter { .. } => ScStatus::InvalidParameter,
            Error::File { .. } => ScStatus::FileError,
            Error::Numerical { .. } => ScStatus::NumericalFailure,
            Error::Cancelled => ScStatus::Cancelled,
            Error::UnknownOption { .. } => ScStatus::UnknownOption,
            Error::ResourceLimit { .. } => ScStatus::ResourceLimit,
            Error::InShape { .. } => unreachable!("innermost is never InShape"),
        };
        Failure::new(status, error.to_string())
    }
}

pub(crate) type FfiResult<T = ()> = Result<T, Failure>;

fn panic_text(payload: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        s.to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "unknown panic".to_string()
    }
}

/// Runs an exported function's body: a failure sets the last error and returns its status,
/// a panic is caught and becomes [`ScStatus::Panic`].
pub(crate) fn boundary(body: impl FnOnce() -> FfiResult) -> ScStatus {
    crate::system::fit_allocator_to_address_space_limit();
    match catch_unwind(AssertUnwindSafe(body)) {
        Ok(Ok(())) => ScStatus::Ok,
        Ok(Err(failure)) => {
            set_last_error(&failure.message);
            failure.status
        }
        Err(payload) => {
            set_last_error(&format!(
                "internal error, please report it: {}",
                panic_text(payload.as_ref())
            ));
            ScStatus::Panic
        }
    }
}

/// As [`boundary`] for functions that return a value (counts, flags): `fallback` on a
/// failure or a panic.
pub(crate) fn boundary_value<T>(fallback: T, body: impl FnOnce() -> FfiResult<T>) -> T {
    match catch_unwind(AssertUnwindSafe(body)) {
        Ok(Ok(value)) => value,
        Ok(Err(failure)) => {
            set_last_error(&failure.message);
            fallback
        }
        Err(payload) => {
            set_last_error(&format!(
                "internal error, please report it: {}",
                panic_text(payload.as_ref())
            ));
            fallback
        }
    }
}

/// The caller's array `ptr[0..len]` (NULL is accepted when `len` is 0).
///
/// # Safety
/// When non-NULL, `ptr` must point to `len` readable elements.
pub(crate) unsafe fn input_slice<'a, T>(
    ptr: *const T,
    len: usize,
    name: &str,
) -> FfiResult<&'a [T]> {
    if len == 0 {
        return Ok(&[]);
    }
    if ptr.is_null() {
        return Err(Failure::null(name));
    }
    if !ptr.is_aligned() {
        return Err(Failure::invalid(format!(
            "`{name}` is not aligned for its element type"
        )));
    }
    if len
        .checked_mul(size_of::<T>())
        .is_none_or(|bytes| bytes > isize::MAX as usize)
    {
        return Err(Failure::invalid(format!(
            "`{name}`: length {len} is too large"
        )));
    }
    Ok(std::slice::from_raw_parts(ptr, len))
}

/// Copies `values` to the caller's buffer `out[0..len]`: `len` must be at least
/// `values.len()`. Nothing is written on error.
///
/// # Safety
/// When non-NULL, `out` must point to `len` writable elements.
pub(crate) unsafe fn write_output<T: Copy>(
    out: *mut T,
    len: usize,
    values: &[T],
    name: &str,
) -> FfiResult {
    if out.is_null() {
        return Err(Failure::null(name));
    }
    if !out.is_aligned() {
        return Err(Failure::invalid(format!(
            "`{name}` is not aligned for its element type"
        )));
    }
    if len < values.len() {
        return Err(Failure::new(
            ScStatus::BufferTooSmall,
            format!(
                "`{name}` holds {len} elements but {} are needed",
                values.len()
            ),
        ));
    }
    std::ptr::copy_nonoverlapping(values.as_ptr(), out, values.len());
    Ok(())
}

/// A use of a handle for the length of one call: the object stays alive until the call
/// returns, even when the caller frees the handle meanwhile (from the progress callback, or
/// on another thread).
pub(crate) type Held<T> = Arc<T>;

/// The object behind a handle, held for the call ([`Held`]).
///
/// # Safety
/// When non-NULL, `ptr` must be a live handle of this type (made by [`give_handle`] and not
/// yet freed when the call started).
pub(crate) unsafe fn handle<T>(ptr: *const T, name: &str) -> FfiResult<Held<T>> {
    if ptr.is_null() {
        return Err(Failure::null(name));
    }
    // SAFETY: a live handle is an `Arc` given out by `give_handle`, whose own reference
    // keeps the count at 1 or more; this use adds one, dropped when the call ends.
    Arc::increment_strong_count(ptr);
    Ok(Arc::from_raw(ptr))
}

/// Checks an out-parameter for a handle before any work is done.
pub(crate) fn check_out<T>(out: *mut *mut T, name: &str) -> FfiResult {
    if out.is_null() {
        Err(Failure::null(name))
    } else {
        Ok(())
    }
}

/// Moves `value` to the heap and hands it to the caller through `out` (checked non-NULL
/// with [`check_out`] first). The handle is the caller's reference to an `Arc`: calls that
/// use it take their own ([`handle`]), so that `_free` during a call drops only the
/// caller's, and the object goes when the last call using it returns.
///
/// # Safety
/// `out` must be a valid, writable pointer.
pub(crate) unsafe fn give_handle<T>(out: *mut *mut T, value: T) -> FfiResult {
    check_out(out, "out")?;
    *out = Arc::into_raw(Arc::new(value)).cast_mut();
    Ok(())
}

/// Drops the caller's reference to a handle made by [`give_handle`]; NULL is a no-op. The
/// object is freed now, or when the last call still using it returns.
///
/// # Safety
/// When non-NULL, `ptr` must be a live handle of this type, not passed to any call
/// afterwards.
pub(crate) unsafe fn free_handle<T>(ptr: *mut T) {
    if !ptr.is_null() {
        // Dropping plain data cannot panic, but the boundary costs nothing.
        let _ = catch_unwind(AssertUnwindSafe(|| drop(Arc::from_raw(ptr.cast_const()))));
    }
}

/// A NUL-terminated UTF-8 string argument.
///
/// # Safety
/// When non-NULL, `ptr` must point to a NUL-terminated string.
pub(crate) unsafe fn input_str<'a>(ptr: *const c_char, name: &str) -> FfiResult<&'a str> {
    if ptr.is_null() {
        return Err(Failure::null(name));
    }
    CStr::from_ptr(ptr)
        .to_str()
        .map_err(|_| Failure::invalid(format!("`{name}` is not valid UTF-8")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_status_has_its_own_text_and_unknown_numbers_have_one_too() {
        let texts: Vec<&CStr> = ScStatus::ALL.iter().map(|s| s.text()).collect();
        for (i, t) in texts.iter().enumerate() {
            assert!(!texts[..i].contains(t));
        }
        let unknown = unsafe { CStr::from_ptr(sc_status_str(12345)) };
        assert_eq!(unknown, c"unknown status");
    }

    #[test]
    fn a_panic_becomes_a_status_and_a_message() {
        let status = boundary(|| panic!("boom"));
        assert_eq!(status, ScStatus::Panic);
        let message = unsafe { CStr::from_ptr(sc_last_error()) };
        assert!(message.to_str().unwrap().contains("boom"));
    }

    #[test]
    fn every_error_variant_has_its_own_status() {
        let errors = [
            Error::NonFiniteCoordinate {
                vertex: 0,
                value: f64::NAN,
            },
            Error::FaceIndexOutOfRange {
                face: 0,
                index: 9,
                n_vertices: 3,
            },
            Error::FaceTooSmall {
                face: 0,
                corners: 2,
            },
            Error::TooFewVertices {
                received: 0,
                required: 32,
            },
            Error::ZeroArea {
                detail: String::new(),
            },
            Error::InvalidParameter {
                name: "x",
                reason: String::new(),
            },
            Error::file("f", "r"),
            Error::Numerical {
                stage: "s",
                reason: String::new(),
            },
            Error::Cancelled,
            Error::UnknownOption {
                name: String::new(),
                known: String::new(),
            },
            Error::ResourceLimit {
                limit: "memory_limit_mib",
                reason: String::new(),
            },
        ];
        let statuses: Vec<ScStatus> = errors
            .into_iter()
            .map(|e| Failure::from(e).status)
            .collect();
        for (i, s) in statuses.iter().enumerate() {
            assert!(!statuses[..i].contains(s), "{s:?} is used twice");
        }
    }
}
