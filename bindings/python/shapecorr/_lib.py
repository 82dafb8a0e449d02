"""The one loader of libshapecorr and the ctypes declarations of every C function.

Where the library comes from, in order:
1. the file named by the environment variable ``SHAPECORR_LIB``;
2. the copy packaged inside this Python package (``pip install ./bindings/python``);
3. ``target/release`` of the repository this package sits in (a development checkout).
"""

import ctypes
import operator
import os
import sys
import threading
from pathlib import Path

#: The C ABI version this binding was written for (``SC_ABI_VERSION`` in shapecorr.h).
ABI_VERSION = 1

_NAMES = {"linux": "libshapecorr.so", "darwin": "libshapecorr.dylib", "win32": "shapecorr.dll"}
LIBRARY_NAME = _NAMES.get(sys.platform, "libshapecorr.so")


def _candidates():
    override = os.environ.get("SHAPECORR_LIB")
    if override:
        return [("SHAPECORR_LIB", Path(override))]
    here = Path(__file__).resolve().parent
    return [
        ("packaged copy", here / LIBRARY_NAME),
        ("development checkout", here.parents[2] / "target" / "release" / LIBRARY_NAME),
    ]


def _load():
    tried = []
    for origin, path in _candidates():
        if path.is_file():
            try:
                return ctypes.CDLL(str(path)), path
            except OSError as error:
                tried.append(f"{path} ({origin}): {error}")
                if origin == "SHAPECORR_LIB":
                    break
        else:
            tried.append(f"{path} ({origin}): no such file")
            if origin == "SHAPECORR_LIB":
                break
    raise ImportError(
        "shapecorr: cannot load the shared library; tried "
        + "; ".join(tried)
        + ". Build it with `cargo build --release`, install the package with "
        "`pip install ./bindings/python`, or set SHAPECORR_LIB to the library's path."
    )


lib, LIBRARY_PATH = _load()

c_size_t = ctypes.c_size_t
c_u32 = ctypes.c_uint32
c_u8p = ctypes.POINTER(ctypes.c_uint8)
c_u32p = ctypes.POINTER(ctypes.c_uint32)
c_f64p = ctypes.POINTER(ctypes.c_double)
c_f32p = ctypes.POINTER(ctypes.c_float)
c_i64p = ctypes.POINTER(ctypes.c_int64)
c_boolp = ctypes.POINTER(ctypes.c_bool)
c_size_tp = ctypes.POINTER(ctypes.c_size_t)
handle_out = ctypes.POINTER(ctypes.c_void_p)
status = ctypes.c_uint32

# Checked argument types: what ctypes would silently truncate, wrap or dereference raises
# instead. ctypes reports a failed conversion as ArgumentError; the wrappers installed below
# re-raise the original TypeError, ValueError or OverflowError.
_argument_error = threading.local()


def _refuse(error):
    _argument_error.value = error
    raise error


class handle:
    """A shapecorr object (or None for NULL): anything else raises TypeError, a closed
    object ValueError, so no stray pointer ever reaches the library."""

    @classmethod
    def from_param(cls, obj):
        if obj is None or isinstance(obj, ctypes.c_void_p):
            return obj
        pointer = getattr(obj, "_handle_pointer", None)
        if pointer is None:
            _refuse(TypeError(f"expected a shapecorr object (e.g. a Shape), got {type(obj).__name__}"))
        try:
            return pointer()
        except ValueError as error:
            _refuse(error)


def _checked_int(ctype, low, high):
    class checked:
        @classmethod
        def from_param(cls, value):
            try:
                value = operator.index(value)
            except TypeError:
                _refuse(TypeError(f"expected an integer, got {type(value).__name__} {value!r}"))
            if not low <= value <= high:
                _refuse(OverflowError(f"{value} is out of range [{low}, {high}]"))
            return ctype(value)

    return checked


u32_arg = _checked_int(ctypes.c_uint32, 0, 2**32 - 1)
c_i64 = _checked_int(ctypes.c_int64, -(2**63), 2**63 - 1)


class c_str:
    """A NUL-terminated byte string (or None): a NUL inside raises ValueError rather than
    cutting the string."""

    @classmethod
    def from_param(cls, value):
        if value is None:
            return None
        if not isinstance(value, bytes):
            _refuse(TypeError(f"expected bytes, got {type(value).__name__}"))
        if b"\0" in value:
            _refuse(ValueError(f"embedded NUL character in {value!r}"))
        return ctypes.c_char_p(value)

#: ``bool (*)(void *userdata, uint32_t stage, float fraction)``
PROGRESS = ctypes.CFUNCTYPE(ctypes.c_bool, ctypes.c_void_p, ctypes.c_uint32, ctypes.c_float)

#: Every exported function: name -> (restype, argtypes). tests check it against the header.
FUNCTIONS = {
    "sc_version": (ctypes.c_char_p, []),
    "sc_version_major": (c_u32, []),
    "sc_version_minor": (c_u32, []),
    "sc_version_patch": (c_u32, []),
    "sc_abi_version": (c_u32, []),
    "sc_status_str": (ctypes.c_char_p, [u32_arg]),
    "sc_last_error": (ctypes.c_char_p, []),
    # shapes
    "sc_shape_new_mesh": (status, [c_f64p, c_size_t, c_u32p, c_size_t, handle_out]),
    "sc_shape_new_mesh_f32": (status, [c_f32p, c_size_t, c_u32p, c_size_t, handle_out]),
    "sc_shape_new_point_cloud": (status, [c_f64p, c_size_t, handle_out]),
    "sc_shape_new_point_cloud_f32": (status, [c_f32p, c_size_t, handle_out]),
    "sc_shape_read": (status, [c_str, ctypes.c_bool, handle_out]),
    "sc_shape_new_figure": (status, [c_str, u32_arg, u32_arg, handle_out]),
    "sc_shape_new_mesh_repaired": (status, [c_f64p, c_size_t, c_u32p, c_size_t, u32_arg, handle_out]),
    "sc_shape_new_point_cloud_repaired": (status, [c_f64p, c_size_t, u32_arg, handle_out]),
    "sc_shape_read_repaired": (status, [c_str, ctypes.c_bool, u32_arg, handle_out]),
    "sc_shape_free": (None, [handle]),
    "sc_shape_n_vertices": (c_size_t, [handle]),
    "sc_shape_n_triangles": (c_size_t, [handle]),
    "sc_shape_is_point_cloud": (ctypes.c_bool, [handle]),
    "sc_shape_vertices": (status, [handle, c_f64p, c_size_t]),
    "sc_shape_triangles": (status, [handle, c_u32p, c_size_t]),
    "sc_shape_warnings": (c_size_t, [handle, ctypes.c_char_p, c_size_t]),
    "sc_shape_repairs": (c_size_t, [handle, ctypes.c_char_p, c_size_t]),
    # parameters
    "sc_params_new": (status, [handle_out]),
    "sc_params_free": (None, [handle]),
    "sc_params_set_int": (status, [handle, c_str, c_i64]),
    "sc_params_set_double": (status, [handle, c_str, ctypes.c_double]),
    "sc_params_set_bool": (status, [handle, c_str, ctypes.c_bool]),
    "sc_params_get_int": (status, [handle, c_str, c_i64p]),
    "sc_params_get_double": (status, [handle, c_str, c_f64p]),
    "sc_params_get_bool": (status, [handle, c_str, c_boolp]),
    "sc_params_set_landmarks": (status, [handle, c_u32p, c_size_t]),
    "sc_params_n_landmarks": (c_size_t, [handle]),
    "sc_params_landmarks": (status, [handle, c_u32p, c_size_t]),
    "sc_option_count": (c_size_t, []),
    "sc_option_name": (ctypes.c_char_p, [c_size_t]),
    "sc_option_doc": (ctypes.c_char_p, [c_size_t]),
    "sc_option_choice": (ctypes.c_char_p, [c_size_t, c_size_t]),
    "sc_option_type": (ctypes.c_uint32, [c_size_t]),
    "sc_option_min": (ctypes.c_double, [c_size_t]),
    "sc_option_max": (ctypes.c_double, [c_size_t]),
    # correspondence
    "sc_match": (status, [handle, handle, handle, PROGRESS, ctypes.c_void_p, handle_out]),
    "sc_correspondence_free": (None, [handle]),
    "sc_correspondence_k": (c_u32, [handle]),
    "sc_correspondence_n_vertices": (c_size_t, [handle, u32_arg]),
    "sc_correspondence_n_regions": (c_size_t, [handle, u32_arg]),
    "sc_correspondence_regions": (status, [handle, u32_arg, c_u32p, c_size_t]),
    "sc_correspondence_n_matches": (c_size_t, [handle, u32_arg]),
    "sc_correspondence_matches": (status, [handle, u32_arg, c_u32p, c_size_t]),
    "sc_correspondence_colors": (status, [handle, u32_arg, u32_arg, c_u8p, c_size_t]),
    "sc_correspondence_descriptor_length": (c_size_t, [handle]),
    "sc_correspondence_region_areas": (status, [handle, u32_arg, c_f64p, c_size_t]),
    "sc_correspondence_region_descriptors": (status, [handle, u32_arg, c_f64p, c_size_t]),
    "sc_correspondence_n_edges": (c_size_t, [handle, u32_arg]),
    "sc_correspondence_edges": (status, [handle, u32_arg, c_u32p, c_size_t]),
    "sc_correspondence_seconds": (status, [handle, c_str, c_f64p]),
    "sc_correspondence_confidence": (ctypes.c_double, [handle]),
    "sc_correspondence_warning": (ctypes.c_char_p, [handle]),
    "sc_correspondence_hypothesis": (ctypes.c_char_p, [handle, u32_arg]),
    "sc_correspondence_hypothesis_cost": (ctypes.c_double, [handle, u32_arg]),
    "sc_correspondence_turn_degrees": (ctypes.c_double, [handle, u32_arg]),
    "sc_correspondence_working": (status, [handle, u32_arg, c_u32p, c_size_tp, c_boolp]),
    "sc_correspondence_objects_left_out": (status, [handle, u32_arg, c_size_tp, c_size_tp]),
    "sc_correspondence_objects_not_tried": (status, [handle, u32_arg, c_size_tp]),
    "sc_correspondence_decided_by": (ctypes.c_char_p, [handle]),
    "sc_correspondence_placement_used": (ctypes.c_bool, [handle]),
    "sc_correspondence_other_answer": (status, [handle, handle_out]),
    # symmetry
    "sc_symmetry_detect": (status, [handle, handle, PROGRESS, ctypes.c_void_p, handle_out]),
    "sc_symmetry_free": (None, [handle]),
    "sc_symmetry_n_vertices": (c_size_t, [handle]),
    "sc_symmetry_n_regions": (c_size_t, [handle]),
    "sc_symmetry_n_groups": (c_size_t, [handle]),
    "sc_symmetry_regions": (status, [handle, c_u32p, c_size_t]),
    "sc_symmetry_region_groups": (status, [handle, c_u32p, c_size_t]),
    "sc_symmetry_colors": (status, [handle, c_u8p, c_size_t]),
    # pointwise maps
    "sc_pointwise_map": (status, [handle, handle, handle, PROGRESS, ctypes.c_void_p, handle_out]),
    "sc_pointwise_free": (None, [handle]),
    "sc_pointwise_n_vertices": (c_size_t, [handle, u32_arg]),
    "sc_pointwise_map_b_to_a": (status, [handle, c_u32p, c_size_t]),
    "sc_pointwise_fmap_rows": (c_size_t, [handle]),
    "sc_pointwise_fmap_cols": (c_size_t, [handle]),
    "sc_pointwise_fmap": (status, [handle, c_f64p, c_size_t]),
    "sc_pointwise_regions": (status, [handle, handle_out]),
    "sc_pointwise_working": (status, [handle, u32_arg, c_u32p, c_size_tp, c_boolp]),
    "sc_pointwise_objects_left_out": (status, [handle, u32_arg, c_size_tp, c_size_tp]),
    "sc_pointwise_objects_not_tried": (status, [handle, u32_arg, c_size_tp]),
    "sc_pointwise_seconds": (status, [handle, c_str, c_f64p]),
    "sc_pointwise_confidence": (ctypes.c_double, [handle]),
    "sc_pointwise_warning": (ctypes.c_char_p, [handle]),
    "sc_pointwise_hypothesis": (ctypes.c_char_p, [handle, u32_arg]),
    "sc_pointwise_hypothesis_cost": (ctypes.c_double, [handle, u32_arg]),
    "sc_pointwise_turn_degrees": (ctypes.c_double, [handle, u32_arg]),
    "sc_pointwise_decided_by": (ctypes.c_char_p, [handle]),
    "sc_pointwise_placement_used": (ctypes.c_bool, [handle]),
    "sc_pointwise_other_answer": (status, [handle, handle_out]),
    "sc_pointwise_taken_as": (ctypes.c_char_p, [handle, c_boolp]),
    "sc_pointwise_covered_share": (ctypes.c_double, [handle]),
    "sc_pointwise_covered": (status, [handle, u32_arg, c_boolp, c_size_t]),
    # transfer
    "sc_surface_map_new": (status, [handle, handle, handle, PROGRESS, ctypes.c_void_p, handle_out]),
    "sc_surface_map_free": (None, [handle]),
    "sc_surface_map_n_vertices": (c_size_t, [handle, u32_arg]),
    "sc_surface_map_points": (status, [handle, c_u32p, c_f64p, c_size_t]),
    "sc_surface_map_nearest": (status, [handle, c_u32p, c_size_t]),
    "sc_surface_map_transfer": (
        status, [handle, c_f64p, c_size_t, c_size_t, u32_arg, u32_arg, c_f64p, c_size_t],
    ),
    "sc_surface_map_transfer_corners": (
        status,
        [handle, handle, c_u32p, c_size_t, c_f64p, c_size_t, c_u32p, c_size_t, c_size_t, c_f64p, c_size_t],
    ),
    # collections
    "sc_batch_new": (status, [handle, c_str, u32_arg, handle_out]),
    "sc_batch_free": (None, [handle]),
    "sc_batch_prepare": (status, [handle, c_str, c_str, handle_out]),
    "sc_batch_match": (status, [handle, c_str, c_str, c_str, c_str, c_str, handle_out]),
    "sc_batch_record_json": (ctypes.c_char_p, [handle]),
    "sc_batch_record_ok": (ctypes.c_bool, [handle]),
    "sc_batch_record_free": (None, [handle]),
    "sc_batch_open_folder": (status, [handle, c_str, handle_out]),
    "sc_batch_folder_free": (None, [handle]),
    "sc_batch_read_pairs": (status, [c_str, handle_out]),
}

def _raising_the_original(function):
    """``function``, raising a checked argument's own error instead of ArgumentError, with
    every shapecorr object among its arguments counted as in use for the call (a ``close()``
    meanwhile frees it only when the call returns)."""

    def call(*args):
        _argument_error.value = None
        held = []
        try:
            for arg in args:
                acquire = getattr(arg, "_acquire", None)
                if acquire is not None:
                    acquire()
                    held.append(arg)
            return function(*args)
        except ctypes.ArgumentError:
            error, _argument_error.value = getattr(_argument_error, "value", None), None
            if error is None:
                raise
            raise error from None
        finally:
            for arg in held:
                arg._release()

    call.__name__ = function.__name__
    call.restype, call.argtypes = function.restype, function.argtypes
    return call


for _name, (_restype, _argtypes) in FUNCTIONS.items():
    _function = getattr(lib, _name)
    _function.restype = _restype
    _function.argtypes = _argtypes
    setattr(lib, _name, _raising_the_original(_function))

if lib.sc_abi_version() != ABI_VERSION:
    raise ImportError(
        f"shapecorr: {LIBRARY_PATH} has C ABI version {lib.sc_abi_version()}, this binding "
        f"needs {ABI_VERSION}; rebuild the library or reinstall the package"
    )

# Constants of shapecorr.h.
SIDE_A, SIDE_B = 0, 1
MATCHES_SYMMETRIC, MATCHES_ONE_TO_ONE = 0, 1
OPTION_INT, OPTION_DOUBLE, OPTION_BOOL = 0, 1, 2
P2P_REGIONS_NONE, P2P_REGIONS_ONE_TO_ONE, P2P_REGIONS_SYMMETRIC = 0, 1, 2
P2P_REFINEMENT_NONE, P2P_REFINEMENT_ZOOMOUT, P2P_REFINEMENT_ICP = 0, 1, 2
PLACEMENT_AUTO, PLACEMENT_IGNORE, PLACEMENT_TRUST = 0, 1, 2
#: ``SC_ANSWER_CHOSEN``, ``SC_ANSWER_RUNNER_UP``: which hypothesis a verdict accessor reads.
ANSWER_CHOSEN, ANSWER_RUNNER_UP = 0, 1
#: ``SC_WORKING_INPUT``, ``SC_WORKING_PROXY``, ``SC_WORKING_REFINED``: what a side ran on.
WORKING_INPUT, WORKING_PROXY, WORKING_REFINED = 0, 1, 2
#: ``SC_MAX_LANDMARKS``: most landmark pairs a job takes.
MAX_LANDMARKS = 100
#: Below this confidence an answer is doubtful and has a warning.
CONFIDENCE_DOUBTFUL_BELOW = 0.45
STATUS_NAMES = {
    0: "OK",
    1: "NULL_ARGUMENT",
    2: "INVALID_ARGUMENT",
    3: "BUFFER_TOO_SMALL",
    4: "UNKNOWN_OPTION",
    10: "NON_FINITE_COORDINATE",
    11: "FACE_INDEX_OUT_OF_RANGE",
    12: "FACE_TOO_SMALL",
    13: "TOO_FEW_VERTICES",
    14: "ZERO_AREA",
    15: "INVALID_PARAMETER",
    16: "FILE_ERROR",
    17: "NUMERICAL_FAILURE",
    18: "CANCELLED",
    19: "RESOURCE_LIMIT",
    100: "PANIC",
}
#: ``SC_STATUS_RESOURCE_LIMIT``: the job is too big for a limit (memory, time, vertices).
STATUS_RESOURCE_LIMIT = 19
STAGE_NAMES = {
    1: "laplacian",
    2: "eigenbasis",
    3: "descriptors",
    4: "segmentation",
    5: "matching",
    6: "symmetry_breaking",
    7: "pointwise_map",
    8: "proxy",
    9: "transfer",
}
#: Batch flags (``SC_BATCH_*``).
BATCH_MAPS, BATCH_POINTS, BATCH_NO_REPAIR = 1, 2, 4
#: Transfer modes (``SC_TRANSFER_*``).
TRANSFER_MODES = {"interpolate": 0, "nearest": 1, "weights": 2}
