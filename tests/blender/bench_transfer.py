"""Benchmark: the Blender Transfer operator end to end on a generated 30K-vertex pair
(the target: at most 3 s; docs/transfer.md), against the library alone on the same data in the same run.

    bash tests/blender/run.sh   # once: builds the extension's environment
    target/blender-venv/bin/python tests/blender/bench_transfer.py [--size 30000] [--repeat 3]

The source carries what a rigged, unwrapped, painted character carries: 24 skin-weight
vertex groups (4 influences a vertex), a UV map, a colour attribute and a float attribute.
The target is another pose of the figure, moved and turned. The operator runs as Blender
runs it headless (`execute`: the same work the modal path gives to its worker thread), so
the time is read the scene + match + map + surface map + transfer + write the target. The
reference is the library's own calls on the same arrays (`pointwise_map`, `surface_map`,
`transfer`, `transfer_corners`); the difference is the add-on's reading and writing.
"""

import argparse
import platform
import sys
import tempfile
import time
from pathlib import Path

import bpy
import numpy as np

REPOSITORY = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPOSITORY / "tests" / "blender"))
sys.path.insert(0, str(REPOSITORY / "blender_addon"))
sys.path.insert(0, str(REPOSITORY / "blender_addon" / "tests"))

import build  # noqa: E402
import render_scene  # noqa: E402
from test_blender import add_cylinder_uv, add_object, library_shape, loop_triangles, loop_uv, select  # noqa: E402

BONES = 24
INFLUENCES = 4


def skin_weights(vertices, rng):
    """Smooth weights of ``BONES`` bones placed on random vertices, the 4 largest kept per
    vertex and normalised (what an automatic-weights rig looks like)."""
    bones = vertices[rng.choice(len(vertices), BONES, replace=False)]
    distance = np.linalg.norm(vertices[:, None, :] - bones[None, :, :], axis=2)
    weights = np.exp(-((distance / (0.1 * np.ptp(vertices[:, 1]))) ** 2))
    smallest = np.argsort(weights, axis=1)[:, : BONES - INFLUENCES]
    np.put_along_axis(weights, smallest, 0.0, axis=1)
    return weights / np.maximum(weights.sum(axis=1, keepdims=True), 1e-12)


def source_and_target(sc, size):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    shapes = [sc.Shape.figure("humanoid", pose, size) for pose in (0, 3)]
    a = add_object("Source", shapes[0].vertices, shapes[0].triangles)
    b = add_object("Target", shapes[1].vertices, shapes[1].triangles, location=(3.0, 0.0, 0.0), rotation_z=0.7)
    vertices = shapes[0].vertices
    weights = skin_weights(vertices, np.random.default_rng(0))
    for bone in range(BONES):
        group = a.vertex_groups.new(name=f"bone_{bone:02d}")
        for vertex in np.flatnonzero(weights[:, bone]):
            group.add([int(vertex)], float(weights[vertex, bone]), "REPLACE")
    height = (vertices[:, 1] - vertices[:, 1].min()) / np.ptp(vertices[:, 1])
    colors = a.data.color_attributes.new("paint", "FLOAT_COLOR", "POINT")
    rgba = np.stack([height, 1.0 - height, np.full_like(height, 0.5), np.ones_like(height)], axis=1)
    colors.data.foreach_set("color", rgba.astype(np.float32).ravel())
    a.data.attributes.new("heat", "FLOAT", "POINT").data.foreach_set("value", height.astype(np.float32))
    add_cylinder_uv(a)
    select(a, b)
    return a, b, weights, rgba, height


def library_alone(addon, a, b, weights, rgba, height):
    """The library's calls on the arrays the operator reads: seconds."""
    shapes = [library_shape(addon, obj) for obj in (a, b)]
    faces_a, loops_a = loop_triangles(a)
    faces_b = loop_triangles(b)[0]
    uv = loop_uv(a, "cylinder")[loops_a]
    sc = addon.shapecorr
    start = time.perf_counter()
    pointwise = sc.pointwise_map(*shapes)
    onto = sc.surface_map(shapes[0], shapes[1], pointwise)
    onto.transfer(weights, mode="weights", max_influences=INFLUENCES)
    onto.transfer(rgba)
    onto.transfer(height[:, None])
    onto.transfer_corners(shapes[0], faces_a, uv, faces_b)
    return time.perf_counter() - start


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=30000, help="vertices a figure")
    parser.add_argument("--repeat", type=int, default=3)
    arguments = parser.parse_args(sys.argv[sys.argv.index("--") + 1 :] if "--" in sys.argv else sys.argv[1:])

    with tempfile.TemporaryDirectory() as folder:
        zip_path = build.build(REPOSITORY / "target" / "dist" / "libshapecorr.so", Path(folder) / "zip")
        addon = render_scene.load_addon(zip_path, Path(folder) / "extensions")
        sc = addon.shapecorr
        print(f"Blender {bpy.app.version_string}, {platform.processor() or platform.machine()}, "
              f"{len(__import__('os').sched_getaffinity(0))} cores, {arguments.size} vertices a figure")
        operator_times, library_times = [], []
        for _ in range(arguments.repeat):
            a, b, weights, rgba, height = source_and_target(sc, arguments.size)
            bpy.context.scene.shapecorr.transfer_max_influences = INFLUENCES
            start = time.perf_counter()
            result = bpy.ops.shapecorr.transfer()
            operator_times.append(time.perf_counter() - start)
            if result != {"FINISHED"}:
                raise SystemExit(f"the operator returned {result}")
            carried = sum(1 for g in b.vertex_groups if g.name.startswith("bone_"))
            if carried != BONES or "cylinder" not in b.data.uv_layers:
                raise SystemExit(f"the target got {carried} groups and UV maps {list(b.data.uv_layers.keys())}")
            library_times.append(library_alone(addon, a, b, weights, rgba, height))
        operator, library = np.median(operator_times), np.median(library_times)
        print(f"operator (median of {arguments.repeat}): {operator:.2f} s  "
              f"[{', '.join(f'{t:.2f}' for t in operator_times)}]")
        print(f"library alone:                {library:.2f} s  [{', '.join(f'{t:.2f}' for t in library_times)}]")
        print(f"operator / library: {operator / library:.2f}; target: operator at most 3 s")
        addon.unregister()


if __name__ == "__main__":
    main()
