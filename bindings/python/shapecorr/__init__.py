"""shapecorr: region-level correspondences between 3D shapes (meshes and point clouds).

A ctypes binding over the C API of libshapecorr (``include/shapecorr.h``)::

    import shapecorr
    a = shapecorr.Shape.read("a.ply")
    b = shapecorr.Shape.read("b.ply")
    result = shapecorr.match(a, b, k_max=8)
    result.regions_a            # region of every vertex of A (numpy uint32)
    result.matches_one_to_one   # (n, 2) array of (region of A, region of B)
    result.colors("a")          # (n_vertices, 4) RGBA bytes, matched regions share a colour
    result.confidence           # in [0, 1], or None when the answer was not verified
    result.warning              # a sentence when the answer is doubtful, else None
    result.hypothesis, result.decided_by, result.runner_up   # what was chosen, and why
    other = result.other_answer()   # the runner-up's answer (nothing recomputed), or None
    shapecorr.match(a, b, landmarks=[(12, 40), (300, 311)], placement="ignore")
    pointwise = shapecorr.pointwise_map(a, b)
    pointwise.map_b_to_a        # vertex of A for every vertex of B (numpy uint32)
    shapecorr.Shape.from_trimesh(mesh)   # also from_open3d, from_mesh (vertices, faces)
    onto = shapecorr.surface_map(a, b, pointwise)
    onto.transfer(weights_a, mode="weights", max_influences=4)   # A's data on B

Options are the library's named options (``shapecorr.options()``), with the same defaults as
the command line, as typed keyword arguments (:class:`RegionOptions`,
:class:`PointwiseOptions`: a type checker catches a misspelt one); a choice is taken by name
or by value (``p2p_refinement="icp"`` or ``2``). Errors raise :class:`ShapecorrError` with
the C status and the message; a job too big for its limits (memory, time, vertices) raises
its subclass :class:`ResourceLimitError`.
Shapes and results may be shared between threads; the library releases the GIL while it
works (ctypes does). The package is typed (PEP 561): arrays are ``numpy.typing.NDArray``.
"""

from __future__ import annotations

import ctypes
import functools
import math
import os
import re
import signal
import sys
import threading
import weakref
from typing import TYPE_CHECKING, Any, Callable, Iterable, Literal, NamedTuple, TypedDict, Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _lib
from ._lib import lib

if sys.version_info >= (3, 11):
    from typing import Unpack
elif TYPE_CHECKING:  # annotations only (PEP 563): nothing needs it at run time
    from typing_extensions import Unpack

__all__ = [
    "ShapecorrError",
    "ResourceLimitError",
    "Shape",
    "Correspondence",
    "Symmetry",
    "PointwiseMap",
    "SurfaceMap",
    "match",
    "detect_symmetry",
    "pointwise_map",
    "surface_map",
    "options",
    "version",
    "CONFIDENCE_DOUBTFUL_BELOW",
    "REPAIRS",
    "RegionGraph",
    "OptionInfo",
    "OptionKind",
    "OptionValue",
    "RegionOptions",
    "PointwiseOptions",
    "IntValue",
    "FloatValue",
    "BoolValue",
    "RegionsChoice",
    "RefinementChoice",
    "PlacementChoice",
    "PartialChoice",
    "Hypothesis",
    "Working",
    "WorkingKind",
    "Landmarks",
    "ProgressCallback",
    "RepairSpec",
    "Side",
    "StrPath",
    "TransferMode",
]

# Type aliases of the public API (strings inside: numpy's generic scalar types cannot be
# subscripted at run time before numpy 1.22).
#: A named option's value (see :func:`options`).
OptionValue = Union[bool, int, float, "np.integer[Any]", "np.floating[Any]", "np.bool_"]
#: ``progress(stage_name, fraction)``: a falsy return other than None cancels.
ProgressCallback = Callable[[str, float], object]
#: ``repair`` of the shape constructors: True, False (or None), or names from :data:`REPAIRS`.
RepairSpec = Union[bool, None, Iterable[str]]
#: One side of a result: ``"a"`` (or ``"A"``, ``0``) or ``"b"`` (``"B"``, ``1``).
Side = Literal["a", "A", 0, "b", "B", 1]
#: A file path as ``open`` takes it.
StrPath = Union[str, bytes, "os.PathLike[str]", "os.PathLike[bytes]"]
#: The kinds of :func:`options`.
OptionKind = Literal["int", "float", "bool"]
#: The modes of :meth:`SurfaceMap.transfer`.
TransferMode = Literal["interpolate", "nearest", "weights"]
#: The value of an ``"int"`` option.
IntValue = Union[int, "np.integer[Any]"]
#: The value of a ``"float"`` option.
FloatValue = Union[float, "np.floating[Any]"]
#: The value of a ``"bool"`` option.
BoolValue = Union[bool, "np.bool_"]
#: ``p2p_regions``: by name, or by value (0, 1, 2).
RegionsChoice = Union[IntValue, Literal["none", "one-to-one", "symmetric"]]
#: ``p2p_refinement``: by name, or by value (0, 1, 2).
RefinementChoice = Union[IntValue, Literal["none", "zoomout", "icp"]]
#: ``placement``: by name, or by value (0, 1, 2); see docs/placement.md.
PlacementChoice = Union[IntValue, Literal["auto", "ignore", "trust"]]
#: ``partial``: by name, or by value (0 to 3); see docs/partial.md.
PartialChoice = Union[IntValue, Literal["auto", "off", "b_in_a", "a_in_b"]]
#: ``landmarks``: pairs ``(vertex of A, vertex of B)``, a sequence of pairs of non-negative
#: integers or an (n, 2) integer array.
Landmarks = Union[Iterable[Iterable[IntValue]], "NDArray[np.integer[Any]]"]


class RegionOptions(TypedDict, total=False):
    """The options of :func:`match` and :func:`detect_symmetry`, as keyword arguments or a
    dict to unpack (``**options``): the library's region options, each optional, with the
    types of :func:`options`. A type checker refuses a misspelt name or a wrong type."""

    k_min: IntValue
    k_max: IntValue
    kmeans_restarts: IntValue
    max_regions: IntValue
    min_region_area: FloatValue
    seed: IntValue
    hks_times: IntValue
    hks_t_min: FloatValue
    hks_t_max: FloatValue
    hks_log: BoolValue
    eigenpairs: IntValue
    threads: IntValue
    sigma: FloatValue
    histogram_bins: IntValue
    gap_ratio: FloatValue
    max_symmetry_order: IntValue
    one_to_one: BoolValue
    exhaustive_limit: IntValue
    symmetry_restarts: IntValue
    hks_fallback: BoolValue
    verify_hypotheses: BoolValue
    proxy_above: IntValue
    proxy_vertices: IntValue
    refine_below: IntValue
    max_vertices: IntValue
    memory_limit_mib: IntValue
    time_limit_s: FloatValue
    placement: PlacementChoice
    partial: PartialChoice


class PointwiseOptions(RegionOptions, total=False):
    """The options of :func:`pointwise_map` (and of a batch): the region options and the
    pointwise map's (``p2p_*``)."""

    p2p_eigenpairs: IntValue
    p2p_fmap_size: IntValue
    p2p_regions: RegionsChoice
    p2p_region_distances: BoolValue
    p2p_wks: BoolValue
    p2p_descriptor_step: IntValue
    p2p_laplacian_weight: FloatValue
    p2p_descriptor_commutativity: FloatValue
    p2p_orientation_term: FloatValue
    p2p_refinement: RefinementChoice
    p2p_zoomout_end: IntValue
    p2p_zoomout_step: IntValue
    p2p_zoomout_sample: IntValue
    p2p_icp_iterations: IntValue
    p2p_orientation: BoolValue
    p2p_hypotheses: BoolValue


class ShapecorrError(Exception):
    """A failed call: ``status`` is the C status code, ``status_name`` its name (e.g.
    ``"NON_FINITE_COORDINATE"``), ``message`` the library's explanation."""

    def __init__(self, status: int, message: str) -> None:
        self.status = int(status)
        self.status_name = _lib.STATUS_NAMES.get(self.status, "UNKNOWN")
        self.message = message
        super().__init__(f"{self.status_name}: {message}")


class ResourceLimitError(ShapecorrError):
    """A job too big for its limits (status ``RESOURCE_LIMIT``): refused before any work
    because its estimated memory or time exceeds ``memory_limit_mib`` or ``time_limit_s``
    (or a shape has more than ``max_vertices`` vertices, or needs more memory than the
    system has), or stopped when it ran past ``time_limit_s``. ``limit`` names the limit:
    the option, or ``"available_memory"``; the message gives the estimate and what to do.
    A :class:`ShapecorrError`, so ``except ShapecorrError`` catches it too."""

    def __init__(self, status: int, message: str) -> None:
        super().__init__(status, message)
        found = re.search(r"resource limit `([a-z_]+)`", message)
        self.limit: str | None = found.group(1) if found else None


#: The exception of a status, where it has its own (else :class:`ShapecorrError`).
_ERRORS: dict[int, type[ShapecorrError]] = {_lib.STATUS_RESOURCE_LIMIT: ResourceLimitError}


def _check(status):
    if status != 0:
        message = lib.sc_last_error().decode("utf-8", "replace")
        raise _ERRORS.get(status, ShapecorrError)(status, message)


#: Below this confidence an answer is doubtful and has a warning (``SC_CONFIDENCE_DOUBTFUL_BELOW``).
CONFIDENCE_DOUBTFUL_BELOW = _lib.CONFIDENCE_DOUBTFUL_BELOW


def version() -> str:
    """The library's version string (the same as ``__version__``)."""
    return lib.sc_version().decode()


__version__ = version()


def _ptr(array, ctype):
    return array.ctypes.data_as(ctypes.POINTER(ctype))


def _fill(function, handle, *args, shape, dtype, ctype):
    """Allocates a numpy array and lets ``function(handle, *args, out, len)`` fill it."""
    out = np.empty(shape, dtype=dtype)
    _check(function(handle, *args, _ptr(out, ctype), out.size))
    return out


class _Handle:
    """Owns a C handle; freed when the object is collected or at interpreter exit.

    Every library call that takes the object counts as a use (``_lib`` wraps each call in
    :meth:`_acquire` and :meth:`_release`): :meth:`close` during a use, from a progress
    callback or another thread, frees the C object only when the last use ends, so a
    running call never reads freed memory."""

    _free = None

    def __init__(self, pointer):
        self._pointer = ctypes.c_void_p(pointer)
        # finalize keeps a reference to the free function, so it works at exit too.
        self._finalizer = weakref.finalize(self, type(self)._free, self._pointer)
        self._lock = threading.Lock()
        self._uses = 0
        self._closing = False

    def _acquire(self):
        """Counts a use; ValueError once :meth:`close` was called."""
        with self._lock:
            if self._closing or not self._finalizer.alive:
                raise ValueError(f"this {type(self).__name__} is closed")
            self._uses += 1

    def _release(self):
        """Ends a use; frees the C object when it was closed meanwhile and this was the last."""
        with self._lock:
            self._uses -= 1
            free = self._closing and self._uses == 0
        if free:
            self._finalizer()

    def _handle_pointer(self):
        """The C pointer; ValueError once :meth:`close` was called (never a dangling one)."""
        if self.closed:
            raise ValueError(f"this {type(self).__name__} is closed")
        return self._pointer

    @property
    def closed(self) -> bool:
        """True once :meth:`close` was called."""
        return self._closing or not self._finalizer.alive

    def close(self) -> None:
        """Frees the C object (also done automatically): now, or when a call still using it
        returns (``close()`` from a progress callback or another thread); using it
        afterwards raises ValueError."""
        with self._lock:
            self._closing = True
            free = self._uses == 0
        if free:
            self._finalizer()


def _expect(value, kind, name):
    """``value`` if it is an open ``kind``: TypeError for anything else (a path, an int, a
    result where a shape goes), ValueError when closed."""
    if not isinstance(value, kind):
        raise TypeError(f"{name} must be a shapecorr.{kind.__name__}, got {type(value).__name__}")
    value._handle_pointer()
    return value


def _new_handle(constructor, *args):
    out = ctypes.c_void_p()
    _check(constructor(*args, ctypes.byref(out)))
    return out.value


class Shape(_Handle):
    """A validated triangle mesh or point cloud (immutable; safe to share between
    threads). Make one with :meth:`mesh`, :meth:`point_cloud`, :meth:`read`,
    :meth:`figure`, or from another library's object with :meth:`from_trimesh`,
    :meth:`from_open3d` or :meth:`from_mesh`."""

    _free = lib.sc_shape_free

    @classmethod
    def mesh(cls, vertices: ArrayLike, triangles: ArrayLike, repair: RepairSpec = True) -> Shape:
        """A mesh from an (n, 3) array of vertices and an (m, 3) array of 0-based triangle
        indices (copied; float32 coordinates stay float32 on the way in).

        ``repair``: ``True`` (the default) welds coincident vertices (UV seams, triangle
        soups), joins pieces that come close for matching (no face is added) and leaves out
        small loose pieces, separate objects (pieces not joined to the largest one) and far
        vertices; ``False`` uses the mesh as given; or a
        collection of ``"weld"``, ``"debris"``, ``"outliers"``, ``"join"``. Every vertex
        keeps its index; the repairs made are in :attr:`warnings`."""
        vertices = np.asarray(vertices)
        flags = _repair_flags(repair)
        coords, function, ctype = _coordinates(vertices, lib.sc_shape_new_mesh_f32, lib.sc_shape_new_mesh)
        if flags != _REPAIR_ALL:
            coords, ctype = np.ascontiguousarray(coords, dtype=np.float64), ctypes.c_double
            function = functools.partial(_with_flags, lib.sc_shape_new_mesh_repaired, 4, flags)
        tris = np.asarray(triangles)
        if tris.size and tris.dtype.kind not in "iu":
            raise TypeError(f"triangle indices must be integers, got {tris.dtype}")
        if tris.size and (tris.ndim != 2 or tris.shape[1] != 3):
            raise ValueError(f"triangles must have shape (m, 3), got {tris.shape}")
        if tris.size and (tris.min() < 0 or tris.max() > np.iinfo(np.uint32).max):
            bad = tris.min() if tris.min() < 0 else tris.max()
            raise ShapecorrError(
                11, f"triangle index {bad} is out of range for {len(coords)} vertices"
            )
        tris = np.ascontiguousarray(tris, dtype=np.uint32).reshape(-1, 3)
        return cls(
            _new_handle(
                function, _ptr(coords, ctype), len(coords), _ptr(tris, ctypes.c_uint32), len(tris)
            )
        )

    @classmethod
    def point_cloud(cls, points: ArrayLike, repair: RepairSpec = True) -> Shape:
        """A point cloud from an (n, 3) array of points (copied). ``repair`` as for
        :meth:`mesh` (coincident points welded, far and isolated points and small loose
        clusters left out)."""
        flags = _repair_flags(repair)
        coords, function, ctype = _coordinates(
            np.asarray(points), lib.sc_shape_new_point_cloud_f32, lib.sc_shape_new_point_cloud
        )
        if flags != _REPAIR_ALL:
            coords, ctype = np.ascontiguousarray(coords, dtype=np.float64), ctypes.c_double
            function = functools.partial(_with_flags, lib.sc_shape_new_point_cloud_repaired, 2, flags)
        return cls(_new_handle(function, _ptr(coords, ctype), len(coords)))

    @classmethod
    def read(cls, path: StrPath, as_point_cloud: bool = False, repair: RepairSpec = True) -> Shape:
        """Reads OFF, OBJ, PLY or XYZ; a file without faces gives a point cloud. ``repair``
        as for :meth:`mesh`."""
        # os.fsencode: str, bytes or path-like, with the file system's encoding; a NUL
        # inside raises ValueError.
        return cls(
            _new_handle(
                lib.sc_shape_read_repaired, os.fsencode(path), bool(as_point_cloud),
                _repair_flags(repair),
            )
        )

    @classmethod
    def figure(cls, kind: str = "humanoid", pose: int = 0, vertices: int = 5000) -> Shape:
        """A generated figure (``"humanoid"``, ``"quadruped"``, ``"star3"``..``"star8"``);
        every pose of a kind and size shares the vertex order (a ground truth)."""
        if not isinstance(kind, str):
            raise TypeError(f"kind must be a str, got {type(kind).__name__}")
        return cls(_new_handle(lib.sc_shape_new_figure, kind.encode(), pose, vertices))

    @classmethod
    def from_mesh(cls, mesh: object, repair: RepairSpec = True) -> Shape:
        """A shape from any object with ``vertices`` ((n, 3) coordinates) and, for a mesh,
        ``faces`` (or ``triangles``: (m, 3) vertex indices), each an array or anything
        ``numpy.asarray`` takes. Without faces (no attribute, None or no rows) it is a point
        cloud, as a file without faces is. ``repair`` as for :meth:`mesh`; nothing else
        (colours, normals) is read."""
        vertices = getattr(mesh, "vertices", None)
        if vertices is None:
            hint = " (an Open3D point cloud? use Shape.from_open3d)" if hasattr(mesh, "points") else ""
            raise TypeError(
                "expected an object with `vertices` (and `faces` for a mesh), got "
                f"{type(mesh).__name__}{hint}"
            )
        faces = getattr(mesh, "faces", None)
        if faces is None:
            faces = getattr(mesh, "triangles", None)
        faces = None if faces is None else np.asarray(faces)
        if faces is not None and faces.size:
            return cls.mesh(vertices, faces, repair)
        return cls.point_cloud(vertices, repair)

    @classmethod
    def from_trimesh(cls, mesh: object, repair: RepairSpec = True) -> Shape:
        """A shape from a ``trimesh.Trimesh`` (a mesh; one without faces is a point cloud)
        or a ``trimesh.PointCloud``; trimesh itself is not needed here. A ``trimesh.Scene``
        (what ``trimesh.load`` gives for a file of several parts) raises TypeError: load it
        with ``trimesh.load(path, force="mesh")`` to get one mesh."""
        parts = getattr(mesh, "geometry", None)
        if getattr(mesh, "vertices", None) is None and isinstance(parts, dict):
            raise TypeError(
                f"got a scene of {len(parts)} geometries, not one mesh: load the file with "
                'trimesh.load(path, force="mesh"), or pass one of scene.geometry\'s values'
            )
        return cls.from_mesh(mesh, repair)

    @classmethod
    def from_open3d(cls, geometry: object, repair: RepairSpec = True) -> Shape:
        """A shape from an Open3D ``TriangleMesh`` (``vertices``, ``triangles``; one
        without triangles is a point cloud) or ``PointCloud`` (``points``), of the legacy
        (``open3d.geometry``) or the tensor API (``open3d.t.geometry``, converted with
        ``to_legacy()``); Open3D itself is not needed here."""
        to_legacy = getattr(geometry, "to_legacy", None)
        if callable(to_legacy):
            geometry = to_legacy()
        if getattr(geometry, "vertices", None) is not None:
            return cls.from_mesh(geometry, repair)
        points = getattr(geometry, "points", None)
        if points is None:
            raise TypeError(
                "expected an Open3D TriangleMesh (vertices, triangles) or PointCloud (points), "
                f"got {type(geometry).__name__}"
            )
        return cls.point_cloud(points, repair)

    @property
    def n_vertices(self) -> int:
        return lib.sc_shape_n_vertices(self)

    @property
    def is_point_cloud(self) -> bool:
        return bool(lib.sc_shape_is_point_cloud(self))

    @property
    def vertices(self) -> NDArray[np.float64]:
        """(n, 3) float64 array of the vertices, in the input order."""
        return _fill(
            lib.sc_shape_vertices, self, shape=(self.n_vertices, 3), dtype=np.float64,
            ctype=ctypes.c_double,
        )

    @property
    def triangles(self) -> NDArray[np.uint32]:
        """(m, 3) uint32 array of triangles (polygons split; empty for a point cloud)."""
        n = lib.sc_shape_n_triangles(self)
        return _fill(lib.sc_shape_triangles, self, shape=(n, 3), dtype=np.uint32, ctype=ctypes.c_uint32)

    @property
    def warnings(self) -> list[str]:
        """What was repaired or is unusual (degenerate faces, pieces, ...), one string each."""
        return _lines(lib.sc_shape_warnings, self)

    @property
    def repairs(self) -> list[str]:
        """The repairs made (coincident vertices welded, debris, far vertices or isolated
        points left out; see ``repair`` of :meth:`mesh`), one string each: a part of
        :attr:`warnings`."""
        return _lines(lib.sc_shape_repairs, self)

    def __repr__(self) -> str:
        kind = "point cloud" if self.is_point_cloud else "mesh"
        return f"<shapecorr.Shape {kind}, {self.n_vertices} vertices>"


def _lines(function, shape):
    """The lines of a text a ``sc_shape_*`` function writes as ``snprintf`` does."""
    n = function(shape, None, 0)
    buf = ctypes.create_string_buffer(n + 1)
    function(shape, buf, n + 1)
    return [line for line in buf.value.decode().split("\n") if line]


#: The repairs by name (the C API's ``SC_REPAIR_*`` flags).
REPAIRS: dict[str, int] = {"weld": 1, "debris": 2, "outliers": 4, "join": 8}
_REPAIR_ALL = 15


def _repair_flags(repair):
    """The C flags of a ``repair`` argument: True (all), False (none) or a collection of
    names from :data:`REPAIRS`."""
    if repair is True:
        return _REPAIR_ALL
    if repair is False or repair is None:
        return 0
    if isinstance(repair, (str, bytes)) or not hasattr(repair, "__iter__"):
        raise TypeError(
            f"repair must be True, False or a collection of {sorted(REPAIRS)}, got {repair!r}"
        )
    flags = 0
    for name in repair:
        if name not in REPAIRS:
            raise ValueError(f"unknown repair {name!r}; the repairs are {sorted(REPAIRS)}")
        flags |= REPAIRS[name]
    return flags


def _with_flags(function, position, flags, *args):
    """Calls a ``*_repaired`` constructor with ``flags`` inserted at ``position``."""
    args = list(args)
    args.insert(position, flags)
    return function(*args)


def _coordinates(array, f32_function, f64_function):
    if array.ndim != 2 or array.shape[1] != 3:
        raise ValueError(f"coordinates must have shape (n, 3), got {array.shape}")
    if array.dtype == np.float32:
        return np.ascontiguousarray(array), f32_function, ctypes.c_float
    return np.ascontiguousarray(array, dtype=np.float64), f64_function, ctypes.c_double


class _Params(_Handle):
    _free = lib.sc_params_free

    def __init__(self, values, landmarks=None):
        super().__init__(_new_handle(lib.sc_params_new))
        if landmarks is not None:
            pairs = _landmark_array(landmarks)
            _check(lib.sc_params_set_landmarks(self, _ptr(pairs, ctypes.c_uint32), len(pairs)))
        table = _option_table()
        for name, value in _choice_values(values).items():
            if name not in table:
                # Let the library produce its message (it lists the options).
                _check(lib.sc_params_set_int(self, name.encode(), 0))
            kind, choices = table[name]
            setter = {
                "int": lib.sc_params_set_int,
                "float": lib.sc_params_set_double,
                "bool": lib.sc_params_set_bool,
            }[kind]
            if kind == "int" and not _is_integer(value):
                names = f" or one of {', '.join(map(repr, choices))}" if choices else ""
                raise _OptionTypeError(2, f"option `{name}` takes an integer{names}, got {value!r}")
            if kind == "float" and not _is_real(value):
                raise _OptionTypeError(2, f"option `{name}` takes a number, got {value!r}")
            if kind == "int" and name == "seed" and 2**63 <= int(value) < 2**64:
                value = int(value) - 2**64  # a seed takes any 64-bit value
            if kind == "int" and not -(2**63) <= int(value) < 2**63:
                raise OverflowError(f"option `{name}`: {value} does not fit in 64 bits")
            if kind == "bool" and not isinstance(value, (bool, np.bool_)):
                raise _OptionTypeError(2, f"option `{name}` takes True or False, got {value!r}")
            converted = {"int": int, "float": float, "bool": bool}[kind](value)
            _check(setter(self, name.encode(), converted))


def _landmark_array(landmarks):
    """``landmarks`` (pairs ``(vertex of A, vertex of B)``: a sequence of pairs of integers
    or an (n, 2) integer array) as a contiguous (n, 2) uint32 array. A bool, a float or a
    string where an index goes is refused (:class:`ShapecorrError` ``INVALID_ARGUMENT`` that
    is also a TypeError), as is anything but pairs; a negative index or one past uint32
    raises :class:`ShapecorrError` ``INVALID_PARAMETER`` naming the pair. The library checks
    the rest against the shapes when the job starts."""
    if isinstance(landmarks, np.ndarray):
        if landmarks.size and landmarks.dtype.kind not in "iu":
            raise _OptionTypeError(
                2, f"`landmarks` must hold integer vertex indices, got an array of {landmarks.dtype}"
            )
        if landmarks.size and (landmarks.ndim != 2 or landmarks.shape[1] != 2):
            raise _OptionTypeError(2, f"`landmarks` must have shape (n, 2), got {landmarks.shape}")
        rows = [tuple(int(v) for v in row) for row in landmarks.reshape(-1, 2)]
    else:
        if isinstance(landmarks, (str, bytes)) or not hasattr(landmarks, "__iter__"):
            raise _OptionTypeError(
                2, f"`landmarks` must be pairs (vertex of A, vertex of B), got {landmarks!r}"
            )
        rows = []
        for i, pair in enumerate(landmarks, start=1):
            if isinstance(pair, (str, bytes)) or not hasattr(pair, "__iter__"):
                raise _OptionTypeError(2, f"`landmarks`: pair {i} is not a pair of vertices: {pair!r}")
            pair = tuple(pair)
            if len(pair) != 2:
                raise _OptionTypeError(
                    2, f"`landmarks`: pair {i} has {len(pair)} values, a pair has 2: {pair!r}"
                )
            for v in pair:
                if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, np.integer)):
                    raise _OptionTypeError(
                        2, f"`landmarks`: pair {i} {pair!r}: a vertex index must be an integer, "
                        f"got {type(v).__name__} {v!r}"
                    )
            rows.append((int(pair[0]), int(pair[1])))
    for i, (va, vb) in enumerate(rows, start=1):
        if not (0 <= va < 2**32 and 0 <= vb < 2**32):
            raise ShapecorrError(
                15, f"invalid parameter `landmarks`: pair {i} ({va}, {vb}): a vertex index "
                "must be a non-negative integer (indices start at 0)"
            )
    return np.array(rows, dtype=np.uint32).reshape(-1, 2)


class _OptionTypeError(ShapecorrError, TypeError):
    """An option given a value of the wrong type (a string for a number, a bool for an
    integer): status ``INVALID_ARGUMENT``, and a TypeError too."""


def _is_integer(value):
    """An int, a numpy integer or a float with an integer value (a bool or a string is
    not)."""
    if isinstance(value, (bool, np.bool_)):
        return False
    if isinstance(value, (float, np.floating)):
        return math.isfinite(value) and float(value).is_integer()
    return isinstance(value, (int, np.integer))


def _is_real(value):
    """An int, a float or a numpy number that is no bool (a string is no number)."""
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(
        value, (bool, np.bool_)
    )


_OPTION_KINDS: dict[int, OptionKind] = {
    _lib.OPTION_INT: "int", _lib.OPTION_DOUBLE: "float", _lib.OPTION_BOOL: "bool"
}


@functools.lru_cache(maxsize=None)
def _option_table() -> dict[str, tuple[OptionKind, tuple[str, ...]]]:
    """Every option's kind and choices' names (by value), from the library's table."""
    table = {}
    for i in range(lib.sc_option_count()):
        choices: list[str] = []
        while (choice := lib.sc_option_choice(i, len(choices))) is not None:
            choices.append(choice.decode())
        table[lib.sc_option_name(i).decode()] = (_OPTION_KINDS[lib.sc_option_type(i)], tuple(choices))
    return table


def _choice_values(values):
    """``values`` with every choice given by name (``p2p_refinement="icp"``, any case)
    replaced by its value (2); an unknown name raises :class:`ShapecorrError`
    (``INVALID_PARAMETER``, as a value out of the list does)."""
    table = _option_table()
    out = dict(values)
    for name, value in values.items():
        choices = table.get(name, ("int", ()))[1]
        if choices and isinstance(value, str):
            if value.strip().lower() not in choices:
                listed = ", ".join(f"{choice} ({i})" for i, choice in enumerate(choices))
                raise ShapecorrError(
                    15, f"invalid parameter `{name}`: expected one of {listed}, got `{value}`"
                )
            out[name] = choices.index(value.strip().lower())
    return out


class OptionInfo(NamedTuple):
    """One option of :func:`options`: it unpacks as ``name, kind, doc, default``."""

    #: The name, as a keyword argument.
    name: str
    #: ``"int"``, ``"float"`` or ``"bool"``.
    kind: OptionKind
    #: One line: what it does.
    doc: str
    #: The library's default.
    default: int | float | bool

    @property
    def choices(self) -> tuple[str, ...]:
        """The names of a choice's values, by value (``p2p_refinement``: ``("none",
        "zoomout", "icp")``), which it also takes; ``()`` for another option."""
        return _option_table()[self.name][1]


def options() -> list[OptionInfo]:
    """Every option as ``(name, kind, doc, default)`` (:class:`OptionInfo`; ``kind`` is
    ``"int"``, ``"float"`` or ``"bool"``; ``.choices`` lists the names a choice also takes).
    The defaults are the library's (the same everywhere)."""
    defaults = ctypes.c_void_p()
    _check(lib.sc_params_new(ctypes.byref(defaults)))
    try:
        result: list[OptionInfo] = []
        for i in range(lib.sc_option_count()):
            name = lib.sc_option_name(i)
            kind = _OPTION_KINDS[lib.sc_option_type(i)]
            value: Any = {"int": ctypes.c_int64, "float": ctypes.c_double, "bool": ctypes.c_bool}[kind]()
            getter = {
                "int": lib.sc_params_get_int,
                "float": lib.sc_params_get_double,
                "bool": lib.sc_params_get_bool,
            }[kind]
            _check(getter(defaults, name, ctypes.byref(value)))
            result.append(OptionInfo(name.decode(), kind, lib.sc_option_doc(i).decode(), value.value))
        return result
    finally:
        lib.sc_params_free(defaults)


class _Progress:
    """Wraps a Python callable ``progress(stage_name, fraction)``: a falsy return other than
    None (``False``, ``0``, ``np.False_``) cancels, None or a truthy value goes on; an
    exception inside it cancels the call and is raised afterwards. Ctrl-C (SIGINT) during
    the call, with or without a callback, cancels it and raises KeyboardInterrupt: while
    the call runs in the main thread, SIGINT only sets a flag that the next progress report
    (at least every 0.2 s) turns into a cancel."""

    def __init__(self, progress):
        self.error = None
        self.user = progress
        self.interrupted = False

        def call(_userdata, stage, fraction):
            if self.interrupted:
                return False
            if self.user is None:
                return True
            try:
                keep_going = self.user(_lib.STAGE_NAMES.get(stage, str(stage)), float(fraction))
                return keep_going is None or bool(keep_going)
            except BaseException as error:  # noqa: BLE001 - re-raised after the C call
                self.error = error
                return False

        self.c_function = _lib.PROGRESS(call)

    def run(self, function, *args):
        """Calls ``function(*args, c_progress, NULL, out)`` and raises what it ended with."""
        out = ctypes.c_void_p()
        previous = None
        if (
            threading.current_thread() is threading.main_thread()
            and signal.getsignal(signal.SIGINT) is signal.default_int_handler
        ):
            previous = signal.signal(signal.SIGINT, self._on_sigint)
        try:
            status = function(*args, self.c_function, None, ctypes.byref(out))
        finally:
            if previous is not None:
                signal.signal(signal.SIGINT, previous)
        if self.interrupted:
            raise KeyboardInterrupt
        if self.error is not None:
            raise self.error
        _check(status)
        return out.value

    def _on_sigint(self, _signum, _frame):
        self.interrupted = True


def _confidence(value):
    """A C confidence (NaN: none) as a float or None."""
    return None if math.isnan(value) else float(value)


def _warning(text):
    """A C warning (NULL: none) as a str or None."""
    return None if text is None else text.decode("utf-8", "replace")


def _side(side):
    if isinstance(side, (bool, np.bool_)) or not isinstance(side, (str, int, np.integer)):
        raise TypeError(f"side must be 'a' or 'b' (or 0, 1), got {side!r}")
    if side in ("a", "A", 0):
        return _lib.SIDE_A
    if side in ("b", "B", 1):
        return _lib.SIDE_B
    raise ValueError(f"side must be 'a' or 'b', got {side!r}")


class RegionGraph(TypedDict):
    """One side's shape graph (:meth:`Correspondence.graph`)."""

    #: Fraction of the shape's area per region.
    areas: NDArray[np.float64]
    #: Mean heat kernel signature per region, (n_regions, descriptor length).
    descriptors: NDArray[np.float64]
    #: (e, 2): regions that touch.
    edges: NDArray[np.uint32]


class Hypothesis(NamedTuple):
    """A verified hypothesis of a result (:attr:`Correspondence.runner_up`,
    :attr:`Correspondence.chosen`): its name, cost and the turn its map implies."""

    #: ``"answer"``, ``"mirror"``, ``"symmetric"``, ``"alternative G.O"``, ``"placement"`` or
    #: ``"landmarks"``.
    hypothesis: str
    #: The cost the hypotheses are ranked by (lower is better).
    cost: float
    #: The rigid turn, in degrees (0 to 180), its map implies between B as placed and A.
    turn_degrees: float


#: What a side ran on (:class:`Working`).
WorkingKind = Literal["input", "proxy", "refined"]
_WORKING_KINDS: dict[int, WorkingKind] = {
    _lib.WORKING_INPUT: "input", _lib.WORKING_PROXY: "proxy", _lib.WORKING_REFINED: "refined",
}


class Working(NamedTuple):
    """What the pipeline ran on for one side (:attr:`Correspondence.working`): the input
    itself, a simplified proxy of a dense shape (options ``proxy_above``,
    ``proxy_vertices``) or a refined copy of a low-poly mesh (``refine_below``), its
    positions smoothed when the input is a noisy mesh (scanner noise). The answers are given
    on every input vertex whatever it ran on."""

    #: ``"input"``, ``"proxy"`` or ``"refined"``.
    kind: WorkingKind
    #: Its vertices (the input's active ones for ``"input"``).
    vertices: int
    #: Whether its positions were smoothed because the input is a noisy mesh.
    smoothed: bool = False
    #: Vertices of objects touching the figure (a prop beside a foot) that were left out
    #: because the pair matched better without them; they take the answer of the nearest
    #: kept vertex (docs/scans.md, "Props").
    objects_left_out: int = 0
    #: Pieces touching the figure that the time limit (``time_limit_s``) kept the pair job
    #: from trying without: they were matched as part of the figure.
    objects_not_tried: int = 0


def _working(prefix, result) -> tuple[Working, Working]:
    """Both sides' :class:`Working` through ``sc_correspondence_working``,
    ``sc_correspondence_objects_left_out`` and ``sc_correspondence_objects_not_tried`` (or
    their ``sc_pointwise_`` forms: ``prefix``)."""
    sides = []
    for side in (_lib.SIDE_A, _lib.SIDE_B):
        kind, vertices, smoothed = ctypes.c_uint32(), ctypes.c_size_t(), ctypes.c_bool()
        working = getattr(lib, f"{prefix}_working")
        _check(working(result, side, ctypes.byref(kind), ctypes.byref(vertices), ctypes.byref(smoothed)))
        pieces, objects = ctypes.c_size_t(), ctypes.c_size_t()
        _check(getattr(lib, f"{prefix}_objects_left_out")(result, side, ctypes.byref(pieces), ctypes.byref(objects)))
        not_tried = ctypes.c_size_t()
        _check(getattr(lib, f"{prefix}_objects_not_tried")(result, side, ctypes.byref(not_tried)))
        sides.append(Working(_WORKING_KINDS[kind.value], vertices.value, smoothed.value, objects.value, not_tried.value))
    return sides[0], sides[1]


class _Verdict:
    """What a result says about its choice among the verified hypotheses (docs/placement.md),
    read through the C functions named ``{_prefix}_hypothesis`` etc."""

    _prefix = ""

    def _c(self, name):
        return getattr(lib, f"{self._prefix}_{name}")

    def _hypothesis(self, which):
        name = self._c("hypothesis")(self, which)
        if name is None:
            return None
        return Hypothesis(
            name.decode("utf-8", "replace"),
            float(self._c("hypothesis_cost")(self, which)),
            float(self._c("turn_degrees")(self, which)),
        )

    @property
    def chosen(self) -> Hypothesis | None:
        """The chosen hypothesis (name, cost, turn), or None when the answer was not verified
        (:attr:`confidence` is None)."""
        return self._hypothesis(_lib.ANSWER_CHOSEN)

    @property
    def hypothesis(self) -> str | None:
        """The chosen hypothesis's name (``"answer"``, ``"mirror"``, ``"symmetric"``,
        ``"alternative G.O"``, ``"placement"``, ``"landmarks"``), or None when the answer was
        not verified."""
        chosen = self.chosen
        return None if chosen is None else chosen.hypothesis

    @property
    def turn_degrees(self) -> float | None:
        """The rigid turn, in degrees (0 to 180), that the chosen map implies between B as
        placed and A (near 0: the map agrees with where the shapes stand; near 180: a
        half-turn), or None when the answer was not verified."""
        chosen = self.chosen
        return None if chosen is None else chosen.turn_degrees

    @property
    def decided_by(self) -> str | None:
        """What settled the choice: ``"cost"``, ``"close call"``, ``"placement"`` (where the
        shapes stand), ``"landmarks"`` or ``"other answer"`` (a result of
        :meth:`other_answer`); None when the answer was not verified."""
        text = self._c("decided_by")(self)
        return None if text is None else text.decode()

    @property
    def placement_used(self) -> bool:
        """True when where the shapes stand settled the choice (``decided_by ==
        "placement"``; option ``placement``)."""
        return bool(self._c("placement_used")(self))

    @property
    def runner_up(self) -> Hypothesis | None:
        """The runner-up (name, cost, turn): the cheapest other hypothesis whose map differs
        from the chosen one, the answer :meth:`other_answer` gives; None when there is none."""
        return self._hypothesis(_lib.ANSWER_RUNNER_UP)

    def _other_handle(self):
        """The C handle of the other answer, or None when there is no runner-up."""
        if self._c("hypothesis")(self, _lib.ANSWER_RUNNER_UP) is None:
            return None
        return _new_handle(self._c("other_answer"), self)


class Correspondence(_Verdict, _Handle):
    """The result of :func:`match` (immutable; safe to share between threads)."""

    _prefix = "sc_correspondence"

    _free = lib.sc_correspondence_free

    @property
    def k(self) -> int:
        """The number of joint clusters chosen."""
        return lib.sc_correspondence_k(self)

    def n_regions(self, side: Side) -> int:
        return lib.sc_correspondence_n_regions(self, _side(side))

    def regions(self, side: Side) -> NDArray[np.uint32]:
        """Region id of every vertex of one side (``"a"`` or ``"b"``), input order."""
        s = _side(side)
        n = lib.sc_correspondence_n_vertices(self, s)
        return _fill(lib.sc_correspondence_regions, self, s, shape=n, dtype=np.uint32, ctype=ctypes.c_uint32)

    @property
    def regions_a(self) -> NDArray[np.uint32]:
        return self.regions("a")

    @property
    def regions_b(self) -> NDArray[np.uint32]:
        return self.regions("b")

    def _matches(self, kind):
        n = lib.sc_correspondence_n_matches(self, kind)
        return _fill(
            lib.sc_correspondence_matches, self, kind, shape=(n, 2), dtype=np.uint32,
            ctype=ctypes.c_uint32,
        )

    @property
    def matches(self) -> NDArray[np.uint32]:
        """Symmetric matches: (n, 2) array of (region of A, region of B)."""
        return self._matches(_lib.MATCHES_SYMMETRIC)

    @property
    def matches_one_to_one(self) -> NDArray[np.uint32]:
        """One-to-one matches after symmetry breaking (empty if ``one_to_one=False``)."""
        return self._matches(_lib.MATCHES_ONE_TO_ONE)

    def colors(self, side: Side, one_to_one: bool = True) -> NDArray[np.uint8]:
        """(n_vertices, 4) uint8 RGBA of one side: matched regions share a colour on both
        shapes, unmatched regions are dark grey."""
        s = _side(side)
        kind = _lib.MATCHES_ONE_TO_ONE if one_to_one else _lib.MATCHES_SYMMETRIC
        n = lib.sc_correspondence_n_vertices(self, s)
        return _fill(lib.sc_correspondence_colors, self, s, kind, shape=(n, 4), dtype=np.uint8, ctype=ctypes.c_uint8)

    def graph(self, side: Side) -> RegionGraph:
        """One side's shape graph: ``areas`` (fraction of the shape's area per region),
        ``descriptors`` (mean HKS per region) and ``edges`` ((e, 2) array, regions that
        touch)."""
        s = _side(side)
        n = lib.sc_correspondence_n_regions(self, s)
        dim = lib.sc_correspondence_descriptor_length(self)
        e = lib.sc_correspondence_n_edges(self, s)
        return {
            "areas": _fill(lib.sc_correspondence_region_areas, self, s, shape=n, dtype=np.float64, ctype=ctypes.c_double),
            "descriptors": _fill(
                lib.sc_correspondence_region_descriptors, self, s, shape=(n, dim), dtype=np.float64,
                ctype=ctypes.c_double,
            ),
            "edges": _fill(lib.sc_correspondence_edges, self, s, shape=(e, 2), dtype=np.uint32, ctype=ctypes.c_uint32),
        }

    @property
    def confidence(self) -> float | None:
        """The confidence of the one-to-one answer, a float in [0, 1] (below
        ``CONFIDENCE_DOUBTFUL_BELOW``, 0.45, the answer is doubtful), or None when it was not
        verified (``verify_hypotheses=False``, ``one_to_one=False``, or nothing to choose
        from)."""
        return _confidence(lib.sc_correspondence_confidence(self))

    @property
    def warning(self) -> str | None:
        """What to tell the user when the answer is doubtful (one sentence), else None."""
        return _warning(lib.sc_correspondence_warning(self))

    @property
    def doubtful(self) -> bool:
        """True when the answer has a confidence below ``CONFIDENCE_DOUBTFUL_BELOW``."""
        return self.warning is not None

    def other_answer(self) -> Correspondence | None:
        """The other answer: a new :class:`Correspondence` whose one-to-one matches are the
        :attr:`runner_up`'s, with its verdict (``decided_by == "other answer"``); nothing is
        recomputed. None when there is no runner-up."""
        pointer = self._other_handle()
        return None if pointer is None else Correspondence(pointer)

    @property
    def working(self) -> tuple[Working, Working]:
        """What the pipeline ran on for A and B: ``(kind, vertices)`` each, ``kind``
        ``"input"``, ``"proxy"`` (a dense shape) or ``"refined"`` (a low-poly mesh)."""
        return _working("sc_correspondence", self)

    @property
    def timings(self) -> dict[str, float]:
        """Seconds per stage, and ``total``."""
        out = {}
        for stage in (
            "eigenbasis_a", "eigenbasis_b", "descriptors", "segmentation", "matching",
            "one_to_one", "total",
        ):
            value = ctypes.c_double()
            _check(lib.sc_correspondence_seconds(self, stage.encode(), ctypes.byref(value)))
            out[stage] = value.value
        return out


class Symmetry(_Handle):
    """The result of :func:`detect_symmetry` (immutable)."""

    _free = lib.sc_symmetry_free

    @property
    def regions(self) -> NDArray[np.uint32]:
        """Region of every vertex."""
        n = lib.sc_symmetry_n_vertices(self)
        return _fill(lib.sc_symmetry_regions, self, shape=n, dtype=np.uint32, ctype=ctypes.c_uint32)

    @property
    def region_groups(self) -> NDArray[np.uint32]:
        """Group of every region: regions of one group are symmetric copies."""
        n = lib.sc_symmetry_n_regions(self)
        return _fill(lib.sc_symmetry_region_groups, self, shape=n, dtype=np.uint32, ctype=ctypes.c_uint32)

    @property
    def groups(self) -> list[list[int]]:
        """List of groups, each a sorted list of regions."""
        groups: list[list[int]] = [[] for _ in range(lib.sc_symmetry_n_groups(self))]
        for region, group in enumerate(self.region_groups):
            groups[group].append(region)
        return groups

    def colors(self) -> NDArray[np.uint8]:
        """(n_vertices, 4) uint8 RGBA: a symmetric group shares a colour, others dark grey."""
        n = lib.sc_symmetry_n_vertices(self)
        return _fill(lib.sc_symmetry_colors, self, shape=(n, 4), dtype=np.uint8, ctype=ctypes.c_uint8)


def match(
    a: Shape,
    b: Shape,
    progress: ProgressCallback | None = None,
    *,
    landmarks: Landmarks | None = None,
    **options: Unpack[RegionOptions],
) -> Correspondence:
    """Region correspondence between shapes ``a`` and ``b``. ``options`` are named options
    (``k_min=5, k_max=10, one_to_one=True, ...``; :class:`RegionOptions`, see
    :func:`options`). ``progress``, if given, is called as ``progress(stage, fraction)`` at
    least every 0.2 s and cancels by returning a falsy value other than None (``False``,
    ``0``, ``np.False_``): :class:`ShapecorrError` with status ``CANCELLED``. Ctrl-C cancels
    and raises KeyboardInterrupt. A job over ``memory_limit_mib``, ``time_limit_s`` or
    ``max_vertices`` raises :class:`ResourceLimitError`.

    ``landmarks``: pairs ``(vertex of A, vertex of B)`` known to correspond (0-based input
    indices; a sequence of pairs or an (n, 2) integer array; at most 100): the answer is
    chosen to agree with them (two pairs on one side of a body settle every symmetric
    choice). ``placement="auto"`` (the default), ``"ignore"`` or ``"trust"``: how where the
    shapes stand is used (docs/placement.md). A bad landmark (past the end of its shape,
    left out by the repairs, one vertex with two partners) raises :class:`ShapecorrError`
    naming the pair."""
    _expect(a, Shape, "a"), _expect(b, Shape, "b")
    params = _Params(options, landmarks)
    return Correspondence(_Progress(progress).run(lib.sc_match, a, b, params))


def detect_symmetry(
    shape: Shape, progress: ProgressCallback | None = None, **options: Unpack[RegionOptions]
) -> Symmetry:
    """Groups of mutually symmetric regions of one shape (arguments as :func:`match`)."""
    _expect(shape, Shape, "shape")
    params = _Params(options)
    return Symmetry(_Progress(progress).run(lib.sc_symmetry_detect, shape, params))


class PointwiseMap(_Verdict, _Handle):
    """The result of :func:`pointwise_map` (immutable; safe to share between threads). The
    verdict's properties (:attr:`hypothesis`, :attr:`decided_by`, :attr:`runner_up`, ...)
    read the choice behind :attr:`confidence`."""

    _prefix = "sc_pointwise"

    _free = lib.sc_pointwise_free

    @property
    def n_vertices_a(self) -> int:
        return lib.sc_pointwise_n_vertices(self, _lib.SIDE_A)

    @property
    def n_vertices_b(self) -> int:
        return lib.sc_pointwise_n_vertices(self, _lib.SIDE_B)

    @property
    def map_b_to_a(self) -> NDArray[np.uint32]:
        """For every vertex of B (input order), the vertex of A it corresponds to: a uint32
        array of ``n_vertices_b`` values below ``n_vertices_a``."""
        return _fill(
            lib.sc_pointwise_map_b_to_a, self, shape=self.n_vertices_b, dtype=np.uint32,
            ctype=ctypes.c_uint32,
        )

    @property
    def fmap(self) -> NDArray[np.float64]:
        """The functional map from A to B, a (k_b, k_a) float64 array: it takes a function's
        coefficients in A's Laplacian eigenbasis to the transported function's on B."""
        rows, cols = lib.sc_pointwise_fmap_rows(self), lib.sc_pointwise_fmap_cols(self)
        return _fill(lib.sc_pointwise_fmap, self, shape=(rows, cols), dtype=np.float64, ctype=ctypes.c_double)

    @property
    def confidence(self) -> float | None:
        """The confidence of the answer, a float in [0, 1]: of the map's own choice among
        region hypotheses when it verified several (``p2p_orientation``,
        ``p2p_hypotheses``), else of its :attr:`regions`; None when nothing was verified."""
        return _confidence(lib.sc_pointwise_confidence(self))

    @property
    def warning(self) -> str | None:
        """What to tell the user when the answer is doubtful (one sentence), else None."""
        return _warning(lib.sc_pointwise_warning(self))

    @property
    def doubtful(self) -> bool:
        """True when the answer has a confidence below ``CONFIDENCE_DOUBTFUL_BELOW``."""
        return self.warning is not None

    @functools.cached_property
    def regions(self) -> Correspondence:
        """The region correspondence the map was built on (a :class:`Correspondence`; its
        timings count the region stages only)."""
        return Correspondence(_new_handle(lib.sc_pointwise_regions, self))

    @property
    def working(self) -> tuple[Working, Working]:
        """What the map was computed on for A and B (as :attr:`Correspondence.working`)."""
        return _working("sc_pointwise", self)

    @property
    def timings(self) -> dict[str, float]:
        """Seconds per stage: ``eigenbasis_a``, ``eigenbasis_b``, ``regions``, ``fmap``,
        ``refinement`` and ``total``."""
        out = {}
        for stage in ("eigenbasis_a", "eigenbasis_b", "regions", "fmap", "refinement", "total"):
            value = ctypes.c_double()
            _check(lib.sc_pointwise_seconds(self, stage.encode(), ctypes.byref(value)))
            out[stage] = value.value
        return out

    @property
    def taken_as(self) -> Literal["whole", "b_in_a", "a_in_b"]:
        """What the pair was taken to be (option ``partial``, docs/partial.md): ``"whole"``,
        ``"b_in_a"`` (B is a part of A) or ``"a_in_b"`` (A is a part of B)."""
        return lib.sc_pointwise_taken_as(self, None).decode()

    @property
    def partial_given(self) -> bool:
        """True when the ``partial`` option decided :attr:`taken_as`, not the measurement."""
        given = ctypes.c_bool()
        lib.sc_pointwise_taken_as(self, ctypes.byref(given))
        return given.value

    @property
    def covered_share(self) -> float:
        """The share of A's area that has a counterpart on B, in [0, 1]."""
        return lib.sc_pointwise_covered_share(self)

    @property
    def covered_a(self) -> NDArray[np.bool_]:
        """For every vertex of A, whether B's image covers it (a bool array)."""
        return _fill(
            lib.sc_pointwise_covered, self, _lib.SIDE_A, shape=self.n_vertices_a,
            dtype=np.bool_, ctype=ctypes.c_bool,
        )

    @property
    def covered_b(self) -> NDArray[np.bool_]:
        """For every vertex of B, whether it has a counterpart on A (all of them unless A was
        taken as a part of B): a transfer from A to B should write only these."""
        return _fill(
            lib.sc_pointwise_covered, self, _lib.SIDE_B, shape=self.n_vertices_b,
            dtype=np.bool_, ctype=ctypes.c_bool,
        )

    def other_answer(self) -> PointwiseMap | None:
        """The other answer: a new :class:`PointwiseMap` holding the :attr:`runner_up`'s
        vertex map (every vertex of B), functional map and one-to-one regions, with its
        verdict (``decided_by == "other answer"``); nothing is recomputed. It works with
        :func:`surface_map` like this one. None when there is no runner-up."""
        pointer = self._other_handle()
        return None if pointer is None else PointwiseMap(pointer)

    def __repr__(self) -> str:
        return f"<shapecorr.PointwiseMap {self.n_vertices_b} vertices of B -> {self.n_vertices_a} of A>"


def pointwise_map(
    a: Shape,
    b: Shape,
    progress: ProgressCallback | None = None,
    *,
    landmarks: Landmarks | None = None,
    **options: Unpack[PointwiseOptions],
) -> PointwiseMap:
    """Point-to-point map from shape ``b`` to shape ``a``: the region correspondence of
    :func:`match`, then a functional map constrained by the matched regions, refined by
    ZoomOut. ``options`` are named options as for :func:`match`, plus the pointwise map's
    (``p2p_fmap_size=40``, ``p2p_regions="one-to-one"`` (``"none"``, ``"one-to-one"``,
    ``"symmetric"``, or 0, 1, 2), ``p2p_refinement="zoomout"`` (``"none"``, ``"zoomout"``,
    ``"icp"``, or 0, 1, 2), ``p2p_wks=False``, ...; :class:`PointwiseOptions`, see
    :func:`options`). ``progress`` as for :func:`match`; the last stage is
    ``"pointwise_map"``. ``landmarks`` and ``placement`` as for :func:`match`; every landmark
    of B maps exactly to its partner. Returns a :class:`PointwiseMap`."""
    _expect(a, Shape, "a"), _expect(b, Shape, "b")
    params = _Params(options, landmarks)
    return PointwiseMap(_Progress(progress).run(lib.sc_pointwise_map, a, b, params))


class SurfaceMap(_Handle):
    """The result of :func:`surface_map`: where every vertex of B lands on A's surface
    (immutable; safe to share between threads)."""

    _free = lib.sc_surface_map_free

    @property
    def n_vertices_a(self) -> int:
        return lib.sc_surface_map_n_vertices(self, _lib.SIDE_A)

    @property
    def n_vertices_b(self) -> int:
        return lib.sc_surface_map_n_vertices(self, _lib.SIDE_B)

    @property
    def points(self) -> tuple[NDArray[np.uint32], NDArray[np.float64]]:
        """``(vertices, weights)``: for every vertex of B, three vertices of A (uint32,
        ``(n_vertices_b, 3)``) and their weights (float64, summing to 1, heaviest first)."""
        n = self.n_vertices_b
        vertices = np.empty((n, 3), dtype=np.uint32)
        weights = np.empty((n, 3), dtype=np.float64)
        _check(lib.sc_surface_map_points(
            self, _ptr(vertices, ctypes.c_uint32), _ptr(weights, ctypes.c_double), vertices.size,
        ))
        return vertices, weights

    @property
    def nearest(self) -> NDArray[np.uint32]:
        """For every vertex of B, the vertex of A whose value ``mode="nearest"`` takes
        (uint32, ``(n_vertices_b,)``)."""
        return _fill(
            lib.sc_surface_map_nearest, self, shape=self.n_vertices_b, dtype=np.uint32,
            ctype=ctypes.c_uint32,
        )

    def transfer(
        self, values: ArrayLike, mode: TransferMode = "interpolate", max_influences: int = 0
    ) -> NDArray[Any]:
        """``values`` on A's vertices (``(n_vertices_a,)`` or ``(n_vertices_a, channels)``)
        carried to B's vertices, same dimensionality. ``mode``: ``"interpolate"``
        (continuous data), ``"nearest"`` (labels, ids) or ``"weights"`` (skin weights:
        non-negative rows, at most ``max_influences`` kept (0: all), each row of B summing
        to 1). The result is float64, except in ``"nearest"`` mode for values that are not
        floats (integers of any size, bools, strings): these are copied exactly, in their
        own dtype (an id above 2**53 stays itself). Numbers only in the other modes
        (TypeError for strings or objects)."""
        if mode not in _lib.TRANSFER_MODES:
            raise ValueError(f"mode must be one of {sorted(_lib.TRANSFER_MODES)}, got {mode!r}")
        given = np.asarray(values)
        if given.ndim not in (1, 2):
            raise ValueError(f"values must be 1-D or 2-D, got shape {given.shape}")
        if mode == "nearest" and given.dtype.kind not in "fc":
            if given.shape[0] != self.n_vertices_a:
                raise ValueError(
                    f"values has {given.shape[0]} rows, A has {self.n_vertices_a} vertices"
                )
            return given[self.nearest]
        if given.dtype.kind not in "biuf":
            raise TypeError(f"values must be numbers, got an array of {given.dtype}")
        values = np.ascontiguousarray(given, dtype=np.float64)
        channels = 1 if values.ndim == 1 else values.shape[1]
        shape = (self.n_vertices_b,) if values.ndim == 1 else (self.n_vertices_b, channels)
        out = np.empty(shape, dtype=np.float64)
        _check(lib.sc_surface_map_transfer(
            self, _ptr(values, ctypes.c_double), values.size, channels,
            _lib.TRANSFER_MODES[mode], max_influences, _ptr(out, ctypes.c_double), out.size,
        ))
        return out

    def transfer_corners(
        self, a: Shape, faces_a: ArrayLike, corner_values: ArrayLike, faces_b: ArrayLike
    ) -> NDArray[np.float64]:
        """Per-corner values of A's triangles ``faces_a`` (``(n_a_triangles, 3)`` vertex
        indices of shape ``a``, the triangles it was made from) carried to the corners of
        B's triangles ``faces_b``, seams kept (texture coordinates: a UV island of A stays
        one island on B, no triangle of B spans A's seam). ``corner_values`` is
        ``(n_a_triangles, 3)`` or ``(n_a_triangles, 3, channels)``; the result is float64,
        ``(n_b_triangles, 3)`` or ``(n_b_triangles, 3, channels)``. Face indices must be
        integers (TypeError for floats) in the range of uint32 (ValueError)."""
        _expect(a, Shape, "a")
        triangles_a = _faces(faces_a, "faces_a")
        triangles_b = _faces(faces_b, "faces_b")
        values = np.asarray(corner_values)
        if values.dtype.kind not in "biuf":
            raise TypeError(f"corner_values must be numbers, got an array of {values.dtype}")
        values = np.ascontiguousarray(values, dtype=np.float64)
        if values.ndim not in (2, 3) or values.shape[:2] != (len(triangles_a), 3):
            raise ValueError(f"corner_values must be ({len(triangles_a)}, 3[, channels]), got {values.shape}")
        channels = 1 if values.ndim == 2 else values.shape[2]
        shape = (len(triangles_b), 3) if values.ndim == 2 else (len(triangles_b), 3, channels)
        out = np.empty(shape, dtype=np.float64)
        _check(lib.sc_surface_map_transfer_corners(
            self, a, _ptr(triangles_a, ctypes.c_uint32), triangles_a.size, _ptr(values, ctypes.c_double),
            values.size, _ptr(triangles_b, ctypes.c_uint32), triangles_b.size, channels,
            _ptr(out, ctypes.c_double), out.size,
        ))
        return out

    def __repr__(self) -> str:
        return f"<shapecorr.SurfaceMap {self.n_vertices_b} vertices of B -> surface of A>"


def _faces(faces, name):
    """An (m, 3) array of vertex indices as contiguous uint32: TypeError for indices that are
    not integers (floats would be truncated), ValueError for a wrong shape or an index
    outside uint32 (a negative one would wrap)."""
    faces = np.asarray(faces)
    if faces.size and faces.dtype.kind not in "iu":
        raise TypeError(f"{name} must hold integer vertex indices, got {faces.dtype}")
    if faces.size and (faces.ndim != 2 or faces.shape[1] != 3):
        raise ValueError(f"{name} must have shape (m, 3), got {faces.shape}")
    if faces.size and (faces.min() < 0 or faces.max() > np.iinfo(np.uint32).max):
        bad = faces.min() if faces.min() < 0 else faces.max()
        raise ValueError(f"{name}: vertex index {bad} is out of range")
    return np.ascontiguousarray(faces, dtype=np.uint32).reshape(-1, 3)


def surface_map(
    a: Shape, b: Shape, pointwise: PointwiseMap, progress: ProgressCallback | None = None
) -> SurfaceMap:
    """Where every vertex of B lands on A's surface, from ``pointwise`` (the
    :class:`PointwiseMap` of ``a`` and ``b``): the vertex map smoothed over B's neighbours
    and projected onto A's triangles. Carry data with :meth:`SurfaceMap.transfer`.
    ``progress`` as for :func:`match` (stage ``"transfer"``)."""
    _expect(a, Shape, "a"), _expect(b, Shape, "b"), _expect(pointwise, PointwiseMap, "pointwise")
    return SurfaceMap(_Progress(progress).run(lib.sc_surface_map_new, a, b, pointwise))
