//! Point-to-point maps between two shapes: `sc_pointwise_map` and the result's accessors.

use std::ffi::{c_char, c_void, CStr};

use super::boundary::{
    boundary, boundary_value, check_out, free_handle, give_handle, handle, input_str, write_output,
    Failure, FfiResult, ScStatus,
};
use super::correspondence::{
    write_objects_left_out, write_objects_not_tried, write_working, ScCorrespondence, SC_SIDE_A,
    SC_SIDE_B,
};
use super::params::{options_or_default, ScParams};
use super::shape::ScShape;
use super::verdict::{self, VerdictText};
use super::{CallbackProgress, ScProgressCallback};
use crate::maps::partial::Partiality;
use crate::pipeline::PointwiseCorrespondence;

/// The result of `sc_pointwise_map`: a vertex map from B to A, the functional map from A to
/// B and the region correspondence it was built on. Immutable: one handle may be read from
/// several threads at once. Free it with `sc_pointwise_free`.
pub struct ScPointwise {
    pub(crate) result: PointwiseCorrespondence,
    /// The verdict's warning and hypothesis names, made once with the handle: what
    /// `sc_pointwise_warning` and `sc_pointwise_hypothesis` point into.
    text: VerdictText,
}

impl ScPointwise {
    pub(crate) fn new(result: PointwiseCorrespondence) -> Self {
        let text = VerdictText::new(result.verdict());
        ScPointwise { result, text }
    }
}

/// Option `p2p_regions`: no region constraint (then `p2p_wks` must be true).
pub const SC_P2P_REGIONS_NONE: i64 = 0;
/// Option `p2p_regions`: one constraint per one-to-one region match (the default).
pub const SC_P2P_REGIONS_ONE_TO_ONE: i64 = 1;
/// Option `p2p_regions`: one constraint per group of symmetric region matches.
pub const SC_P2P_REGIONS_SYMMETRIC: i64 = 2;
/// Option `p2p_refinement`: the first functional map's vertex map, unrefined.
pub const SC_P2P_REFINEMENT_NONE: i64 = 0;
/// Option `p2p_refinement`: ZoomOut (the default).
pub const SC_P2P_REFINEMENT_ZOOMOUT: i64 = 1;
/// Option `p2p_refinement`: spectral ICP.
pub const SC_P2P_REFINEMENT_ICP: i64 = 2;

/// Point-to-point map from shape `b` to shape `a` (meshes, point clouds or one of each):
/// the region correspondence of `sc_match`, then a functional map constrained by the matched
/// regions (options `p2p_*`), converted to a vertex map and refined. Each shape's eigenbasis
/// is computed once for both steps. Arguments as `sc_match`: `params` may be NULL for the
/// defaults, `progress` may be NULL; the progress stages are `sc_match`'s followed by
/// `SC_STAGE_POINTWISE_MAP`. The result is deterministic for given shapes and parameters,
/// whatever the number of threads.
///
/// Errors: `SC_STATUS_INVALID_PARAMETER` (checked before any work, e.g. `p2p_fmap_size`
/// above `p2p_eigenpairs`, or no region constraint and no descriptor),
/// `SC_STATUS_RESOURCE_LIMIT` (as `sc_match`), `SC_STATUS_NUMERICAL_FAILURE`,
/// `SC_STATUS_CANCELLED` (the callback returned false).
///
/// # Safety
/// `a`, `b` must be live shapes, `params` NULL or live parameters not being modified,
/// `progress` NULL or a function safe to call with `userdata`; `out_pointwise` writable.
#[no_mangle]
pub unsafe extern "C" fn sc_pointwise_map(
    a: *const ScShape,
    b: *const ScShape,
    params: *const ScParams,
    progress: ScProgressCallback,
    userdata: *mut c_void,
    out_pointwise: *mut *mut ScPointwise,
) -> ScStatus {
    boundary(|| {
        check_out(out_pointwise, "out_pointwise")?;
        let a = handle(a, "a")?;
        let a = &a.shape;
        let b = handle(b, "b")?;
        let b = &b.shape;
        let options = options_or_default(params);
        let mut progress = CallbackProgress {
            callback: progress,
            userdata,
        };
        let result = PointwiseCorrespondence::compute(
            a,
            b,
            &options.params,
            options.pointwise(),
            &mut progress,
        )?;
        give_handle(out_pointwise, ScPointwise::new(result))
    })
}

/// Frees a pointwise map; NULL is a no-op. It drops the caller's reference: a call still using the
/// handle (freed from its progress callback, or on another thread) keeps the object alive
/// until that call returns.
///
/// # Safety
/// `pointwise` must be NULL or live, not passed to a call afterwards.
#[no_mangle]
pub unsafe extern "C" fn sc_pointwise_free(pointwise: *mut ScPointwise) {
    free_handle(pointwise)
}

unsafe fn count(p: *const ScPointwise, f: impl FnOnce(&ScPointwise) -> FfiResult<usize>) -> usize {
    boundary_value(0, || f(&*handle(p, "pointwise")?))
}

/// Number of vertices of one side (`SC_SIDE_A` or `SC_SIDE_B`, as given to
/// `sc_pointwise_map`); 0 for NULL or a bad side. The map has `SC_SIDE_B`'s count of
/// values, each below `SC_SIDE_A`'s count.
///
/// # Safety
/// `pointwise` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn sc_pointwise_n_vertices(
    pointwise: *const ScPointwise,
    side: u32,
) -> usize {
    count(pointwise, |p| match side {
        SC_SIDE_A => Ok(p.result.regions.graph_a.labels.len()),
        SC_SIDE_B => Ok(p.result.map.p2p_ba.len()),
        _ => Err(Failure::invalid(format!(
            "side must be SC_SIDE_A (0) or SC_SIDE_B (1), got {side}"
        ))),
    })
}

/// Copies the map from B to A: for every vertex `v` of B, in the caller's vertex order, the
/// vertex of A it corresponds to (`sc_pointwise_n_vertices(p, SC_SIDE_B)` values, each below
/// `sc_pointwise_n_vertices(p, SC_SIDE_A)`) into `out_map` of `len` elements.
///
/// # Safety
/// `pointwise` must be live; `out_map` must point to `len` writable elements.
#[no_mangle]
pub unsafe extern "C" fn sc_pointwise_map_b_to_a(
    pointwise: *const ScPointwise,
    out_map: *mut u32,
    len: usize,
) -> ScStatus {
    boundary(|| {
        let p = handle(pointwise, "pointwise")?;
        write_output(out_map, len, &p.result.map.p2p_ba, "out_map")
    })
}

/// Rows of the functional map from A to B: the number of B's basis functions (0 for NULL).
///
/// # Safety
/// `pointwise` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn sc_pointwise_fmap_rows(pointwise: *const ScPointwise) -> usize {
    count(pointwise, |p| Ok(p.result.map.fmap_ab.nrows()))
}

/// Columns of the functional map from A to B: the number of A's basis functions (0 for
/// NULL).
///
/// # Safety
/// `pointwise` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn sc_pointwise_fmap_cols(pointwise: *const ScPointwise) -> usize {
    count(pointwise, |p| Ok(p.result.map.fmap_ab.ncols()))
}

/// Copies the final functional map from A to B, row by row (`rows * cols` values, see
/// `sc_pointwise_fmap_rows` and `_cols`), into `out_fmap` of `len` elements: it maps the
/// spectral coefficients of a function on A (in A's Laplacian eigenbasis) to those of the
/// transported function on B.
///
/// # Safety
/// `pointwise` must be live; `out_fmap` must point to `len` writable elements.
#[no_mangle]
pub unsafe extern "C" fn sc_pointwise_fmap(
    pointwise: *const ScPointwise,
    out_fmap: *mut f64,
    len: usize,
) -> ScStatus {
    boundary(|| {
        let fmap = handle(pointwise, "pointwise")?;
        let fmap = &fmap.result.map.fmap_ab;
        let flat: Vec<f64> = (0..fmap.nrows())
            .flat_map(|i| (0..fmap.ncols()).map(move |j| fmap[(i, j)]))
            .collect();
        write_output(out_fmap, len, &flat, "out_fmap")
    })
}

/// The region correspondence the map was built on, as a new `sc_correspondence` (a copy the
/// caller frees with `sc_correspondence_free`, independent of `pointwise`). Its timings count
/// the region stages only: the eigenbases' are `sc_pointwise_seconds`'.
///
/// # Safety
/// `pointwise` must be live; `out_correspondence` writable.
#[no_mangle]
pub unsafe extern "C" fn sc_pointwise_regions(
    pointwise: *const ScPointwise,
    out_correspondence: *mut *mut ScCorrespondence,
) -> ScStatus {
    boundary(|| {
        check_out(out_correspondence, "out_correspondence")?;
        let p = handle(pointwise, "pointwise")?;
        give_handle(
            out_correspondence,
            ScCorrespondence::new(p.result.regions.clone()),
        )
    })
}

/// The objects touching one side's figure that the pair job left out, as
/// `sc_correspondence_objects_left_out`.
///
/// # Safety
/// `pointwise` must be live; `out_pieces` writable, `out_vertices` NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn sc_pointwise_objects_left_out(
    pointwise: *const ScPointwise,
    side: u32,
    out_pieces: *mut usize,
    out_vertices: *mut usize,
) -> ScStatus {
    boundary(|| {
        let p = handle(pointwise, "pointwise")?;
        write_objects_left_out(&p.result.regions, side, out_pieces, out_vertices)
    })
}

/// The objects touching one side's figure that the time limit kept the pair job from
/// trying without, as `sc_correspondence_objects_not_tried`.
///
/// # Safety
/// `pointwise` must be live; `out_pieces` writable.
#[no_mangle]
pub unsafe extern "C" fn sc_pointwise_objects_not_tried(
    pointwise: *const ScPointwise,
    side: u32,
    out_pieces: *mut usize,
) -> ScStatus {
    boundary(|| {
        let p = handle(pointwise, "pointwise")?;
        write_objects_not_tried(&p.result.regions, side, out_pieces)
    })
}

/// What the pipeline ran on for one side, as `sc_correspondence_working` (the map was
/// computed on the same working shapes as its regions).
///
/// # Safety
/// `pointwise` must be live; `out_kind` and `out_vertices` writable, `out_smoothed` NULL
/// or writable.
#[no_mangle]
pub unsafe extern "C" fn sc_pointwise_working(
    pointwise: *const ScPointwise,
    side: u32,
    out_kind: *mut u32,
    out_vertices: *mut usize,
    out_smoothed: *mut bool,
) -> ScStatus {
    boundary(|| {
        let p = handle(pointwise, "pointwise")?;
        write_working(
            &p.result.regions,
            side,
            out_kind,
            out_vertices,
            out_smoothed,
        )
    })
}

/// Seconds spent in a stage of the call: `stage` is one of `"eigenbasis_a"`,
/// `"eigenbasis_b"`, `"regions"` (the region correspondence after the eigenbases), `"fmap"`
/// (descriptors and the first functional map), `"refinement"` (the vertex map and its
/// refinement), `"total"`.
///
/// # Safety
/// `pointwise` must be live; `stage` a NUL-terminated string; `out_seconds` writable.
#[no_mangle]
pub unsafe extern "C" fn sc_pointwise_seconds(
    pointwise: *const ScPointwise,
    stage: *const c_char,
    out_seconds: *mut f64,
) -> ScStatus {
    boundary(|| {
        let p = handle(pointwise, "pointwise")?;
        let p = &p.result;
        let stage = input_str(stage, "stage")?;
        let out = out_seconds
            .as_mut()
            .ok_or_else(|| Failure::null("out_seconds"))?;
        *out = match stage {
            "eigenbasis_a" => p.eigenbasis_a,
            "eigenbasis_b" => p.eigenbasis_b,
            "regions" => p.regions.timings.total,
            "fmap" => p.map.timings.fmap,
            "refinement" => p.map.timings.refinement,
            "total" => p.total,
            other => {
                return Err(Failure::invalid(format!(
                    "unknown stage `{other}`; use eigenbasis_a, eigenbasis_b, regions, fmap, \
                     refinement or total"
                )))
            }
        };
        Ok(())
    })
}

/// The confidence of the answer, in [0, 1]: that of the pointwise map's own choice among
/// region hypotheses when it verified several (options `p2p_orientation`,
/// `p2p_hypotheses`), else that of the region correspondence it was built on (as
/// `sc_correspondence_confidence`). Below `SC_CONFIDENCE_DOUBTFUL_BELOW` the answer is
/// doubtful (see `sc_pointwise_warning`). NaN when there is none (nothing was verified) and for NULL.
///
/// # Safety
/// `pointwise` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn sc_pointwise_confidence(pointwise: *const ScPointwise) -> f64 {
    boundary_value(f64::NAN, || {
        let p = handle(pointwise, "pointwise")?;
        Ok(p.result.confidence().unwrap_or(f64::NAN))
    })
}

/// What to tell the user when the answer is doubtful (as `sc_correspondence_warning`, for
/// the verdict behind `sc_pointwise_confidence`): NULL when it is not doubtful, when there
/// is no confidence, and for NULL. The string belongs to `pointwise`: valid until it is
/// freed; never free it.
///
/// # Safety
/// `pointwise` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn sc_pointwise_warning(pointwise: *const ScPointwise) -> *const c_char {
    boundary_value(std::ptr::null(), || {
        Ok(handle(pointwise, "pointwise")?.text.warning())
    })
}

/// The name of a verified hypothesis, for the verdict behind `sc_pointwise_confidence` (as
/// `sc_correspondence_hypothesis`: `which` is `SC_ANSWER_CHOSEN` or `SC_ANSWER_RUNNER_UP`;
/// NULL when there is none). The string belongs to `pointwise`: valid until it is freed.
///
/// # Safety
/// `pointwise` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn sc_pointwise_hypothesis(
    pointwise: *const ScPointwise,
    which: u32,
) -> *const c_char {
    boundary_value(std::ptr::null(), || {
        handle(pointwise, "pointwise")?.text.name(which)
    })
}

/// The cost of hypothesis `which` (as `sc_correspondence_hypothesis_cost`; NaN when there is
/// none).
///
/// # Safety
/// `pointwise` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn sc_pointwise_hypothesis_cost(
    pointwise: *const ScPointwise,
    which: u32,
) -> f64 {
    boundary_value(f64::NAN, || {
        let p = handle(pointwise, "pointwise")?;
        verdict::hypothesis_value(p.result.verdict(), which, |h| h.energy.cost())
    })
}

/// The rigid turn, in degrees, that the map of hypothesis `which` implies between B as
/// placed and A (as `sc_correspondence_turn_degrees`; NaN when there is none).
///
/// # Safety
/// `pointwise` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn sc_pointwise_turn_degrees(
    pointwise: *const ScPointwise,
    which: u32,
) -> f64 {
    boundary_value(f64::NAN, || {
        let p = handle(pointwise, "pointwise")?;
        verdict::hypothesis_value(p.result.verdict(), which, |h| h.turn_degrees)
    })
}

/// What settled the choice among the hypotheses (as `sc_correspondence_decided_by`; static,
/// NULL when nothing was verified).
///
/// # Safety
/// `pointwise` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn sc_pointwise_decided_by(pointwise: *const ScPointwise) -> *const c_char {
    boundary_value(std::ptr::null(), || {
        Ok(verdict::decided_by(
            handle(pointwise, "pointwise")?.result.verdict(),
        ))
    })
}

/// True when the shapes' placement settled the choice (`sc_pointwise_decided_by` is
/// `"placement"`); false otherwise, and for NULL.
///
/// # Safety
/// `pointwise` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn sc_pointwise_placement_used(pointwise: *const ScPointwise) -> bool {
    boundary_value(false, || {
        Ok(verdict::placement_used(
            handle(pointwise, "pointwise")?.result.verdict(),
        ))
    })
}

/// What the pair was taken to be (docs/partial.md, option `partial`): `"whole"`, `"b_in_a"`
/// (B is a part of A) or `"a_in_b"`; static, NULL for NULL. `out_given`, when not NULL, is
/// set to true when the option decided it rather than the measurement.
///
/// # Safety
/// `pointwise` must be NULL or live; `out_given` NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn sc_pointwise_taken_as(
    pointwise: *const ScPointwise,
    out_given: *mut bool,
) -> *const c_char {
    boundary_value(std::ptr::null(), || {
        let report = &handle(pointwise, "pointwise")?.result.map.partial;
        if !out_given.is_null() {
            *out_given = report.given;
        }
        let name: &'static CStr = match report.partiality {
            Partiality::Whole => c"whole",
            Partiality::BInA => c"b_in_a",
            Partiality::AInB => c"a_in_b",
        };
        Ok(name.as_ptr())
    })
}

/// The share of A's area that has a counterpart on B under the map, in [0, 1] (near 1 for
/// two whole shapes, the part's share for a part of A); NaN for NULL.
///
/// # Safety
/// `pointwise` must be NULL or live.
#[no_mangle]
pub unsafe extern "C" fn sc_pointwise_covered_share(pointwise: *const ScPointwise) -> f64 {
    boundary_value(f64::NAN, || {
        Ok(handle(pointwise, "pointwise")?.result.map.coverage.share_a)
    })
}

/// Copies one side's coverage mask into `out_covered` of `len` elements
/// (`sc_pointwise_n_vertices(p, side)` of them, in the caller's vertex order): for
/// `SC_SIDE_A`, whether B's image covers the vertex; for `SC_SIDE_B`, whether the vertex has
/// a counterpart on A (every vertex, unless A was taken as a part of B). A transfer from A
/// to B should write only B's covered vertices (docs/partial.md).
///
/// # Safety
/// `pointwise` must be live; `out_covered` must point to `len` writable elements.
#[no_mangle]
pub unsafe extern "C" fn sc_pointwise_covered(
    pointwise: *const ScPointwise,
    side: u32,
    out_covered: *mut bool,
    len: usize,
) -> ScStatus {
    boundary(|| {
        let coverage = &handle(pointwise, "pointwise")?.result.map.coverage;
        let mask = match side {
            SC_SIDE_A => &coverage.a,
            SC_SIDE_B => &coverage.b,
            _ => {
                return Err(Failure::invalid(format!(
                    "side must be SC_SIDE_A (0) or SC_SIDE_B (1), got {side}"
                )))
            }
        };
        write_output(out_covered, len, mask, "out_covered")
    })
}

/// The other answer: a new pointwise map holding the runner-up hypothesis's vertex map (at
/// full resolution), functional map and one-to-one regions, with its verdict (decided by
/// `"other answer"`). Nothing is recomputed: the hypotheses were verified with the first
/// answer. Every accessor, `sc_surface_map_new` (with the same two shapes) included, works on
/// it; the caller frees it with `sc_pointwise_free`, independently of `pointwise`.
///
/// Errors: `SC_STATUS_INVALID_ARGUMENT` when there is no other answer (nothing was verified,
/// or no other hypothesis gives a different map; `sc_last_error` says which).
///
/// # Safety
/// `pointwise` must be live; `out_pointwise` writable.
#[no_mangle]
pub unsafe extern "C" fn sc_pointwise_other_answer(
    pointwise: *const ScPointwise,
    out_pointwise: *mut *mut ScPointwise,
) -> ScStatus {
    boundary(|| {
        check_out(out_pointwise, "out_pointwise")?;
        let p = handle(pointwise, "pointwise")?;
        let other = p
            .result
            .other_answer()
            .ok_or_else(|| verdict::no_other_answer(p.result.verdict()))?;
        give_handle(out_pointwise, ScPointwise::new(other))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::maps::pointwise::RegionConstraints;
    use crate::options::{
        P2P_REFINEMENT_ICP, P2P_REFINEMENT_NONE, P2P_REFINEMENT_ZOOMOUT, P2P_REGIONS,
    };

    #[test]
    fn header_choice_constants_match_the_options() {
        assert_eq!(
            P2P_REGIONS[SC_P2P_REGIONS_NONE as usize],
            RegionConstraints::None
        );
        assert_eq!(
            P2P_REGIONS[SC_P2P_REGIONS_ONE_TO_ONE as usize],
            RegionConstraints::OneToOne
        );
        assert_eq!(
            P2P_REGIONS[SC_P2P_REGIONS_SYMMETRIC as usize],
            RegionConstraints::Symmetric
        );
        assert_eq!(SC_P2P_REFINEMENT_NONE, P2P_REFINEMENT_NONE);
        assert_eq!(SC_P2P_REFINEMENT_ZOOMOUT, P2P_REFINEMENT_ZOOMOUT);
        assert_eq!(SC_P2P_REFINEMENT_ICP, P2P_REFINEMENT_ICP);
    }

    #[test]
    fn null_handles_have_no_confidence_and_no_warning() {
        unsafe {
            assert!(sc_pointwise_confidence(std::ptr::null()).is_nan());
            assert!(sc_pointwise_warning(std::ptr::null()).is_null());
        }
    }
}
