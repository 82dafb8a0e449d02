"""See and correct the answer: Show Map colours the target by where its points land on the
source, so a swapped left and right or front and back shows at a glance; Use Other Answer
redoes the last run of the selected pair with the library's runner-up answer (kept with the
result: nothing is matched again)."""

import bpy
import numpy as np

from . import memory, shapecorr
from .operators import (
    _STAGES, PairInput, _LibraryOperator, confidence_text, ordered_selection, read_geometry,
    write_correspondence,
)
from .transfer import write_carried

#: Colour attribute (point domain) of Show Map: the source coloured by its position, the
#: target by the position its vertices land on.
MAP_ATTRIBUTE = "shapecorr_map"


def position_colors(vertices):
    """(n, 3) uint8: each coordinate scaled from its range over the shape to 0..255, as the
    command line's ``a_colors.ply`` (``coordinate_colors`` in src/colors.rs)."""
    vertices = np.asarray(vertices, dtype=np.float64)
    low, high = vertices.min(axis=0), vertices.max(axis=0)
    span = np.maximum(high - low, np.finfo(np.float64).tiny)
    # Rust's round() takes halves away from zero; numpy's to even.
    return np.floor(np.clip((vertices - low) / span, 0.0, 1.0) * 255.0 + 0.5).astype(np.uint8)


def write_colors(obj, rgb):
    """Writes (n, 3) uint8 sRGB colours as the point colour attribute ``shapecorr_map`` of
    ``obj``'s mesh, made the active and rendered one."""
    mesh = obj.data
    existing = mesh.attributes.get(MAP_ATTRIBUTE)
    if existing is not None:
        mesh.attributes.remove(existing)
    colors = mesh.color_attributes.new(MAP_ATTRIBUTE, "BYTE_COLOR", "POINT")
    rgba = np.concatenate([rgb, np.full((len(rgb), 1), 255, dtype=np.uint8)], axis=1)
    colors.data.foreach_set("color_srgb", (rgba.astype(np.float32) / 255.0).ravel())
    mesh.color_attributes.active_color_name = MAP_ATTRIBUTE
    mesh.color_attributes.render_color_index = mesh.color_attributes.active_color_index
    mesh.update()


def write_map(objects, world_a, pointwise):
    """Show Map's colours: A by its world position, B by the colour of the vertex of A that
    each of its vertices maps to (``b_mapped.ply``)."""
    colors_a = position_colors(world_a)
    write_colors(objects[0], colors_a)
    write_colors(objects[1], colors_a[pointwise.map_b_to_a])


class SHAPECORR_OT_show_map(_LibraryOperator, bpy.types.Operator):
    """Colour the active mesh by position and the other selected mesh by where its points land
    on it: a swapped left and right, or front and back, shows at a glance"""

    bl_idname = "shapecorr.show_map"
    bl_label = "Show Map"
    selection_size = 2
    stages = _STAGES + ["pointwise_map"]

    def prepare(self, context):
        pair = PairInput(context)
        self._pair = pair
        self._names = list(pair.names)
        self._repairs = pair.repairs
        # The map of an earlier Transfer or Show Map from the same input, as the scene shows
        # it (perhaps the other answer): shown as it is.
        kept = pair.kept_map()
        self._kept = kept
        pointwise = None if kept is None else kept.current(context.scene)
        arguments = pair.arguments()

        def work(progress):
            if pointwise is not None:
                return pointwise
            return shapecorr.pointwise_map(pair.shapes[0], pair.shapes[1], progress=progress, **arguments)

        return work

    def apply(self, context, result):
        objects = [bpy.data.objects[name] for name in self._names]
        write_map(objects, self._pair.geometries[0][0], result)
        entry = self._kept or self._pair.entry(result)
        entry.views["map"] = True
        memory.remember(entry)
        memory.write_summary(context.scene, self.bl_label, self._pair.names, result)
        reused = " (the map kept from the last run)" if self._kept is not None else ""
        return (
            f"shapecorr: '{objects[1].name}' coloured by where it lands on '{objects[0].name}'{reused}: "
            f"{confidence_text(result.confidence)}{memory.answer_text(result)}"
        )


class _Redone:
    """What Use Other Answer computed: the other answer and, when the last run carried
    attributes, the items carried through it."""

    def __init__(self, answer, items):
        self.answer = answer
        self.items = items
        self.confidence = answer.confidence
        self.warning = answer.warning


class SHAPECORR_OT_other_answer(_LibraryOperator, bpy.types.Operator):
    """Take the runner-up answer of the last run on the two selected meshes and redo what it
    did (region colours, Show Map, Transfer) with it; nothing is matched again"""

    bl_idname = "shapecorr.other_answer"
    bl_label = "Use Other Answer"
    selection_size = 2
    stages = ["transfer"]

    def prepare(self, context):
        objects = ordered_selection(context)
        names = tuple(o.name for o in objects)
        entry = memory.entry(names)
        if entry is None:
            raise ValueError(
                f"no answer kept for '{names[0]}' -> '{names[1]}' in this session (answers "
                "are kept in memory, not in the file): run Match Regions, Show Map or Transfer first"
            )
        depsgraph = context.evaluated_depsgraph_get()
        if memory.fingerprint([read_geometry(o, depsgraph) for o in objects]) != entry.geometry:
            raise ValueError(
                f"'{names[0]}' or '{names[1]}' changed since the last run (moved or edited): "
                "run it again"
            )
        current = entry.current(context.scene)
        if current.confidence is None:
            raise ValueError(
                "the last answer was not verified (One-to-One off), so there is no other answer"
            )
        other = current.other_answer()
        if other is None:
            raise ValueError(
                f"the answer '{current.hypothesis}' has no runner-up: every answer the "
                "library verified gives the same map"
            )
        self._entry, self._names = entry, list(names)
        carrying = entry.views.get("transfer")
        shapes = entry.shapes

        def work(progress):
            items = None if carrying is None else carrying.carry(shapes, other, progress)
            return _Redone(other, items)

        return work

    def apply(self, context, result):
        entry = self._entry
        objects = [bpy.data.objects[name] for name in self._names]
        other = result.answer
        done = []
        if "regions" in entry.views:
            correspondence = other if isinstance(other, shapecorr.Correspondence) else other.regions
            write_correspondence(objects, correspondence, entry.views["regions"]["one_to_one"])
            done.append("regions")
        if "map" in entry.views:
            write_map(objects, entry.world_a, other)
            done.append("map")
        if result.items is not None:
            carried = write_carried(objects[1], result.items)
            done.append(f"{carried} items carried")
        entry.answers.append(other)
        memory.write_summary(context.scene, self.bl_label, entry.names, other)
        return (
            f"shapecorr: other answer '{other.hypothesis}' for '{objects[0].name}' -> "
            f"'{objects[1].name}' ({', '.join(done)}), {confidence_text(other.confidence)}"
            f"{memory.answer_text(other)}"
        )
