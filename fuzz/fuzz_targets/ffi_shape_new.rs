//! The C API's shape constructors (`sc_shape_new_mesh`, `_f32`, `_repaired`,
//! `sc_shape_new_point_cloud`, `_f32`, `_repaired`) called with buffers decoded from the
//! input and any counts that keep the pointers valid: the buffer's own, fewer, zero with
//! NULL, a NULL buffer with a count, counts whose byte size overflows, misaligned buffers, a
//! NULL out-parameter. Never `SC_STATUS_PANIC`; the out-parameter is written only on
//! success; a shape made answers its queries consistently and is freed.
//!
//! Input: `how, xyz_count, tri_count: u8, repairs: u32`, then a shape
//! (`shapecorr_fuzz::decode_shape`, triangles). `how % 6` picks the constructor, `how & 8`
//! a NULL out-parameter, `how & 16` misaligned buffers.
#![no_main]

use std::ffi::c_char;
use std::ptr::{null, null_mut};

use libfuzzer_sys::fuzz_target;
use shapecorr::ffi::*;
use shapecorr_fuzz::{decode_shape, Bytes};

/// The count and pointer passed for `items` (whose pointer is `ptr`), `per` values per item.
fn count<T>(choice: u8, items: usize, ptr: *const T) -> (usize, *const T) {
    match choice % 6 {
        0 => (items, ptr),
        1 => (items / 2, ptr),
        2 => (0, null()),
        3 => (items.max(1), null()),
        4 => (usize::MAX / 3 + 1, ptr),
        _ => (isize::MAX as usize / 3, ptr),
    }
}

/// `values` copied to a buffer 1 byte past 8-byte alignment, when `misaligned`.
struct Buffer<T> {
    values: Vec<T>,
    bytes: Vec<u64>,
    misaligned: bool,
}

impl<T: Copy> Buffer<T> {
    fn new(values: Vec<T>, misaligned: bool) -> Self {
        let size = std::mem::size_of_val(values.as_slice());
        let mut bytes = vec![0u64; size / 8 + 2];
        if misaligned {
            // SAFETY: `bytes` holds `size + 1` bytes and more.
            unsafe {
                let to = bytes.as_mut_ptr().cast::<u8>().add(1);
                std::ptr::copy_nonoverlapping(values.as_ptr().cast::<u8>(), to, size);
            }
        }
        Buffer {
            values,
            bytes,
            misaligned,
        }
    }
    fn ptr(&self) -> *const T {
        if self.misaligned {
            // SAFETY: in bounds of `bytes`.
            unsafe { self.bytes.as_ptr().cast::<u8>().add(1).cast() }
        } else {
            self.values.as_ptr()
        }
    }
}

unsafe fn check_shape(shape: *mut ScShape, n_vertices: usize, point_cloud: bool) {
    assert_eq!(sc_shape_n_vertices(shape), n_vertices);
    assert_eq!(sc_shape_is_point_cloud(shape), point_cloud);
    let n_triangles = sc_shape_n_triangles(shape);
    assert_eq!(n_triangles == 0, point_cloud);
    let mut xyz = vec![0.0; 3 * n_vertices];
    assert_eq!(
        sc_shape_vertices(shape, xyz.as_mut_ptr(), xyz.len()),
        ScStatus::Ok
    );
    let short = sc_shape_vertices(shape, xyz.as_mut_ptr(), xyz.len() - 1);
    assert_eq!(short, ScStatus::BufferTooSmall);
    let mut triangles = vec![0u32; 3 * n_triangles];
    let status = sc_shape_triangles(shape, triangles.as_mut_ptr(), triangles.len());
    assert_eq!(status, ScStatus::Ok);
    assert!(triangles.iter().all(|&v| (v as usize) < n_vertices));
    for text in [sc_shape_warnings, sc_shape_repairs] {
        let len = text(shape, null_mut(), 0);
        let mut buf = vec![1 as c_char; len / 2 + 1];
        assert_eq!(text(shape, buf.as_mut_ptr(), buf.len()), len);
        assert_eq!(buf[buf.len() - 1], 0);
    }
    sc_shape_free(shape);
}

fuzz_target!(|data: &[u8]| {
    let mut b = Bytes(data);
    let (how, xyz_count, tri_count, repairs) = (b.u8(), b.u8(), b.u8(), b.u32());
    let raw = decode_shape(&mut b, false);
    let n = raw.vertices.len();
    let misaligned = how & 16 != 0;
    let xyz = Buffer::new(raw.vertices.iter().flatten().copied().collect(), misaligned);
    let xyz32 = Buffer::new(xyz.values.iter().map(|&c| c as f32).collect(), misaligned);
    let corners: Vec<u32> = raw.polygons.iter().flatten().copied().collect();
    let corners = Buffer::new(corners, misaligned);
    let (n_xyz, p_xyz) = count(xyz_count, n, xyz.ptr());
    let p_xyz32 = if p_xyz.is_null() { null() } else { xyz32.ptr() };
    let (n_tri, p_tri) = count(tri_count, raw.polygons.len(), corners.ptr());
    let mut shape: *mut ScShape = null_mut();
    let out = if how & 8 != 0 { null_mut() } else { &mut shape };
    // SAFETY: every pointer is NULL or holds its count (or the count is refused before any
    // read: its byte size overflows); `out` is NULL or writable.
    unsafe {
        let status = match how % 6 {
            0 => sc_shape_new_mesh(p_xyz, n_xyz, p_tri, n_tri, out),
            1 => sc_shape_new_mesh_f32(p_xyz32, n_xyz, p_tri, n_tri, out),
            2 => sc_shape_new_mesh_repaired(p_xyz, n_xyz, p_tri, n_tri, repairs, out),
            3 => sc_shape_new_point_cloud(p_xyz, n_xyz, out),
            4 => sc_shape_new_point_cloud_f32(p_xyz32, n_xyz, out),
            _ => sc_shape_new_point_cloud_repaired(p_xyz, n_xyz, repairs, out),
        };
        assert_ne!(status, ScStatus::Panic);
        assert_eq!(status == ScStatus::Ok, !shape.is_null());
        if !shape.is_null() {
            check_shape(shape, n_xyz, how % 6 >= 3);
        }
    }
});
