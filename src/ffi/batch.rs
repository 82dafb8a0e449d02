//! Collections: the per-shape and per-pair jobs of a batch (`shapecorr batch`, Python's
//! `shapecorr.batch` locally or on a Dask cluster), each returning its log line as JSON
//! (docs/collections.md). The batch's own loop, its log and its scheduling are the
//! caller's.

use std::ffi::{c_char, CString};

use super::boundary::{
    boundary, boundary_value, check_out, free_handle, give_handle, handle, input_str, Failure,
    FfiResult, ScStatus,
};
use super::params::ScParams;
use super::shape::input_path;
use crate::collection::{
    read_pairs, Batch, BatchSettings, OutputFolder, Outputs, Prepared, Reading,
    DEFAULT_MEMORY_BYTES,
};
use crate::options::Options;

/// `sc_batch_new` flag: point-to-point maps too (as `sc_pointwise_map`), each written to
/// `OUT_DIR/maps/A--B.u32` (a vertex of A for every vertex of B, little-endian u32).
pub const SC_BATCH_MAPS: u32 = 1;
/// `sc_batch_new` flag: read every file as a point cloud.
pub const SC_BATCH_POINTS: u32 = 2;
/// `sc_batch_new` flag: read the files as given, without the default repairs.
pub const SC_BATCH_NO_REPAIR: u32 = 4;

/// The settings of a batch and the shapes it keeps prepared in memory. One per process is
/// enough: it may be used from several threads at once. Free it with `sc_batch_free`.
pub struct ScBatch {
    batch: Batch,
}

/// A batch log line: a shape's (`sc_batch_prepare`) or a pair's (`sc_batch_match`). Free
/// it with `sc_batch_record_free`.
pub struct ScBatchRecord {
    json: CString,
    ok: bool,
}

/// A batch with these options (`params` may be NULL: the defaults), eigenbases cached in
/// `cache_dir` (created if missing; shared by every process of the batch), and `flags`
/// (`SC_BATCH_*`).
///
/// Errors: `SC_STATUS_INVALID_PARAMETER`, `SC_STATUS_FILE_ERROR` (the cache folder cannot be
/// made), `SC_STATUS_INVALID_ARGUMENT` (an unknown flag).
///
/// # Safety
/// `params` NULL or live; `cache_dir` a NUL-terminated path; `out_batch` writable.
#[no_mangle]
pub unsafe extern "C" fn sc_batch_new(
    params: *const ScParams,
    cache_dir: *const c_char,
    flags: u32,
    out_batch: *mut *mut ScBatch,
) -> ScStatus {
    boundary(|| {
        check_out(out_batch, "out_batch")?;
        let options = if params.is_null() {
            Options::default()
        } else {
            handle(params, "params")?.options.clone()
        };
        let cache_dir = input_path(cache_dir, "cache_dir")?;
        if flags & !(SC_BATCH_MAPS | SC_BATCH_POINTS | SC_BATCH_NO_REPAIR) != 0 {
            return Err(Failure::invalid(format!("unknown batch flags {flags:#x}")));
        }
        let batch = Batch::new(BatchSettings {
            options,
            reading: Reading {
                points: flags & SC_BATCH_POINTS != 0,
                repair: flags & SC_BATCH_NO_REPAIR == 0,
                ..Default::default()
            },
            outputs: if flags & SC_BATCH_MAPS != 0 {
                Outputs::RegionsAndMaps
            } else {
                Outputs::Regions
            },
            cache_dir,
            memory_bytes: DEFAULT_MEMORY_BYTES,
        })?;
        give_handle(out_batch, ScBatch { batch })
    })
}

/// Frees a batch (NULL is a no-op). It drops the caller's reference: a call still using the
/// handle (freed on another thread) keeps the object alive until that call returns.
///
/// # Safety
/// `batch` NULL or live, and not passed to a call again.
#[no_mangle]
pub unsafe extern "C" fn sc_batch_free(batch: *mut ScBatch) {
    free_handle(batch);
}

/// The per-shape job: the shape in `path`, named `name` in the batch, read, its proxy built
/// when dense and its eigenbasis loaded from the cache or computed and stored. The record
/// is the line of `shapes.jsonl`: `ok`, `error` (the library's message), `computed`
/// (false: from the cache), seconds. A shape that cannot be used is a record with `ok`
/// false, not an error status.
///
/// # Safety
/// `batch` live; `name`, `path` NUL-terminated (UTF-8 name); `out_record` writable.
#[no_mangle]
pub unsafe extern "C" fn sc_batch_prepare(
    batch: *const ScBatch,
    name: *const c_char,
    path: *const c_char,
    out_record: *mut *mut ScBatchRecord,
) -> ScStatus {
    boundary(|| {
        check_out(out_record, "out_record")?;
        let batch = handle(batch, "batch")?;
        let batch = &batch.batch;
        let name = input_str(name, "name")?;
        let path = input_path(path, "path")?;
        let (_, record) = batch.prepare(name, &path);
        give_record(out_record, &record, record.ok)
    })
}

/// The per-pair job: the regions (and with `SC_BATCH_MAPS` the map, written under
/// `out_dir/maps/`) of shapes A and B, each prepared as `sc_batch_prepare` (from memory or
/// the cache). The record is the line of `pairs.jsonl`: names, `ok`, `error`, `k`, the
/// regions of every vertex, the matches, `confidence`, `map` (the file, relative to
/// `out_dir`), seconds. A failed pair is a record with `ok` false and the reason, not an
/// error status.
///
/// # Safety
/// `batch` live; the strings NUL-terminated (UTF-8 names); `out_record` writable.
#[no_mangle]
pub unsafe extern "C" fn sc_batch_match(
    batch: *const ScBatch,
    name_a: *const c_char,
    path_a: *const c_char,
    name_b: *const c_char,
    path_b: *const c_char,
    out_dir: *const c_char,
    out_record: *mut *mut ScBatchRecord,
) -> ScStatus {
    boundary(|| {
        check_out(out_record, "out_record")?;
        let batch = handle(batch, "batch")?;
        let batch = &batch.batch;
        let name_a = input_str(name_a, "name_a")?;
        let name_b = input_str(name_b, "name_b")?;
        let path_a = input_path(path_a, "path_a")?;
        let path_b = input_path(path_b, "path_b")?;
        let out_dir = input_path(out_dir, "out_dir")?;
        let a: Prepared = batch.prepare(name_a, &path_a).0;
        let b: Prepared = batch.prepare(name_b, &path_b).0;
        let record = batch.match_pair((name_a, &a), (name_b, &b), &out_dir);
        give_record(out_record, &record, record.ok)
    })
}

fn give_record(
    out_record: *mut *mut ScBatchRecord,
    record: &impl serde::Serialize,
    ok: bool,
) -> FfiResult {
    let json = serde_json::to_string(record).map_err(|e| Failure::invalid(e.to_string()))?;
    let json = CString::new(json).map_err(|e| Failure::invalid(e.to_string()))?;
    // SAFETY: `out_record` was checked writable by the caller's `check_out`.
    unsafe { give_handle(out_record, ScBatchRecord { json, ok }) }
}

/// The record as one line of JSON (UTF-8, no newline). The string belongs to `record`:
/// valid until it is freed; never free it. NULL for NULL.
///
/// # Safety
/// `record` NULL or live.
#[no_mangle]
pub unsafe extern "C" fn sc_batch_record_json(record: *const ScBatchRecord) -> *const c_char {
    boundary_value(std::ptr::null(), || {
        Ok(handle(record, "record")?.json.as_ptr())
    })
}

/// Whether the record's job succeeded (false for NULL).
///
/// # Safety
/// `record` NULL or live.
#[no_mangle]
pub unsafe extern "C" fn sc_batch_record_ok(record: *const ScBatchRecord) -> bool {
    boundary_value(false, || Ok(handle(record, "record")?.ok))
}

/// Frees a record (NULL is a no-op). It drops the caller's reference: a call still using the
/// handle (freed on another thread) keeps the object alive until that call returns.
///
/// # Safety
/// `record` NULL or live, and not passed to a call again.
#[no_mangle]
pub unsafe extern "C" fn sc_batch_record_free(record: *mut ScBatchRecord) {
    free_handle(record);
}

/// A batch's output folder, locked by this process (`sc_batch_open_folder`) until it is
/// freed with `sc_batch_folder_free` (or the process ends, also when killed).
pub struct ScBatchFolder {
    _folder: OutputFolder,
}

/// Opens the output folder `out_dir` (created if missing) for a batch with `batch`'s
/// settings, as `shapecorr batch --out` does: locks it, refuses a folder another run holds
/// or one whose `batch.json` records other settings, and records them on a first run. Keep
/// the folder until the batch's log is written, then free it.
///
/// Errors: `SC_STATUS_FILE_ERROR` (held by another run, other settings, not writable).
///
/// # Safety
/// `batch` live; `out_dir` a NUL-terminated path; `out_folder` writable.
#[no_mangle]
pub unsafe extern "C" fn sc_batch_open_folder(
    batch: *const ScBatch,
    out_dir: *const c_char,
    out_folder: *mut *mut ScBatchFolder,
) -> ScStatus {
    boundary(|| {
        check_out(out_folder, "out_folder")?;
        let batch = &handle(batch, "batch")?.batch;
        let out_dir = input_path(out_dir, "out_dir")?;
        let folder = OutputFolder::open(&out_dir, batch.settings())?;
        give_handle(out_folder, ScBatchFolder { _folder: folder })
    })
}

/// Releases a folder's lock (NULL is a no-op).
///
/// # Safety
/// `folder` NULL or live, and not used again.
#[no_mangle]
pub unsafe extern "C" fn sc_batch_folder_free(folder: *mut ScBatchFolder) {
    free_handle(folder);
}

/// The pairs of the pair file at `path` as a record whose JSON is an array of
/// `{"a", "b", "category", "line"}` (the format is in docs/collections.md: tab-separated
/// fields, names may hold spaces).
///
/// Errors: `SC_STATUS_FILE_ERROR` (unreadable, or a malformed line: the message names it).
///
/// # Safety
/// `path` a NUL-terminated path; `out_record` writable.
#[no_mangle]
pub unsafe extern "C" fn sc_batch_read_pairs(
    path: *const c_char,
    out_record: *mut *mut ScBatchRecord,
) -> ScStatus {
    boundary(|| {
        check_out(out_record, "out_record")?;
        let path = input_path(path, "path")?;
        let pairs = read_pairs(&path)?;
        give_record(out_record, &pairs, true)
    })
}
