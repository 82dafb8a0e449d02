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


def test_the_extension_ships_a_small_library_and_its_licences():
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
    # The manifest's licence and the project's two travel with it (issue 23).
    with zipfile.ZipFile(zip_path) as archive:
        manifest = archive.read("blender_manifest.toml").decode()
        licences = {name: archive.read(name).decode() for name in
                    ("LICENSE-GPL-3.0", "LICENSE-MIT", "LICENSE-APACHE")}
    assert 'license = ["SPDX:GPL-3.0-or-later"]' in manifest
    assert "GNU GENERAL PUBLIC LICENSE" in licences["LICENSE-GPL-3.0"]
    assert "Permission is hereby granted" in licences["LICENSE-MIT"]
    assert "Apache License" in licences["LICENSE-APACHE"]


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


# ------------------------------------------------------------------------ Transfer (issue 21)


def library_shape(addon, obj):
    """The library's shape of ``obj`` as the add-on reads it (world space, loop triangles)."""
    n = len(obj.data.vertices)
    co = np.empty(3 * n, dtype=np.float32)
    obj.data.vertices.foreach_get("co", co)
    matrix = np.array(obj.matrix_world, dtype=np.float64)
    world = co.reshape(n, 3).astype(np.float64) @ matrix[:3, :3].T + matrix[:3, 3]
    return addon.shapecorr.Shape.mesh(world, loop_triangles(obj)[0])


def library_surface_map(addon, a, b):
    """The library's surface map on the world-space data the add-on reads from ``a``, ``b``."""
    shapes = [library_shape(addon, obj) for obj in (a, b)]
    pointwise = addon.shapecorr.pointwise_map(*shapes)
    return addon.shapecorr.surface_map(shapes[0], shapes[1], pointwise), pointwise


def group_weights(obj, name):
    group = obj.vertex_groups[name]
    weights = np.zeros(len(obj.data.vertices))
    for vertex in obj.data.vertices:
        for element in vertex.groups:
            if element.group == group.index:
                weights[vertex.index] = element.weight
    return weights


def rigged_source(addon):
    """A in the rest pose with two skin-weight groups, a mask, a colour and two point
    attributes; B posed, moved and turned, with nothing."""
    fresh_scene()
    (va, ta), (vb, tb) = figures(addon)
    a = add_object("Source", va, ta)
    b = add_object("Target", vb, tb, location=(3.0, 0.0, 0.0), rotation_z=0.7)
    height = va[:, 1]
    upper = np.clip((height - height.min()) / np.ptp(height), 0.0, 1.0)
    for name, weights in (("upper", upper), ("lower", 1.0 - upper), ("mask", upper > 0.8)):
        group = a.vertex_groups.new(name=name)
        for vertex in np.flatnonzero(weights > 0):
            group.add([int(vertex)], float(weights[vertex]), "REPLACE")
    mesh = a.data
    colors = mesh.color_attributes.new("paint", "FLOAT_COLOR", "POINT")
    rgba = np.stack([upper, 1.0 - upper, np.full_like(upper, 0.5), np.ones_like(upper)], axis=1)
    colors.data.foreach_set("color", rgba.astype(np.float32).ravel())
    mesh.attributes.new("heat", "FLOAT", "POINT").data.foreach_set("value", upper.astype(np.float32))
    labels = (va[:, 0] > 0).astype(np.int32) + 2 * (va[:, 1] > np.median(va[:, 1]))
    mesh.attributes.new("part", "INT", "POINT").data.foreach_set("value", labels)
    add_cylinder_uv(a)
    select(a, b)
    return a, b, upper, labels


def add_cylinder_uv(obj):
    """A UV map "cylinder": u the angle about the vertical axis, v the height; a face
    across the back takes u + 1 at its corners below 0.5 (the back is a seam)."""
    mesh = obj.data
    mesh.uv_layers.new(name="cylinder")
    xyz = np.empty(3 * len(mesh.vertices), dtype=np.float32)
    mesh.vertices.foreach_get("co", xyz)
    xyz = xyz.reshape(-1, 3).astype(np.float64)
    corner_vertex = np.empty(len(mesh.loops), dtype=np.int32)
    mesh.loops.foreach_get("vertex_index", corner_vertex)
    u = np.arctan2(xyz[:, 0], xyz[:, 2]) / (2 * np.pi) + 0.5
    v = (xyz[:, 1] - xyz[:, 1].min()) / np.ptp(xyz[:, 1])
    uv = np.stack([u[corner_vertex], v[corner_vertex]], axis=1)
    for polygon in mesh.polygons:
        loops = np.arange(polygon.loop_start, polygon.loop_start + polygon.loop_total)
        if uv[loops, 0].max() > 0.75 and uv[loops, 0].min() < 0.25:
            uv[loops[uv[loops, 0] < 0.5], 0] += 1.0
    mesh.attributes["cylinder"].data.foreach_set("vector", uv.astype(np.float32).ravel())


def loop_uv(obj, name):
    mesh = obj.data
    uv = np.empty(2 * len(mesh.loops), dtype=np.float32)
    mesh.attributes[name].data.foreach_get("vector", uv)
    return uv.reshape(-1, 2).astype(np.float64)


def loop_triangles(obj):
    mesh = obj.data
    mesh.calc_loop_triangles()
    n = len(mesh.loop_triangles)
    vertices, loops = np.empty(3 * n, dtype=np.int32), np.empty(3 * n, dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", vertices)
    mesh.loop_triangles.foreach_get("loops", loops)
    return vertices.reshape(n, 3), loops.reshape(n, 3)


def test_transfer_carries_groups_colours_and_attributes_like_the_library(addon):
    a, b, upper, labels = rigged_source(addon)
    settings = bpy.context.scene.shapecorr
    settings.transfer_max_influences = 4
    assert bpy.ops.shapecorr.transfer.poll()
    assert bpy.ops.shapecorr.transfer() == {"FINISHED"}
    onto, pointwise = library_surface_map(addon, a, b)
    stored = lambda w: w.astype(np.float32).astype(np.float64)  # noqa: E731 - Blender keeps float32
    # Skin weights: normalised together, as the library carries them.
    source = np.stack([group_weights(a, n) for n in ("upper", "lower", "mask")], axis=1)
    expected = onto.transfer(source, mode="weights", max_influences=4)
    got = np.stack([group_weights(b, n) for n in ("upper", "lower", "mask")], axis=1)
    assert np.allclose(got, stored(expected), atol=1e-6)
    assert np.allclose(got.sum(axis=1), 1.0, atol=1e-5)
    # Colour and float attribute interpolated, integer attribute from the nearest vertex.
    n = len(b.data.vertices)
    rgba = np.empty(4 * n, dtype=np.float32)
    b.data.color_attributes["paint"].data.foreach_get("color", rgba)
    source_rgba = np.empty(4 * len(a.data.vertices), dtype=np.float32)
    a.data.color_attributes["paint"].data.foreach_get("color", source_rgba)
    expected = onto.transfer(source_rgba.reshape(-1, 4).astype(np.float64))
    assert np.allclose(rgba.reshape(n, 4), expected, atol=1e-6)
    heat = np.empty(n, dtype=np.float32)
    b.data.attributes["heat"].data.foreach_get("value", heat)
    assert np.allclose(heat, onto.transfer(stored(upper)), atol=1e-6)
    part = np.empty(n, dtype=np.int32)
    b.data.attributes["part"].data.foreach_get("value", part)
    assert np.array_equal(part, onto.transfer(labels, mode="nearest").astype(np.int32))
    # The figures share their vertex order: a right map carries most labels to their own
    # vertices.
    assert np.mean(part == labels) > 0.9
    assert pointwise.confidence is not None
    # The UV map per corner, as the library carries it (tests/it/transfer.rs checks the seams).
    faces_a, loops_a = loop_triangles(a)
    faces_b, loops_b = loop_triangles(b)
    expected = onto.transfer_corners(library_shape(addon, a), faces_a, loop_uv(a, "cylinder")[loops_a], faces_b)
    got = loop_uv(b, "cylinder")[loops_b]
    assert np.allclose(got, expected, atol=1e-6)


def test_transfer_prefix_active_group_and_plain_interpolation(addon):
    a, b, upper, _ = rigged_source(addon)
    settings = bpy.context.scene.shapecorr
    settings.transfer_prefix = "from_source_"
    settings.transfer_active_group_only = True
    settings.transfer_normalize_weights = False
    settings.transfer_colors = False
    settings.transfer_attributes = False
    settings.transfer_uvs = False
    a.vertex_groups.active_index = a.vertex_groups["mask"].index
    try:
        assert bpy.ops.shapecorr.transfer() == {"FINISHED"}
    finally:
        settings.transfer_prefix = ""
        settings.transfer_active_group_only = False
        settings.transfer_normalize_weights = True
        settings.transfer_colors = True
        settings.transfer_attributes = True
        settings.transfer_uvs = True
    assert [g.name for g in b.vertex_groups] == ["from_source_mask"]
    assert len(b.data.uv_layers) == 0
    assert "paint" not in b.data.color_attributes and "heat" not in b.data.attributes
    onto, _ = library_surface_map(addon, a, b)
    expected = onto.transfer(group_weights(a, "mask"))
    assert np.allclose(group_weights(b, "from_source_mask"), expected, atol=1e-6)


@pytest.mark.parametrize("case, message", [("no_faces", "has no faces"), ("nan", "NON_FINITE_COORDINATE")])
def test_transfer_to_a_bad_target_writes_nothing(addon, case, message):
    a, b, _, _ = rigged_source(addon)
    (_, _), (vb, tb) = figures(addon)
    if case == "no_faces":
        bad = add_object("Bad", vb, [])
    else:
        vertices = vb.copy()
        vertices[3, 2] = np.nan
        bad = add_object("Bad", vertices, tb)
    select(a, bad)
    with pytest.raises(RuntimeError, match=message):
        bpy.ops.shapecorr.transfer()
    assert len(bad.vertex_groups) == 0
    assert len(bad.data.color_attributes) == 0
    assert len(bad.data.uv_layers) == 0
    assert "heat" not in bad.data.attributes


def test_transfer_with_nothing_to_carry_says_so(addon):
    fresh_scene()
    (va, ta), (vb, tb) = figures(addon)
    a = add_object("Plain", va, ta)
    b = add_object("Other", vb, tb)
    select(a, b)
    with pytest.raises(RuntimeError, match="nothing of what"):
        bpy.ops.shapecorr.transfer()
