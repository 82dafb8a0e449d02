"""The Blender extension, headless, with the `bpy` module from PyPI: the built zip is
unpacked and registered as Blender would load it (a package with relative imports), two
generated figures become Blender meshes, the operators run, and the attributes they write
are checked against the library's own result. Run by tests/blender/run.sh."""

import ctypes
import math
import os
import sys
from pathlib import Path

import bpy
import numpy as np
import pytest

REPOSITORY = Path(__file__).resolve().parents[2]
SIZE = 2500


@pytest.fixture(scope="module")
def addon(tmp_path_factory):
    """The extension from the zip, registered; yields the package."""
    zip_path = os.environ.get("SHAPECORR_BLENDER_ZIP")
    if zip_path is None:
        sys.path.insert(0, str(REPOSITORY / "blender_addon"))
        import build

        zip_path = build.build(REPOSITORY / "target" / "dist" / "libshapecorr.so",
                               tmp_path_factory.mktemp("zip"))
    sys.path.insert(0, str(REPOSITORY / "tests" / "blender"))
    import render_scene

    package = render_scene.load_addon(zip_path, tmp_path_factory.mktemp("extensions"))
    yield package
    package.unregister()


def fresh_scene():
    bpy.ops.wm.read_factory_settings(use_empty=True)


def add_object(name, vertices, triangles, location=(0.0, 0.0, 0.0), rotation_z=0.0):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([tuple(v) for v in vertices], [], [tuple(t) for t in triangles])
    mesh.update()
    obj = bpy.data.objects.new(name, mesh)
    obj.location = location
    obj.rotation_euler = (0.0, 0.0, rotation_z)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def select(*objects):
    for obj in bpy.context.view_layer.objects:
        obj.select_set(False)
    for obj in objects:
        obj.select_set(True)
    bpy.context.view_layer.objects.active = objects[0] if objects else None
    bpy.context.view_layer.update()


def figures(addon, kind="humanoid", poses=(0, 3)):
    sc = addon.shapecorr
    shapes = [sc.Shape.figure(kind, pose, SIZE) for pose in poses]
    return [(s.vertices, s.triangles) for s in shapes]


def attribute_arrays(obj):
    mesh = obj.data
    n = len(mesh.vertices)
    colors = mesh.color_attributes[addon_module().COLOR_ATTRIBUTE]
    rgba = np.empty(4 * n, dtype=np.float32)
    colors.data.foreach_get("color_srgb", rgba)
    regions = np.empty(n, dtype=np.int32)
    mesh.attributes[addon_module().REGION_ATTRIBUTE].data.foreach_get("value", regions)
    return np.round(rgba.reshape(n, 4) * 255).astype(np.uint8), regions


def addon_module():
    return sys.modules["shapecorr_ext.operators"]


def test_poll_says_why_the_button_is_greyed_out(addon):
    fresh_scene()
    (va, ta), (vb, tb) = figures(addon)
    a = add_object("A", va, ta)
    select(a)
    assert not bpy.ops.shapecorr.match_regions.poll()
    assert addon_module().selection_problem(bpy.context, 2) == "Select exactly 2 mesh objects (1 selected)"
    b = add_object("B", vb, tb)
    select(a, b)
    assert bpy.ops.shapecorr.match_regions.poll()
    assert not bpy.ops.shapecorr.detect_symmetry.poll()


def test_match_regions_colours_both_meshes_in_place_like_the_library(addon):
    fresh_scene()
    (va, ta), (vb, tb) = figures(addon)
    # B is moved and turned: the add-on reads world space, the match must not care.
    a = add_object("A", va, ta)
    b = add_object("B", vb, tb, location=(3.0, 0.0, 0.0), rotation_z=0.7)
    select(a, b)
    assert bpy.ops.shapecorr.match_regions() == {"FINISHED"}
    sc = addon.shapecorr
    # The library's own answer on the same world-space data.
    rotation = np.array([[math.cos(0.7), -math.sin(0.7), 0], [math.sin(0.7), math.cos(0.7), 0], [0, 0, 1]])
    world_b = vb.astype(np.float32).astype(np.float64) @ rotation.T + [3.0, 0.0, 0.0]
    world_a = va.astype(np.float32).astype(np.float64)
    expected = sc.match(sc.Shape.mesh(world_a, ta), sc.Shape.mesh(world_b, tb))
    for obj, side in [(a, "a"), (b, "b")]:
        rgba, regions = attribute_arrays(obj)
        assert np.array_equal(regions, expected.regions(side).astype(np.int32)), side
        assert np.array_equal(rgba, expected.colors(side)), side
        colors = obj.data.color_attributes
        assert colors.active_color_name == addon_module().COLOR_ATTRIBUTE
        assert colors[addon_module().COLOR_ATTRIBUTE].domain == "POINT"
    # The confidence of the answer is kept on both objects, the library's own (up to the
    # rounding of the transformed coordinates).
    assert expected.confidence is not None
    for obj in (a, b):
        confidence = obj[addon_module().CONFIDENCE_PROPERTY]
        assert 0.0 <= confidence <= 1.0
        assert confidence == pytest.approx(expected.confidence, abs=1e-6)
    # Matched regions really share colours: most vertices (shared vertex order) agree.
    rgba_a, _ = attribute_arrays(a)
    rgba_b, _ = attribute_arrays(b)
    agree = np.mean(np.all(rgba_a == rgba_b, axis=1))
    assert agree >= 0.5, agree


def reports(capfd):
    """The operator reports printed since the last call (headless Blender prints each as
    ``Info: ...`` or ``Warning: ...``), as (level, text) pairs."""
    ctypes.CDLL(None).fflush(None)  # Blender prints with C stdio
    out, err = capfd.readouterr()
    found = []
    for line in (out + err).splitlines():
        level, colon, text = line.partition(": ")
        if colon and level in ("Info", "Warning", "Error"):
            found.append((level, text))
    return found


def test_the_confidence_is_reported_and_a_doubtful_answer_warned_about(addon, capfd):
    """An eight-limbed star against a quadruped: no consistent map, the answer is doubtful
    (confidence 0.003 measured). The info report gives the confidence, a warning report the
    library's sentence, the objects keep the confidence; without one-to-one matches there is
    no confidence, and the property goes away."""
    fresh_scene()
    sc = addon.shapecorr
    shapes = [sc.Shape.figure(kind, 1, 2000) for kind in ("star8", "quadruped")]
    a = add_object("Star", shapes[0].vertices, shapes[0].triangles)
    b = add_object("Quadruped", shapes[1].vertices, shapes[1].triangles, location=(3.0, 0.0, 0.0))
    select(a, b)
    reports(capfd)
    assert bpy.ops.shapecorr.match_regions() == {"FINISHED"}, "a warning is not a failure"
    expected = sc.match(*[sc.Shape.mesh(s.vertices.astype(np.float32).astype(np.float64), s.triangles) for s in shapes])
    assert expected.doubtful, expected.confidence
    found = reports(capfd)
    info = [text for level, text in found if level == "Info"]
    assert any(f"confidence {expected.confidence:.2f}" in text for text in info), found
    assert ("Warning", f"shapecorr: {expected.warning}") in found, found
    for obj in (a, b):
        assert obj[addon_module().CONFIDENCE_PROPERTY] == pytest.approx(expected.confidence, abs=1e-6)
        assert obj[addon_module().CONFIDENCE_PROPERTY] < sc.CONFIDENCE_DOUBTFUL_BELOW

    bpy.context.scene.shapecorr.one_to_one = False
    assert bpy.ops.shapecorr.match_regions() == {"FINISHED"}
    found = reports(capfd)
    assert any("not verified" in text for level, text in found if level == "Info"), found
    assert not [text for level, text in found if level == "Warning"], found
    for obj in (a, b):
        assert addon_module().CONFIDENCE_PROPERTY not in obj


def seam_split(vertices, triangles):
    """The faces on the +x side get their own copies of the vertices they share with the -x
    side (appended), as exporters split a mesh along a UV seam. Returns the vertices, the
    triangles and, per vertex, the figure vertex it copies."""
    right = vertices[triangles].sum(axis=1)[:, 0] > 0.0
    on_left = np.zeros(len(vertices), dtype=bool)
    on_left[triangles[~right].ravel()] = True
    shared = np.unique(triangles[right].ravel()[on_left[triangles[right].ravel()]])
    copy = np.arange(len(vertices))
    copy[shared] = len(vertices) + np.arange(len(shared))
    split = triangles.copy()
    split[right] = copy[triangles[right]]
    original = np.concatenate([np.arange(len(vertices)), shared])
    return vertices[original], split, original


def test_a_mesh_split_along_a_seam_is_welded_and_the_repair_reported(addon, capfd):
    """Vertices duplicated along a seam: the library welds them (a warning report says so)
    and every copy gets the region of the vertex it copies."""
    fresh_scene()
    (va, ta), (vb, tb) = figures(addon)
    vertices, triangles, original = seam_split(va, ta)
    assert len(vertices) > len(va) + 20
    a = add_object("Seamed", vertices, triangles)
    b = add_object("Posed", vb, tb, location=(3.0, 0.0, 0.0))
    select(a, b)
    reports(capfd)
    assert bpy.ops.shapecorr.match_regions() == {"FINISHED"}
    found = reports(capfd)
    assert any(level == "Warning" and "'Seamed'" in text and "welded" in text for level, text in found), found
    _, regions = attribute_arrays(a)
    assert np.array_equal(regions[len(va):], regions[original[len(va):]])


def test_undo_removes_the_attributes(addon):
    operator = addon.operators.SHAPECORR_OT_match_regions
    assert {"REGISTER", "UNDO"} <= operator.bl_options
    fresh_scene()
    (va, ta), (vb, tb) = figures(addon, "star4", (0, 2))
    a = add_object("A", va, ta)
    b = add_object("B", vb, tb, location=(3.0, 0.0, 0.0))
    select(a, b)
    bpy.ops.ed.undo_push(message="before shapecorr")
    assert bpy.ops.shapecorr.match_regions() == {"FINISHED"}
    assert addon_module().COLOR_ATTRIBUTE in bpy.data.objects["A"].data.color_attributes
    if not bpy.ops.ed.undo.poll():
        # The bpy module has no window, and Blender's undo operator needs one.
        pytest.skip("ed.undo needs a window, which headless bpy does not have")
    bpy.ops.ed.undo()
    for name in ("A", "B"):
        mesh = bpy.data.objects[name].data
        assert addon_module().COLOR_ATTRIBUTE not in mesh.color_attributes
        assert addon_module().REGION_ATTRIBUTE not in mesh.attributes


def test_detect_symmetry_on_a_star(addon):
    fresh_scene()
    ((v, t),) = figures(addon, "star5", (0,))
    star = add_object("Star", v, t)
    select(star)
    assert bpy.ops.shapecorr.detect_symmetry() == {"FINISHED"}
    rgba, regions = attribute_arrays(star)
    colours = {tuple(c) for c in rgba[:, :3]}
    assert len(colours) >= 2
    assert regions.min() >= 0


def test_a_mesh_without_faces_is_matched_as_a_point_cloud(addon):
    fresh_scene()
    (va, ta), (vb, _) = figures(addon)
    a = add_object("A", va, ta)
    b = add_object("B", vb, [])
    select(a, b)
    assert bpy.ops.shapecorr.match_regions() == {"FINISHED"}
    _, regions = attribute_arrays(b)
    assert regions.max() >= 4


@pytest.mark.parametrize(
    "case, message",
    [
        ("one_vertex", "TOO_FEW_VERTICES"),
        ("nan", "NON_FINITE_COORDINATE"),
        ("loose_only", "TOO_FEW_VERTICES"),
    ],
)
def test_bad_meshes_give_a_reported_error_not_a_crash(addon, case, message):
    fresh_scene()
    (va, ta), _ = figures(addon)
    good = add_object("Good", va, ta)
    if case == "one_vertex":
        bad = add_object("Bad", [(0.0, 0.0, 0.0)], [])
    elif case == "nan":
        vertices = va.copy()
        vertices[5, 1] = np.nan
        bad = add_object("Bad", vertices, ta)
    else:
        bad = add_object("Bad", [(float(i), 0.0, 0.0) for i in range(10)], [])
    select(good, bad)
    # Blender turns an operator's ERROR report into a RuntimeError for Python callers.
    with pytest.raises(RuntimeError, match=message):
        bpy.ops.shapecorr.match_regions()
    assert addon_module().COLOR_ATTRIBUTE not in good.data.color_attributes


def test_modifiers_that_change_the_vertex_count_are_reported(addon):
    fresh_scene()
    (va, ta), (vb, tb) = figures(addon, "star4", (0, 1))
    a = add_object("A", va, ta)
    b = add_object("B", vb, tb)
    b.modifiers.new("Subdivision", "SUBSURF")
    select(a, b)
    with pytest.raises(RuntimeError, match="apply them first"):
        bpy.ops.shapecorr.match_regions()


def test_settings_default_to_the_library_defaults(addon):
    fresh_scene()
    settings = bpy.context.scene.shapecorr
    defaults = {name: value for name, _, _, value in addon.shapecorr.options()}
    passed = settings.library_options()
    # Every option the panel passes is a name of the library's one table, with its default.
    assert passed and set(passed) <= set(defaults), set(passed) - set(defaults)
    for name, value in passed.items():
        assert value == defaults[name], name
        assert getattr(settings, name) == defaults[name], name


def test_the_extension_ships_a_small_library():
    zip_path = os.environ.get("SHAPECORR_BLENDER_ZIP")
    if zip_path is None:
        pytest.skip("needs the zip built by tests/blender/run.sh")
    import zipfile

    with zipfile.ZipFile(zip_path) as archive:
        sizes = {i.filename: i.file_size for i in archive.infolist()}
    library = [name for name in sizes if name.startswith("shapecorr/libshapecorr")]
    assert library, sorted(sizes)
    # Built with the `dist` profile, no debug information (issue 17: at most 8 MB).
    assert sizes[library[0]] <= 8 * 1024 * 1024, sizes[library[0]]


def test_render_the_coloured_figures_with_cycles(addon, tmp_path):
    """Renders a small Cycles picture of two matched figures (the README's picture comes
    from tests/blender/render_readme.py, which uses the same scene)."""
    import render_scene

    out = tmp_path / "match.png"
    render_scene.render(addon, out, resolution=(160, 90), samples=4, size=1500)
    assert out.stat().st_size > 1000
    image = bpy.data.images.load(str(out))
    pixels = np.array(image.pixels[:]).reshape(-1, 4)
    # The figures are coloured: many distinct saturated colours in the picture.
    saturated = pixels[(pixels[:, :3].max(axis=1) - pixels[:, :3].min(axis=1)) > 0.2]
    assert len(saturated) > 200
