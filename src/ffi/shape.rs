//! Shapes: from the caller's arrays, from a file, or generated.

use std::ffi::c_char;

use super::boundary::{
    boundary, boundary_value, check_out, free_handle, give_handle, handle, input_slice, input_str,
    write_output, Failure, FfiResult, ScStatus,
};
use crate::shape::Repairs;
use crate::synth::{self, FigureKind, FigureSpec, Proportions};
use crate::{ReadAs, Shape, ShapeKind};

/// A shape: a triangle mesh or a point cloud, validated. Immutable after creation: one
/// handle may be used from several threads at once (e.g. in concurrent `sc_match` calls).
/// Free it with `sc_shape_free`.
pub struct ScShape {
    pub(crate) shape: Shape,
}

fn points_from<T: Copy + Into<f64>>(xyz: &[T]) -> Vec<[f64; 3]> {
    xyz.chunks_exact(3)
        .map(|p| [p[0].into(), p[1].into(), p[2].into()])
        .collect()
}

unsafe fn xyz_input<'a, T>(xyz: *const T, n_vertices: usize) -> FfiResult<&'a [T]> {
    let len = n_vertices
        .checked_mul(3)
        .ok_or_else(|| Failure::invalid(format!("n_vertices = {n_vertices} is too large")))?;
    input_slice(xyz, len, "xyz")
}

/// Repair flags of the `*_repaired` constructors: weld coincident vertices (seams,
/// triangle soups).
pub const SC_REPAIR_WELD: u32 = 1;
/// Repair flag: leave out small loose pieces (scan debris) and separate objects (pieces not
/// joined to the largest one: a prop beside the figure).
pub const SC_REPAIR_DEBRIS: u32 = 2;
/// Repair flag: leave out far vertices and a point cloud's isolated points.
pub const SC_REPAIR_OUTLIERS: u32 = 4;
/// Repair flag: join a mesh's pieces that come close, for matching (no face is added;
/// `Repairs::join_gap`).
pub const SC_REPAIR_JOIN: u32 = 8;
/// Every repair (what `sc_shape_new_mesh`, `sc_shape_new_point_cloud` and `sc_shape_read`
/// make).
pub const SC_REPAIR_ALL: u32 =
    SC_REPAIR_WELD | SC_REPAIR_DEBRIS | SC_REPAIR_OUTLIERS | SC_REPAIR_JOIN;
/// No repair: the shape is used as given.
pub const SC_REPAIR_NONE: u32 = 0;

/// The repairs of `flags` (`SC_REPAIR_*`) with the default tolerances.
fn repairs_of(flags: u32) -> Result<Repairs, Failure> {
    if flags & !SC_REPAIR_ALL != 0 {
        return Err(Failure::invalid(format!(
            "repair flags {flags:#x}: only SC_REPAIR_WELD (1), SC_REPAIR_DEBRIS (2), SC_REPAIR_OUTLIERS (4) and SC_REPAIR_JOIN (8) exist"
        )));
    }
    let default = Repairs::default();
    let on = |flag: u32| flags & flag != 0;
    Ok(Repairs {
        weld_tolerance: if on(SC_REPAIR_WELD) {
            default.weld_tolerance
        } else {
            0.0
        },
        debris_fraction: if on(SC_REPAIR_DEBRIS) {
            default.debris_fraction
        } else {
            0.0
        },
        join_gap: if on(SC_REPAIR_JOIN) {
            default.join_gap
        } else {
            0.0
        },
        outliers: on(SC_REPAIR_OUTLIERS),
        ..default
    })
}

unsafe fn new_mesh<T: Copy + Into<f64>>(
    xyz: *const T,
    n_vertices: usize,
    triangles: *const u32,
    n_triangles: usize,
    out_shape: *mut *mut ScShape,
) -> ScStatus {
    new_mesh_repaired(
        xyz,
        n_vertices,
        triangles,
        n_triangles,
        SC_REPAIR_ALL,
        out_shape,
    )
}

unsafe fn new_mesh_repaired<T: Copy + Into<f64>>(
    xyz: *const T,
    n_vertices: usize,
    triangles: *const u32,
    n_triangles: usize,
    repairs: u32,
    out_shape: *mut *mut ScShape,
) -> ScStatus {
    boundary(|| {
        check_out(out_shape, "out_shape")?;
        let xyz = xyz_input(xyz, n_vertices)?;
        let len = n_triangles
            .checked_mul(3)
            .ok_or_else(|| Failure::invalid(format!("n_triangles = {n_triangles} is too large")))?;
        let corners = input_slice(triangles, len, "triangles")?;
        let triangles: Vec<Vec<u32>> = corners.chunks_exact(3).map(<[u32]>::to_vec).collect();
        let shape = Shape::mesh_with(points_from(xyz), &triangles, &repairs_of(repairs)?)?;
        give_handle(out_shape, ScShape { shape })
    })
}

unsafe fn new_point_cloud<T: Copy + Into<f64>>(
    xyz: *const T,
    n_points: usize,
    repairs: u32,
    out_shape: *mut *mut ScShape,
) -> ScStatus {
    boundary(|| {
        check_out(out_shape, "out_shape")?;
        let xyz = xyz_input(xyz, n_points)?;
        let shape = Shape::point_cloud_with(points_from(xyz), &repairs_of(repairs)?)?;
        give_handle(out_shape, ScShape { shape })
    })
}

/// A triangle mesh from `n_vertices` points `xyz = x0 y0 z0 x1 y1 z1 ...` (doubles, packed,
/// 3 per vertex) and `n_triangles` triangles `triangles = a0 b0 c0 a1 ...` (0-based vertex
/// indices, 3 per triangle). Both arrays are copied; the caller keeps ownership.
///
/// Errors: `SC_STATUS_NON_FINITE_COORDINATE`, `SC_STATUS_FACE_INDEX_OUT_OF_RANGE`,
/// `SC_STATUS_TOO_FEW_VERTICES` (fewer than 32 used vertices), `SC_STATUS_ZERO_AREA`.
/// Degenerate, duplicate or non-manifold faces and disconnected pieces are accepted and
/// reported by `sc_shape_warnings`, as are the repairs made (`SC_REPAIR_ALL`: coincident
/// vertices welded, small loose pieces and far vertices left out; every vertex keeps its
/// index, a repaired-away one takes the answer of its nearest kept vertex).
/// `sc_shape_new_mesh_repaired` chooses the repairs.
///
/// # Safety
/// `xyz` must point to `3 * n_vertices` doubles and `triangles` to `3 * n_triangles`
/// indices (either may be NULL when its count is 0); `out_shape` must be writable.
#[no_mangle]
pub unsafe extern "C" fn sc_shape_new_mesh(
    xyz: *const f64,
    n_vertices: usize,
    triangles: *const u32,
    n_triangles: usize,
    out_shape: *mut *mut ScShape,
) -> ScStatus {
    new_mesh(xyz, n_vertices, triangles, n_triangles, out_shape)
}

/// As `sc_shape_new_mesh` with single-precision coordinates (converted to double).
///
/// # Safety
/// As `sc_shape_new_mesh`, with `xyz` pointing to `3 * n_vertices` floats.
#[no_mangle]
pub unsafe extern "C" fn sc_shape_new_mesh_f32(
    xyz: *const f32,
    n_vertices: usize,
    triangles: *const u32,
    n_triangles: usize,
    out_shape: *mut *mut ScShape,
) -> ScStatus {
    new_mesh(xyz, n_vertices, triangles, n_triangles, out_shape)
}

/// A point cloud from `n_points` points `xyz = x0 y0 z0 x1 ...` (doubles, packed, copied).
/// Its Laplacian is built from local triangulations of each point's neighbourhood.
///
/// # Safety
/// `xyz` must point to `3 * n_points` doubles; `out_shape` must be writable.
#[no_mangle]
pub unsafe extern "C" fn sc_shape_new_point_cloud(
    xyz: *const f64,
    n_points: usize,
    out_shape: *mut *mut ScShape,
) -> ScStatus {
    new_point_cloud(xyz, n_points, SC_REPAIR_ALL, out_shape)
}

/// As `sc_shape_new_mesh` with the repairs `repairs` (`SC_REPAIR_*` flags or-ed together;
/// `SC_REPAIR_NONE` uses the mesh as given). Other bits: `SC_STATUS_INVALID_PARAMETER`.
///
/// # Safety
/// As `sc_shape_new_mesh`.
#[no_mangle]
pub unsafe extern "C" fn sc_shape_new_mesh_repaired(
    xyz: *const f64,
    n_vertices: usize,
    triangles: *const u32,
    n_triangles: usize,
    repairs: u32,
    out_shape: *mut *mut ScShape,
) -> ScStatus {
    new_mesh_repaired(xyz, n_vertices, triangles, n_triangles, repairs, out_shape)
}

/// As `sc_shape_new_point_cloud` with the repairs `repairs` (`SC_REPAIR_*` flags; the
/// default `SC_REPAIR_ALL` welds coincident points and leaves out far and isolated points
/// and small loose clusters).
///
/// # Safety
/// As `sc_shape_new_point_cloud`.
#[no_mangle]
pub unsafe extern "C" fn sc_shape_new_point_cloud_repaired(
    xyz: *const f64,
    n_points: usize,
    repairs: u32,
    out_shape: *mut *mut ScShape,
) -> ScStatus {
    new_point_cloud(xyz, n_points, repairs, out_shape)
}

/// As `sc_shape_read` with the repairs `repairs` (`SC_REPAIR_*` flags).
///
/// # Safety
/// As `sc_shape_read`.
#[no_mangle]
pub unsafe extern "C" fn sc_shape_read_repaired(
    path: *const c_char,
    as_point_cloud: bool,
    repairs: u32,
    out_shape: *mut *mut ScShape,
) -> ScStatus {
    boundary(|| {
        check_out(out_shape, "out_shape")?;
        let path = input_path(path, "path")?;
        let shape = Shape::read_with(
            &path,
            ReadAs::point_cloud_when(as_point_cloud),
            &repairs_of(repairs)?,
        )?;
        give_handle(out_shape, ScShape { shape })
    })
}

/// As `sc_shape_new_point_cloud` with single-precision coordinates.
///
/// # Safety
/// `xyz` must point to `3 * n_points` floats; `out_shape` must be writable.
#[no_mangle]
pub unsafe extern "C" fn sc_shape_new_point_cloud_f32(
    xyz: *const f32,
    n_points: usize,
    out_shape: *mut *mut ScShape,
) -> ScStatus {
    new_point_cloud(xyz, n_points, SC_REPAIR_ALL, out_shape)
}

/// Reads a shape from a file: OFF, OBJ, PLY (ascii or binary) or XYZ/PTS points, chosen by
/// the extension. A file without faces, or `as_point_cloud = true`, gives a point cloud.
/// `SC_STATUS_FILE_ERROR` names the file and the problem.
///
/// # Safety
/// `path` must be a NUL-terminated string (UTF-8; on Unix any bytes, as the file system
/// takes them); `out_shape` must be writable.
#[no_mangle]
pub unsafe extern "C" fn sc_shape_read(
    path: *const c_char,
    as_point_cloud: bool,
    out_shape: *mut *mut ScShape,
) -> ScStatus {
    sc_shape_read_repaired(path, as_point_cloud, SC_REPAIR_ALL, out_shape)
}

/// A path from C: any bytes on Unix (file names need not be UTF-8), UTF-8 elsewhere.
pub(super) unsafe fn input_path(ptr: *const c_char, name: &str) -> FfiResult<std::path::PathBuf> {
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        if ptr.is_null() {
            return Err(Failure::null(name));
        }
        let bytes = std::ffi::CStr::from_ptr(ptr).to_bytes();
        Ok(std::ffi::OsStr::from_bytes(bytes).into())
    }
    #[cfg(not(unix))]
    {
        input_str(ptr, name).map(std::path::PathBuf::from)
    }
}

/// A generated figure (closed mesh, for tests and demos): `kind` is `"humanoid"`,
/// `"quadruped"` or `"star3"` .. `"star8"`; `pose` 0 is the rest pose (humanoid: 0..6,
/// others 0..5); `target_vertices` in 500..200000. Every pose of a kind has the same vertex
/// order, so vertex i of one pose corresponds to vertex i of another: a ground truth.
///
/// # Safety
/// `kind` must be a NUL-terminated string; `out_shape` must be writable.
#[no_mangle]
pub unsafe extern "C" fn sc_shape_new_figure(
    kind: *const c_char,
    pose: u32,
    target_vertices: u32,
    out_shape: *mut *mut ScShape,
) -> ScStatus {
    boundary(|| {
        check_out(out_shape, "out_shape")?;
        let name = input_str(kind, "kind")?;
        let kind = FigureKind::parse(name).ok_or_else(|| {
            Failure::invalid(format!(
                "unknown figure kind `{name}`; use humanoid, quadruped or star3..star8"
            ))
        })?;
        let mesh = synth::figure(&FigureSpec {
            kind,
            pose: pose as usize,
            target_vertices: target_vertices as usize,
            proportions: Proportions::default(),
            ..Default::default()
        })?;
        let shape = Shape::mesh(mesh.vertices, &mesh.triangles)?;
        give_handle(out_shape, ScShape { shape })
    })
}

/// Frees a shape; NULL is a no-op. It drops the caller's reference: a call still using the
/// handle (freed from its progress callback, or on another thread) keeps the object alive
/// until that call returns.
///
/// # Safety
/// `shape` must be NULL or a live shape, not passed to a call afterwards.
#[no_mangle]
pub unsafe extern "C" fn sc_shape_free(shape: *mut ScShape) {
    free_handle(shape)
}

/// Number of vertices (points) of the shape, as given by the caller; 0 for NULL.
///
/// # Safety
/// `shape` must be NULL or a live shape.
#[no_mangle]
pub unsafe extern "C" fn sc_shape_n_vertices(shape: *const ScShape) -> usize {
    boundary_value(0, || Ok(handle(shape, "shape")?.shape.n_vertices()))
}

/// Number of triangles (after polygons are split; 0 for a point cloud or NULL).
///
/// # Safety
/// `shape` must be NULL or a live shape.
#[no_mangle]
pub unsafe extern "C" fn sc_shape_n_triangles(shape: *const ScShape) -> usize {
    boundary_value(0, || Ok(handle(shape, "shape")?.shape.triangles().len()))
}

/// True for a point cloud, false for a mesh (or NULL).
///
/// # Safety
/// `shape` must be NULL or a live shape.
#[no_mangle]
pub unsafe extern "C" fn sc_shape_is_point_cloud(shape: *const ScShape) -> bool {
    boundary_value(false, || {
        Ok(handle(shape, "shape")?.shape.kind() == ShapeKind::PointCloud)
    })
}

/// Copies the vertex coordinates (packed xyz, `3 * sc_shape_n_vertices` doubles) into
/// `out_xyz`, which holds `len` doubles.
///
/// # Safety
/// `shape` must be a live shape; `out_xyz` must point to `len` writable doubles.
#[no_mangle]
pub unsafe extern "C" fn sc_shape_vertices(
    shape: *const ScShape,
    out_xyz: *mut f64,
    len: usize,
) -> ScStatus {
    boundary(|| {
        let shape = handle(shape, "shape")?;
        let shape = &shape.shape;
        let flat: Vec<f64> = shape.vertices().iter().flatten().copied().collect();
        write_output(out_xyz, len, &flat, "out_xyz")
    })
}

/// Copies the triangles (`3 * sc_shape_n_triangles` indices) into `out_triangles`, which
/// holds `len` indices.
///
/// # Safety
/// `shape` must be a live shape; `out_triangles` must point to `len` writable indices.
#[no_mangle]
pub unsafe extern "C" fn sc_shape_triangles(
    shape: *const ScShape,
    out_triangles: *mut u32,
    len: usize,
) -> ScStatus {
    boundary(|| {
        let shape = handle(shape, "shape")?;
        let shape = &shape.shape;
        let flat: Vec<u32> = shape.triangles().iter().flatten().copied().collect();
        write_output(out_triangles, len, &flat, "out_triangles")
    })
}

/// What was repaired or is unusual about the shape (degenerate or non-manifold faces,
/// disconnected pieces, ...), one warning per line, as in `snprintf`: writes at most
/// `len` bytes including the terminating NUL into `buf` (which may be NULL when `len` is
/// 0) and returns the length of the whole text without the NUL, so a return value `>= len`
/// means it was truncated. Returns 0 for NULL `shape` or a shape without warnings.
///
/// # Safety
/// `shape` must be NULL or a live shape; `buf` must point to `len` writable bytes.
#[no_mangle]
pub unsafe extern "C" fn sc_shape_warnings(
    shape: *const ScShape,
    buf: *mut c_char,
    len: usize,
) -> usize {
    boundary_value(0, || {
        let shape = handle(shape, "shape")?;
        let shape = &shape.shape;
        let text: String = shape.warnings().iter().map(|w| format!("{w}\n")).collect();
        write_c_string(&text, buf, len)?;
        Ok(text.len())
    })
}

/// The repairs made to the shape (coincident vertices welded, small loose pieces, far
/// vertices or isolated points left out), one per line, as `sc_shape_warnings` (of whose
/// lines they are a part) writes them. Returns 0 for NULL `shape` or a shape used as given.
///
/// # Safety
/// `shape` must be NULL or a live shape; `buf` must point to `len` writable bytes.
#[no_mangle]
pub unsafe extern "C" fn sc_shape_repairs(
    shape: *const ScShape,
    buf: *mut c_char,
    len: usize,
) -> usize {
    boundary_value(0, || {
        let shape = handle(shape, "shape")?;
        let shape = &shape.shape;
        let text: String = shape
            .warnings()
            .iter()
            .filter(|w| w.is_repair())
            .map(|w| format!("{w}\n"))
            .collect();
        write_c_string(&text, buf, len)?;
        Ok(text.len())
    })
}

/// Writes `text` truncated to `len - 1` bytes plus a NUL into `buf` (nothing when `len` is
/// 0).
pub(crate) unsafe fn write_c_string(text: &str, buf: *mut c_char, len: usize) -> FfiResult {
    if len == 0 {
        return Ok(());
    }
    if buf.is_null() {
        return Err(Failure::null("buf"));
    }
    let n = text.len().min(len - 1);
    std::ptr::copy_nonoverlapping(text.as_ptr().cast::<c_char>(), buf, n);
    *buf.add(n) = 0;
    Ok(())
}
