"""Landmarks: pairs of vertices the user knows to correspond (a left hand and a left hand),
kept in ``Scene.shapecorr.landmarks`` (saved with the file) and passed to the library, which
maps every landmark of B exactly to its partner and chooses among its answers with them.

A pair is taken in Edit Mode, with both meshes in it: the active vertex of each (the one
clicked last; a mesh with exactly one selected vertex gives that one).
"""

import bmesh
import bpy


def landmark_pairs(scene, a, b):
    """The landmark pairs between objects ``a`` and ``b`` as (vertex of A, vertex of B),
    whichever object each pair names first. Raises ValueError when a pair names a vertex
    its object no longer has (the mesh was edited since)."""
    pairs = []
    for number, pair in enumerate(scene.shapecorr.landmarks, start=1):
        if (pair.object_1, pair.object_2) == (a, b):
            ends = ((a, pair.vertex_1), (b, pair.vertex_2))
        elif (pair.object_1, pair.object_2) == (b, a):
            ends = ((a, pair.vertex_2), (b, pair.vertex_1))
        else:
            continue
        for obj, vertex in ends:
            n = len(obj.data.vertices)
            if vertex >= n:
                raise ValueError(
                    f"landmark pair {number}: '{obj.name}' has no vertex {vertex} (it has {n}); "
                    "remove the pair and add it again"
                )
        pairs.append((ends[0][1], ends[1][1]))
    return pairs


def edit_meshes(context):
    """The mesh objects in Edit Mode, the active one first."""
    active = context.view_layer.objects.active
    meshes = [o for o in context.view_layer.objects if o.type == "MESH" and o.mode == "EDIT"]
    meshes.sort(key=lambda o: (o != active, o.name))
    return meshes


def active_vertex(obj):
    """The index of ``obj``'s active vertex in Edit Mode (the last clicked; else the only
    selected one). Raises ValueError saying what to do when there is none."""
    mesh = bmesh.from_edit_mesh(obj.data)
    mesh.verts.index_update()
    active = mesh.select_history.active
    if isinstance(active, bmesh.types.BMVert) and active.select:
        return active.index
    selected = [v.index for v in mesh.verts if v.select]
    if len(selected) == 1:
        return selected[0]
    raise ValueError(
        f"'{obj.name}': make one vertex active (click it in vertex select mode; "
        f"{len(selected)} vertices selected, none active)"
    )


class SHAPECORR_OT_landmark_add(bpy.types.Operator):
    """Add the active vertices of the two meshes in Edit Mode as a landmark pair (they
    correspond: the library maps one exactly to the other)"""

    bl_idname = "shapecorr.landmark_add"
    bl_label = "Add Pair"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        meshes = edit_meshes(context)
        if len(meshes) != 2:
            cls.poll_message_set(
                f"Edit both meshes together (select the two, Tab): {len(meshes)} in Edit Mode"
            )
            return False
        return True

    def execute(self, context):
        meshes = edit_meshes(context)
        if len(meshes) != 2:
            self.report({"ERROR"}, f"shapecorr: edit exactly two meshes together ({len(meshes)} in Edit Mode)")
            return {"CANCELLED"}
        if meshes[0].data == meshes[1].data:
            self.report({"ERROR"}, f"shapecorr: '{meshes[0].name}' and '{meshes[1].name}' share one mesh")
            return {"CANCELLED"}
        try:
            vertices = [active_vertex(obj) for obj in meshes]
        except ValueError as error:
            self.report({"ERROR"}, f"shapecorr: {error}")
            return {"CANCELLED"}
        settings = context.scene.shapecorr
        # One vertex, one partner: the library refuses a vertex in two pairs.
        for number, pair in enumerate(settings.landmarks, start=1):
            for end in ((pair.object_1, pair.vertex_1), (pair.object_2, pair.vertex_2)):
                for obj, vertex in zip(meshes, vertices):
                    if end == (obj, vertex):
                        self.report(
                            {"ERROR"},
                            f"shapecorr: vertex {vertex} of '{obj.name}' is already in landmark pair "
                            f"{number}; remove that pair first",
                        )
                        return {"CANCELLED"}
        pair = settings.landmarks.add()
        pair.object_1, pair.vertex_1 = meshes[0], vertices[0]
        pair.object_2, pair.vertex_2 = meshes[1], vertices[1]
        settings.landmark_index = len(settings.landmarks) - 1
        self.report(
            {"INFO"},
            f"shapecorr: landmark pair {len(settings.landmarks)}: vertex {vertices[0]} of "
            f"'{meshes[0].name}' and vertex {vertices[1]} of '{meshes[1].name}'",
        )
        return {"FINISHED"}


class SHAPECORR_OT_landmark_remove(bpy.types.Operator):
    """Remove the landmark pair selected in the list"""

    bl_idname = "shapecorr.landmark_remove"
    bl_label = "Remove"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        settings = context.scene.shapecorr
        return 0 <= settings.landmark_index < len(settings.landmarks)

    def execute(self, context):
        settings = context.scene.shapecorr
        settings.landmarks.remove(settings.landmark_index)
        settings.landmark_index = max(0, min(settings.landmark_index, len(settings.landmarks) - 1))
        return {"FINISHED"}


class SHAPECORR_OT_landmark_clear(bpy.types.Operator):
    """Remove every landmark pair of the list"""

    bl_idname = "shapecorr.landmark_clear"
    bl_label = "Clear"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return len(context.scene.shapecorr.landmarks) > 0

    def execute(self, context):
        settings = context.scene.shapecorr
        settings.landmarks.clear()
        settings.landmark_index = 0
        return {"FINISHED"}


class SHAPECORR_UL_landmarks(bpy.types.UIList):
    """The landmark pairs: each row names the two objects and their vertices."""

    bl_idname = "SHAPECORR_UL_landmarks"

    def draw_item(self, context, layout, data, item, icon, active_data, active_propname, index):
        def end(obj, vertex):
            return f"{obj.name if obj is not None else '(deleted)'} {vertex}"

        text = f"{index + 1}. {end(item.object_1, item.vertex_1)} \u2194 {end(item.object_2, item.vertex_2)}"
        layout.label(text=text, icon="PIVOT_INDIVIDUAL")
