//! Carrying data from A to B: `sc_surface_map_new` (where every vertex of B lands on A's
//! surface) and `sc_surface_map_transfer`.

use std::ffi::c_void;

use super::boundary::{
    boundary, boundary_value, check_out, free_handle, give_handle, handle, input_slice,
    write_output, Failure, FfiResult, ScStatus,
};
use super::correspondence::{SC_SIDE_A, SC_SIDE_B};
use super::pointwise::ScPointwise;
use super::shape::ScShape;
use super::{CallbackProgress, ScProgressCallback};
use crate::maps::surface::SurfaceMap;
use crate::transfer::TransferMode;

/// Where every vertex of B lands on A's surface: three vertices of A and their weights.
/// Immutable: one handle may be read from several threads at once. Free it with
/// `sc_surface_map_free`.
pub struct ScSurfaceMap {
    map: SurfaceMap,
}

/// Transfer mode: the weighted mean of the three vertices' values (continuous data).
pub const SC_TRANSFER_INTERPOLATE: u32 = 0;
/// Transfer mode: the value of the nearest of the three vertices (labels, ids).
pub const SC_TRANSFER_NEAREST: u32 = 1;
/// Transfer mode: skin weights (interpolated, at most `max_influences` kept, each row of B
/// scaled to sum to 1; A's values must be non-negative).
pub const SC_TRANSFER_WEIGHTS: u32 = 2;

/// The surface map of a pointwise map: for every vertex of B, a point of A's surface (the
/// vertex map smoothed over B's neighbours and projected onto A's triangles). `a` and `b`
/// must be the shapes `pointwise` was computed from, in that order: each is checked by a
/// hash of its positions and faces kept with the map. `progress` may be NULL; its stage is
/// `SC_STAGE_TRANSFER`.
///
/// Errors: `SC_STATUS_INVALID_ARGUMENT` when `a` or `b` is not the map's shape (another
/// vertex count, other positions or faces, or A and B swapped), `SC_STATUS_CANCELLED`.
///
/// # Safety
/// `a`, `b`, `pointwise` must be live; `progress` NULL or a function safe to call with
/// `userdata`; `out_map` writable.
#[no_mangle]
pub unsafe extern "C" fn sc_surface_map_new(
    a: *const ScShape,
    b: *const ScShape,
    pointwise: *const ScPointwise,
    progress: ScProgressCallback,
    userdata: *mut c_void,
    out_map: *mut *mut ScSurfaceMap,
) -> ScStatus {
    boundary(|| {
        check_out(out_map, "out_map")?;
        let a = handle(a, "a")?;
        let a = &a.shape;
        let b = handle(b, "b")?;
        let b = &b.shape;
        let result = handle(pointwise, "pointwise")?;
        let result = &result.result;
        let n_a = result.regions.graph_a.labels.len();
        if a.n_vertices() != n_a || b.n_vertices() != result.map.p2p_ba.len() {
            return Err(Failure::invalid(format!(
                "the shapes have {} and {} vertices, the map was computed for {} and {}",
                a.n_vertices(),
                b.n_vertices(),
                n_a,
                result.map.p2p_ba.len()
            )));
        }
        result
            .check_shapes(a, b)
            .map_err(|e| Failure::invalid(e.to_string()))?;
        let mut progress = CallbackProgress {
            callback: progress,
            userdata,
        };
        let map = SurfaceMap::from_vertex_map(a, b, &result.map.p2p_ba, &mut progress)?;
        give_handle(out_map, ScSurfaceMap { map })
    })
}

/// Frees a surface map; NULL is a no-op. It drops the caller's reference: a call still using the
/// handle (freed from its progress callback, or on another thread) keeps the object alive
/// until that call returns.
///
/// # Safety
/// `map` must be NULL or live, not passed to a call afterwards.
#[no_mangle]
pub unsafe extern "C" fn sc_surface_map_free(map: *mut ScSurfaceMap) {
    free_handle(map)
}

/// Number of vertices of one side (`SC_SIDE_A` or `SC_SIDE_B`); 0 for NULL or a bad side.
///
/// # Safety
/// `map` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn sc_surface_map_n_vertices(map: *const ScSurfaceMap, side: u32) -> usize {
    boundary_value(0, || {
        let map = handle(map, "map")?;
        let map = &map.map;
        match side {
            SC_SIDE_A => Ok(map.n_vertices_a),
            SC_SIDE_B => Ok(map.points.len()),
            _ => Err(Failure::invalid(format!(
                "side must be SC_SIDE_A (0) or SC_SIDE_B (1), got {side}"
            ))),
        }
    })
}

/// Copies where every vertex of B lands: three vertices of A per vertex of B into
/// `out_vertices` and their weights (summing to 1, heaviest first) into `out_weights`, each
/// of `len` = 3 x `sc_surface_map_n_vertices(map, SC_SIDE_B)` elements.
///
/// # Safety
/// `map` must be live; each output must point to `len` writable elements.
#[no_mangle]
pub unsafe extern "C" fn sc_surface_map_points(
    map: *const ScSurfaceMap,
    out_vertices: *mut u32,
    out_weights: *mut f64,
    len: usize,
) -> ScStatus {
    boundary(|| {
        let map = handle(map, "map")?;
        let map = &map.map;
        let vertices: Vec<u32> = map.points.iter().flat_map(|p| p.vertices).collect();
        let weights: Vec<f64> = map.points.iter().flat_map(|p| p.weights).collect();
        write_output(out_vertices, len, &vertices, "out_vertices")?;
        write_output(out_weights, len, &weights, "out_weights")
    })
}

/// Copies, for every vertex of B, the vertex of A whose value `SC_TRANSFER_NEAREST` takes
/// (`sc_surface_map_n_vertices(map, SC_SIDE_B)` values) into `out_vertices` of `len`
/// elements: data of any type (64-bit ids, strings) is carried exactly by indexing it.
///
/// # Safety
/// `map` must be live; `out_vertices` must point to `len` writable elements.
#[no_mangle]
pub unsafe extern "C" fn sc_surface_map_nearest(
    map: *const ScSurfaceMap,
    out_vertices: *mut u32,
    len: usize,
) -> ScStatus {
    boundary(|| {
        let map = handle(map, "map")?;
        let nearest: Vec<u32> = map.map.points.iter().map(|p| p.nearest()).collect();
        write_output(out_vertices, len, &nearest, "out_vertices")
    })
}

/// Carries `values_a` (A's vertices x `channels`, row-major, `n_values` elements) to B's
/// vertices by `mode` (`SC_TRANSFER_*`; `max_influences` is used by `SC_TRANSFER_WEIGHTS`
/// only, 0 for no limit), into `out_values_b` of `len` = B's vertices x `channels` elements.
///
/// Errors: `SC_STATUS_INVALID_ARGUMENT` for an unknown mode; `SC_STATUS_INVALID_PARAMETER`
/// for a wrong length or count of channels, a value that is not finite or a negative skin
/// weight (`sc_last_error` names the vertex and channel); `SC_STATUS_BUFFER_TOO_SMALL`.
///
/// # Safety
/// `map` must be live; `values_a` must point to `n_values` readable elements and
/// `out_values_b` to `len` writable ones.
#[no_mangle]
pub unsafe extern "C" fn sc_surface_map_transfer(
    map: *const ScSurfaceMap,
    values_a: *const f64,
    n_values: usize,
    channels: usize,
    mode: u32,
    max_influences: u32,
    out_values_b: *mut f64,
    len: usize,
) -> ScStatus {
    boundary(|| {
        let map = handle(map, "map")?;
        let map = &map.map;
        let values = input_slice(values_a, n_values, "values_a")?;
        let mode = transfer_mode(mode, max_influences)?;
        let out = map.transfer(values, channels, mode)?;
        write_output(out_values_b, len, &out, "out_values_b")
    })
}

/// Carries per-corner values of A's triangles (texture coordinates) to the corners of B's
/// triangles, seams kept: a triangle of B never spans two of A's islands (see the Rust
/// `SurfaceMap::transfer_corners`). `faces_a` (`faces_a_len` = 3 x A's triangles, vertex
/// indices of `a`) must be the triangles `a` was made from; `corner_values_a` holds
/// `channels` values per corner of each, row-major (`n_values` = `faces_a_len` x
/// `channels`); `faces_b` (`faces_b_len` = 3 x B's triangles) index B's vertices; the
/// result, `channels` values per corner of B's triangles, goes to `out_values_b` of `len` =
/// `faces_b_len` x `channels` elements.
///
/// Errors: `SC_STATUS_INVALID_ARGUMENT` for a face length that is not a multiple of 3;
/// `SC_STATUS_INVALID_PARAMETER` for sizes that do not fit, vertex indices out of range,
/// values that are not finite, `a` not the map's shape A (checked by a hash of its
/// positions and faces), a point cloud `a`, or `faces_a` empty or not `a`'s triangles (all
/// of them; a face with a repeated corner is passed over); `SC_STATUS_BUFFER_TOO_SMALL`.
///
/// # Safety
/// `map` and `a` must be live; each input must point to its length of readable elements and
/// `out_values_b` to `len` writable ones.
#[no_mangle]
pub unsafe extern "C" fn sc_surface_map_transfer_corners(
    map: *const ScSurfaceMap,
    a: *const ScShape,
    faces_a: *const u32,
    faces_a_len: usize,
    corner_values_a: *const f64,
    n_values: usize,
    faces_b: *const u32,
    faces_b_len: usize,
    channels: usize,
    out_values_b: *mut f64,
    len: usize,
) -> ScStatus {
    boundary(|| {
        let map = handle(map, "map")?;
        let map = &map.map;
        let a = handle(a, "a")?;
        let a = &a.shape;
        let faces_a = triangles(input_slice(faces_a, faces_a_len, "faces_a")?, "faces_a")?;
        let faces_b = triangles(input_slice(faces_b, faces_b_len, "faces_b")?, "faces_b")?;
        let values = input_slice(corner_values_a, n_values, "corner_values_a")?;
        let out = map.transfer_corners((a, &faces_a), values, &faces_b, channels)?;
        write_output(out_values_b, len, &out, "out_values_b")
    })
}

/// Flat vertex indices as triangles.
fn triangles(flat: &[u32], name: &str) -> FfiResult<Vec<[u32; 3]>> {
    if !flat.len().is_multiple_of(3) {
        return Err(Failure::invalid(format!(
            "`{name}` has {} indices, not a multiple of 3",
            flat.len()
        )));
    }
    Ok(flat.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect())
}

fn transfer_mode(mode: u32, max_influences: u32) -> FfiResult<TransferMode> {
    match mode {
        SC_TRANSFER_INTERPOLATE => Ok(TransferMode::Interpolate),
        SC_TRANSFER_NEAREST => Ok(TransferMode::Nearest),
        SC_TRANSFER_WEIGHTS => Ok(TransferMode::Weights {
            max_influences: max_influences as usize,
        }),
        _ => Err(Failure::invalid(format!(
            "mode must be SC_TRANSFER_INTERPOLATE (0), SC_TRANSFER_NEAREST (1) or \
             SC_TRANSFER_WEIGHTS (2), got {mode}"
        ))),
    }
}
