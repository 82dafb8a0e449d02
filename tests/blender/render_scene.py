"""Renders two generated humanoids, matched by the Blender extension, with Cycles on the CPU.

    target/blender-venv/bin/python tests/blender/render_scene.py [OUT.png]

(run `bash tests/blender/run.sh` once first: it makes that environment) writes the README's
picture, docs/images/blender_match.png, from generated shapes only. The tests use render()
at a tiny size.
"""

import importlib
import math
import os
import sys
import tempfile
import zipfile
from pathlib import Path

import bpy

REPOSITORY = Path(__file__).resolve().parents[2]


def load_addon(zip_path, folder):
    """Unpacks the extension zip into ``folder`` and registers it as a package with relative
    imports, as Blender loads an installed extension. Returns the package."""
    with zipfile.ZipFile(zip_path) as archive:
        archive.extractall(Path(folder) / "shapecorr_ext")
    sys.path.insert(0, str(folder))
    package = importlib.import_module("shapecorr_ext")
    package.register()
    return package


def add_figure(sc, name, pose, size, x):
    shape = sc.Shape.figure("humanoid", pose, size)
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(shape.vertices.tolist(), [], shape.triangles.tolist())
    mesh.polygons.foreach_set("use_smooth", [True] * len(mesh.polygons))
    mesh.update()
    obj = bpy.data.objects.new(name, mesh)
    obj.location = (x, 0.0, 0.0)
    obj.rotation_euler = (math.pi / 2, 0.0, 0.0)  # the figures are Y-up, Blender is Z-up
    bpy.context.scene.collection.objects.link(obj)
    return obj


def render(addon, out, resolution=(640, 360), samples=32, size=5000):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    sc = addon.shapecorr
    a = add_figure(sc, "A", 0, size, -0.8)
    b = add_figure(sc, "B", 4, size, 0.8)
    for obj in scene.objects:
        obj.select_set(obj in (a, b))
    bpy.context.view_layer.objects.active = a
    if bpy.ops.shapecorr.match_regions() != {"FINISHED"}:
        raise RuntimeError("matching failed")

    material = bpy.data.materials.new("shapecorr regions")
    material.use_nodes = True
    nodes = material.node_tree.nodes
    attribute = nodes.new("ShaderNodeAttribute")
    attribute.attribute_name = "shapecorr_regions"
    bsdf = nodes["Principled BSDF"]
    bsdf.inputs["Roughness"].default_value = 0.6
    material.node_tree.links.new(attribute.outputs["Color"], bsdf.inputs["Base Color"])
    for obj in (a, b):
        obj.data.materials.append(material)

    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    camera.location = (0.0, -5.2, 0.95)
    camera.rotation_euler = (math.pi / 2, 0.0, 0.0)
    scene.collection.objects.link(camera)
    scene.camera = camera
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 3.0
    sun.rotation_euler = (math.radians(50), math.radians(-20), math.radians(-30))
    scene.collection.objects.link(sun)
    world = bpy.data.worlds.new("World")
    world.color = (0.6, 0.6, 0.6)
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.6, 0.6, 0.6, 1.0)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.6
    scene.world = world

    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False
    scene.cycles.seed = 0
    scene.view_settings.view_transform = "Standard"
    scene.render.resolution_x, scene.render.resolution_y = resolution
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "PNG"
    scene.render.filepath = str(out)
    bpy.ops.render.render(write_still=True)


def main():
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else REPOSITORY / "docs" / "images" / "blender_match.png"
    out.parent.mkdir(parents=True, exist_ok=True)
    sys.path.insert(0, str(REPOSITORY / "blender_addon"))
    import build

    with tempfile.TemporaryDirectory() as folder:
        zip_path = build.build(REPOSITORY / "target" / "release" / "libshapecorr.so", folder)
        addon = load_addon(zip_path, folder)
        render(addon, out)
    print(out)


if __name__ == "__main__":
    main()
    # bpy 4.5's exit handler can deadlock after a Cycles render (its delayed-close thread
    # waits on a condition variable that the global destructor is tearing down); the work is
    # done and written, so leave without running it.
    sys.stdout.flush()
    os._exit(0)
