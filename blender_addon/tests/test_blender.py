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


def split_apart(vertices, triangles, gap):
    """:func:`seam_split`, then the +x side moved ``gap`` further along x: two pieces of one
    figure that come close without touching, as a model in parts."""
    vertices, split, original = seam_split(vertices, triangles)
    right = vertices[split].sum(axis=1)[:, 0] > 0.0
    moved = np.zeros(len(vertices), dtype=bool)
    moved[split[right].ravel()] = True
    vertices = vertices.copy()
    vertices[moved, 0] += gap
    return vertices, split, original


def test_pieces_joined_for_matching_are_reported(addon, capfd):
    """A figure in two pieces 0.5% of its height apart (within the 1% the library joins,
    docs/decisions.md, "Shapes in pieces"): a warning report on that object says they were
    joined; both ran on their input, so no line says what they were matched on."""
    fresh_scene()
    (va, ta), (vb, tb) = figures(addon)
    vertices, triangles, _ = split_apart(va, ta, 0.005 * np.ptp(va, axis=0).max())
    shape = addon.shapecorr.Shape.mesh(vertices, triangles)
    assert not any("welded" in r for r in shape.repairs), shape.repairs
    a = add_object("Parts", vertices, triangles)
    b = add_object("Posed", vb, tb, location=(3.0, 0.0, 0.0))
    select(a, b)
    reports(capfd)
    assert bpy.ops.shapecorr.match_regions() == {"FINISHED"}
    found = reports(capfd)
    assert any(level == "Warning" and "'Parts'" in text and "joined" in text for level, text in found), found
    assert not any("was matched on" in text for _, text in found), found


def test_a_low_poly_mesh_is_reported_as_matched_on_a_refined_copy(addon, capfd):
    """A figure of 600 vertices (below ``refine_below``, 2,000) runs on a refined copy: one
    info report names it with both sizes; the 2,500-vertex one ran on its input."""
    fresh_scene()
    low = addon.shapecorr.Shape.figure("humanoid", 0, 600)
    (vb, tb), = figures(addon, poses=(3,))
    a = add_object("Fox", low.vertices, low.triangles)
    b = add_object("Posed", vb, tb, location=(3.0, 0.0, 0.0))
    select(a, b)
    reports(capfd)
    assert bpy.ops.shapecorr.match_regions() == {"FINISHED"}
    lines = [text for _, text in reports(capfd) if "was matched on" in text]
    expected = addon.shapecorr.match(low, addon.shapecorr.Shape.figure("humanoid", 3, SIZE)).working[0]
    assert expected.kind == "refined" and expected.vertices > low.n_vertices
    assert lines == [
        f"shapecorr: 'Fox' was matched on a refined copy of {expected.vertices:,} vertices "
        f"(the input has {low.n_vertices:,})"
    ], lines


def test_the_report_says_a_noisy_object_was_smoothed(addon):
    from types import SimpleNamespace

    Working = addon.shapecorr.Working
    result = SimpleNamespace(
        n_vertices_a=5000, n_vertices_b=250000,
        working=(Working("input", 5000, True), Working("proxy", 8000, True)),
    )
    assert addon.operators.working_notes(["Scan", "Statue"], result) == [
        "shapecorr: 'Scan' looks noisy (scanner noise): it was matched on a smoothed copy; the answers are on its own vertices",
        "shapecorr: 'Statue' was matched on a smoothed proxy of 8,000 vertices (the input has 250,000)",
    ]


def test_the_report_says_an_object_touching_the_figure_was_left_out(addon):
    from types import SimpleNamespace

    Working = addon.shapecorr.Working
    result = SimpleNamespace(
        n_vertices_a=5000, n_vertices_b=5866,
        working=(Working("input", 5000), Working("input", 5000, False, 866)),
    )
    assert addon.operators.working_notes(["Body", "Body and box"], result) == [
        "shapecorr: 'Body and box': 866 vertices of an object touching the figure (a prop) were left out: the pair matched better without them; they take the answer of the nearest kept vertex",
    ]


def test_the_report_says_the_time_limit_kept_an_object_from_being_tried(addon):
    from types import SimpleNamespace

    Working = addon.shapecorr.Working
    result = SimpleNamespace(
        n_vertices_a=5000, n_vertices_b=5866,
        working=(Working("input", 5000), Working("input", 5866, False, 0, 1)),
    )
    assert addon.operators.working_notes(["Body", "Body and box"], result) == [
        "shapecorr: 'Body and box': 1 object(s) touching the figure were matched as part of it: the time limit passed before the pair could try without them (raise the time limit to try)",
    ]


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
    options = {o.name: o for o in addon.shapecorr.options()}
    # A choice (placement) by its name, as the panel passes it.
    defaults = {name: o.choices[o.default] if o.choices else o.default for name, o in options.items()}
    passed = settings.library_options()
    # Every option the panel passes is a name of the library's one table, with its default.
    assert passed and set(passed) <= set(defaults), set(passed) - set(defaults)
    assert "placement" in passed
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
    # Built with the `dist` profile, no debug information (the target is at most 8 MB).
    assert sizes[library[0]] <= 8 * 1024 * 1024, sizes[library[0]]
    # The manifest's licence and the project's two travel with it.
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


# ----------------------------------------------------------------------------------- Transfer


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


def test_transfer_from_a_part_writes_only_what_the_part_covers(addon):
    """A quadruped with its lower third cut away carries an attribute to the whole one: the
    vertices the part holds get it, the others keep their own value, and the report and the
    panel say so. The figures share their vertex order, which gives the truth."""
    fresh_scene()
    (va, ta), (vb, tb) = figures(addon, "quadruped", (0, 1))
    height = va[:, 1]
    floor = height.min() + (height.max() - height.min()) / 3
    kept_triangles = ta[(height[ta] > floor).all(axis=1)]
    kept = np.unique(kept_triangles)
    new_index = np.full(len(va), -1, dtype=np.int64)
    new_index[kept] = np.arange(len(kept))
    a = add_object("Part", va[kept], new_index[kept_triangles])
    b = add_object("Whole", vb, tb, location=(3.0, 0.0, 0.0))
    a.data.attributes.new("heat", "FLOAT", "POINT").data.foreach_set("value", np.ones(len(kept), dtype=np.float32))
    b.data.attributes.new("heat", "FLOAT", "POINT").data.foreach_set("value", np.full(len(vb), -1.0, dtype=np.float32))
    select(a, b)
    settings = bpy.context.scene.shapecorr
    settings.partial = "a_in_b"
    try:
        assert bpy.ops.shapecorr.transfer() == {"FINISHED"}
    finally:
        settings.partial = "auto"
    heat = np.empty(len(vb), dtype=np.float32)
    b.data.attributes["heat"].data.foreach_get("value", heat)
    inside = np.zeros(len(vb), dtype=bool)
    inside[kept] = True
    written = np.isclose(heat, 1.0)
    assert np.isclose(heat[~written], -1.0).all(), "a vertex is either carried or left as it was"
    assert written[inside].mean() > 0.9
    assert (~written[~inside]).mean() > 0.75
    answer = settings.answer
    assert answer.taken_as == "a_in_b"
    assert answer.uncovered_target == int((~written).sum()) > 0


# ------------------------------------------------------------- Check and correct the answer


def answers_module():
    return sys.modules["shapecorr_ext.answers"]


def memory_module():
    return sys.modules["shapecorr_ext.memory"]


def world_shape(addon, obj):
    """The library's shape of ``obj`` as the add-on reads it (world space, its triangles)."""
    return library_shape(addon, obj)


def point_colors(obj, name):
    """A point colour attribute as (n, 4) sRGB bytes."""
    n = len(obj.data.vertices)
    rgba = np.empty(4 * n, dtype=np.float32)
    obj.data.color_attributes[name].data.foreach_get("color_srgb", rgba)
    return np.round(rgba.reshape(n, 4) * 255).astype(np.uint8)


def expected_position_colors(vertices):
    """Each coordinate scaled from its range to 0..255 (the command line's a_colors.ply),
    written again here from its definition."""
    low, high = vertices.min(axis=0), vertices.max(axis=0)
    return np.floor((vertices - low) / (high - low) * 255.0 + 0.5).astype(np.uint8)


def world_vertices(obj):
    n = len(obj.data.vertices)
    co = np.empty(3 * n, dtype=np.float32)
    obj.data.vertices.foreach_get("co", co)
    matrix = np.array(obj.matrix_world, dtype=np.float64)
    return co.reshape(n, 3).astype(np.float64) @ matrix[:3, :3].T + matrix[:3, 3]


def two_figures(addon, poses=(0, 3), rotation_z=0.0):
    fresh_scene()
    (va, ta), (vb, tb) = figures(addon, "humanoid", poses)
    a = add_object("A", va, ta)
    b = add_object("B", vb, tb, location=(3.0, 0.0, 0.0), rotation_z=rotation_z)
    select(a, b)
    return a, b


def make_active_vertex(obj, index):
    """In Edit Mode: ``index`` becomes the only selected vertex of ``obj`` and the active one."""
    import bmesh

    mesh = bmesh.from_edit_mesh(obj.data)
    mesh.verts.ensure_lookup_table()
    for vertex in mesh.verts:
        vertex.select = False
    mesh.select_history.clear()
    if index is not None:
        mesh.verts[index].select = True
        mesh.select_history.add(mesh.verts[index])
    bmesh.update_edit_mesh(obj.data)


def add_landmark(a, b, vertex_a, vertex_b):
    """A landmark pair written directly into the scene's list (as Add Pair stores one)."""
    pair = bpy.context.scene.shapecorr.landmarks.add()
    pair.object_1, pair.vertex_1, pair.object_2, pair.vertex_2 = a, vertex_a, b, vertex_b
    return pair


def test_landmark_pairs_are_added_in_edit_mode_removed_and_cleared(addon):
    a, b = two_figures(addon)
    settings = bpy.context.scene.shapecorr
    assert not bpy.ops.shapecorr.landmark_add.poll(), "Object Mode: no pair to take"
    bpy.ops.object.mode_set(mode="EDIT")
    assert {o.name for o in bpy.context.view_layer.objects if o.mode == "EDIT"} == {"A", "B"}
    make_active_vertex(a, 10)
    make_active_vertex(b, 20)
    assert bpy.ops.shapecorr.landmark_add() == {"FINISHED"}
    make_active_vertex(a, 30)
    make_active_vertex(b, 40)
    assert bpy.ops.shapecorr.landmark_add() == {"FINISHED"}
    # A vertex already in a pair is refused (the library takes one partner per vertex).
    make_active_vertex(b, 20)
    with pytest.raises(RuntimeError, match="already in landmark pair 1"):
        bpy.ops.shapecorr.landmark_add()
    # No active vertex on one mesh: said, nothing added.
    make_active_vertex(b, None)
    with pytest.raises(RuntimeError, match="'B': make one vertex active"):
        bpy.ops.shapecorr.landmark_add()
    bpy.ops.object.mode_set(mode="OBJECT")
    stored = [(p.object_1.name, p.vertex_1, p.object_2.name, p.vertex_2) for p in settings.landmarks]
    assert stored == [("A", 10, "B", 20), ("A", 30, "B", 40)]
    # The pairs as the library gets them: A's vertex first, whichever object is active.
    pairs_of = sys.modules["shapecorr_ext.landmarks"].landmark_pairs
    assert pairs_of(bpy.context.scene, a, b) == [(10, 20), (30, 40)]
    assert pairs_of(bpy.context.scene, b, a) == [(20, 10), (40, 30)]
    settings.landmark_index = 0
    assert bpy.ops.shapecorr.landmark_remove() == {"FINISHED"}
    assert [(p.vertex_1, p.vertex_2) for p in settings.landmarks] == [(30, 40)]
    assert bpy.ops.shapecorr.landmark_clear() == {"FINISHED"}
    assert len(settings.landmarks) == 0
    assert not bpy.ops.shapecorr.landmark_remove.poll()


def test_landmarks_survive_save_and_reload_and_the_kept_answer_does_not(addon, tmp_path):
    a, b = two_figures(addon)
    add_landmark(a, b, 10, 20)
    add_landmark(b, a, 40, 30)
    assert bpy.ops.shapecorr.match_regions() == {"FINISHED"}
    path = str(tmp_path / "landmarks.blend")
    bpy.ops.wm.save_as_mainfile(filepath=path)
    fresh_scene()
    assert len(bpy.context.scene.shapecorr.landmarks) == 0
    bpy.ops.wm.open_mainfile(filepath=path)
    scene = bpy.context.scene
    stored = [(p.object_1.name, p.vertex_1, p.object_2.name, p.vertex_2) for p in scene.shapecorr.landmarks]
    assert stored == [("A", 10, "B", 20), ("B", 40, "A", 30)]
    a, b = bpy.data.objects["A"], bpy.data.objects["B"]
    assert sys.modules["shapecorr_ext.landmarks"].landmark_pairs(scene, a, b) == [(10, 20), (30, 40)]
    # The panel's summary is saved with the file; the library's result is not.
    assert scene.shapecorr.answer.operation == "Match Regions"
    select(a, b)
    with pytest.raises(RuntimeError, match="no answer kept for 'A' -> 'B'"):
        bpy.ops.shapecorr.other_answer()


def test_show_map_colours_the_target_by_where_it_lands_like_the_library(addon):
    a, b = two_figures(addon, rotation_z=0.7)
    bpy.context.scene.shapecorr.placement = "ignore"  # B is turned: the shapes alone decide
    try:
        assert bpy.ops.shapecorr.show_map() == {"FINISHED"}
    finally:
        bpy.context.scene.shapecorr.placement = "auto"
    name = answers_module().MAP_ATTRIBUTE
    world_a = world_vertices(a)
    colors_a = expected_position_colors(world_a)
    got_a, got_b = point_colors(a, name), point_colors(b, name)
    assert np.array_equal(got_a[:, :3], colors_a)
    assert np.all(got_a[:, 3] == 255) and np.all(got_b[:, 3] == 255)
    expected = addon.shapecorr.pointwise_map(world_shape(addon, a), world_shape(addon, b), placement="ignore")
    assert np.array_equal(got_b[:, :3], colors_a[expected.map_b_to_a])
    for obj in (a, b):
        assert obj.data.color_attributes.active_color_name == name
        assert obj.data.color_attributes[name].domain == "POINT"
    # The figures share their vertex order: a right map gives most vertices of B the colour
    # of the same vertex of A (a swap would not).
    close = np.all(np.abs(got_b[:, :3].astype(int) - colors_a.astype(int)) <= 20, axis=1)
    assert np.mean(close) > 0.8, np.mean(close)
    answer = bpy.context.scene.shapecorr.answer
    assert (answer.operation, answer.source, answer.target) == ("Show Map", "A", "B")
    assert answer.hypothesis == expected.hypothesis
    assert answer.confidence == pytest.approx(expected.confidence, abs=1e-6)


def test_show_map_is_undoable(addon):
    assert {"REGISTER", "UNDO"} <= answers_module().SHAPECORR_OT_show_map.bl_options
    two_figures(addon)
    bpy.ops.ed.undo_push(message="before shapecorr")
    assert bpy.ops.shapecorr.show_map() == {"FINISHED"}
    name = answers_module().MAP_ATTRIBUTE
    assert name in bpy.data.objects["B"].data.color_attributes
    if not bpy.ops.ed.undo.poll():
        pytest.skip("ed.undo needs a window, which headless bpy does not have")
    bpy.ops.ed.undo()
    for obj_name in ("A", "B"):
        assert name not in bpy.data.objects[obj_name].data.color_attributes


def test_landmarks_reach_the_library_and_map_exactly_to_their_partners(addon):
    """A landmark the figures' own vertex order contradicts (vertex 2000 of B to vertex 10 of
    A): the map sends it exactly there, as the library's own map with that landmark does."""
    a, b = two_figures(addon)
    add_landmark(a, b, 10, 2000)
    add_landmark(b, a, 700, 1500)  # named B first: the add-on turns it round
    assert bpy.ops.shapecorr.show_map() == {"FINISHED"}
    colors_a = expected_position_colors(world_vertices(a))
    got_b = point_colors(b, answers_module().MAP_ATTRIBUTE)[:, :3]
    assert np.array_equal(got_b[2000], colors_a[10])
    assert np.array_equal(got_b[700], colors_a[1500])
    assert not np.array_equal(colors_a[10], colors_a[2000])
    sc = addon.shapecorr
    expected = sc.pointwise_map(world_shape(addon, a), world_shape(addon, b), landmarks=[(10, 2000), (1500, 700)])
    assert np.array_equal(got_b, colors_a[expected.map_b_to_a])


@pytest.mark.parametrize("operation", ["match_regions", "transfer"])
@pytest.mark.parametrize(
    "case, message",
    [("out_of_range", "landmark pair 1: 'Target' has no vertex 99999"), ("two_partners", "landmarks")],
)
def test_a_bad_landmark_is_reported_and_leaves_the_scene_unchanged(addon, operation, case, message):
    a, b, _, _ = rigged_source(addon)
    if case == "out_of_range":
        add_landmark(a, b, 5, 99999)
    else:
        # One vertex of A with two partners (Add Pair refuses it; a script need not).
        add_landmark(a, b, 5, 6)
        add_landmark(a, b, 5, 7)
    before = {o.name: (len(o.vertex_groups), len(o.data.color_attributes), len(o.data.attributes)) for o in (a, b)}
    with pytest.raises(RuntimeError, match=message):
        getattr(bpy.ops.shapecorr, operation)()
    after = {o.name: (len(o.vertex_groups), len(o.data.color_attributes), len(o.data.attributes)) for o in (a, b)}
    assert after == before
    assert bpy.context.scene.shapecorr.answer.operation == ""
    assert memory_module().entry(("Source", "Target")) is None


@pytest.mark.parametrize("placement, used", [("ignore", False), ("trust", True)])
def test_the_placement_setting_reaches_the_library(addon, placement, used):
    """Trust always takes the answer of least turn (the placement is used), Ignore never: the
    panel's summary says which, as the library's own result with that setting does."""
    a, b = two_figures(addon)
    settings = bpy.context.scene.shapecorr  # after the new scene: the old one is freed
    settings.placement = placement
    try:
        assert settings.library_options()["placement"] == placement
        assert bpy.ops.shapecorr.match_regions() == {"FINISHED"}
    finally:
        settings.placement = "auto"
    expected = addon.shapecorr.match(world_shape(addon, a), world_shape(addon, b), placement=placement)
    answer = settings.answer
    assert expected.placement_used is used
    assert answer.placement_used is used
    assert answer.hypothesis == expected.hypothesis
    assert answer.decided_by == expected.decided_by


def test_use_other_answer_recolours_the_regions_with_the_runner_up(addon, capfd):
    a, b = two_figures(addon)
    assert bpy.ops.shapecorr.match_regions() == {"FINISHED"}
    sc = addon.shapecorr
    expected = sc.match(world_shape(addon, a), world_shape(addon, b))
    other = expected.other_answer()
    assert other is not None, "the figures' mirror is a different answer"
    assert other.hypothesis != expected.hypothesis
    first = [attribute_arrays(o)[0] for o in (a, b)]
    reports(capfd)
    assert bpy.ops.shapecorr.other_answer() == {"FINISHED"}
    found = reports(capfd)
    assert any(f"other answer '{other.hypothesis}'" in text for level, text in found if level == "Info"), found
    for obj, side, before in zip((a, b), "ab", first):
        rgba, regions = attribute_arrays(obj)
        assert np.array_equal(rgba, other.colors(side)), side
        assert np.array_equal(regions, other.regions(side).astype(np.int32))
    assert not all(np.array_equal(attribute_arrays(o)[0], f) for o, f in zip((a, b), first))
    answer = bpy.context.scene.shapecorr.answer
    assert (answer.operation, answer.hypothesis, answer.decided_by) == (
        "Use Other Answer", other.hypothesis, "other answer")
    # Once more: the runner-up of the other answer, again from memory.
    again = other.other_answer()
    assert bpy.ops.shapecorr.other_answer() == {"FINISHED"}
    assert bpy.context.scene.shapecorr.answer.hypothesis == again.hypothesis


def test_use_other_answer_carries_again_through_the_runner_up(addon):
    a, b, _, _ = rigged_source(addon)
    settings = bpy.context.scene.shapecorr
    settings.transfer_uvs = False
    try:
        assert bpy.ops.shapecorr.transfer() == {"FINISHED"}
        names = ("upper", "lower", "mask")
        first = np.stack([group_weights(b, n) for n in names], axis=1)
        assert bpy.ops.shapecorr.show_map() == {"FINISHED"}  # the same map, kept
        assert bpy.ops.shapecorr.other_answer() == {"FINISHED"}
    finally:
        settings.transfer_uvs = True
    shapes = [library_shape(addon, o) for o in (a, b)]
    sc = addon.shapecorr
    pointwise = sc.pointwise_map(*shapes)
    other = pointwise.other_answer()
    assert other is not None
    onto = sc.surface_map(shapes[0], shapes[1], other)
    source = np.stack([group_weights(a, n) for n in names], axis=1)
    expected = onto.transfer(source, mode="weights", max_influences=4)
    got = np.stack([group_weights(b, n) for n in names], axis=1)
    assert np.allclose(got, expected.astype(np.float32), atol=1e-6)
    assert not np.allclose(got, first, atol=1e-3), "the other answer carries elsewhere"
    # Show Map was redone with it too.
    colors_a = expected_position_colors(world_vertices(a))
    got_b = point_colors(b, answers_module().MAP_ATTRIBUTE)[:, :3]
    assert np.array_equal(got_b, colors_a[other.map_b_to_a])
    # A Transfer now uses the answer taken (kept in memory), not a new match.
    assert bpy.ops.shapecorr.transfer() == {"FINISHED"}
    again = np.stack([group_weights(b, n) for n in names], axis=1)
    assert np.allclose(again, got, atol=1e-6)


def test_use_other_answer_says_when_there_is_none(addon):
    a, b = two_figures(addon)
    with pytest.raises(RuntimeError, match="no answer kept"):
        bpy.ops.shapecorr.other_answer()
    settings = bpy.context.scene.shapecorr
    settings.one_to_one = False
    try:
        assert bpy.ops.shapecorr.match_regions() == {"FINISHED"}
    finally:
        settings.one_to_one = True
    before = attribute_arrays(b)[0]
    with pytest.raises(RuntimeError, match="not verified"):
        bpy.ops.shapecorr.other_answer()
    assert np.array_equal(attribute_arrays(b)[0], before)
    # A mesh moved since the answer: refused, not applied to another shape.
    assert bpy.ops.shapecorr.match_regions() == {"FINISHED"}
    b.location.x += 1.0
    bpy.context.view_layer.update()
    with pytest.raises(RuntimeError, match="changed since the last run"):
        bpy.ops.shapecorr.other_answer()



def test_use_other_answer_without_a_runner_up_says_so_and_changes_nothing(addon):
    """Two quadrupeds (1500 vertices, poses 0 and 1): every answer the library verifies gives
    the same map (measured), so there is no other answer."""
    fresh_scene()
    sc = addon.shapecorr
    shapes = [sc.Shape.figure("quadruped", pose, 1500) for pose in (0, 1)]
    a = add_object("A", shapes[0].vertices, shapes[0].triangles)
    b = add_object("B", shapes[1].vertices, shapes[1].triangles, location=(3.0, 0.0, 0.0))
    select(a, b)
    assert bpy.ops.shapecorr.match_regions() == {"FINISHED"}
    expected = sc.match(world_shape(addon, a), world_shape(addon, b))
    assert expected.confidence is not None and expected.runner_up is None
    assert expected.other_answer() is None
    assert "Runner-up: none" in [text for kind, text in draw_panels(addon) if kind == "label"]
    before = [attribute_arrays(o)[0] for o in (a, b)]
    with pytest.raises(RuntimeError, match=f"the answer '{expected.hypothesis}' has no runner-up"):
        bpy.ops.shapecorr.other_answer()
    assert all(np.array_equal(attribute_arrays(o)[0], f) for o, f in zip((a, b), before))
    assert bpy.context.scene.shapecorr.answer.operation == "Match Regions"


class RecordingLayout:
    """Stands in for a panel's layout (headless Blender draws no panel): records the labels,
    properties and operators drawn, in order."""

    def __init__(self, record=None):
        self.record = [] if record is None else record
        self.enabled = True

    def _sub(self, *args, **kwargs):
        return RecordingLayout(self.record)

    column = row = box = split = _sub

    def label(self, text="", icon="NONE"):
        self.record.append(("label", text))

    def prop(self, data, name, **kwargs):
        assert hasattr(data, name), name
        self.record.append(("prop", name))

    def operator(self, idname, **kwargs):
        category, name = idname.split(".")
        assert hasattr(getattr(bpy.ops, category), name), idname
        self.record.append(("operator", idname))

    def template_list(self, list_type, list_id, data, name, active_data, active_name, **kwargs):
        assert hasattr(bpy.types, list_type), list_type
        assert hasattr(data, name) and hasattr(active_data, active_name)
        self.record.append(("list", name))


def draw_panels(addon):
    """What every panel of the add-on draws now, as RecordingLayout records."""
    layout = RecordingLayout()
    panel = addon.panel
    for cls in (panel.SHAPECORR_PT_panel, panel.SHAPECORR_PT_answer, panel.SHAPECORR_PT_landmarks,
                panel.SHAPECORR_PT_transfer):
        fake = type("Panel", (), {"layout": layout})()
        cls.draw(fake, bpy.context)
    return layout.record


def test_the_panel_shows_the_answer_the_buttons_and_the_landmarks(addon):
    a, b = two_figures(addon)
    drawn = draw_panels(addon)
    assert ("prop", "placement") in drawn
    for idname in ("shapecorr.show_map", "shapecorr.other_answer", "shapecorr.landmark_add",
                   "shapecorr.landmark_remove", "shapecorr.landmark_clear"):
        assert ("operator", idname) in drawn, idname
    assert ("list", "landmarks") in drawn
    assert ("label", "No answer yet") in drawn
    assert bpy.ops.shapecorr.match_regions() == {"FINISHED"}
    expected = addon.shapecorr.match(world_shape(addon, a), world_shape(addon, b))
    labels = [text for kind, text in draw_panels(addon) if kind == "label"]
    assert "Match Regions: A \u2192 B" in labels, labels
    assert f"Confidence {expected.confidence:.2f}" in labels, labels
    assert f"Answer: {expected.hypothesis} (by {expected.decided_by})" in labels, labels
    placement = [t for t in labels if t.startswith("Placement: ")]
    assert placement == [f"Placement: {'used' if expected.placement_used else 'not used'}, "
                         f"turn {expected.turn_degrees:.0f}\u00b0"], labels
    runner_up = expected.runner_up
    if runner_up is None:
        assert "Runner-up: none" in labels, labels
    else:
        field = memory_module()._field
        text = f"Runner-up: {field(runner_up, 'hypothesis')}, cost {field(runner_up, 'cost'):.3g}"
        assert text in labels, labels
