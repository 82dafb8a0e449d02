"""The Python binding against the real library: the same cases as tests/c/test_api.c
(life cycle, every error path, cancellation, threads, versions), plus the loader, freeing at
interpreter exit and the README's Python example."""

import ctypes
import math
import os
import re
import subprocess
import sys
import textwrap
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest

import shapecorr
from shapecorr import ResourceLimitError, ShapecorrError, _lib

REPOSITORY = Path(__file__).resolve().parents[3]
SIZE = 2500


@pytest.fixture(scope="module")
def humanoids():
    return shapecorr.Shape.figure("humanoid", 0, SIZE), shapecorr.Shape.figure("humanoid", 3, SIZE)


def symmetric_accuracy(result, matches):
    """Fraction of vertices (shared vertex order) whose two regions are matched."""
    pairs = {tuple(m) for m in matches.tolist()}
    ra, rb = result.regions_a, result.regions_b
    return float(np.mean([(int(x), int(y)) in pairs for x, y in zip(ra, rb)]))


# ------------------------------------------------------------------------ versions, loader


def test_versions_agree_everywhere():
    cargo = re.search(r'^version = "(.*)"$', (REPOSITORY / "Cargo.toml").read_text(), re.M)
    pyproject = re.search(
        r'^version = "(.*)"$', (REPOSITORY / "bindings/python/pyproject.toml").read_text(), re.M
    )
    assert shapecorr.__version__ == shapecorr.version() == cargo.group(1) == pyproject.group(1)
    major, minor, patch = (int(x) for x in cargo.group(1).split("."))
    assert (_lib.lib.sc_version_major(), _lib.lib.sc_version_minor(), _lib.lib.sc_version_patch()) == (
        major,
        minor,
        patch,
    )
    assert _lib.lib.sc_abi_version() == _lib.ABI_VERSION


def test_every_header_function_is_declared_and_nothing_else():
    header = (REPOSITORY / "include" / "shapecorr.h").read_text()
    declared_in_header = set(re.findall(r"\b(sc_[a-z0-9_]+)\(", header))
    # Names that appear followed by "(" only inside comments are not functions.
    functions = {
        name
        for name in declared_in_header
        if re.search(rf"^[A-Za-z0-9_ ]+[ *]{name}\(", header, re.M)
    }
    assert functions == set(_lib.FUNCTIONS)


def test_doubtful_threshold_matches_the_header():
    header = (REPOSITORY / "include" / "shapecorr.h").read_text()
    value = re.search(r"#define SC_CONFIDENCE_DOUBTFUL_BELOW ([0-9.]+)", header)
    assert value and float(value.group(1)) == shapecorr.CONFIDENCE_DOUBTFUL_BELOW


def check_confidence(result):
    """``confidence`` is a float in [0, 1] or None; ``warning`` a non-empty str exactly when
    the answer is doubtful, else None."""
    confidence, warning = result.confidence, result.warning
    assert confidence is None or (isinstance(confidence, float) and 0.0 <= confidence <= 1.0), confidence
    assert warning is None or (isinstance(warning, str) and warning), warning
    doubtful = confidence is not None and confidence < shapecorr.CONFIDENCE_DOUBTFUL_BELOW
    assert (warning is not None) == doubtful == result.doubtful, (confidence, warning)
    if warning is not None:
        assert "doubtful" in warning and f"{confidence:.2f}" in warning, warning


def test_status_names_match_the_header():
    header = (REPOSITORY / "include" / "shapecorr.h").read_text()
    in_header = {int(v): n for n, v in re.findall(r"SC_STATUS_([A-Z_]+) = (\d+)", header)}
    assert in_header == _lib.STATUS_NAMES


def run_python(code, **env):
    return subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)],
        capture_output=True,
        text=True,
        env={**os.environ, **env},
        timeout=120,
    )


def test_shapecorr_lib_overrides_the_loader():
    library = REPOSITORY / "target" / "release" / _lib.LIBRARY_NAME
    done = run_python(
        "import shapecorr._lib as l; print(l.LIBRARY_PATH)", SHAPECORR_LIB=str(library)
    )
    assert done.returncode == 0, done.stderr
    assert Path(done.stdout.strip()) == library
    missing = run_python("import shapecorr", SHAPECORR_LIB="/nonexistent/libshapecorr.so")
    assert missing.returncode != 0
    assert "SHAPECORR_LIB" in missing.stderr and "/nonexistent/libshapecorr.so" in missing.stderr


def test_objects_alive_at_interpreter_exit_are_freed_cleanly():
    done = run_python(
        """
        import shapecorr
        a = shapecorr.Shape.figure("star4", 0, 800)
        b = shapecorr.Shape.figure("star4", 1, 800)
        keep = [a, b, shapecorr.match(a, b, k_max=6), shapecorr.detect_symmetry(a, k_max=6)]
        a.close(); a.close()   # closing twice is harmless
        print("ok")
        """
    )
    assert done.returncode == 0 and done.stdout.strip() == "ok", done.stderr
    assert done.stderr == ""


# --------------------------------------------------------------------------------- options


def test_options_and_defaults():
    table = {name: (kind, default) for name, kind, doc, default in shapecorr.options()}
    assert table["k_min"] == ("int", 5)
    assert table["k_max"] == ("int", 10)
    assert table["gap_ratio"] == ("float", 0.9)
    assert table["one_to_one"] == ("bool", True)
    assert len(table) == _lib.lib.sc_option_count()
    info = {option.name: option for option in shapecorr.options()}
    assert info["k_min"].kind == "int" and info["k_min"].default == 5 and info["k_min"].doc
    assert info["k_min"].choices == ()
    assert info["p2p_refinement"].choices == ("none", "zoomout", "icp")
    assert info["p2p_regions"].choices == ("none", "one-to-one", "symmetric")
    assert info["placement"].choices == ("auto", "ignore", "trust")
    assert info["placement"].default == _lib.PLACEMENT_AUTO
    assert [o.name for o in shapecorr.options() if o.choices] == [
        "p2p_regions", "p2p_refinement", "placement", "partial"
    ]
    assert info["partial"].choices == ("auto", "off", "b_in_a", "a_in_b")


def read_back(options, name):
    """The integer value of option ``name`` after setting ``options`` as the functions do."""
    params, value = shapecorr._Params(options), ctypes.c_int64()
    shapecorr._check(_lib.lib.sc_params_get_int(params, name.encode(), ctypes.byref(value)))
    return value.value


def test_choices_are_taken_by_name_or_by_value():
    for option in shapecorr.options():
        for value, name in enumerate(option.choices):
            assert read_back({option.name: name}, option.name) == value, name
            assert read_back({option.name: name.upper()}, option.name) == value, name
            assert read_back({option.name: value}, option.name) == value, name
            assert read_back({option.name: np.int32(value)}, option.name) == value, name
    with pytest.raises(ShapecorrError) as error:
        read_back({"p2p_refinement": "zoom"}, "p2p_refinement")
    assert error.value.status_name == "INVALID_PARAMETER"
    assert "none (0), zoomout (1), icp (2)" in error.value.message
    with pytest.raises(ShapecorrError) as error:
        read_back({"k_min": "five"}, "k_min")
    assert error.value.status_name == "INVALID_ARGUMENT"
    with pytest.raises(ShapecorrError) as error:
        read_back({"p2p_refinement": 2.5}, "p2p_refinement")
    assert error.value.status_name == "INVALID_ARGUMENT"
    assert "'icp'" in error.value.message, error.value.message


def test_the_typed_options_are_the_table():
    """``RegionOptions`` and ``PointwiseOptions`` (the keyword arguments' types) name every
    option of the library with its kind, the choices with their names."""
    region = shapecorr.RegionOptions.__annotations__
    pointwise = shapecorr.PointwiseOptions.__annotations__
    table = shapecorr.options()
    assert set(pointwise) == {o.name for o in table}
    assert set(region) == {o.name for o in table if not o.name.startswith("p2p_")}
    assert not shapecorr.PointwiseOptions.__required_keys__
    expected = {"int": "IntValue", "float": "FloatValue", "bool": "BoolValue"}
    for option in table:
        annotation = pointwise[option.name]
        text = getattr(annotation, "__forward_arg__", annotation)
        if option.choices:
            alias = getattr(shapecorr, text)
            literal = [arg for arg in alias.__args__ if getattr(arg, "__origin__", None) is not None]
            names = {name for arg in literal for name in arg.__args__}
            assert names == set(option.choices), option.name
        else:
            assert text == expected[option.kind], option.name


def test_a_job_over_its_limits_raises_resource_limit_error(humanoids):
    """A job refused by the memory ceiling is a ResourceLimitError (status RESOURCE_LIMIT,
    naming the limit), which ``except ShapecorrError`` still catches; the same option out of
    its range is a plain INVALID_PARAMETER."""
    a, b = shapecorr.Shape.figure("humanoid", 0, 700), shapecorr.Shape.figure("humanoid", 3, 700)
    for call in [
        lambda: shapecorr.match(a, b, memory_limit_mib=1),
        lambda: shapecorr.detect_symmetry(a, memory_limit_mib=1),
        lambda: shapecorr.pointwise_map(a, b, memory_limit_mib=1),
    ]:
        with pytest.raises(ResourceLimitError) as error:
            call()
        assert error.value.status == _lib.STATUS_RESOURCE_LIMIT == 19
        assert error.value.status_name == "RESOURCE_LIMIT"
        assert error.value.limit == "memory_limit_mib"
        assert "needs about" in error.value.message
        assert "raise memory_limit_mib" in error.value.message
        try:
            call()
        except ShapecorrError as caught:  # what callers wrote before
            assert isinstance(caught, ResourceLimitError)
    with pytest.raises(ResourceLimitError) as error:
        shapecorr.match(a, b, max_vertices=100)
    assert error.value.limit == "max_vertices", error.value.message
    with pytest.raises(ShapecorrError) as error:
        shapecorr.match(a, b, memory_limit_mib=-1)
    assert error.value.status_name == "INVALID_PARAMETER"
    assert not isinstance(error.value, ResourceLimitError)


def test_option_errors(humanoids):
    a, b = humanoids
    with pytest.raises(ShapecorrError) as error:
        shapecorr.match(a, b, k_mni=3)
    assert error.value.status_name == "UNKNOWN_OPTION"
    assert "k_mni" in error.value.message and "k_min" in error.value.message
    for bad in [dict(k_min=2.5), dict(k_min=True), dict(one_to_one=1)]:
        with pytest.raises(ShapecorrError) as error:
            shapecorr.match(a, b, **bad)
        assert error.value.status_name == "INVALID_ARGUMENT", bad
    for bad in [dict(k_min=-1), dict(gap_ratio=math.nan), dict(k_min=8, k_max=5)]:
        with pytest.raises(ShapecorrError) as error:
            shapecorr.match(a, b, **bad)
        assert error.value.status_name == "INVALID_PARAMETER", bad


# ---------------------------------------------------------------------------- bad shapes


def sphere_points(n=40):
    i = np.arange(n)
    z = -1 + (2 * i + 1) / n
    r = np.sqrt(1 - z * z)
    return np.stack([r * np.cos(2.4 * i), r * np.sin(2.4 * i), z], axis=1)


@pytest.mark.parametrize(
    "make, status",
    [
        (lambda p: shapecorr.Shape.point_cloud(np.where(np.arange(120).reshape(40, 3) == 7, np.nan, p)), "NON_FINITE_COORDINATE"),
        (lambda p: shapecorr.Shape.point_cloud(np.where(np.arange(120).reshape(40, 3) == 7, np.inf, p)), "NON_FINITE_COORDINATE"),
        (lambda p: shapecorr.Shape.mesh(p, [[0, 1, 40]]), "FACE_INDEX_OUT_OF_RANGE"),
        (lambda p: shapecorr.Shape.mesh(p, [[0, 1, -1]]), "FACE_INDEX_OUT_OF_RANGE"),
        (lambda p: shapecorr.Shape.mesh(np.zeros((0, 3)), np.zeros((0, 3))), "TOO_FEW_VERTICES"),
        (lambda p: shapecorr.Shape.point_cloud(p[:10]), "TOO_FEW_VERTICES"),
        (lambda p: shapecorr.Shape.mesh(p, np.zeros((0, 3))), "ZERO_AREA"),
        (lambda p: shapecorr.Shape.read("/nonexistent/shape.ply"), "FILE_ERROR"),
        (lambda p: shapecorr.Shape.figure("dragon"), "INVALID_ARGUMENT"),
        (lambda p: shapecorr.Shape.figure("humanoid", pose=99, vertices=1000), "INVALID_PARAMETER"),
    ],
)
def test_bad_shapes_raise_with_status_and_message(make, status):
    with pytest.raises(ShapecorrError) as error:
        make(sphere_points())
    assert error.value.status_name == status
    assert error.value.message


def test_malformed_file(tmp_path):
    path = tmp_path / "bad.ply"
    path.write_text("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1 2\n")
    with pytest.raises(ShapecorrError) as error:
        shapecorr.Shape.read(path)
    assert error.value.status_name == "FILE_ERROR" and "bad.ply" in error.value.message


def test_wrong_array_shapes_are_value_errors():
    with pytest.raises(ValueError):
        shapecorr.Shape.point_cloud(np.zeros((40, 2)))
    with pytest.raises(ValueError):
        shapecorr.Shape.mesh(sphere_points(), [0, 1, 2, 3])


def test_raw_api_null_and_buffer_errors(humanoids):
    lib = _lib.lib
    a, b = humanoids
    assert lib.sc_shape_n_vertices(None) == 0
    out = ctypes.c_void_p()
    assert lib.sc_match(None, b, None, _lib.PROGRESS(), None, ctypes.byref(out)) == 1
    assert lib.sc_match(a, b, None, _lib.PROGRESS(), None, None) == 1
    assert "out_correspondence" in lib.sc_last_error().decode()
    n = a.n_vertices
    buffer = np.full(3 * n, -1.0)
    status = lib.sc_shape_vertices(a, buffer.ctypes.data_as(_lib.c_f64p), 3 * n - 1)
    assert _lib.STATUS_NAMES[status] == "BUFFER_TOO_SMALL"
    assert np.all(buffer == -1.0), "nothing written on failure"
    assert lib.sc_shape_vertices(a, None, 3 * n) == 1


# ----------------------------------------------------------------------------- life cycle


def test_life_cycle(humanoids):
    a, b = humanoids
    stages = []
    result = shapecorr.match(a, b, progress=lambda stage, f: stages.append((stage, f)) or True)
    assert {s for s, _ in stages} >= {"eigenbasis", "segmentation", "matching"}
    assert all(0.0 <= f <= 1.0 for _, f in stages)
    assert 5 <= result.k <= 10
    assert result.regions_a.shape == (a.n_vertices,) and result.regions_a.dtype == np.uint32
    sym = symmetric_accuracy(result, result.matches)
    assert sym >= 0.9, sym
    one = result.matches_one_to_one
    assert set(map(tuple, one.tolist())) <= set(map(tuple, result.matches.tolist()))
    colors_a, colors_b = result.colors("a"), result.colors("b")
    assert colors_a.shape == (a.n_vertices, 4) and np.all(colors_b[:, 3] == 255)
    pairs = {tuple(m) for m in one.tolist()}
    in_one = np.array([(int(x), int(y)) in pairs for x, y in zip(result.regions_a, result.regions_b)])
    assert np.all(colors_a[in_one] == colors_b[in_one])
    graph = result.graph("b")
    assert abs(graph["areas"].sum() - 1.0) < 1e-9
    assert graph["descriptors"].shape == (result.n_regions("b"), 15)
    assert np.all(graph["edges"][:, 0] < graph["edges"][:, 1])
    timings = result.timings
    assert 0 < timings["eigenbasis_a"] <= timings["total"]
    check_confidence(result)
    assert result.confidence is not None, "verified by default"


def test_dissimilar_shapes_are_doubtful_with_a_warning():
    """An eight-limbed star against a quadruped: no consistent map (confidence 0.003 measured;
    a six-limbed star, 0.41, was too near the threshold after the confidence was recalibrated,
    docs/decisions.md, "Confidence")."""
    a, b = shapecorr.Shape.figure("star8", 1, 2000), shapecorr.Shape.figure("quadruped", 1, 2000)
    result = shapecorr.match(a, b)
    check_confidence(result)
    assert result.doubtful and result.confidence < shapecorr.CONFIDENCE_DOUBTFUL_BELOW
    assert result.warning.startswith("doubtful correspondence"), result.warning


def test_no_confidence_without_verification():
    a, b = shapecorr.Shape.figure("star4", 0, 1500), shapecorr.Shape.figure("star4", 2, 1500)
    for options in (dict(verify_hypotheses=False), dict(one_to_one=False)):
        result = shapecorr.match(a, b, **options)
        assert result.confidence is None and result.warning is None, options
        assert not result.doubtful
    lib = _lib.lib
    assert math.isnan(lib.sc_correspondence_confidence(None))
    assert lib.sc_correspondence_warning(None) is None
    assert math.isnan(lib.sc_pointwise_confidence(None))
    assert lib.sc_pointwise_warning(None) is None


def test_working_constants_match_the_header():
    header = (REPOSITORY / "include" / "shapecorr.h").read_text()
    found = dict(re.findall(r"#define SC_WORKING_([A-Z]+) ([0-9]+)", header))
    assert {name: int(value) for name, value in found.items()} == {
        "INPUT": _lib.WORKING_INPUT, "PROXY": _lib.WORKING_PROXY, "REFINED": _lib.WORKING_REFINED,
    }


def test_working_says_input_proxy_or_refined(humanoids):
    """A plain figure runs on itself, a low-poly one (600 vertices, below ``refine_below``)
    on a refined copy with more vertices, a shape above ``proxy_above`` on a smaller proxy."""
    a, b = humanoids
    low = shapecorr.Shape.figure("humanoid", 0, 600)
    assert low.n_vertices < 2000
    result = shapecorr.match(low, b, verify_hypotheses=False)
    working_a, working_b = result.working
    assert isinstance(working_a, shapecorr.Working)
    assert working_a.kind == "refined" and working_a.vertices > low.n_vertices, working_a
    assert working_b == ("input", b.n_vertices, False, 0, 0)
    assert shapecorr.match(a, b, verify_hypotheses=False).working == (
        ("input", a.n_vertices, False, 0, 0), ("input", b.n_vertices, False, 0, 0),
    )
    dense = shapecorr.match(a, b, verify_hypotheses=False, proxy_above=2000, proxy_vertices=1000)
    assert [w.kind for w in dense.working] == ["proxy", "proxy"]
    assert all(w.vertices < 2000 for w in dense.working), dense.working


def test_a_noisy_mesh_is_matched_on_a_smoothed_copy(humanoids):
    """Vertex noise of about 1% of the diagonal: B runs on a smoothed copy of its own
    vertices, said in ``working``; the answer stays on B's vertices and close to the clean
    pair's."""
    a, b = humanoids
    diagonal = float(np.linalg.norm(b.vertices.max(0) - b.vertices.min(0)))
    rng = np.random.default_rng(3)
    noisy = shapecorr.Shape.mesh(b.vertices + rng.normal(0, 0.01 * diagonal / 3**0.5, (b.n_vertices, 3)), b.triangles)
    result = shapecorr.match(a, noisy, verify_hypotheses=False)
    assert result.working == (("input", a.n_vertices, False, 0, 0), ("input", b.n_vertices, True, 0, 0))
    clean = shapecorr.match(a, b, verify_hypotheses=False)
    assert symmetric_accuracy(result, result.matches) >= 0.8 * symmetric_accuracy(clean, clean.matches)


def test_working_raw_api_errors(humanoids):
    a, b = humanoids
    result = shapecorr.match(a, b, verify_hypotheses=False)
    lib = _lib.lib
    kind, vertices = ctypes.c_uint32(7), ctypes.c_size_t(7)
    names = _lib.STATUS_NAMES
    assert names[lib.sc_correspondence_working(result, 2, ctypes.byref(kind), ctypes.byref(vertices), None)] == "INVALID_ARGUMENT"
    assert names[lib.sc_correspondence_working(result, 0, None, ctypes.byref(vertices), None)] == "NULL_ARGUMENT"
    assert names[lib.sc_correspondence_working(None, 0, ctypes.byref(kind), ctypes.byref(vertices), None)] == "NULL_ARGUMENT"
    assert names[lib.sc_pointwise_working(None, 0, ctypes.byref(kind), ctypes.byref(vertices), None)] == "NULL_ARGUMENT"
    assert (kind.value, vertices.value) == (7, 7), "nothing written on failure"


def test_vertices_round_trip_and_float32_input(humanoids):
    a, _ = humanoids
    v, t = a.vertices, a.triangles
    copy = shapecorr.Shape.mesh(v.astype(np.float32), t)
    assert copy.n_vertices == a.n_vertices
    assert np.allclose(copy.vertices, v, atol=1e-6)
    assert np.array_equal(copy.triangles, t)
    assert not copy.is_point_cloud and copy.warnings == []


def test_mesh_against_noisy_point_cloud(humanoids):
    a, b = humanoids
    rng = np.random.default_rng(7)
    cloud = shapecorr.Shape.point_cloud(b.vertices + rng.uniform(-0.001, 0.001, (b.n_vertices, 3)))
    assert cloud.is_point_cloud
    result = shapecorr.match(a, cloud)
    assert symmetric_accuracy(result, result.matches) >= 0.8


def test_cancellation_and_exceptions_in_the_callback(humanoids):
    a, b = humanoids
    with pytest.raises(ShapecorrError) as error:
        shapecorr.match(a, b, progress=lambda stage, f: stage != "segmentation")
    assert error.value.status_name == "CANCELLED"

    def broken(stage, fraction):
        raise ZeroDivisionError("from the callback")

    with pytest.raises(ZeroDivisionError, match="from the callback"):
        shapecorr.match(a, b, progress=broken)


def test_concurrent_matches_on_shared_shapes_give_the_same_answer(humanoids):
    a, b = humanoids
    reference = shapecorr.match(a, b)
    with ThreadPoolExecutor(max_workers=4) as pool:
        results = list(pool.map(lambda _: shapecorr.match(a, b), range(4)))
    for r in results:
        assert np.array_equal(r.regions_a, reference.regions_a)
        assert np.array_equal(r.matches_one_to_one, reference.matches_one_to_one)


def test_symmetry_detection_on_a_star():
    star = shapecorr.Shape.figure("star5", 0, SIZE)
    symmetry = shapecorr.detect_symmetry(star)
    sizes = [len(g) for g in symmetry.groups]
    assert max(sizes) == 5, sizes
    assert sum(sizes) == len(symmetry.region_groups)
    assert symmetry.regions.shape == (star.n_vertices,)
    assert symmetry.colors().shape == (star.n_vertices, 4)


def test_readme_python_example(tmp_path):
    readme = (REPOSITORY / "README.md").read_text()
    match = re.search(r"<!-- readme-python-example -->\s*```python\n(.*?)```", readme, re.S)
    assert match, "README.md has no Python example after the marker"
    code = match.group(1)
    assert len(code.strip().splitlines()) <= 12
    cli = REPOSITORY / "target" / "release" / "shapecorr"
    for name, pose in [("a.ply", 0), ("b.ply", 4)]:
        subprocess.run(
            [str(cli), "synth", "--pose", str(pose), "--vertices", "3000", "--out", str(tmp_path / name)],
            check=True,
            capture_output=True,
        )
    done = subprocess.run(
        [sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 0, done.stderr
    assert "region 0 of A" in done.stdout, done.stdout


# ------------------------------------------------------------------------- pointwise maps


def permuted_copy(shape, seed):
    """B = A with its vertices permuted (vertex j of B is vertex perm[j] of A) and its
    triangles re-indexed: an isometric copy whose true map from B to A is ``perm``."""
    perm = np.random.default_rng(seed).permutation(shape.n_vertices)
    inverse = np.empty_like(perm)
    inverse[perm] = np.arange(len(perm))
    return shapecorr.Shape.mesh(shape.vertices[perm], inverse[shape.triangles]), perm


def test_pointwise_options_and_defaults():
    table = {name: (kind, default) for name, kind, doc, default in shapecorr.options()}
    assert table["p2p_eigenpairs"] == ("int", 100)
    assert table["p2p_fmap_size"] == ("int", 40)
    assert table["p2p_regions"] == ("int", _lib.P2P_REGIONS_ONE_TO_ONE)
    assert table["p2p_refinement"] == ("int", _lib.P2P_REFINEMENT_ZOOMOUT)
    assert table["p2p_region_distances"] == ("bool", True)
    assert table["p2p_wks"] == ("bool", False)
    assert table["p2p_laplacian_weight"] == ("float", 1.0)
    assert table["p2p_zoomout_end"] == ("int", 100)


def test_permuted_copy_is_mapped_back(humanoids):
    a = shapecorr.Shape.figure("humanoid", 3, SIZE)
    b, perm = permuted_copy(a, seed=5)
    stages = []
    result = shapecorr.pointwise_map(a, b, progress=lambda stage, f: stages.append((stage, f)) or True)
    assert stages[-1][0] == "pointwise_map" and all(0.0 <= f <= 1.0 for _, f in stages)
    assert {s for s, _ in stages} >= {"eigenbasis", "segmentation", "matching", "pointwise_map"}
    assert (result.n_vertices_a, result.n_vertices_b) == (a.n_vertices, b.n_vertices)
    assert result.working == (("input", a.n_vertices, False, 0, 0), ("input", b.n_vertices, False, 0, 0))
    assert result.working == result.regions.working
    mapped = result.map_b_to_a
    assert mapped.dtype == np.uint32 and mapped.shape == (b.n_vertices,)
    assert mapped.max() < a.n_vertices
    exact = float(np.mean(mapped == perm))
    v = a.vertices
    diagonal = np.linalg.norm(v.max(axis=0) - v.min(axis=0))
    error = np.linalg.norm(v[mapped] - v[perm], axis=1).mean() / diagonal
    assert exact >= 0.95, exact
    assert error < 0.005, error
    fmap = result.fmap
    assert fmap.dtype == np.float64 and fmap.shape == (100, 100)
    assert np.all(np.isfinite(fmap))
    # Both shapes have unit area, so constants map to constants: |C[0, 0]| = 1.
    assert abs(abs(fmap[0, 0]) - 1.0) < 1e-6
    regions = result.regions
    assert isinstance(regions, shapecorr.Correspondence)
    assert regions is result.regions
    assert regions.regions_b.shape == (b.n_vertices,) and len(regions.matches_one_to_one) >= 5
    timings = result.timings
    assert set(timings) == {"eigenbasis_a", "eigenbasis_b", "regions", "fmap", "refinement", "total"}
    assert 0 < timings["eigenbasis_a"] <= timings["total"]
    assert "PointwiseMap" in repr(result)
    check_confidence(result)
    check_confidence(regions)
    assert result.confidence is not None, "verified by default"


@pytest.mark.parametrize(
    "options, size",
    [
        (dict(p2p_refinement="icp"), 40),
        (dict(p2p_refinement=_lib.P2P_REFINEMENT_NONE), 40),
        (dict(p2p_regions=_lib.P2P_REGIONS_SYMMETRIC), 100),
        (dict(p2p_regions=_lib.P2P_REGIONS_NONE, p2p_wks=True), 100),
        (dict(p2p_eigenpairs=60, p2p_zoomout_end=60, p2p_fmap_size=20), 60),
    ],
)
def test_every_method_maps_a_permuted_copy_back(options, size):
    a = shapecorr.Shape.figure("humanoid", 3, 1500)
    b, perm = permuted_copy(a, seed=9)
    result = shapecorr.pointwise_map(a, b, **options)
    assert result.fmap.shape == (size, size), options
    assert np.mean(result.map_b_to_a == perm) >= 0.95, options


def test_two_poses_are_mapped_up_to_the_mirror(humanoids):
    """Poses of one figure share the vertex order, so the truth is the identity, or its
    mirror image (the rest pose is symmetric under x -> -x; a left/right flip is allowed)."""
    a, b = humanoids
    mapped = shapecorr.pointwise_map(a, b).map_b_to_a
    v = a.vertices
    mirrored = v * np.array([-1.0, 1.0, 1.0])
    mirror = np.array([np.argmin(np.sum((v - p) ** 2, axis=1)) for p in mirrored])
    assert np.allclose(v[mirror], mirrored, atol=1e-9), "the rest pose is symmetric"
    diagonal = np.linalg.norm(v.max(axis=0) - v.min(axis=0))
    plain = np.linalg.norm(v[mapped] - v, axis=1).mean() / diagonal
    flipped = np.linalg.norm(v[mirror[mapped]] - v, axis=1).mean() / diagonal
    assert min(plain, flipped) < 0.04, (plain, flipped)


def test_pointwise_option_errors(humanoids):
    a, b = humanoids
    for bad in [dict(p2p_fmap_size=2.5), dict(p2p_wks=1), dict(p2p_regions=True)]:
        with pytest.raises(ShapecorrError) as error:
            shapecorr.pointwise_map(a, b, **bad)
        assert error.value.status_name == "INVALID_ARGUMENT", bad
    for bad in [
        dict(p2p_regions=3),
        dict(p2p_refinement=-1),
        dict(p2p_laplacian_weight=math.inf),
        dict(p2p_fmap_size=120),
        dict(p2p_zoomout_end=150),
        dict(p2p_regions=_lib.P2P_REGIONS_NONE),
        dict(k_min=8, k_max=5),
    ]:
        with pytest.raises(ShapecorrError) as error:
            shapecorr.pointwise_map(a, b, **bad)
        assert error.value.status_name == "INVALID_PARAMETER", bad
    with pytest.raises(ShapecorrError) as error:
        shapecorr.pointwise_map(a, b, p2p_nonsense=1)
    assert error.value.status_name == "UNKNOWN_OPTION"


def test_pointwise_cancellation_and_raw_api_errors(humanoids):
    a, b = humanoids
    with pytest.raises(ShapecorrError) as error:
        shapecorr.pointwise_map(a, b, progress=lambda stage, f: stage != "pointwise_map")
    assert error.value.status_name == "CANCELLED"
    lib = _lib.lib
    out = ctypes.c_void_p()
    assert lib.sc_pointwise_map(None, b, None, _lib.PROGRESS(), None, ctypes.byref(out)) == 1
    assert lib.sc_pointwise_map(a, b, None, _lib.PROGRESS(), None, None) == 1
    assert "out_pointwise" in lib.sc_last_error().decode()
    assert out.value is None, "nothing written on failure"
    assert lib.sc_pointwise_n_vertices(None, _lib.SIDE_B) == 0
    result = shapecorr.pointwise_map(a, b, p2p_refinement=_lib.P2P_REFINEMENT_NONE)
    assert result.fmap.shape == (40, 40), "unrefined: the first map's size"
    n = result.n_vertices_b
    buffer = np.full(n, 7, dtype=np.uint32)
    status = lib.sc_pointwise_map_b_to_a(result, buffer.ctypes.data_as(_lib.c_u32p), n - 1)
    assert _lib.STATUS_NAMES[status] == "BUFFER_TOO_SMALL"
    assert np.all(buffer == 7), "nothing written on failure"
    assert lib.sc_pointwise_map_b_to_a(result, None, n) == 1
    with pytest.raises(ShapecorrError) as error:
        _check_seconds(result, "lunch")
    assert error.value.status_name == "INVALID_ARGUMENT"


def _check_seconds(result, stage):
    value = ctypes.c_double()
    shapecorr._check(_lib.lib.sc_pointwise_seconds(result, stage.encode(), ctypes.byref(value)))
    return value.value


def test_a_triangle_soup_is_welded_unless_repair_is_off():
    figure = shapecorr.Shape.figure("humanoid", 0, 1500)
    corners = figure.triangles.reshape(-1)
    soup_vertices = figure.vertices[corners]
    soup_triangles = np.arange(len(corners), dtype=np.uint32).reshape(-1, 3)
    welded = shapecorr.Shape.mesh(soup_vertices, soup_triangles)
    assert welded.n_vertices == len(corners)
    assert any("welded" in w for w in welded.warnings), welded.warnings
    assert welded.repairs == [w for w in welded.warnings if "welded" in w]
    as_given = shapecorr.Shape.mesh(soup_vertices, soup_triangles, repair=False)
    assert not any("welded" in w for w in as_given.warnings)
    assert as_given.repairs == []
    assert any("disconnected" in w for w in as_given.warnings), as_given.warnings
    only_debris = shapecorr.Shape.mesh(soup_vertices.astype(np.float32), soup_triangles, repair={"debris"})
    assert not any("welded" in w for w in only_debris.warnings)
    # Welded duplicates share one answer: the regions of every corner of a vertex agree.
    result = shapecorr.match(welded, shapecorr.Shape.figure("humanoid", 3, 1500))
    regions = result.regions("a")
    by_vertex = {}
    for corner, vertex in enumerate(corners):
        by_vertex.setdefault(int(vertex), set()).add(int(regions[corner]))
    assert all(len(labels) == 1 for labels in by_vertex.values())


def test_bad_repair_arguments_raise():
    points = shapecorr.Shape.figure("humanoid", 0, 1000).vertices
    with pytest.raises(TypeError):
        shapecorr.Shape.point_cloud(points, repair="weld")
    with pytest.raises(ValueError, match="unknown repair"):
        shapecorr.Shape.point_cloud(points, repair={"glue"})
    cloud = shapecorr.Shape.point_cloud(np.vstack([points, [[1e3, 1e3, 1e3]]]), repair={"outliers"})
    assert any("far from" in w for w in cloud.warnings), cloud.warnings


# ----------------------------------------------------------------------------------- transfer


def test_transfer_modes_agree_with_the_surface_points(humanoids):
    a, b = humanoids
    pointwise = shapecorr.pointwise_map(a, b)
    stages = []
    onto = shapecorr.surface_map(a, b, pointwise, progress=lambda s, f: stages.append(s))
    assert stages and set(stages) == {"transfer"}
    assert (onto.n_vertices_a, onto.n_vertices_b) == (a.n_vertices, b.n_vertices)
    corners, weights = onto.points
    assert corners.shape == (b.n_vertices, 3) and corners.max() < a.n_vertices
    assert np.allclose(weights.sum(axis=1), 1.0)
    xyz = a.vertices
    carried = onto.transfer(xyz)
    assert carried.shape == (b.n_vertices, 3)
    assert np.allclose(carried, np.einsum("vk,vkc->vc", weights, xyz[corners]))
    labels = np.arange(a.n_vertices) % 5
    assert np.array_equal(onto.transfer(labels, mode="nearest"), labels[corners[:, 0]])
    skin = np.stack([xyz[:, 1] > 0, xyz[:, 1] <= 0], axis=1).astype(float) * 0.7 + 0.1
    one = onto.transfer(skin, mode="weights", max_influences=1)
    assert np.allclose(one.sum(axis=1), 1.0) and np.all((one > 0).sum(axis=1) == 1)


def test_transfer_errors(humanoids):
    a, b = humanoids
    pointwise = shapecorr.pointwise_map(a, b)
    onto = shapecorr.surface_map(a, b, pointwise)
    with pytest.raises(ValueError, match="mode"):
        onto.transfer(np.zeros(a.n_vertices), mode="cubic")
    with pytest.raises(ShapecorrError, match="vertices"):
        onto.transfer(np.zeros(a.n_vertices + 1))
    bad = np.full((a.n_vertices, 2), 0.5)
    bad[4, 1] = -1.0
    with pytest.raises(ShapecorrError, match="vertex 4 channel 1"):
        onto.transfer(bad, mode="weights")
    bad[4, 1] = np.nan
    with pytest.raises(ShapecorrError, match="finite"):
        onto.transfer(bad)
    with pytest.raises(TypeError):
        shapecorr.surface_map(a, b, a)
    other = shapecorr.Shape.figure("humanoid", 0, 1200)
    with pytest.raises(ShapecorrError, match="vertices"):
        shapecorr.surface_map(other, b, pointwise)
    with pytest.raises(ShapecorrError) as cancelled:
        shapecorr.surface_map(a, b, pointwise, progress=lambda s, f: False)
    assert cancelled.value.status_name == "CANCELLED"


def cylinder_corners(vertices, triangles):
    """Per-corner (u, v): u the angle about the vertical axis, v the height; a triangle across
    the back takes u + 1 at its corners below 0.5."""
    u = np.arctan2(vertices[:, 0], vertices[:, 2]) / (2 * np.pi) + 0.5
    v = (vertices[:, 1] - vertices[:, 1].min()) / np.ptp(vertices[:, 1])
    uv = np.stack([u[triangles], v[triangles]], axis=2)
    wraps = (uv[:, :, 0].max(axis=1) > 0.75) & (uv[:, :, 0].min(axis=1) < 0.25)
    uv[:, :, 0] += wraps[:, None] & (uv[:, :, 0] < 0.5)
    return uv


def test_transfer_corners_keeps_the_seam(humanoids):
    a, b = humanoids
    onto = shapecorr.surface_map(a, b, shapecorr.pointwise_map(a, b))
    uv_a = cylinder_corners(a.vertices, a.triangles)
    carried = onto.transfer_corners(a, a.triangles, uv_a, b.triangles)
    assert carried.shape == (len(b.triangles), 3, 2)
    # No triangle of B spans the seam (away from the top of the head, where the unwrap turns
    # fast and its own triangles spread a tenth of a turn); the figures share their vertex
    # order, so most corners land near their own coordinates.
    truth = cylinder_corners(b.vertices, b.triangles)
    clear = np.ptp(truth[:, :, 0], axis=1) < 0.1
    assert np.all(np.ptp(carried[clear, :, 0], axis=1) < 0.5)
    du = np.abs(carried[:, :, 0] - truth[:, :, 0]) % 1.0
    assert np.median(np.minimum(du, 1 - du)) < 0.02
    one = onto.transfer_corners(a, a.triangles, uv_a[:, :, 0], b.triangles)
    assert one.shape == (len(b.triangles), 3)
    with pytest.raises(ValueError, match="corner_values"):
        onto.transfer_corners(a, a.triangles, uv_a[:-1], b.triangles)
    bad = uv_a.copy()
    bad[2, 1, 0] = np.inf
    with pytest.raises(ShapecorrError, match="triangle 2 corner 1 channel 0"):
        onto.transfer_corners(a, a.triangles, bad, b.triangles)
    with pytest.raises(ShapecorrError, match="faces_b"):
        onto.transfer_corners(a, a.triangles, uv_a, b.triangles + b.n_vertices)
