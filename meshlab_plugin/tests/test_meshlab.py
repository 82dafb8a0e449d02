"""The MeshLab script with pymeshlab from PyPI, on generated figures: as a function on a
MeshSet, as a command on PLY files, on an STL file (which pymeshlab reads and the library's
own reader does not), and on bad input; its command-line options come from the library's
option table."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pymeshlab
import pytest

REPOSITORY = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPOSITORY / "meshlab_plugin"))
import shapecorr_meshlab  # noqa: E402
from shapecorr_meshlab import shapecorr  # noqa: E402

SCRIPT = REPOSITORY / "meshlab_plugin" / "shapecorr_meshlab.py"


def figure_mesh(kind, pose, size=2500):
    shape = shapecorr.Shape.figure(kind, pose, size)
    return pymeshlab.Mesh(vertex_matrix=shape.vertices, face_matrix=shape.triangles.astype(np.int32))


def save(mesh, path):
    ms = pymeshlab.MeshSet()
    ms.add_mesh(mesh)
    ms.save_current_mesh(str(path))


def test_function_takes_and_returns_a_meshset():
    ms = pymeshlab.MeshSet()
    ms.add_mesh(figure_mesh("humanoid", 0))
    ms.add_mesh(figure_mesh("humanoid", 3))
    out = shapecorr_meshlab.match_regions(ms, k_max=8)
    assert out.mesh_number() == 2
    expected = shapecorr.match(
        shapecorr_meshlab.shape_of(ms.mesh(0)), shapecorr_meshlab.shape_of(ms.mesh(1)), k_max=8
    )
    for mesh_id, side in ((0, "a"), (1, "b")):
        mesh = out.mesh(mesh_id)
        colours = np.round(mesh.vertex_color_matrix() * 255).astype(np.uint8)
        assert np.array_equal(colours, expected.colors(side))
        assert np.array_equal(mesh.vertex_scalar_array(), expected.regions(side))
        custom = mesh.vertex_custom_scalar_attribute_array(shapecorr_meshlab.REGION_ATTRIBUTE)
        assert np.array_equal(custom, expected.regions(side))
        assert np.array_equal(mesh.vertex_matrix(), ms.mesh(mesh_id).vertex_matrix())
    # match() gives the result too: the same confidence, reported on the first line.
    again, result = shapecorr_meshlab.match(ms, k_max=8)
    assert again.mesh_number() == 2
    assert result.confidence is not None and 0.0 <= result.confidence <= 1.0
    assert result.confidence == expected.confidence
    lines = shapecorr_meshlab.report(result)
    assert lines[0].startswith(f"confidence {expected.confidence:.2f}, hypothesis '{result.hypothesis}'")
    advice = [f"warning: {expected.warning}", shapecorr_meshlab.ADVICE]
    assert lines[1:] == (advice if expected.doubtful else [])


def run_script(*args):
    return subprocess.run([sys.executable, str(SCRIPT), *map(str, args)], capture_output=True, text=True, timeout=300)


def test_command_writes_coloured_files_with_region_ids(tmp_path):
    save(figure_mesh("quadruped", 0), tmp_path / "a.ply")
    save(figure_mesh("quadruped", 2), tmp_path / "b.ply")
    done = run_script(tmp_path / "a.ply", tmp_path / "b.ply", "--out-a", tmp_path / "a_col.ply", "--out-b", tmp_path / "b_col.ply")
    assert done.returncode == 0, done.stderr
    expected = shapecorr.match(shapecorr.Shape.read(tmp_path / "a.ply"), shapecorr.Shape.read(tmp_path / "b.ply"))
    for name, side in (("a_col.ply", "a"), ("b_col.ply", "b")):
        ms = pymeshlab.MeshSet()
        ms.load_new_mesh(str(tmp_path / name))
        mesh = ms.current_mesh()
        colours = np.round(mesh.vertex_color_matrix() * 255).astype(np.uint8)
        assert np.array_equal(colours, expected.colors(side))
        assert np.array_equal(mesh.vertex_scalar_array(), expected.regions(side))
    # Shared vertex order: matched regions mostly share colours across the two files.
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(tmp_path / "a_col.ply"))
    ms.load_new_mesh(str(tmp_path / "b_col.ply"))
    agree = np.mean(np.all(ms.mesh(0).vertex_color_matrix() == ms.mesh(1).vertex_color_matrix(), axis=1))
    assert agree > 0.5, agree
    # The report gives the confidence; a warning on stderr only when doubtful.
    assert expected.confidence is not None
    assert f"(confidence {expected.confidence:.2f}, hypothesis '" in done.stdout, done.stdout
    assert ("shapecorr_meshlab: warning:" in done.stderr) == expected.doubtful, done.stderr


def test_a_doubtful_answer_is_reported_with_its_warning(tmp_path):
    """An eight-limbed star against a quadruped: no consistent map (confidence 0.003
    measured), so the command warns on stderr with the library's sentence, and still writes
    the files."""
    save(figure_mesh("star8", 1, 2000), tmp_path / "a.ply")
    save(figure_mesh("quadruped", 1, 2000), tmp_path / "b.ply")
    done = run_script(tmp_path / "a.ply", tmp_path / "b.ply", "--out-a", tmp_path / "a_col.ply", "--out-b", tmp_path / "b_col.ply")
    assert done.returncode == 0, done.stderr
    expected = shapecorr.match(shapecorr.Shape.read(tmp_path / "a.ply"), shapecorr.Shape.read(tmp_path / "b.ply"))
    assert expected.doubtful, expected.confidence
    assert f"(confidence {expected.confidence:.2f}, hypothesis '" in done.stdout, done.stdout
    assert f"shapecorr_meshlab: warning: {expected.warning}" in done.stderr.splitlines(), done.stderr
    assert f"shapecorr_meshlab: {shapecorr_meshlab.ADVICE}" in done.stderr.splitlines(), done.stderr
    assert (tmp_path / "a_col.ply").exists() and (tmp_path / "b_col.ply").exists()


def test_a_format_only_meshlab_reads(tmp_path):
    save(figure_mesh("star5", 0), tmp_path / "a.stl")
    save(figure_mesh("star5", 2), tmp_path / "b.ply")
    with pytest.raises(shapecorr.ShapecorrError):
        shapecorr.Shape.read(tmp_path / "a.stl")  # the library has no STL reader
    done = run_script(tmp_path / "a.stl", tmp_path / "b.ply", "--out-a", tmp_path / "a_col.ply", "--out-b", tmp_path / "b_col.ply", "--symmetric")
    assert done.returncode == 0, done.stderr
    assert "(not verified)" in done.stdout, "symmetric matches have no confidence"
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(tmp_path / "a_col.ply"))
    mesh = ms.current_mesh()
    regions = mesh.vertex_scalar_array()
    assert mesh.vertex_number() > 1000 and regions.max() >= 4
    assert len({tuple(c) for c in np.round(mesh.vertex_color_matrix() * 255).astype(int)}) >= 3


def test_bad_input_exits_with_a_reason(tmp_path):
    tetrahedron = pymeshlab.Mesh(
        vertex_matrix=np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float),
        face_matrix=np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]], dtype=np.int32),
    )
    save(tetrahedron, tmp_path / "tiny.ply")
    save(figure_mesh("star4", 0, 1000), tmp_path / "b.ply")
    done = run_script(tmp_path / "tiny.ply", tmp_path / "b.ply", "--out-a", tmp_path / "x.ply", "--out-b", tmp_path / "y.ply")
    assert done.returncode == 1 and "TOO_FEW_VERTICES" in done.stderr
    missing = run_script(tmp_path / "nothing.ply", tmp_path / "b.ply", "--out-a", tmp_path / "x.ply", "--out-b", tmp_path / "y.ply")
    assert missing.returncode == 1 and "cannot load" in missing.stderr
    assert not (tmp_path / "x.ply").exists()


def test_command_options_are_the_library_table():
    parser = shapecorr_meshlab.argument_parser()
    flags = {flag for action in parser._actions for flag in action.option_strings}
    region = [name for name, *_ in shapecorr.options() if not name.startswith("p2p_")]
    assert region and all("--" + name.replace("_", "-") in flags for name in region)
    assert not any(flag.startswith("--p2p-") for flag in flags)
    base = ["a.ply", "b.ply", "--out-a", "x.ply", "--out-b", "y.ply"]
    by_flag = shapecorr_meshlab.options_of(parser.parse_args(base + ["--k-max", "8", "--one-to-one", "no"]))
    by_set = shapecorr_meshlab.options_of(parser.parse_args(base + ["--set", "k_max=8", "--set", "one_to_one=false"]))
    assert by_flag == by_set == {"k_max": 8, "one_to_one": False}
    # --set comes after the flags.
    later = shapecorr_meshlab.options_of(parser.parse_args(base + ["--set", "k_max=7", "--k-max", "9"]))
    assert later == {"k_max": 7}
    assert shapecorr_meshlab.options_of(parser.parse_args(base)) == {}


def test_bad_options_exit_with_a_reason(tmp_path):
    for args, expected in ((["--set", "nope=1"], "nope"), (["--k-min", "five"], "k_min"), (["--gap-ratio", "x"], "gap_ratio")):
        done = run_script(tmp_path / "a.ply", tmp_path / "b.ply", "--out-a", tmp_path / "x.ply", "--out-b", tmp_path / "y.ply", *args)
        assert done.returncode == 2 and expected in done.stderr, (args, done.stderr)


def test_the_repairs_made_are_reported(tmp_path):
    """B is a point cloud with one far stray point: the library leaves it out, and the
    report (and the command's stderr) says so, naming B."""
    ms = pymeshlab.MeshSet()
    ms.add_mesh(figure_mesh("humanoid", 0))
    points = shapecorr.Shape.figure("humanoid", 3, 2500).vertices
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=np.vstack([points, [[50.0, 50.0, 50.0]]])))
    _, result, shapes = shapecorr_meshlab.match_with_shapes(ms)
    lines = shapecorr_meshlab.report(result, shapes)
    assert [line for line in lines if line.startswith("repaired")] == [
        f"repaired B: {repair}" for repair in shapes[1].repairs
    ]
    assert any("far from" in line for line in lines), lines
    save(ms.mesh(0), tmp_path / "a.ply")
    save(ms.mesh(1), tmp_path / "b.ply")
    run = subprocess.run(
        [sys.executable, str(SCRIPT), str(tmp_path / "a.ply"), str(tmp_path / "b.ply"),
         "--out-a", str(tmp_path / "a_out.ply"), "--out-b", str(tmp_path / "b_out.ply")],
        capture_output=True, text=True,
    )
    assert run.returncode == 0, run.stderr
    assert "shapecorr_meshlab: repaired B: 1 vertices far from" in run.stderr, run.stderr


# ------------------------------------------------------------------------ placement, landmarks


def test_placement_is_taken_by_name_and_a_wrong_one_refused(tmp_path):
    parser = shapecorr_meshlab.argument_parser()
    base = ["a.ply", "b.ply", "--out-a", "x.ply", "--out-b", "y.ply"]
    for args, expected in ((["--placement", "trust"], "trust"), (["--set", "placement=Ignore"], "ignore"),
                           (["--placement", "2"], 2)):
        assert shapecorr_meshlab.options_of(parser.parse_args(base + args)) == {"placement": expected}
    save(figure_mesh("humanoid", 0, 2000), tmp_path / "a.ply")
    save(figure_mesh("humanoid", 3, 2000), tmp_path / "b.ply")
    done = run_script(tmp_path / "a.ply", tmp_path / "b.ply", "--out-a", tmp_path / "x.ply", "--out-b", tmp_path / "y.ply",
                      "--placement", "bogus")
    assert done.returncode == 2 and "auto (0), ignore (1), trust (2)" in done.stderr, done.stderr
    # The name reaches the library: `ignore` never lets the shapes' placement decide.
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(tmp_path / "a.ply"))
    ms.load_new_mesh(str(tmp_path / "b.ply"))
    _, result = shapecorr_meshlab.match(ms, placement="ignore")
    assert result.hypothesis is not None and not result.placement_used and result.decided_by != "placement"


@pytest.mark.parametrize(
    "text, expected",
    [
        ("1 2\n3\n", "line 2, column 2: B's vertex is missing"),
        ("1 2 3\n", "line 1, column 5: a third value `3`"),
        ("1,2,3\n", "line 1, column 4: a second comma"),
        (",1 2\n", "line 1, column 1: a comma that is not between"),
        ("\n\n  4 x9\n", "line 3, column 5: B's vertex `x9` is not a vertex index"),
        ("-1 2\n", "line 1, column 1: A's vertex `-1` is negative"),
        ("1 4294967296\n", "line 1, column 3: B's vertex `4294967296` is larger"),
    ],
)
def test_a_malformed_landmarks_file_names_line_and_column(tmp_path, text, expected):
    path = tmp_path / "landmarks.txt"
    path.write_text(text)
    with pytest.raises(ValueError, match=expected.replace("(", r"\(")) as error:
        shapecorr_meshlab.read_landmarks(path)
    assert str(path) in str(error.value)


def test_landmarks_files_are_read_like_the_command_line_and_bad_ones_write_nothing(tmp_path):
    path = tmp_path / "landmarks.txt"
    path.write_bytes(b"\xef\xbb\xbf# A B\n12 40\n\n  7\t9  # left hand\r\n3,4\n5 , 6\n")
    assert shapecorr_meshlab.read_landmarks(path) == [(12, 40), (7, 9), (3, 4), (5, 6)]
    save(figure_mesh("humanoid", 0, 2000), tmp_path / "a.ply")
    save(figure_mesh("humanoid", 3, 2000), tmp_path / "b.ply")
    path.write_text("10 10\n7 x\n")
    outputs = ("--out-a", tmp_path / "x.ply", "--out-b", tmp_path / "y.ply")
    done = run_script(tmp_path / "a.ply", tmp_path / "b.ply", *outputs, "--landmarks", path)
    assert done.returncode == 1 and "line 2, column 3" in done.stderr and "Traceback" not in done.stderr, done.stderr
    done = run_script(tmp_path / "a.ply", tmp_path / "b.ply", *outputs, "--landmarks", tmp_path / "none.txt")
    assert done.returncode == 1 and "none.txt" in done.stderr and "Traceback" not in done.stderr, done.stderr
    # Checked by the library against the shapes: B has fewer vertices than this.
    path.write_text("10 10\n20 99999\n")
    done = run_script(tmp_path / "a.ply", tmp_path / "b.ply", *outputs, "--landmarks", path)
    assert done.returncode == 1 and "vertex 99999 is not a vertex of B" in done.stderr, done.stderr
    assert not (tmp_path / "x.ply").exists() and not (tmp_path / "y.ply").exists()
    done = run_script("transfer", tmp_path / "a.ply", tmp_path / "b.ply", "--out", tmp_path / "x.ply", "--landmarks", path)
    assert done.returncode == 1 and not (tmp_path / "x.ply").exists(), done.stderr


def test_landmarks_reach_the_library_and_the_report_names_the_choice(tmp_path):
    """Two figures sharing their vertex order, two true landmark pairs: the command passes
    them on (the library's answer with them is the script's), and the report names the
    hypothesis, what decided it and the runner-up's cost."""
    save(figure_mesh("humanoid", 0, 2000), tmp_path / "a.ply")
    save(figure_mesh("humanoid", 3, 2000), tmp_path / "b.ply")
    path = tmp_path / "landmarks.txt"
    path.write_text("# hand, foot\n10 10\n1500, 1500\n")
    done = run_script(tmp_path / "a.ply", tmp_path / "b.ply", "--out-a", tmp_path / "a_col.ply",
                      "--out-b", tmp_path / "b_col.ply", "--landmarks", path)
    assert done.returncode == 0, done.stderr
    shapes = (shapecorr.Shape.read(tmp_path / "a.ply"), shapecorr.Shape.read(tmp_path / "b.ply"))
    expected = shapecorr.match(*shapes, landmarks=[(10, 10), (1500, 1500)])
    assert expected.hypothesis is not None
    first = shapecorr_meshlab.report(expected)[0]
    assert f"({first})" in done.stdout, done.stdout
    assert f"hypothesis '{expected.hypothesis}' decided by {expected.decided_by}" in first
    if expected.runner_up is not None:
        assert "runner-up '" in first and " cost " in first, first
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(tmp_path / "b_col.ply"))
    colours = np.round(ms.current_mesh().vertex_color_matrix() * 255).astype(np.uint8)
    assert np.array_equal(colours, expected.colors("b"))


def in_two_pieces(shape, gap):
    """``shape``'s faces on the +x side get their own copies of the vertices they share with
    the -x side, and that side moves ``gap`` along x: two pieces that come close without
    touching, as a model in parts."""
    vertices, triangles = shape.vertices, shape.triangles.copy()
    right = vertices[triangles].sum(axis=1)[:, 0] > 0.0
    on_left = np.zeros(len(vertices), dtype=bool)
    on_left[triangles[~right].ravel()] = True
    shared = np.unique(triangles[right].ravel()[on_left[triangles[right].ravel()]])
    index = np.arange(len(vertices))
    index[shared] = len(vertices) + np.arange(len(shared))
    triangles[right] = index[triangles[right]]
    vertices = np.vstack([vertices, vertices[shared]])
    vertices[np.unique(triangles[right].ravel()), 0] += gap
    return pymeshlab.Mesh(vertex_matrix=vertices, face_matrix=triangles.astype(np.int32))


def test_pieces_joined_for_matching_are_reported():
    """A figure in two pieces 0.5% of its height apart (within the 1% the library joins,
    docs/decisions.md, "Shapes in pieces"): the report says A's were joined; both ran on
    their input, so no line says what they were matched on."""
    figure = shapecorr.Shape.figure("humanoid", 0, 2500)
    ms = pymeshlab.MeshSet()
    ms.add_mesh(in_two_pieces(figure, 0.005 * np.ptp(figure.vertices, axis=0).max()))
    ms.add_mesh(figure_mesh("humanoid", 3))
    _, result, shapes = shapecorr_meshlab.match_with_shapes(ms)
    lines = shapecorr_meshlab.report(result, shapes)
    joined = [line for line in lines if line.startswith("repaired A:") and "joined" in line]
    assert len(joined) == 1, lines
    assert not any("was matched on" in line for line in lines), lines


def test_the_report_says_what_each_side_was_matched_on():
    """A low-poly A (600 vertices, below ``refine_below``) runs on a refined copy: one line
    says so with both sizes; B, matched on its input, has none."""
    ms = pymeshlab.MeshSet()
    ms.add_mesh(figure_mesh("humanoid", 0, 600))
    ms.add_mesh(figure_mesh("humanoid", 3))
    _, result, shapes = shapecorr_meshlab.match_with_shapes(ms)
    working_a, working_b = result.working
    assert working_a.kind == "refined" and working_b.kind == "input"
    lines = [line for line in shapecorr_meshlab.report(result, shapes) if "was matched on" in line]
    assert lines == [
        f"A was matched on a refined copy of {working_a.vertices:,} vertices (the input has {shapes[0].n_vertices:,})"
    ]


def test_the_report_names_a_proxy_and_is_silent_on_inputs():
    from types import SimpleNamespace

    proxy = SimpleNamespace(
        confidence=None, warning=None, hypothesis=None, n_vertices_a=250000, n_vertices_b=5000,
        working=(shapecorr.Working("proxy", 20000), shapecorr.Working("input", 5000)),
    )
    assert shapecorr_meshlab.report(proxy) == [
        "not verified", "A was matched on a proxy of 20,000 vertices (the input has 250,000)",
    ]
    inputs = SimpleNamespace(**{**vars(proxy), "working": (shapecorr.Working("input", 250000),) * 2})
    assert shapecorr_meshlab.report(inputs) == ["not verified"]


def test_the_report_says_a_noisy_side_was_smoothed():
    from types import SimpleNamespace

    noisy = SimpleNamespace(
        confidence=None, warning=None, hypothesis=None, n_vertices_a=5000, n_vertices_b=250000,
        working=(shapecorr.Working("input", 5000, True), shapecorr.Working("proxy", 8000, True)),
    )
    assert shapecorr_meshlab.report(noisy) == [
        "not verified",
        "A looks noisy (scanner noise): it was matched on a smoothed copy; the answers are on its own vertices",
        "B was matched on a smoothed proxy of 8,000 vertices (the input has 250,000)",
    ]


def test_the_report_says_an_object_touching_the_figure_was_left_out():
    from types import SimpleNamespace

    prop = SimpleNamespace(
        confidence=None, warning=None, hypothesis=None, n_vertices_a=5000, n_vertices_b=5866,
        working=(shapecorr.Working("input", 5000), shapecorr.Working("input", 5000, False, 866)),
    )
    assert shapecorr_meshlab.report(prop) == [
        "not verified",
        "B: 866 vertices of an object touching the figure (a prop) were left out: the pair matched better without them; they take the answer of the nearest kept vertex",
    ]


def test_the_report_says_how_the_answer_was_chosen_and_what_to_do():
    from types import SimpleNamespace

    result = SimpleNamespace(
        confidence=0.3, warning="doubtful correspondence", hypothesis="answer", decided_by="placement",
        placement_used=True, turn_degrees=9.4, runner_up={"hypothesis": "mirror", "cost": 0.07574},
    )
    assert shapecorr_meshlab.report(result) == [
        "confidence 0.30, hypothesis 'answer' decided by placement (placement used), turn 9 degrees, "
        "runner-up 'mirror' cost 0.07574",
        "warning: doubtful correspondence",
        shapecorr_meshlab.ADVICE,
    ]
    result = SimpleNamespace(confidence=0.9, warning=None, hypothesis="mirror", decided_by="cost",
                             placement_used=False, turn_degrees=None, runner_up=None)
    assert shapecorr_meshlab.report(result) == [
        "confidence 0.90, hypothesis 'mirror' decided by cost (placement not used), no runner-up"
    ]
    unverified = SimpleNamespace(confidence=None, warning=None, hypothesis=None)
    assert shapecorr_meshlab.report(unverified) == ["not verified"]


# ----------------------------------------------------------------------------------- transfer


def painted_pair():
    """A in the rest pose with colours, quality and texture coordinates from its position; B
    posed with nothing."""
    a = shapecorr.Shape.figure("humanoid", 0, 2500)
    b = shapecorr.Shape.figure("humanoid", 3, 2500)
    xyz = a.vertices
    t = (xyz - xyz.min(axis=0)) / np.ptp(xyz, axis=0)
    colours = np.concatenate([t, np.ones((len(t), 1))], axis=1)
    mesh_a = pymeshlab.Mesh(
        vertex_matrix=xyz, face_matrix=a.triangles.astype(np.int32), v_color_matrix=colours,
        v_scalar_array=t[:, 1], v_tex_coords_matrix=t[:, :2],
    )
    ms = pymeshlab.MeshSet()
    ms.add_mesh(mesh_a)
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=b.vertices, face_matrix=b.triangles.astype(np.int32)))
    return ms, a, b, colours, t


def test_transfer_function_carries_colours_quality_and_texcoords_like_the_library():
    ms, a, b, colours, t = painted_pair()
    out, pointwise = shapecorr_meshlab.transfer(ms)
    shape_a, shape_b = shapecorr_meshlab.shape_of(ms.mesh(0)), shapecorr_meshlab.shape_of(ms.mesh(1))
    onto = shapecorr.surface_map(shape_a, shape_b, shapecorr.pointwise_map(shape_a, shape_b))
    mesh = out.mesh(0)
    assert np.array_equal(mesh.vertex_matrix(), ms.mesh(1).vertex_matrix())
    # MeshLab keeps colours in 8 bits (truncated): A holds its colours so, and B its own.
    expected = onto.transfer(ms.mesh(0).vertex_color_matrix())
    assert np.allclose(mesh.vertex_color_matrix(), expected, atol=1 / 255 + 1e-9)
    assert np.allclose(mesh.vertex_scalar_array(), onto.transfer(t[:, 1]), atol=1e-9)
    assert np.allclose(mesh.vertex_tex_coord_matrix(), onto.transfer(t[:, :2]), atol=1e-6)
    # The figures share their vertex order: a right map carries the texture coordinates to
    # within a few hundredths of their own.
    assert np.median(np.abs(mesh.vertex_tex_coord_matrix() - t[:, :2])) < 0.02
    assert pointwise.confidence is not None


def test_transfer_from_a_part_keeps_what_b_has_where_the_part_holds_nothing():
    """A quadruped with its lower third cut away (A, told it is a part) carries its quality
    to the whole figure: the vertices A holds get it, the others keep B's own, and the report
    says how many. The figures share their vertex order, which gives the truth."""
    whole_a, whole_b = (shapecorr.Shape.figure("quadruped", pose, 3000) for pose in (0, 1))
    vertices, triangles = whole_a.vertices, whole_a.triangles
    height = vertices[:, 1]
    floor = height.min() + (height.max() - height.min()) / 3
    kept_triangles = triangles[(height[triangles] > floor).all(axis=1)]
    kept = np.unique(kept_triangles)
    new_index = np.full(len(vertices), -1, dtype=np.int64)
    new_index[kept] = np.arange(len(kept))
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=vertices[kept], face_matrix=new_index[kept_triangles].astype(np.int32),
                               v_scalar_array=np.ones(len(kept))))
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=whole_b.vertices, face_matrix=whole_b.triangles.astype(np.int32),
                               v_scalar_array=np.full(whole_b.n_vertices, -1.0)))
    out, pointwise = shapecorr_meshlab.transfer(ms, colors=False, texcoords=False, partial="a_in_b")
    quality = out.mesh(0).vertex_scalar_array()
    written = np.isclose(quality, 1.0)
    assert np.isclose(quality[~written], -1.0).all(), "a vertex is either carried or left as it was"
    inside = np.zeros(whole_b.n_vertices, dtype=bool)
    inside[kept] = True
    assert written[inside].mean() > 0.9 and (~written[~inside]).mean() > 0.75
    lines = shapecorr_meshlab.report(pointwise)
    assert any(line.startswith("partial: A is a part of B (given)") for line in lines), lines
    assert any(f"partial: {int((~written).sum())} vertices of B" in line for line in lines), lines


def cylinder_wedges(vertices, triangles):
    """A per-wedge UV layout: u the angle about the vertical axis, v the height; a triangle
    across the back takes u + 1 at its corners below 0.5 (the back is a seam)."""
    u = np.arctan2(vertices[:, 0], vertices[:, 2]) / (2 * np.pi) + 0.5
    v = (vertices[:, 1] - vertices[:, 1].min()) / np.ptp(vertices[:, 1])
    corners = np.stack([u[triangles], v[triangles]], axis=2)
    across = (corners[:, :, 0].max(axis=1) > 0.75) & (corners[:, :, 0].min(axis=1) < 0.25)
    corners[:, :, 0] += np.where(across[:, None] & (corners[:, :, 0] < 0.5), 1.0, 0.0)
    return corners


def test_transfer_carries_wedge_texcoords_per_corner_with_the_seam_kept():
    a = shapecorr.Shape.figure("humanoid", 0, 2500)
    b = shapecorr.Shape.figure("humanoid", 3, 2500)
    corners_a = cylinder_wedges(a.vertices, a.triangles)
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=a.vertices, face_matrix=a.triangles.astype(np.int32),
                               w_tex_coords_matrix=corners_a.reshape(-1, 2)))
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=b.vertices, face_matrix=b.triangles.astype(np.int32)))
    out, _ = shapecorr_meshlab.transfer(ms)
    carried = out.mesh(0).wedge_tex_coord_matrix().reshape(-1, 3, 2)
    shape_a, shape_b = shapecorr_meshlab.shape_of(ms.mesh(0)), shapecorr_meshlab.shape_of(ms.mesh(1))
    onto = shapecorr.surface_map(shape_a, shape_b, shapecorr.pointwise_map(shape_a, shape_b))
    assert np.allclose(carried, onto.transfer_corners(shape_a, a.triangles, corners_a, b.triangles), atol=1e-6)
    # B's own layout (the figures share their triangles): close where the truth does not
    # cross the seam, and no more triangles smeared across the seam (a u-span far above a
    # triangle's own) than the truth has near the poles of the angle.
    truth = cylinder_wedges(b.vertices, b.triangles)
    inside = np.ptp(truth[:, :, 0], axis=1) < 0.1
    assert np.median(np.abs(carried[inside] - truth[inside])) < 0.03
    smeared = np.count_nonzero(np.ptp(carried[:, :, 0], axis=1) > 0.3)
    assert smeared <= np.count_nonzero(np.ptp(truth[:, :, 0], axis=1) > 0.3) + 0.005 * len(carried)
    # Per vertex (what MeshLab had before wedges were carried) the seam is smeared.
    per_vertex = onto.transfer(np.arctan2(a.vertices[:, 0], a.vertices[:, 2]) / (2 * np.pi) + 0.5)
    assert np.count_nonzero(np.ptp(per_vertex[b.triangles], axis=1) > 0.3) > smeared + 10


def test_transfer_command_writes_b_with_a_colours(tmp_path):
    ms, _, _, _, _ = painted_pair()
    for mesh_id, name in ((0, "a.ply"), (1, "b.ply")):
        ms.set_current_mesh(mesh_id)
        ms.save_current_mesh(str(tmp_path / name), save_vertex_color=True, save_vertex_quality=True)
    out = tmp_path / "b_from_a.ply"
    done = run_script("transfer", tmp_path / "a.ply", tmp_path / "b.ply", "--out", out, "--no-texcoords")
    assert done.returncode == 0, done.stderr
    assert "confidence" in done.stdout
    loaded = pymeshlab.MeshSet()
    loaded.load_new_mesh(str(out))
    assert loaded.current_mesh().has_vertex_color()
    # Formats without vertex quality (OBJ, OFF) are written without it, not refused; a
    # folder that does not exist is a reason and exit 1, not a traceback.
    for suffix in ("obj", "off"):
        written = tmp_path / f"b_from_a.{suffix}"
        done = run_script("transfer", tmp_path / "a.ply", tmp_path / "b.ply", "--out", written)
        assert done.returncode == 0 and written.exists(), done.stderr
    done = run_script("transfer", tmp_path / "a.ply", tmp_path / "b.ply", "--out", tmp_path / "no" / "b.ply")
    assert done.returncode == 1 and "cannot save" in done.stderr and "Traceback" not in done.stderr, done.stderr
    # Nothing to carry, or no faces: a reason and exit 1.
    plain = pymeshlab.MeshSet()
    plain.add_mesh(pymeshlab.Mesh(vertex_matrix=ms.mesh(1).vertex_matrix(), face_matrix=ms.mesh(1).face_matrix()))
    plain.save_current_mesh(str(tmp_path / "plain.ply"), save_vertex_color=False, save_vertex_quality=False)
    done = run_script("transfer", tmp_path / "plain.ply", tmp_path / "b.ply", "--out", out)
    assert done.returncode == 1 and "none of what" in done.stderr, done.stderr
