//! Region correspondence between two shapes: `sc_match` and the result's accessors.

use std::ffi::{c_char, c_void};

use super::boundary::{
    boundary, boundary_value, check_out, free_handle, give_handle, handle, input_str, write_output,
    Failure, FfiResult, ScStatus,
};
use super::params::{params_or_default, ScParams};
use super::shape::ScShape;
use super::verdict::{self, VerdictText};
use super::{CallbackProgress, ScProgressCallback};
use crate::pipeline::multiresolution::{Working, WorkingKind};
use crate::pipeline::Correspondence;
use crate::regions::graph::ShapeGraph;

/// The result of `sc_match`. Immutable: one handle may be read from several threads at
/// once. Free it with `sc_correspondence_free`.
pub struct ScCorrespondence {
    pub(crate) result: Correspondence,
    /// The verdict's warning and hypothesis names, made once with the handle: what
    /// `sc_correspondence_warning` and `sc_correspondence_hypothesis` point into.
    text: VerdictText,
}

impl ScCorrespondence {
    pub(crate) fn new(result: Correspondence) -> Self {
        let text = VerdictText::new(result.verdict.as_ref());
        ScCorrespondence { result, text }
    }
}

/// Side A: the first shape given to `sc_match`.
pub const SC_SIDE_A: u32 = 0;
/// Side B: the second shape given to `sc_match`.
pub const SC_SIDE_B: u32 = 1;
/// The symmetric (many-to-many) region matches: a region may match all its symmetric
/// copies on the other shape.
pub const SC_MATCHES_SYMMETRIC: u32 = 0;
/// The one-to-one region matches after symmetry breaking (a subset of the symmetric ones;
/// empty when the option `one_to_one` is false).
pub const SC_MATCHES_ONE_TO_ONE: u32 = 1;
/// Below this confidence (`sc_correspondence_confidence`, `sc_pointwise_confidence`) an
/// answer is doubtful and has a warning (`sc_correspondence_warning`,
/// `sc_pointwise_warning`).
pub const SC_CONFIDENCE_DOUBTFUL_BELOW: f64 = 0.45;
/// The pipeline ran on the input shape itself (`sc_correspondence_working`).
pub const SC_WORKING_INPUT: u32 = 0;
/// The pipeline ran on a simplified proxy of a dense shape (options `proxy_above`,
/// `proxy_vertices`); the answers were brought back to every input vertex.
pub const SC_WORKING_PROXY: u32 = 1;
/// The pipeline ran on a refined copy of a low-poly mesh (option `refine_below`); the
/// answers were brought back to every input vertex.
pub const SC_WORKING_REFINED: u32 = 2;

/// Region correspondence between shapes `a` and `b` (meshes, point clouds or one of each):
/// eigenbases, heat kernel signatures, joint segmentation over the range of k, spectral
/// graph matching, symmetry breaking. `params` may be NULL for the defaults; `progress`
/// may be NULL; `userdata` is passed to it. The shapes are only read, so the same shapes may
/// be matched from several threads at once. The result is deterministic for given shapes
/// and parameters, whatever the number of threads.
///
/// Errors: `SC_STATUS_INVALID_PARAMETER` (checked before any work),
/// `SC_STATUS_RESOURCE_LIMIT` (the job's estimate exceeds `memory_limit_mib`,
/// `time_limit_s` or `max_vertices`, checked before any work, or it ran past
/// `time_limit_s`), `SC_STATUS_NUMERICAL_FAILURE`, `SC_STATUS_CANCELLED` (the callback
/// returned false).
///
/// # Safety
/// `a`, `b` must be live shapes, `params` NULL or live parameters not being modified,
/// `progress` NULL or a function safe to call with `userdata`; `out_correspondence`
/// writable.
#[no_mangle]
pub unsafe extern "C" fn sc_match(
    a: *const ScShape,
    b: *const ScShape,
    params: *const ScParams,
    progress: ScProgressCallback,
    userdata: *mut c_void,
    out_correspondence: *mut *mut ScCorrespondence,
) -> ScStatus {
    boundary(|| {
        check_out(out_correspondence, "out_correspondence")?;
        let a = handle(a, "a")?;
        let a = &a.shape;
        let b = handle(b, "b")?;
        let b = &b.shape;
        let params = params_or_default(params);
        let mut progress = CallbackProgress {
            callback: progress,
            userdata,
        };
        let result = Correspondence::compute(a, b, &params, &mut progress)?;
        give_handle(out_correspondence, ScCorrespondence::new(result))
    })
}

/// Frees a correspondence; NULL is a no-op. It drops the caller's reference: a call still using the
/// handle (freed from its progress callback, or on another thread) keeps the object alive
/// until that call returns.
///
/// # Safety
/// `correspondence` must be NULL or live, not passed to a call afterwards.
#[no_mangle]
pub unsafe extern "C" fn sc_correspondence_free(correspondence: *mut ScCorrespondence) {
    free_handle(correspondence)
}

fn graph(c: &ScCorrespondence, side: u32) -> FfiResult<&ShapeGraph> {
    match side {
        SC_SIDE_A => Ok(&c.result.graph_a),
        SC_SIDE_B => Ok(&c.result.graph_b),
        _ => Err(Failure::invalid(format!(
            "side must be SC_SIDE_A (0) or SC_SIDE_B (1), got {side}"
        ))),
    }
}

fn matches(c: &ScCorrespondence, kind: u32) -> FfiResult<&[(u32, u32)]> {
    match kind {
        SC_MATCHES_SYMMETRIC => Ok(&c.result.matches),
        SC_MATCHES_ONE_TO_ONE => Ok(&c.result.matches_one_to_one),
        _ => Err(Failure::invalid(format!(
            "kind must be SC_MATCHES_SYMMETRIC (0) or SC_MATCHES_ONE_TO_ONE (1), got {kind}"
        ))),
    }
}

unsafe fn count(
    c: *const ScCorrespondence,
    f: impl FnOnce(&ScCorrespondence) -> FfiResult<usize>,
) -> usize {
    boundary_value(0, || f(&*handle(c, "correspondence")?))
}

/// The number of joint clusters chosen (0 for NULL).
///
/// # Safety
/// `correspondence` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn sc_correspondence_k(correspondence: *const ScCorrespondence) -> u32 {
    count(correspondence, |c| Ok(c.result.k)) as u32
}

/// Number of vertices of one side (as given to `sc_match`); 0 for NULL or a bad side.
///
/// # Safety
/// `correspondence` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn sc_correspondence_n_vertices(
    correspondence: *const ScCorrespondence,
    side: u32,
) -> usize {
    count(correspondence, |c| Ok(graph(c, side)?.labels.len()))
}

/// Number of regions (shape-graph nodes) of one side; region ids run from 0 to this - 1.
///
/// # Safety
/// `correspondence` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn sc_correspondence_n_regions(
    correspondence: *const ScCorrespondence,
    side: u32,
) -> usize {
    count(correspondence, |c| Ok(graph(c, side)?.n_nodes()))
}

/// Copies the region id of every vertex of one side, in the caller's vertex order
/// (`sc_correspondence_n_vertices` values) into `out_regions` of `len` elements.
///
/// # Safety
/// `correspondence` must be live; `out_regions` must point to `len` writable elements.
#[no_mangle]
pub unsafe extern "C" fn sc_correspondence_regions(
    correspondence: *const ScCorrespondence,
    side: u32,
    out_regions: *mut u32,
    len: usize,
) -> ScStatus {
    boundary(|| {
        let c = handle(correspondence, "correspondence")?;
        let c = &*c;
        write_output(out_regions, len, &graph(c, side)?.labels, "out_regions")
    })
}

/// Number of region matches of a kind (`SC_MATCHES_SYMMETRIC` or `SC_MATCHES_ONE_TO_ONE`).
///
/// # Safety
/// `correspondence` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn sc_correspondence_n_matches(
    correspondence: *const ScCorrespondence,
    kind: u32,
) -> usize {
    count(correspondence, |c| Ok(matches(c, kind)?.len()))
}

/// Copies the matches of a kind as pairs `region_a0 region_b0 region_a1 ...`
/// (`2 * sc_correspondence_n_matches` values, sorted) into `out_pairs` of `len` elements.
///
/// # Safety
/// `correspondence` must be live; `out_pairs` must point to `len` writable elements.
#[no_mangle]
pub unsafe extern "C" fn sc_correspondence_matches(
    correspondence: *const ScCorrespondence,
    kind: u32,
    out_pairs: *mut u32,
    len: usize,
) -> ScStatus {
    boundary(|| {
        let c = handle(correspondence, "correspondence")?;
        let c = &*c;
        let flat: Vec<u32> = matches(c, kind)?
            .iter()
            .flat_map(|&(i, j)| [i, j])
            .collect();
        write_output(out_pairs, len, &flat, "out_pairs")
    })
}

/// Copies a colour per vertex of one side as RGBA bytes (`4 * sc_correspondence_n_vertices`
/// values, alpha 255) into `out_rgba` of `len` bytes: regions linked by matches of `kind`
/// share a colour on both shapes, unmatched regions are dark grey (64, 64, 64).
///
/// # Safety
/// `correspondence` must be live; `out_rgba` must point to `len` writable bytes.
#[no_mangle]
pub unsafe extern "C" fn sc_correspondence_colors(
    correspondence: *const ScCorrespondence,
    side: u32,
    kind: u32,
    out_rgba: *mut u8,
    len: usize,
) -> ScStatus {
    boundary(|| {
        let c = handle(correspondence, "correspondence")?;
        let c = &*c;
        graph(c, side)?;
        matches(c, kind)?;
        let (a, b) = c.result.vertex_colors(kind == SC_MATCHES_ONE_TO_ONE);
        let colors = if side == SC_SIDE_A { a } else { b };
        write_output(out_rgba, len, &rgba(&colors), "out_rgba")
    })
}

/// RGB colours as packed RGBA bytes with alpha 255.
pub(crate) fn rgba(colors: &[[u8; 3]]) -> Vec<u8> {
    colors
        .iter()
        .flat_map(|&[r, g, b]| [r, g, b, 255])
        .collect()
}

/// Length of each region's mean descriptor (the number of HKS times).
///
/// # Safety
/// `correspondence` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn sc_correspondence_descriptor_length(
    correspondence: *const ScCorrespondence,
) -> usize {
    count(correspondence, |c| {
        Ok(c.result.graph_a.node_descriptor.first().map_or(0, Vec::len))
    })
}

/// Copies each region's area, as a fraction of its shape's area
/// (`sc_correspondence_n_regions` values), into `out_areas` of `len` elements.
///
/// # Safety
/// `correspondence` must be live; `out_areas` must point to `len` writable elements.
#[no_mangle]
pub unsafe extern "C" fn sc_correspondence_region_areas(
    correspondence: *const ScCorrespondence,
    side: u32,
    out_areas: *mut f64,
    len: usize,
) -> ScStatus {
    boundary(|| {
        let c = handle(correspondence, "correspondence")?;
        let c = &*c;
        write_output(out_areas, len, &graph(c, side)?.node_area, "out_areas")
    })
}

/// Copies each region's mean descriptor, row by row (`n_regions * descriptor_length`
/// values), into `out_descriptors` of `len` elements.
///
/// # Safety
/// `correspondence` must be live; `out_descriptors` must point to `len` writable elements.
#[no_mangle]
pub unsafe extern "C" fn sc_correspondence_region_descriptors(
    correspondence: *const ScCorrespondence,
    side: u32,
    out_descriptors: *mut f64,
    len: usize,
) -> ScStatus {
    boundary(|| {
        let c = handle(correspondence, "correspondence")?;
        let c = &*c;
        let flat: Vec<f64> = graph(c, side)?
            .node_descriptor
            .iter()
            .flatten()
            .copied()
            .collect();
        write_output(out_descriptors, len, &flat, "out_descriptors")
    })
}

/// Number of edges of one side's shape graph (regions that touch).
///
/// # Safety
/// `correspondence` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn sc_correspondence_n_edges(
    correspondence: *const ScCorrespondence,
    side: u32,
) -> usize {
    count(correspondence, |c| Ok(graph(c, side)?.edges.len()))
}

/// Copies one side's graph edges as pairs `r0 s0 r1 s1 ...` (`2 * sc_correspondence_n_edges`
/// values, each pair with r < s) into `out_edges` of `len` elements.
///
/// # Safety
/// `correspondence` must be live; `out_edges` must point to `len` writable elements.
#[no_mangle]
pub unsafe extern "C" fn sc_correspondence_edges(
    correspondence: *const ScCorrespondence,
    side: u32,
    out_edges: *mut u32,
    len: usize,
) -> ScStatus {
    boundary(|| {
        let c = handle(correspondence, "correspondence")?;
        let c = &*c;
        let flat: Vec<u32> = graph(c, side)?
            .edges
            .iter()
            .flat_map(|&(i, j)| [i, j])
            .collect();
        write_output(out_edges, len, &flat, "out_edges")
    })
}

/// Seconds spent in a stage of the call: `stage` is one of `"eigenbasis_a"`,
/// `"eigenbasis_b"`, `"descriptors"`, `"segmentation"`, `"matching"`, `"one_to_one"`,
/// `"total"`.
///
/// # Safety
/// `correspondence` must be live; `stage` a NUL-terminated string; `out_seconds` writable.
#[no_mangle]
pub unsafe extern "C" fn sc_correspondence_seconds(
    correspondence: *const ScCorrespondence,
    stage: *const c_char,
    out_seconds: *mut f64,
) -> ScStatus {
    boundary(|| {
        let c = handle(correspondence, "correspondence")?;
        let c = &*c;
        let stage = input_str(stage, "stage")?;
        let out = out_seconds
            .as_mut()
            .ok_or_else(|| Failure::null("out_seconds"))?;
        let t = &c.result.timings;
        *out = match stage {
            "eigenbasis_a" => t.eigenbasis_a,
            "eigenbasis_b" => t.eigenbasis_b,
            "descriptors" => t.descriptors,
            "segmentation" => t.segmentation,
            "matching" => t.matching,
            "one_to_one" => t.one_to_one,
            "total" => t.total,
            other => {
                return Err(Failure::invalid(format!(
                    "unknown stage `{other}`; use eigenbasis_a, eigenbasis_b, descriptors, \
                     segmentation, matching, one_to_one or total"
                )))
            }
        };
        Ok(())
    })
}

/// The confidence of the one-to-one answer, in [0, 1]: high when the chosen region
/// hypothesis gives a consistent map clearly better than the runner-up's (below
/// `SC_CONFIDENCE_DOUBTFUL_BELOW` the answer is doubtful, see `sc_correspondence_warning`).
/// NaN when there is none: the answer was not verified (option `verify_hypotheses` or
/// `one_to_one` false, or a single hypothesis, so nothing to choose from), and for NULL.
/// Test it with `isnan`.
///
/// # Safety
/// `correspondence` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn sc_correspondence_confidence(
    correspondence: *const ScCorrespondence,
) -> f64 {
    boundary_value(f64::NAN, || {
        let c = handle(correspondence, "correspondence")?;
        let c = &*c;
        Ok(c.result.confidence().unwrap_or(f64::NAN))
    })
}

/// What to tell the user when the answer is doubtful (confidence below
/// `SC_CONFIDENCE_DOUBTFUL_BELOW`): one sentence, UTF-8, saying whether another region
/// hypothesis came close (parts may be swapped or mirrored) or the best map found is itself
/// poor. NULL when the answer is not doubtful, when it has no confidence
/// (`sc_correspondence_confidence` is NaN), and for NULL. The string belongs to
/// `correspondence`: valid until it is freed; never free it.
///
/// # Safety
/// `correspondence` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn sc_correspondence_warning(
    correspondence: *const ScCorrespondence,
) -> *const c_char {
    boundary_value(std::ptr::null(), || {
        Ok(handle(correspondence, "correspondence")?.text.warning())
    })
}

/// The name of a verified hypothesis: `which` is `SC_ANSWER_CHOSEN` (the answer returned) or
/// `SC_ANSWER_RUNNER_UP` (the cheapest other hypothesis whose map differs, the one
/// `sc_correspondence_other_answer` gives). Names: `"answer"`, `"mirror"`, `"symmetric"`,
/// `"alternative G.O"`, `"placement"`, `"landmarks"` (docs/placement.md). NULL when the answer
/// was not verified (`sc_correspondence_confidence` is NaN), when there is no runner-up, and
/// for NULL or a bad `which`. The string belongs to `correspondence`: valid until it is freed.
///
/// # Safety
/// `correspondence` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn sc_correspondence_hypothesis(
    correspondence: *const ScCorrespondence,
    which: u32,
) -> *const c_char {
    boundary_value(std::ptr::null(), || {
        handle(correspondence, "correspondence")?.text.name(which)
    })
}

/// The cost of hypothesis `which` (`SC_ANSWER_CHOSEN` or `SC_ANSWER_RUNNER_UP`): its map's
/// distortion divided by the square of its coverage times the orientation kept; lower is
/// better. NaN when there is no such hypothesis (as `sc_correspondence_hypothesis`).
///
/// # Safety
/// `correspondence` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn sc_correspondence_hypothesis_cost(
    correspondence: *const ScCorrespondence,
    which: u32,
) -> f64 {
    boundary_value(f64::NAN, || {
        let c = handle(correspondence, "correspondence")?;
        verdict::hypothesis_value(c.result.verdict.as_ref(), which, |h| h.energy.cost())
    })
}

/// The rigid turn, in degrees (0 to 180), that the map of hypothesis `which`
/// (`SC_ANSWER_CHOSEN` or `SC_ANSWER_RUNNER_UP`) implies between B as placed and A: near 0
/// when the map agrees with where the shapes stand, near 180 for a half-turn. NaN when there
/// is no such hypothesis (as `sc_correspondence_hypothesis`).
///
/// # Safety
/// `correspondence` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn sc_correspondence_turn_degrees(
    correspondence: *const ScCorrespondence,
    which: u32,
) -> f64 {
    boundary_value(f64::NAN, || {
        let c = handle(correspondence, "correspondence")?;
        verdict::hypothesis_value(c.result.verdict.as_ref(), which, |h| h.turn_degrees)
    })
}

/// What the pipeline ran on for one side (`SC_SIDE_A` or `SC_SIDE_B`): `out_kind` gets
/// `SC_WORKING_INPUT`, `SC_WORKING_PROXY` or `SC_WORKING_REFINED`, `out_vertices` that
/// shape's vertices (the input's active ones for `SC_WORKING_INPUT`), and `out_smoothed`
/// (NULL: not asked) whether its positions were smoothed because the input is a noisy mesh
/// (docs/scans.md). Nothing is written on error.
///
/// Errors: `SC_STATUS_NULL_ARGUMENT`, `SC_STATUS_INVALID_ARGUMENT` (a bad side).
///
/// # Safety
/// `correspondence` must be live; `out_kind` and `out_vertices` writable, `out_smoothed`
/// NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn sc_correspondence_working(
    correspondence: *const ScCorrespondence,
    side: u32,
    out_kind: *mut u32,
    out_vertices: *mut usize,
    out_smoothed: *mut bool,
) -> ScStatus {
    boundary(|| {
        let c = handle(correspondence, "correspondence")?;
        write_working(&c.result, side, out_kind, out_vertices, out_smoothed)
    })
}

/// Side `side`'s working shape of `result`; a side other than A or B is an invalid argument.
fn working_of(result: &Correspondence, side: u32) -> FfiResult<Working> {
    match side {
        SC_SIDE_A | SC_SIDE_B => Ok(result.working[side as usize]),
        _ => Err(Failure::invalid(format!(
            "side must be SC_SIDE_A (0) or SC_SIDE_B (1), got {side}"
        ))),
    }
}

/// Writes side `side`'s working shape of `result` (`sc_correspondence_working`).
///
/// # Safety
/// `out_kind`, `out_vertices` and `out_smoothed` must be NULL or writable.
pub(crate) unsafe fn write_working(
    result: &Correspondence,
    side: u32,
    out_kind: *mut u32,
    out_vertices: *mut usize,
    out_smoothed: *mut bool,
) -> FfiResult {
    let working = working_of(result, side)?;
    let kind = out_kind.as_mut().ok_or_else(|| Failure::null("out_kind"))?;
    let vertices = out_vertices
        .as_mut()
        .ok_or_else(|| Failure::null("out_vertices"))?;
    *kind = match working.kind {
        WorkingKind::Input => SC_WORKING_INPUT,
        WorkingKind::Proxy => SC_WORKING_PROXY,
        WorkingKind::Refined => SC_WORKING_REFINED,
    };
    *vertices = working.vertices;
    if let Some(smoothed) = out_smoothed.as_mut() {
        *smoothed = working.smoothed;
    }
    Ok(())
}

/// The objects touching one side's figure (`SC_SIDE_A` or `SC_SIDE_B`) that the pair job
/// left out because the pair matched better without them (a prop touching a foot,
/// docs/scans.md, "Props"): `out_pieces` gets their number of pieces and `out_vertices`
/// (NULL: not asked) their vertices, which take the answer of the nearest kept vertex;
/// both 0 when nothing was left out. Nothing is written on error.
///
/// Errors: `SC_STATUS_NULL_ARGUMENT`, `SC_STATUS_INVALID_ARGUMENT` (a bad side).
///
/// # Safety
/// `correspondence` must be live; `out_pieces` writable, `out_vertices` NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn sc_correspondence_objects_left_out(
    correspondence: *const ScCorrespondence,
    side: u32,
    out_pieces: *mut usize,
    out_vertices: *mut usize,
) -> ScStatus {
    boundary(|| {
        let c = handle(correspondence, "correspondence")?;
        write_objects_left_out(&c.result, side, out_pieces, out_vertices)
    })
}

/// Writes side `side`'s objects left out of `result` (`sc_correspondence_objects_left_out`).
///
/// # Safety
/// `out_pieces` and `out_vertices` must be NULL or writable.
pub(crate) unsafe fn write_objects_left_out(
    result: &Correspondence,
    side: u32,
    out_pieces: *mut usize,
    out_vertices: *mut usize,
) -> FfiResult {
    let working = working_of(result, side)?;
    let pieces = out_pieces
        .as_mut()
        .ok_or_else(|| Failure::null("out_pieces"))?;
    *pieces = working.objects_left_out.pieces;
    if let Some(vertices) = out_vertices.as_mut() {
        *vertices = working.objects_left_out.vertices;
    }
    Ok(())
}

/// The objects touching one side's figure (`SC_SIDE_A` or `SC_SIDE_B`) that the pair job
/// could not try leaving out because the time limit (`time_limit_s`) passed first: the
/// answer matched them as part of the figure. `out_pieces` gets their number of pieces, 0
/// when none. Nothing is written on error.
///
/// Errors: `SC_STATUS_NULL_ARGUMENT`, `SC_STATUS_INVALID_ARGUMENT` (a bad side).
///
/// # Safety
/// `correspondence` must be live; `out_pieces` writable.
#[no_mangle]
pub unsafe extern "C" fn sc_correspondence_objects_not_tried(
    correspondence: *const ScCorrespondence,
    side: u32,
    out_pieces: *mut usize,
) -> ScStatus {
    boundary(|| {
        let c = handle(correspondence, "correspondence")?;
        write_objects_not_tried(&c.result, side, out_pieces)
    })
}

/// Writes side `side`'s objects not tried of `result` (`sc_correspondence_objects_not_tried`).
///
/// # Safety
/// `out_pieces` must be NULL or writable.
pub(crate) unsafe fn write_objects_not_tried(
    result: &Correspondence,
    side: u32,
    out_pieces: *mut usize,
) -> FfiResult {
    let working = working_of(result, side)?;
    let pieces = out_pieces
        .as_mut()
        .ok_or_else(|| Failure::null("out_pieces"))?;
    *pieces = working.objects_not_tried;
    Ok(())
}

/// What settled the choice among the hypotheses (static; never free it): `"cost"` (the
/// cheapest), `"close call"` (settled at full resolution), `"placement"` (where the shapes
/// stand, option `placement`), `"landmarks"` (`sc_params_set_landmarks`) or `"other answer"`
/// (a result of `sc_correspondence_other_answer`). NULL when the answer was not verified,
/// and for NULL.
///
/// # Safety
/// `correspondence` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn sc_correspondence_decided_by(
    correspondence: *const ScCorrespondence,
) -> *const c_char {
    boundary_value(std::ptr::null(), || {
        let c = handle(correspondence, "correspondence")?;
        Ok(verdict::decided_by(c.result.verdict.as_ref()))
    })
}

/// True when the shapes' placement settled the choice (`sc_correspondence_decided_by` is
/// `"placement"`); false otherwise, and for NULL.
///
/// # Safety
/// `correspondence` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn sc_correspondence_placement_used(
    correspondence: *const ScCorrespondence,
) -> bool {
    boundary_value(false, || {
        let c = handle(correspondence, "correspondence")?;
        Ok(verdict::placement_used(c.result.verdict.as_ref()))
    })
}

/// The other answer: a new correspondence whose one-to-one matches are the runner-up
/// hypothesis's (`sc_correspondence_hypothesis(c, SC_ANSWER_RUNNER_UP)`), with its verdict
/// (decided by `"other answer"`; its runner-up is usually the first answer). Nothing is
/// recomputed: the hypotheses were verified with the first answer. The caller frees it with
/// `sc_correspondence_free`; it is independent of `correspondence`.
///
/// Errors: `SC_STATUS_INVALID_ARGUMENT` when there is no other answer (the answer was not
/// verified, or no other hypothesis gives a different map; `sc_last_error` says which).
///
/// # Safety
/// `correspondence` must be live; `out_correspondence` writable.
#[no_mangle]
pub unsafe extern "C" fn sc_correspondence_other_answer(
    correspondence: *const ScCorrespondence,
    out_correspondence: *mut *mut ScCorrespondence,
) -> ScStatus {
    boundary(|| {
        check_out(out_correspondence, "out_correspondence")?;
        let c = handle(correspondence, "correspondence")?;
        let other = c
            .result
            .other_answer()
            .ok_or_else(|| verdict::no_other_answer(c.result.verdict.as_ref()))?;
        give_handle(out_correspondence, ScCorrespondence::new(other))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ffi::{SC_ANSWER_CHOSEN, SC_ANSWER_RUNNER_UP};
    use crate::maps::hypotheses::{
        HypothesisKind, HypothesisScore, MapEnergy, Verdict, DOUBTFUL_BELOW,
    };
    use crate::pipeline::Timings;
    use std::ffi::CStr;

    #[test]
    fn header_threshold_matches_the_verdicts() {
        assert_eq!(SC_CONFIDENCE_DOUBTFUL_BELOW, DOUBTFUL_BELOW);
    }

    fn empty_graph() -> ShapeGraph {
        ShapeGraph {
            labels: Vec::new(),
            node_cluster: Vec::new(),
            node_area: Vec::new(),
            node_descriptor: Vec::new(),
            edges: Vec::new(),
        }
    }

    fn score(kind: HypothesisKind, distortion: f64, distance_to_chosen: f64) -> HypothesisScore {
        HypothesisScore {
            kind,
            energy: MapEnergy {
                distortion,
                coverage: 1.0,
                orientation: Some(1.0),
                residual: 0.1,
            },
            fmap_ab: faer::Mat::zeros(2, 2),
            distance_to_chosen,
            rotation: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            turn_degrees: 0.0,
            landmark_error: None,
            one_to_one: Vec::new(),
        }
    }

    /// A handle as the C API gives one out (an `Arc`'s pointer; see `ffi::boundary`).
    fn with_verdict(confidence: Option<f64>) -> *const ScCorrespondence {
        with_mirror_at(confidence, 0.3)
    }

    /// As [`with_verdict`], the mirror's map `distance` from the answer's.
    fn with_mirror_at(confidence: Option<f64>, distance: f64) -> *const ScCorrespondence {
        let correspondence = ScCorrespondence::new(Correspondence {
            k: 5,
            graph_a: empty_graph(),
            graph_b: empty_graph(),
            matches: Vec::new(),
            matches_one_to_one: Vec::new(),
            candidates: Vec::new(),
            timings: Timings::default(),
            verdict: confidence.map(|confidence| Verdict {
                chosen: 0,
                scores: vec![
                    score(HypothesisKind::Answer, 0.05, 0.0),
                    score(HypothesisKind::Mirror, 0.051, distance),
                ],
                confidence,
                decided_by: crate::maps::hypotheses::Decision::Cost,
                distances: vec![vec![0.0, distance], vec![distance, 0.0]],
                ruled_out: vec![false; 2],
            }),
            estimate: None,
            working: [
                (WorkingKind::Input, 300, true),
                (WorkingKind::Refined, 1200, false),
            ]
            .map(|(kind, vertices, smoothed)| {
                crate::pipeline::multiresolution::Working {
                    kind,
                    vertices,
                    smoothed,
                    objects_left_out: crate::shape::ObjectsLeftOut {
                        pieces: usize::from(kind == WorkingKind::Refined),
                        vertices: 40 * usize::from(kind == WorkingKind::Refined),
                    },
                    objects_not_tried: 2 * usize::from(kind == WorkingKind::Input),
                }
            }),
        });
        std::sync::Arc::into_raw(std::sync::Arc::new(correspondence))
    }

    #[test]
    fn confidence_and_warning_follow_the_verdict() {
        let none = with_verdict(None);
        let sure = with_verdict(Some(0.9));
        let doubtful = with_verdict(Some(0.2));
        unsafe {
            assert!(sc_correspondence_confidence(none).is_nan());
            assert!(sc_correspondence_warning(none).is_null());
            assert_eq!(sc_correspondence_confidence(sure), 0.9);
            assert!(sc_correspondence_warning(sure).is_null());
            assert_eq!(sc_correspondence_confidence(doubtful), 0.2);
            let text = sc_correspondence_warning(doubtful);
            assert!(!text.is_null());
            let text = CStr::from_ptr(text).to_str().unwrap();
            assert_eq!(
                Some(text.to_string()),
                (*doubtful).result.verdict.as_ref().unwrap().warning()
            );
            assert!(text.contains("mirror"), "{text}");
            // The same pointer every time: the handle owns the string.
            assert_eq!(
                sc_correspondence_warning(doubtful),
                sc_correspondence_warning(doubtful)
            );
            for handle in [none, sure, doubtful] {
                sc_correspondence_free(handle.cast_mut());
            }
        }
    }

    unsafe fn name(c: *const ScCorrespondence, which: u32) -> Option<String> {
        let p = sc_correspondence_hypothesis(c, which);
        (!p.is_null()).then(|| CStr::from_ptr(p).to_str().unwrap().to_string())
    }

    #[test]
    fn the_other_answer_is_the_runner_up_with_its_verdict() {
        let c = with_verdict(Some(0.9));
        unsafe {
            assert_eq!(name(c, SC_ANSWER_CHOSEN).as_deref(), Some("answer"));
            assert_eq!(name(c, SC_ANSWER_RUNNER_UP).as_deref(), Some("mirror"));
            assert_eq!(
                sc_correspondence_hypothesis_cost(c, SC_ANSWER_RUNNER_UP),
                0.051
            );
            assert_eq!(CStr::from_ptr(sc_correspondence_decided_by(c)), c"cost");
            assert!(!sc_correspondence_placement_used(c));
            let mut other = std::ptr::null_mut();
            assert_eq!(sc_correspondence_other_answer(c, &mut other), ScStatus::Ok);
            assert_eq!(name(other, SC_ANSWER_CHOSEN).as_deref(), Some("mirror"));
            assert_eq!(name(other, SC_ANSWER_RUNNER_UP).as_deref(), Some("answer"));
            assert_eq!(
                sc_correspondence_hypothesis_cost(other, SC_ANSWER_CHOSEN),
                0.051
            );
            assert_eq!(
                CStr::from_ptr(sc_correspondence_decided_by(other)),
                c"other answer"
            );
            sc_correspondence_free(other);
            sc_correspondence_free(c.cast_mut());
        }
    }

    #[test]
    fn without_a_different_map_or_a_verdict_there_is_no_other_answer() {
        let same = with_mirror_at(Some(0.9), 0.0);
        let unverified = with_verdict(None);
        unsafe {
            assert_eq!(name(same, SC_ANSWER_CHOSEN).as_deref(), Some("answer"));
            assert_eq!(name(same, SC_ANSWER_RUNNER_UP), None);
            assert!(sc_correspondence_turn_degrees(same, SC_ANSWER_RUNNER_UP).is_nan());
            assert_eq!(name(unverified, SC_ANSWER_CHOSEN), None);
            assert!(sc_correspondence_decided_by(unverified).is_null());
            for (c, why) in [(same, "different map"), (unverified, "not verified")] {
                let sentinel = 0x10 as *mut ScCorrespondence;
                let mut out = sentinel;
                assert_eq!(
                    sc_correspondence_other_answer(c, &mut out),
                    ScStatus::InvalidArgument
                );
                assert_eq!(out, sentinel, "nothing written on failure");
                let message = CStr::from_ptr(super::super::sc_last_error())
                    .to_str()
                    .unwrap();
                assert!(message.starts_with("no other answer") && message.contains(why));
                sc_correspondence_free(c.cast_mut());
            }
        }
    }

    #[test]
    fn null_handles_have_no_confidence_and_no_warning() {
        unsafe {
            assert!(sc_correspondence_confidence(std::ptr::null()).is_nan());
            assert!(sc_correspondence_warning(std::ptr::null()).is_null());
            let message = CStr::from_ptr(super::super::sc_last_error());
            assert!(message.to_str().unwrap().contains("correspondence"));
        }
    }

    #[test]
    fn objects_left_out_gives_each_sides_count_and_checks_its_arguments() {
        let c = with_verdict(None);
        unsafe {
            let (mut pieces, mut vertices) = (99, 99);
            for (side, want) in [(SC_SIDE_A, (0, 0)), (SC_SIDE_B, (1, 40))] {
                let status =
                    sc_correspondence_objects_left_out(c, side, &mut pieces, &mut vertices);
                assert_eq!(status, ScStatus::Ok);
                assert_eq!((pieces, vertices), want);
                let status =
                    sc_correspondence_objects_left_out(c, side, &mut pieces, std::ptr::null_mut());
                assert_eq!(status, ScStatus::Ok, "out_vertices may be NULL");
            }
            assert_eq!(
                sc_correspondence_objects_left_out(c, 2, &mut pieces, &mut vertices),
                ScStatus::InvalidArgument
            );
            assert_eq!(
                sc_correspondence_objects_left_out(c, 0, std::ptr::null_mut(), &mut vertices),
                ScStatus::NullArgument
            );
            assert_eq!(
                sc_correspondence_objects_left_out(std::ptr::null(), 0, &mut pieces, &mut vertices),
                ScStatus::NullArgument
            );
            sc_correspondence_free(c.cast_mut());
        }
    }

    #[test]
    fn objects_not_tried_gives_each_sides_count_and_checks_its_arguments() {
        let c = with_verdict(None);
        unsafe {
            let mut pieces = 99;
            for (side, want) in [(SC_SIDE_A, 2), (SC_SIDE_B, 0)] {
                let status = sc_correspondence_objects_not_tried(c, side, &mut pieces);
                assert_eq!(status, ScStatus::Ok);
                assert_eq!(pieces, want);
            }
            assert_eq!(
                sc_correspondence_objects_not_tried(c, 2, &mut pieces),
                ScStatus::InvalidArgument
            );
            assert_eq!(
                sc_correspondence_objects_not_tried(c, 0, std::ptr::null_mut()),
                ScStatus::NullArgument
            );
            assert_eq!(
                sc_correspondence_objects_not_tried(std::ptr::null(), 0, &mut pieces),
                ScStatus::NullArgument
            );
            sc_correspondence_free(c.cast_mut());
        }
    }

    #[test]
    fn working_gives_each_sides_kind_and_size_and_checks_its_arguments() {
        let c = with_verdict(None);
        unsafe {
            let (mut kind, mut vertices, mut smoothed) = (99, 99, false);
            let expected = [
                (SC_WORKING_INPUT, 300, true),
                (SC_WORKING_REFINED, 1200, false),
            ];
            for (side, want) in [SC_SIDE_A, SC_SIDE_B].into_iter().zip(expected) {
                let status =
                    sc_correspondence_working(c, side, &mut kind, &mut vertices, &mut smoothed);
                assert_eq!(status, ScStatus::Ok);
                assert_eq!((kind, vertices, smoothed), want);
                let status = sc_correspondence_working(
                    c,
                    side,
                    &mut kind,
                    &mut vertices,
                    std::ptr::null_mut(),
                );
                assert_eq!(status, ScStatus::Ok, "out_smoothed may be NULL");
            }
            let (mut kind, mut vertices) = (99, 99);
            assert_eq!(
                sc_correspondence_working(c, 2, &mut kind, &mut vertices, &mut smoothed),
                ScStatus::InvalidArgument
            );
            let message = CStr::from_ptr(super::super::sc_last_error());
            assert!(message.to_str().unwrap().contains("side"));
            assert_eq!(
                sc_correspondence_working(
                    c,
                    SC_SIDE_A,
                    std::ptr::null_mut(),
                    &mut vertices,
                    &mut smoothed
                ),
                ScStatus::NullArgument
            );
            assert_eq!(
                sc_correspondence_working(
                    c,
                    SC_SIDE_A,
                    &mut kind,
                    std::ptr::null_mut(),
                    &mut smoothed
                ),
                ScStatus::NullArgument
            );
            assert_eq!(
                sc_correspondence_working(
                    std::ptr::null(),
                    0,
                    &mut kind,
                    &mut vertices,
                    &mut smoothed
                ),
                ScStatus::NullArgument
            );
            assert_eq!((kind, vertices), (99, 99), "nothing written on failure");
            sc_correspondence_free(c.cast_mut());
        }
    }
}
