"""The operators: read the evaluated meshes in world space, call libshapecorr, write the
result in place as attributes.

Run from the UI (invoke), the library works in a background thread while a modal handler
shows progress and lets Esc cancel; run from a script (execute), it blocks. Either way the
result is written by the main thread, in one undo step.
"""

import threading

import bpy
import numpy as np

from . import memory, shapecorr
from .landmarks import landmark_pairs

#: Colour attribute (point domain): matched regions share a colour, unmatched ones dark grey.
COLOR_ATTRIBUTE = "shapecorr_regions"
#: Integer attribute (point domain): the region id of every vertex.
REGION_ATTRIBUTE = "shapecorr_region"

#: Custom property (object): the confidence of the last Match Regions, in [0, 1]; absent when
#: the answer was not verified.
CONFIDENCE_PROPERTY = "shapecorr_confidence"

#: Pipeline stages as reported by the library, in order (for one overall progress value).
_STAGES = ["proxy", "laplacian", "eigenbasis", "descriptors", "segmentation", "matching", "symmetry_breaking"]


def selection_problem(context, wanted):
    """Why the operator cannot run on the selection (None when it can)."""
    selected = list(getattr(context, "selected_objects", []) or [])
    meshes = [o for o in selected if o.type == "MESH"]
    noun = "mesh object" if wanted == 1 else "mesh objects"
    if len(meshes) != len(selected):
        return f"Select only mesh objects ({len(selected) - len(meshes)} other selected)"
    if len(meshes) != wanted:
        return f"Select exactly {wanted} {noun} ({len(meshes)} selected)"
    if getattr(context, "mode", "OBJECT") != "OBJECT":
        return "Switch to Object Mode"
    return None


def ordered_selection(context):
    """The selected meshes, the active one first (it is shape A)."""
    selected = [o for o in context.selected_objects if o.type == "MESH"]
    active = context.view_layer.objects.active
    selected.sort(key=lambda o: (o != active, o.name))
    return selected


def read_geometry(obj, depsgraph):
    """The evaluated mesh of ``obj`` (modifiers applied) in world space, in Blender's vertex
    order: (vertices (n, 3) float64, triangles (m, 3) int32). Raises ValueError with a message
    for the user when the evaluated mesh cannot be written back to the object's own vertices."""
    evaluated = obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    try:
        n = len(mesh.vertices)
        if n != len(obj.data.vertices):
            raise ValueError(
                f"'{obj.name}': its modifiers change the vertex count "
                f"({len(obj.data.vertices)} -> {n}); apply them first"
            )
        coordinates = np.empty(3 * n, dtype=np.float32)
        mesh.vertices.foreach_get("co", coordinates)
        matrix = np.array(evaluated.matrix_world, dtype=np.float64)
        world = coordinates.reshape(n, 3).astype(np.float64) @ matrix[:3, :3].T + matrix[:3, 3]
        mesh.calc_loop_triangles()
        triangles = np.empty(3 * len(mesh.loop_triangles), dtype=np.int32)
        mesh.loop_triangles.foreach_get("vertices", triangles)
    finally:
        evaluated.to_mesh_clear()
    return world, triangles.reshape(-1, 3)


def shape_of(geometry, as_point_cloud):
    """The shapecorr.Shape of a :func:`read_geometry` result."""
    world, triangles = geometry
    if as_point_cloud or len(triangles) == 0:
        return shapecorr.Shape.point_cloud(world)
    return shapecorr.Shape.mesh(world, triangles)


def read_shape(obj, depsgraph, as_point_cloud):
    """The evaluated mesh of ``obj`` as a shapecorr.Shape (:func:`read_geometry`)."""
    return shape_of(read_geometry(obj, depsgraph), as_point_cloud)


class PairInput:
    """What a library call on two selected objects reads (main thread): the objects' names,
    their geometry and shapes, the options and the landmarks, and the fingerprints that say
    whether a result kept in memory was computed from the same (memory.fingerprint)."""

    def __init__(self, context, as_point_cloud=None):
        settings = context.scene.shapecorr
        objects = ordered_selection(context)
        depsgraph = context.evaluated_depsgraph_get()
        point_cloud = settings.point_cloud if as_point_cloud is None else as_point_cloud
        self.names = tuple(o.name for o in objects)
        self.geometries = [read_geometry(o, depsgraph) for o in objects]
        self.landmarks = landmark_pairs(context.scene, *objects)
        self.shapes = [shape_of(g, point_cloud) for g in self.geometries]
        self.repairs = repair_notes(self.names, self.shapes)
        self.options = settings.library_options()
        self.geometry = memory.fingerprint(self.geometries)
        self.inputs = memory.fingerprint(self.geometries, {**self.options, "point_cloud": point_cloud},
                                         self.landmarks)

    def arguments(self):
        """The keyword arguments of shapecorr.match and pointwise_map: the options, and the
        landmarks when there are any."""
        if self.landmarks:
            return {**self.options, "landmarks": self.landmarks}
        return dict(self.options)

    def entry(self, result):
        """A memory entry for ``result`` computed from this input."""
        return memory.Entry(self.names, self.geometry, self.inputs, self.shapes, self.geometries[0][0], result)

    def kept_map(self):
        """The pointwise map kept in memory for this pair when it was computed from the same
        input (the answer the scene shows, perhaps the other one): its entry, else None."""
        kept = memory.entry(self.names)
        if kept is None or kept.inputs != self.inputs or not isinstance(kept.answers[0], shapecorr.PointwiseMap):
            return None
        return kept


def repair_notes(names, shapes):
    """The repairs the library made to each object's shape, one report line each."""
    return [f"shapecorr: '{name}': {repair}" for name, shape in zip(names, shapes) for repair in shape.repairs]


def working_notes(names, result):
    """One report line per object that the library matched on a proxy (a dense mesh), a
    refined copy (a low-poly mesh) or a smoothed copy (a noisy mesh) rather than on its input
    as it is, or with an object touching it left out (``result.working``); none for results
    that do not say (symmetry)."""
    working = getattr(result, "working", None)
    if working is None:
        return []
    notes = []
    for name, side, shape in zip(names, "ab", working):
        kind, vertices, smoothed = shape[0], shape[1], getattr(shape, "smoothed", False)
        left_out = getattr(shape, "objects_left_out", 0)
        if left_out:
            notes.append(f"shapecorr: '{name}': {left_out:,} vertices of an object touching the figure (a prop) were left out: the pair matched better without them; they take the answer of the nearest kept vertex")
        not_tried = getattr(shape, "objects_not_tried", 0)
        if not_tried:
            notes.append(f"shapecorr: '{name}': {not_tried} object(s) touching the figure were matched as part of it: the time limit passed before the pair could try without them (raise the time limit to try)")
        if kind == "input" and not smoothed:
            continue
        if kind == "input":
            notes.append(f"shapecorr: '{name}' looks noisy (scanner noise): it was matched on a smoothed copy; the answers are on its own vertices")
            continue
        what = "a refined copy" if kind == "refined" else "a proxy"
        if smoothed:
            what = what.replace("a ", "a smoothed ", 1)
        inputs = getattr(result, f"n_vertices_{side}", None)
        inputs = len(result.regions(side)) if inputs is None else inputs
        notes.append(f"shapecorr: '{name}' was matched on {what} of {vertices:,} vertices (the input has {inputs:,})")
    return notes


def write_regions(obj, regions, rgba):
    """Writes the region ids and colours as point attributes of ``obj``'s mesh, makes the
    colour attribute the active (and rendered) one."""
    mesh = obj.data
    for name in (COLOR_ATTRIBUTE, REGION_ATTRIBUTE):
        existing = mesh.attributes.get(name)
        if existing is not None:
            mesh.attributes.remove(existing)
    colors = mesh.color_attributes.new(COLOR_ATTRIBUTE, "BYTE_COLOR", "POINT")
    # The library's colours are sRGB bytes; color_srgb takes them as 0..1 floats.
    colors.data.foreach_set("color_srgb", (rgba.astype(np.float32) / 255.0).ravel())
    region = mesh.attributes.new(REGION_ATTRIBUTE, "INT", "POINT")
    region.data.foreach_set("value", regions.astype(np.int32))
    mesh.color_attributes.active_color_name = COLOR_ATTRIBUTE
    mesh.color_attributes.render_color_index = mesh.color_attributes.active_color_index
    mesh.update()


def confidence_text(confidence):
    """The confidence for a report: ``confidence 0.74`` or ``not verified`` (None)."""
    return "not verified" if confidence is None else f"confidence {confidence:.2f}"


def write_confidence(obj, confidence):
    """Stores the confidence as the custom property ``shapecorr_confidence`` of ``obj``
    (removes an older one when there is none)."""
    if confidence is None:
        if CONFIDENCE_PROPERTY in obj:
            del obj[CONFIDENCE_PROPERTY]
    else:
        obj[CONFIDENCE_PROPERTY] = float(confidence)


def show_attribute_colors(context):
    """Switches solid-mode 3D views of the current screen to attribute colours."""
    screen = getattr(context, "screen", None)
    if screen is None:
        return
    for area in screen.areas:
        if area.type != "VIEW_3D":
            continue
        for space in area.spaces:
            if space.type == "VIEW_3D":
                if space.shading.type == "WIREFRAME":
                    space.shading.type = "SOLID"
                space.shading.color_type = "VERTEX"
        area.tag_redraw()


class _Job:
    """A library call run in a thread: progress in, cancel flag out."""

    def __init__(self, work, stages=_STAGES):
        self.work = work
        self.stages = stages
        self.cancel = threading.Event()
        self.fraction = 0.0
        self.result = None
        self.error = None
        self.thread = None

    def progress(self, stage, fraction):
        index = self.stages.index(stage) if stage in self.stages else 0
        self.fraction = max(self.fraction, (index + fraction) / len(self.stages))
        return not self.cancel.is_set()

    def run(self):
        try:
            self.result = self.work(self.progress)
        except Exception as error:  # noqa: BLE001 - reported by the operator, never lost
            self.error = error

    def start(self):
        self.thread = threading.Thread(target=self.run, name="shapecorr", daemon=True)
        self.thread.start()


class _LibraryOperator:
    """Shared invoke/modal/execute: subclasses give ``prepare`` (main thread: read the
    scene, return the work function) and ``apply`` (main thread: write the result)."""

    bl_options = {"REGISTER", "UNDO"}
    #: How many selected meshes the operator works on.
    selection_size = 0
    #: The library's stages the operator goes through, in order (for one progress value).
    stages = _STAGES
    _timer = None
    _job = None

    @classmethod
    def poll(cls, context):
        problem = selection_problem(context, cls.selection_size)
        if problem:
            cls.poll_message_set(problem)
        return problem is None

    def execute(self, context):
        try:
            work = self.prepare(context)
        except (ValueError, shapecorr.ShapecorrError) as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        wm = context.window_manager
        wm.progress_begin(0, 1000)
        job = _Job(work, self.stages)

        def progress(stage, fraction):
            keep_going = job.progress(stage, fraction)
            wm.progress_update(int(1000 * job.fraction))
            return keep_going

        try:
            job.result = work(progress)
        except (shapecorr.ShapecorrError, ValueError, TypeError) as error:
            # The library's errors, and the binding's refusal of an argument (as the modal
            # path reports whatever the worker thread raised).
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        finally:
            wm.progress_end()
        return self.finish(context, job.result)

    def invoke(self, context, event):
        if bpy.app.background or context.window is None:
            return self.execute(context)
        try:
            work = self.prepare(context)
        except (ValueError, shapecorr.ShapecorrError) as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        self._job = _Job(work, self.stages)
        self._job.start()
        wm = context.window_manager
        wm.progress_begin(0, 1000)
        self._timer = wm.event_timer_add(0.1, window=context.window)
        wm.modal_handler_add(self)
        self.report({"INFO"}, "shapecorr: working (Esc cancels)")
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        job = self._job
        if event.type == "ESC":
            job.cancel.set()
        if event.type != "TIMER":
            return {"RUNNING_MODAL"}
        context.window_manager.progress_update(int(1000 * job.fraction))
        if job.thread.is_alive():
            return {"RUNNING_MODAL"}
        self._stop(context)
        if job.error is not None:
            cancelled = getattr(job.error, "status_name", "") == "CANCELLED"
            self.report({"WARNING"} if cancelled else {"ERROR"}, str(job.error))
            return {"CANCELLED"}
        return self.finish(context, job.result)

    def cancel(self, context):
        if self._job is not None:
            self._job.cancel.set()
            self._job.thread.join()
        self._stop(context)

    def _stop(self, context):
        wm = context.window_manager
        if self._timer is not None:
            wm.event_timer_remove(self._timer)
            self._timer = None
        wm.progress_end()

    def finish(self, context, result):
        try:
            message = self.apply(context, result)
        except (ValueError, ReferenceError, KeyError, RuntimeError, TypeError) as error:
            self.report({"ERROR"}, f"shapecorr: the result could not be written: {error}")
            return {"CANCELLED"}
        show_attribute_colors(context)
        self.report({"INFO"}, message)
        # What the library repaired in the input (welded seams, debris left out, ...).
        for note in getattr(self, "_repairs", []):
            self.report({"WARNING"}, note)
        # What each side ran on, when not its input (docs/decisions.md, "Low-poly meshes").
        for note in working_notes(getattr(self, "_names", []), result):
            self.report({"INFO"}, note)
        # A doubtful answer (results that have a confidence) is also a warning.
        warning = getattr(result, "warning", None)
        if warning:
            self.report({"WARNING"}, f"shapecorr: {warning}")
        return {"FINISHED"}


class SHAPECORR_OT_match_regions(_LibraryOperator, bpy.types.Operator):
    """Colour the matching regions of the two selected meshes (the active one is A)"""

    bl_idname = "shapecorr.match_regions"
    bl_label = "Match Regions"
    selection_size = 2

    def prepare(self, context):
        pair = PairInput(context)
        self._pair = pair
        self._names = list(pair.names)
        self._repairs = pair.repairs
        arguments = pair.arguments()

        def work(progress):
            return shapecorr.match(pair.shapes[0], pair.shapes[1], progress=progress, **arguments)

        return work

    def apply(self, context, result):
        one_to_one = context.scene.shapecorr.one_to_one
        objects = [bpy.data.objects[name] for name in self._names]
        confidence = result.confidence
        write_correspondence(objects, result, one_to_one)
        entry = self._pair.entry(result)
        entry.views["regions"] = {"one_to_one": one_to_one}
        memory.remember(entry)
        memory.write_summary(context.scene, self.bl_label, self._pair.names, result)
        matches = result.matches_one_to_one if one_to_one else result.matches
        return (
            f"shapecorr: {len(matches)} region matches between '{objects[0].name}' "
            f"({result.n_regions('a')} regions) and '{objects[1].name}' "
            f"({result.n_regions('b')} regions), {confidence_text(confidence)}{memory.answer_text(result)}"
        )


def write_correspondence(objects, result, one_to_one):
    """Writes a Correspondence's regions, colours and confidence on the two objects."""
    for obj, side in zip(objects, ("a", "b")):
        write_regions(obj, result.regions(side), result.colors(side, one_to_one=one_to_one))
        write_confidence(obj, result.confidence)


class SHAPECORR_OT_detect_symmetry(_LibraryOperator, bpy.types.Operator):
    """Colour the symmetric regions of the selected mesh (regions of one group share a colour)"""

    bl_idname = "shapecorr.detect_symmetry"
    bl_label = "Detect Symmetry"
    selection_size = 1

    def prepare(self, context):
        settings = context.scene.shapecorr
        obj = ordered_selection(context)[0]
        shape = read_shape(obj, context.evaluated_depsgraph_get(), settings.point_cloud)
        self._names = [obj.name]
        self._repairs = repair_notes(self._names, [shape])
        options = settings.library_options(one_to_one=False)

        def work(progress):
            return shapecorr.detect_symmetry(shape, progress=progress, **options)

        return work

    def apply(self, context, result):
        obj = bpy.data.objects[self._names[0]]
        write_regions(obj, result.regions, result.colors())
        groups = [g for g in result.groups if len(g) > 1]
        return f"shapecorr: {len(groups)} groups of symmetric regions on '{obj.name}'"
