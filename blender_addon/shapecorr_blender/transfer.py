"""Transfer: carry vertex groups, UV maps, colour attributes and point attributes from the active
mesh (the source, A) to the other selected mesh (the target, B) through the library's map
(match, pointwise map, surface map, transfer), whatever their poses and bodies.

Everything the target gets is computed in the worker thread before anything is written;
the main thread then writes it in one undo step, so a failure leaves the scene as it was.
"""

import bpy
import numpy as np

from . import memory, shapecorr
from .operators import _STAGES, PairInput, _LibraryOperator, confidence_text, ordered_selection

#: Point attributes that are Blender's own, never carried.
_INTERNAL = {"position", "sharp_face", "material_index"}
#: Data types carried by interpolation (float) and by the nearest vertex (integer, boolean).
_FLOAT_TYPES = {"FLOAT": 1, "FLOAT2": 2, "FLOAT_VECTOR": 3, "FLOAT_COLOR": 4, "BYTE_COLOR": 4}
_DISCRETE_TYPES = {"INT": 1, "INT8": 1, "BOOLEAN": 1}


def _field(data_type):
    """The foreach_get field of an attribute's data type."""
    if data_type in ("FLOAT_VECTOR", "FLOAT2"):
        return "vector"
    if data_type in ("FLOAT_COLOR", "BYTE_COLOR"):
        return "color"
    return "value"


def vertex_group_weights(obj, names):
    """The weights of ``obj``'s vertex groups ``names`` as an (n_vertices, len(names)) array
    (0 where a vertex is not in a group)."""
    index_of = {obj.vertex_groups[name].index: column for column, name in enumerate(names)}
    weights = np.zeros((len(obj.data.vertices), len(names)))
    for index, vertex in enumerate(obj.data.vertices):
        for element in vertex.groups:
            column = index_of.get(element.group)
            if column is not None:
                weights[index, column] = element.weight
    return weights


def point_values(mesh, attribute):
    """A point-domain attribute (or a corner-domain colour, averaged per vertex) as an
    (n_vertices, channels) float array."""
    channels = {**_FLOAT_TYPES, **_DISCRETE_TYPES}[attribute.data_type]
    n = len(attribute.data)
    flat = np.empty(n * channels, dtype=np.float64 if attribute.data_type != "BOOLEAN" else bool)
    if attribute.data_type == "BOOLEAN":
        attribute.data.foreach_get("value", flat)
        values = flat.astype(np.float64).reshape(n, 1)
    else:
        buffer = np.empty(n * channels, dtype=np.float32 if attribute.data_type in _FLOAT_TYPES else np.int32)
        attribute.data.foreach_get(_field(attribute.data_type), buffer)
        values = buffer.astype(np.float64).reshape(n, channels)
    if attribute.domain == "CORNER":
        corner_vertex = np.empty(len(mesh.loops), dtype=np.int32)
        mesh.loops.foreach_get("vertex_index", corner_vertex)
        sums = np.zeros((len(mesh.vertices), channels))
        np.add.at(sums, corner_vertex, values)
        counts = np.bincount(corner_vertex, minlength=len(mesh.vertices))[:, None]
        values = sums / np.maximum(counts, 1)
    return values


class _Item:
    """One thing to carry: its name on the source and the target, what it is, the source
    values and how the library carries them."""

    def __init__(self, kind, name, target_name, values, mode, data_type=None, domain="POINT"):
        self.kind, self.name, self.target_name = kind, name, target_name
        self.values, self.mode = values, mode
        self.data_type, self.domain = data_type, domain
        #: The carried values, and for every target vertex whether it has a counterpart on
        #: the source (all but where the source is a part of the target).
        self.result = self.covered = None

    def fresh(self):
        """The same item, not carried yet (to carry it again through another map)."""
        return _Item(self.kind, self.name, self.target_name, self.values, self.mode, self.data_type, self.domain)


def loop_triangles(mesh):
    """A mesh's loop triangles: their vertices and their loops (corners), (n, 3) each."""
    mesh.calc_loop_triangles()
    n = len(mesh.loop_triangles)
    vertices = np.empty(3 * n, dtype=np.int32)
    loops = np.empty(3 * n, dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", vertices)
    mesh.loop_triangles.foreach_get("loops", loops)
    return vertices.reshape(n, 3), loops.reshape(n, 3)


def uv_values(mesh, name):
    """A UV map's coordinates per loop, (n_loops, 2)."""
    uv = np.empty(2 * len(mesh.loops), dtype=np.float32)
    mesh.attributes[name].data.foreach_get("vector", uv)
    return uv.reshape(-1, 2).astype(np.float64)


def items_to_carry(source, settings):
    """What the settings ask to carry from ``source``: a list of :class:`_Item`."""
    prefix = settings.transfer_prefix
    mesh = source.data
    items = []
    if settings.transfer_vertex_groups and source.vertex_groups:
        if settings.transfer_active_group_only:
            names = [source.vertex_groups.active.name] if source.vertex_groups.active else []
        else:
            names = [group.name for group in source.vertex_groups]
        if names:
            mode = "weights" if settings.transfer_normalize_weights else "interpolate"
            item = _Item("groups", names, [prefix + n for n in names], vertex_group_weights(source, names), mode)
            items.append(item)
    if settings.transfer_uvs and mesh.uv_layers:
        _, loops = loop_triangles(mesh)
        for layer in mesh.uv_layers:
            corners = uv_values(mesh, layer.name)[loops]
            items.append(_Item("uv", layer.name, prefix + layer.name, corners, "corners"))
    if settings.transfer_colors:
        for attribute in mesh.color_attributes:
            values = point_values(mesh, attribute)
            items.append(_Item("color", attribute.name, prefix + attribute.name, values, "interpolate",
                               attribute.data_type, attribute.domain))
    if settings.transfer_attributes:
        colors = {a.name for a in mesh.color_attributes}
        for attribute in mesh.attributes:
            if (attribute.domain != "POINT" or attribute.name in colors or attribute.name in _INTERNAL
                    or attribute.name.startswith(".")):
                continue
            if attribute.data_type in _FLOAT_TYPES:
                mode = "interpolate"
            elif attribute.data_type in _DISCRETE_TYPES:
                mode = "nearest"
            else:
                continue
            items.append(_Item("attribute", attribute.name, prefix + attribute.name,
                               point_values(mesh, attribute), mode, attribute.data_type))
    return items


def _keep_uncovered(item, carried, old):
    """``carried`` where the target vertex has a counterpart on the source (``item.covered``),
    the target's ``old`` values elsewhere (rows of both by target vertex)."""
    if item.covered is None or item.covered.all():
        return carried
    covered = item.covered.reshape(-1, *([1] * (carried.ndim - 1)))
    return np.where(covered, carried, old)


def write_groups(target, item):
    """Replaces the target's vertex groups of the item's names with the carried weights (a
    vertex without a counterpart on the source keeps its weight in a group of that name)."""
    for column, name in enumerate(item.target_name):
        existing = target.vertex_groups.get(name)
        old = np.zeros(len(target.data.vertices))
        if existing is not None:
            old = vertex_group_weights(target, [name])[:, 0]
            target.vertex_groups.remove(existing)
        add = target.vertex_groups.new(name=name).add
        weights = _keep_uncovered(item, item.result[:, column], old)
        vertices = np.flatnonzero(weights > 0.0)
        # One call a vertex (no bulk setter for weights); plain ints and floats are the
        # cheapest arguments: 0.23 -> 0.13 s for 24 groups at 30K vertices.
        for vertex, weight in zip(vertices.tolist(), weights[vertices].tolist()):
            add((vertex,), weight, "REPLACE")


def write_uv(target, item):
    """Writes a carried UV map (per corner of the target's loop triangles) on the target,
    over one of that name or as a new one; a corner whose vertex has no counterpart on the
    source keeps what it had."""
    mesh = target.data
    if item.target_name not in mesh.uv_layers:
        mesh.uv_layers.new(name=item.target_name)
    vertices, loops = loop_triangles(mesh)
    uv = uv_values(mesh, item.target_name)
    carried = item.result.reshape(-1, 2)
    written = np.ones(len(carried), dtype=bool) if item.covered is None else item.covered[vertices.ravel()]
    uv[loops.ravel()[written]] = carried[written]
    mesh.attributes[item.target_name].data.foreach_set("vector", uv.astype(np.float32).ravel())


def write_attribute(target, item):
    """Writes a carried attribute (same name with the prefix, type and domain as the
    source's) on the target, replacing one of that name."""
    mesh = target.data
    existing = mesh.attributes.get(item.target_name)
    # A vertex without a counterpart on the source keeps its value of the same type, else 0.
    old = np.zeros_like(item.result)
    if existing is not None:
        if existing.data_type == item.data_type and existing.domain in ("POINT", "CORNER"):
            old = point_values(mesh, existing)
        mesh.attributes.remove(existing)
    values = _keep_uncovered(item, item.result, old)
    if item.kind == "color":
        attribute = mesh.color_attributes.new(item.target_name, item.data_type, item.domain)
    else:
        attribute = mesh.attributes.new(item.target_name, item.data_type, "POINT")
    if item.domain == "CORNER":
        corner_vertex = np.empty(len(mesh.loops), dtype=np.int32)
        mesh.loops.foreach_get("vertex_index", corner_vertex)
        values = values[corner_vertex]
    if item.data_type == "BOOLEAN":
        attribute.data.foreach_set("value", values.ravel() > 0.5)
    elif item.data_type in _DISCRETE_TYPES:
        attribute.data.foreach_set("value", np.round(values).astype(np.int32).ravel())
    else:
        attribute.data.foreach_set(_field(item.data_type), values.astype(np.float32).ravel())


class Carrying:
    """What carrying needs besides the map, kept in memory to carry again through another
    answer: the items (source values), both meshes' loop triangles, the influence limit."""

    def __init__(self, items, faces_a, faces_b, max_influences):
        self.items, self.faces_a, self.faces_b = items, faces_a, faces_b
        self.max_influences = max_influences

    def carry(self, shapes, pointwise, progress):
        """The items carried through ``pointwise`` (a PointwiseMap; its surface map is made
        here): new items with their results, nothing written."""
        onto = shapecorr.surface_map(shapes[0], shapes[1], pointwise, progress=progress)
        covered = pointwise.covered_b
        items = [item.fresh() for item in self.items]
        for item in items:
            item.covered = covered
            if item.mode == "corners":
                item.result = onto.transfer_corners(shapes[0], self.faces_a, item.values, self.faces_b)
            else:
                item.result = onto.transfer(item.values, mode=item.mode, max_influences=self.max_influences)
        return items


def write_carried(target, items):
    """Writes carried items on the target; returns how many names were written."""
    for item in items:
        if item.kind == "groups":
            write_groups(target, item)
        elif item.kind == "uv":
            write_uv(target, item)
        else:
            write_attribute(target, item)
    target.data.update()
    return sum(len(i.target_name) if i.kind == "groups" else 1 for i in items)


class SHAPECORR_OT_transfer(_LibraryOperator, bpy.types.Operator):
    """Carry vertex groups, UV maps, colour and point attributes from the active mesh to the
    other selected mesh, through the correspondence (any pose and body)"""

    bl_idname = "shapecorr.transfer"
    bl_label = "Transfer"
    selection_size = 2
    stages = _STAGES + ["pointwise_map", "transfer"]

    def prepare(self, context):
        settings = context.scene.shapecorr
        source, target = ordered_selection(context)
        for obj in (source, target):
            if len(obj.data.polygons) == 0:
                raise ValueError(f"'{obj.name}' has no faces: Transfer needs two meshes with faces")
        pair = PairInput(context, as_point_cloud=False)
        self._pair = pair
        self._names = list(pair.names)
        self._repairs = pair.repairs
        items = items_to_carry(source, settings)
        if not items:
            raise ValueError(f"'{source.name}' has nothing of what the Transfer settings ask to carry")
        carrying = Carrying(items, loop_triangles(source.data)[0], loop_triangles(target.data)[0],
                            settings.transfer_max_influences)
        self._carrying = carrying
        # The map Show Map or an earlier Transfer made from the same input (perhaps the other
        # answer the user took) is used as it is.
        kept = pair.kept_map()
        self._kept = kept
        pointwise = None if kept is None else kept.current(context.scene)
        arguments = pair.arguments()

        def work(progress):
            answer = pointwise
            if answer is None:
                answer = shapecorr.pointwise_map(pair.shapes[0], pair.shapes[1], progress=progress, **arguments)
            return _Carried(answer, carrying.carry(pair.shapes, answer, progress))

        return work

    def apply(self, context, result):
        source, target = (bpy.data.objects[name] for name in self._names)
        carried = write_carried(target, result.items)
        entry = self._kept or self._pair.entry(result.pointwise)
        entry.views["transfer"] = self._carrying
        memory.remember(entry)
        memory.write_summary(context.scene, self.bl_label, self._pair.names, result.pointwise)
        reused = ", the map kept from the last run" if self._kept is not None else ""
        uncovered = int((~result.items[0].covered).sum()) if result.items else 0
        if uncovered:
            reused += f", {uncovered} vertices of '{target.name}' without a counterpart left as they were"
        return (
            f"shapecorr: {carried} items carried from '{source.name}' to '{target.name}'{reused}, "
            f"{confidence_text(result.confidence)}{memory.answer_text(result.pointwise)}"
        )


class _Carried:
    """What the worker thread computed: the map, the carried items and the map's confidence
    and warning (reported by the operator)."""

    def __init__(self, pointwise, items):
        self.pointwise = pointwise
        self.items = items
        self.confidence = pointwise.confidence
        self.warning = pointwise.warning
