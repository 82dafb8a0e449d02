//! The stable C API: `include/shapecorr.h` is generated from this module by cbindgen
//! (`cbindgen.toml`; `tests/it/header.rs` fails when the committed header drifts).
//!
//! No algorithm lives here: every function checks its arguments, calls the Rust API
//! ([`crate::Shape`], [`crate::correspondence::Correspondence`], [`crate::options`]) and
//! turns the result into a status code. The rules, after rustls-ffi:
//! - every exported body runs inside one panic boundary (`boundary.rs`); a panic becomes
//!   `SC_STATUS_PANIC`, never an abort or an unwind into C;
//! - NULL arguments give `SC_STATUS_NULL_ARGUMENT`; `_free(NULL)` is a no-op;
//! - out-parameters come last and are written only on success;
//! - every buffer is followed by its length in elements; output buffers are the caller's,
//!   sized with the matching `_n_` query;
//! - status codes are numbered once and never change meaning ([`ScStatus`]);
//! - the detail of the last failure on a thread is [`sc_last_error`].
//!
//! Direction and naming: "side" A is the first shape given to `sc_match` (or
//! `sc_pointwise_map`), B the second; a match `(i, j)` pairs region `i` of A with region `j`
//! of B; the pointwise map goes from B to A (a vertex of A for every vertex of B) and the
//! functional map from A to B.

mod batch;
mod boundary;
mod correspondence;
mod params;
mod pointwise;
mod shape;
mod symmetry;
mod transfer;
mod verdict;

pub use batch::*;
pub use boundary::{sc_last_error, sc_status_str, ScStatus};
pub use correspondence::*;
pub use params::*;
pub use pointwise::*;
pub use shape::*;
pub use symmetry::*;
pub use transfer::*;
pub use verdict::{SC_ANSWER_CHOSEN, SC_ANSWER_RUNNER_UP};

use std::ffi::{c_char, c_void};

/// Major version of the library (the header's value; `sc_version_major()` is the runtime's).
pub const SC_VERSION_MAJOR: u32 = 0;
/// Minor version of the library.
pub const SC_VERSION_MINOR: u32 = 1;
/// Patch version of the library.
pub const SC_VERSION_PATCH: u32 = 0;
/// Version of the C ABI: raised only when a function's signature or meaning changes
/// (functions are only ever added within one ABI version).
pub const SC_ABI_VERSION: u32 = 1;

/// Stage numbers passed to the progress callback (they never change meaning).
pub const SC_STAGE_LAPLACIAN: u32 = 1;
/// Computing a shape's Laplacian eigenbasis.
pub const SC_STAGE_EIGENBASIS: u32 = 2;
/// Computing descriptors (heat kernel signatures).
pub const SC_STAGE_DESCRIPTORS: u32 = 3;
/// Joint segmentation and shape graphs over the range of k.
pub const SC_STAGE_SEGMENTATION: u32 = 4;
/// Spectral graph matching.
pub const SC_STAGE_MATCHING: u32 = 5;
/// Symmetry breaking into a one-to-one region correspondence.
pub const SC_STAGE_SYMMETRY_BREAKING: u32 = 6;
/// The point-to-point map (functional map and its refinement; `sc_pointwise_map` only).
pub const SC_STAGE_POINTWISE_MAP: u32 = 7;
/// Simplifying a dense shape to its proxy (above `proxy_above` vertices) or refining a
/// low-poly mesh (below `refine_below`), and bringing the answers back to every input vertex:
/// the first and the last stage on that path (`sc_correspondence_working` says which side
/// ran on what).
pub const SC_STAGE_PROXY: u32 = 8;
/// Carrying data from A to B (`sc_surface_map_new`).
pub const SC_STAGE_TRANSFER: u32 = 9;
/// Reading a shape file and repairing the shape (front ends that read files as part of a
/// job; `sc_shape_read` itself takes no callback).
pub const SC_STAGE_READING: u32 = 10;

/// Progress callback: called on the calling thread with a stage (`SC_STAGE_*`) and the
/// fraction of that stage done (0 to 1). Return `false` to cancel: the call then returns
/// `SC_STATUS_CANCELLED` promptly. `userdata` is passed through untouched.
pub type ScProgressCallback =
    Option<unsafe extern "C" fn(userdata: *mut c_void, stage: u32, fraction: f32) -> bool>;

/// The version string, e.g. `"0.1.0"` (static; never free it).
#[no_mangle]
pub extern "C" fn sc_version() -> *const c_char {
    concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr().cast()
}

/// Major version of the loaded library (compare with `SC_VERSION_MAJOR`).
#[no_mangle]
pub extern "C" fn sc_version_major() -> u32 {
    SC_VERSION_MAJOR
}

/// Minor version of the loaded library.
#[no_mangle]
pub extern "C" fn sc_version_minor() -> u32 {
    SC_VERSION_MINOR
}

/// Patch version of the loaded library.
#[no_mangle]
pub extern "C" fn sc_version_patch() -> u32 {
    SC_VERSION_PATCH
}

/// ABI version of the loaded library (compare with `SC_ABI_VERSION`).
#[no_mangle]
pub extern "C" fn sc_abi_version() -> u32 {
    SC_ABI_VERSION
}

/// Adapts the C callback to [`crate::Progress`].
struct CallbackProgress {
    callback: ScProgressCallback,
    userdata: *mut c_void,
}

impl crate::Progress for CallbackProgress {
    fn report(&mut self, stage: crate::Stage, fraction: f32) -> bool {
        match self.callback {
            // SAFETY: the caller of sc_match/sc_symmetry_detect/sc_pointwise_map promised a
            // valid callback for the duration of the call; it gets back its own userdata.
            Some(callback) => unsafe { callback(self.userdata, stage as u32, fraction) },
            None => true,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_version_constants_match_cargo_toml() {
        let parse = |s: &str| s.parse::<u32>().unwrap();
        assert_eq!(SC_VERSION_MAJOR, parse(env!("CARGO_PKG_VERSION_MAJOR")));
        assert_eq!(SC_VERSION_MINOR, parse(env!("CARGO_PKG_VERSION_MINOR")));
        assert_eq!(SC_VERSION_PATCH, parse(env!("CARGO_PKG_VERSION_PATCH")));
        let version = unsafe { std::ffi::CStr::from_ptr(sc_version()) };
        assert_eq!(version.to_str().unwrap(), env!("CARGO_PKG_VERSION"));
    }

    #[test]
    fn stage_numbers_match_the_rust_stages() {
        use crate::Stage;
        assert_eq!(SC_STAGE_LAPLACIAN, Stage::Laplacian as u32);
        assert_eq!(SC_STAGE_EIGENBASIS, Stage::Eigenbasis as u32);
        assert_eq!(SC_STAGE_DESCRIPTORS, Stage::Descriptors as u32);
        assert_eq!(SC_STAGE_SEGMENTATION, Stage::Segmentation as u32);
        assert_eq!(SC_STAGE_MATCHING, Stage::Matching as u32);
        assert_eq!(SC_STAGE_SYMMETRY_BREAKING, Stage::SymmetryBreaking as u32);
        assert_eq!(SC_STAGE_POINTWISE_MAP, Stage::PointwiseMap as u32);
        assert_eq!(SC_STAGE_PROXY, Stage::Proxy as u32);
        assert_eq!(SC_STAGE_TRANSFER, Stage::Transfer as u32);
        assert_eq!(SC_STAGE_READING, Stage::Reading as u32);
    }

    /// The handles' thread-safety promises in the header rest on these.
    #[test]
    fn handles_are_send_and_sync() {
        fn check<T: Send + Sync>() {}
        check::<ScShape>();
        check::<ScParams>();
        check::<ScCorrespondence>();
        check::<ScSymmetry>();
        check::<ScPointwise>();
        check::<ScSurfaceMap>();
    }
}
