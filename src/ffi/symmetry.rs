//! Symmetry detection for one shape: `sc_symmetry_detect` and the result's accessors.

use std::ffi::c_void;

use super::boundary::{
    boundary, boundary_value, check_out, free_handle, give_handle, handle, write_output, FfiResult,
    ScStatus,
};
use super::correspondence::rgba;
use super::params::{params_or_default, ScParams};
use super::shape::ScShape;
use super::{CallbackProgress, ScProgressCallback};
use crate::pipeline::Symmetry;

/// The result of `sc_symmetry_detect`. Immutable: one handle may be read from several
/// threads at once. Free it with `sc_symmetry_free`.
pub struct ScSymmetry {
    pub(crate) result: Symmetry,
}

/// Symmetric regions of one shape, found by matching the shape to itself: its regions and
/// groups of mutually symmetric regions (the limbs of a star, left and right limbs of a
/// body). Arguments and errors as `sc_match`.
///
/// # Safety
/// As `sc_match`.
#[no_mangle]
pub unsafe extern "C" fn sc_symmetry_detect(
    shape: *const ScShape,
    params: *const ScParams,
    progress: ScProgressCallback,
    userdata: *mut c_void,
    out_symmetry: *mut *mut ScSymmetry,
) -> ScStatus {
    boundary(|| {
        check_out(out_symmetry, "out_symmetry")?;
        let shape = handle(shape, "shape")?;
        let shape = &shape.shape;
        let params = params_or_default(params);
        let mut progress = CallbackProgress {
            callback: progress,
            userdata,
        };
        let result = Symmetry::detect(shape, &params, &mut progress)?;
        give_handle(out_symmetry, ScSymmetry { result })
    })
}

/// Frees a symmetry result; NULL is a no-op. It drops the caller's reference: a call still using the
/// handle (freed from its progress callback, or on another thread) keeps the object alive
/// until that call returns.
///
/// # Safety
/// `symmetry` must be NULL or live, not passed to a call afterwards.
#[no_mangle]
pub unsafe extern "C" fn sc_symmetry_free(symmetry: *mut ScSymmetry) {
    free_handle(symmetry)
}

unsafe fn count(s: *const ScSymmetry, f: impl FnOnce(&Symmetry) -> usize) -> usize {
    boundary_value(0, || -> FfiResult<usize> {
        Ok(f(&handle(s, "symmetry")?.result))
    })
}

/// Number of vertices of the shape (0 for NULL).
///
/// # Safety
/// `symmetry` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn sc_symmetry_n_vertices(symmetry: *const ScSymmetry) -> usize {
    count(symmetry, |s| s.graph.labels.len())
}

/// Number of regions.
///
/// # Safety
/// `symmetry` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn sc_symmetry_n_regions(symmetry: *const ScSymmetry) -> usize {
    count(symmetry, |s| s.graph.n_nodes())
}

/// Number of groups (a region without a symmetric partner is a group of its own).
///
/// # Safety
/// `symmetry` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn sc_symmetry_n_groups(symmetry: *const ScSymmetry) -> usize {
    count(symmetry, |s| s.groups.len())
}

/// Copies the region of every vertex (`sc_symmetry_n_vertices` values) into `out_regions`.
///
/// # Safety
/// `symmetry` must be live; `out_regions` must point to `len` writable elements.
#[no_mangle]
pub unsafe extern "C" fn sc_symmetry_regions(
    symmetry: *const ScSymmetry,
    out_regions: *mut u32,
    len: usize,
) -> ScStatus {
    boundary(|| {
        let s = handle(symmetry, "symmetry")?;
        let s = &s.result;
        write_output(out_regions, len, &s.graph.labels, "out_regions")
    })
}

/// Copies the group of every region (`sc_symmetry_n_regions` values, groups numbered from
/// 0) into `out_groups`: regions with the same group are symmetric copies of each other.
///
/// # Safety
/// `symmetry` must be live; `out_groups` must point to `len` writable elements.
#[no_mangle]
pub unsafe extern "C" fn sc_symmetry_region_groups(
    symmetry: *const ScSymmetry,
    out_groups: *mut u32,
    len: usize,
) -> ScStatus {
    boundary(|| {
        let s = handle(symmetry, "symmetry")?;
        let s = &s.result;
        let mut group_of = vec![0u32; s.graph.n_nodes()];
        for (g, members) in s.groups.iter().enumerate() {
            for &r in members {
                group_of[r as usize] = g as u32;
            }
        }
        write_output(out_groups, len, &group_of, "out_groups")
    })
}

/// Copies a colour per vertex as RGBA bytes (`4 * sc_symmetry_n_vertices` values): the
/// regions of a group of two or more share a colour, the others are dark grey.
///
/// # Safety
/// `symmetry` must be live; `out_rgba` must point to `len` writable bytes.
#[no_mangle]
pub unsafe extern "C" fn sc_symmetry_colors(
    symmetry: *const ScSymmetry,
    out_rgba: *mut u8,
    len: usize,
) -> ScStatus {
    boundary(|| {
        let s = handle(symmetry, "symmetry")?;
        let s = &s.result;
        write_output(out_rgba, len, &rgba(&s.vertex_colors()), "out_rgba")
    })
}
