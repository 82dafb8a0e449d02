"""The sidebar panel (View3D > Sidebar > shapecorr)."""

import textwrap

import bpy

from .operators import selection_problem


class SHAPECORR_PT_panel(bpy.types.Panel):
    bl_label = "shapecorr"
    bl_idname = "SHAPECORR_PT_panel"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "shapecorr"

    def draw(self, context):
        layout = self.layout
        settings = context.scene.shapecorr
        column = layout.column(align=True)
        column.prop(settings, "k_min")
        column.prop(settings, "k_max")
        layout.prop(settings, "one_to_one")
        layout.prop(settings, "point_cloud")
        layout.prop(settings, "placement")
        layout.prop(settings, "partial")
        layout.operator("shapecorr.match_regions", icon="MOD_DATA_TRANSFER")
        problem = selection_problem(context, 2)
        if problem:
            layout.label(text=problem, icon="INFO")
        layout.operator("shapecorr.detect_symmetry", icon="MOD_MIRROR")
        layout.label(text="Esc cancels a running match", icon="CANCEL")


class SHAPECORR_PT_transfer(bpy.types.Panel):
    bl_label = "Transfer"
    bl_idname = "SHAPECORR_PT_transfer"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "shapecorr"
    bl_parent_id = "SHAPECORR_PT_panel"

    def draw(self, context):
        layout = self.layout
        settings = context.scene.shapecorr
        layout.label(text="From the active mesh to the other selected one")
        column = layout.column(align=True)
        column.prop(settings, "transfer_vertex_groups")
        sub = column.column(align=True)
        sub.enabled = settings.transfer_vertex_groups
        sub.prop(settings, "transfer_active_group_only")
        sub.prop(settings, "transfer_normalize_weights")
        sub.prop(settings, "transfer_max_influences")
        column.prop(settings, "transfer_uvs")
        column.prop(settings, "transfer_colors")
        column.prop(settings, "transfer_attributes")
        layout.prop(settings, "transfer_prefix")
        layout.operator("shapecorr.transfer", icon="MOD_DATA_TRANSFER")


def draw_answer(layout, answer):
    """The summary of the last answer (Scene.shapecorr.answer)."""
    if not answer.operation:
        layout.label(text="No answer yet", icon="INFO")
        return
    box = layout.box()
    column = box.column(align=True)
    column.label(text=f"{answer.operation}: {answer.source} \u2192 {answer.target}")
    if not answer.verified:
        column.label(text="Not verified (One-to-One off)")
        return
    icon = "ERROR" if answer.warning else "CHECKMARK"
    column.label(text=f"Confidence {answer.confidence:.2f}", icon=icon)
    column.label(text=f"Answer: {answer.hypothesis} (by {answer.decided_by})")
    turn = f", turn {answer.turn:.0f}\u00b0" if answer.has_turn else ""
    used = "used" if answer.placement_used else "not used"
    column.label(text=f"Placement: {used}{turn}")
    if answer.taken_as and answer.taken_as != "whole":
        part = "target" if answer.taken_as == "b_in_a" else "source"
        column.label(text=f"Partial: the {part} is a part, {100 * answer.covered_share:.0f}% of the source covered")
        if answer.uncovered_target:
            column.label(text=f"{answer.uncovered_target} target vertices without a counterpart")
    if answer.has_runner_up:
        column.label(text=f"Runner-up: {answer.runner_up}, cost {answer.runner_up_cost:.3g}")
    else:
        column.label(text="Runner-up: none")
    if answer.warning:
        warning = box.column(align=True)
        for line in textwrap.wrap(answer.warning, 40):
            warning.label(text=line)


class SHAPECORR_PT_answer(bpy.types.Panel):
    bl_label = "Check the Answer"
    bl_idname = "SHAPECORR_PT_answer"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "shapecorr"
    bl_parent_id = "SHAPECORR_PT_panel"

    def draw(self, context):
        layout = self.layout
        row = layout.row(align=True)
        row.operator("shapecorr.show_map", icon="COLOR")
        row.operator("shapecorr.other_answer", icon="FILE_REFRESH")
        draw_answer(layout, context.scene.shapecorr.answer)


class SHAPECORR_PT_landmarks(bpy.types.Panel):
    bl_label = "Landmarks"
    bl_idname = "SHAPECORR_PT_landmarks"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "shapecorr"
    bl_parent_id = "SHAPECORR_PT_panel"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        layout = self.layout
        settings = context.scene.shapecorr
        column = layout.column(align=True)
        column.label(text="Edit Mode, both meshes: make one")
        column.label(text="vertex active on each, Add Pair")
        row = layout.row()
        row.template_list("SHAPECORR_UL_landmarks", "", settings, "landmarks", settings, "landmark_index", rows=3)
        buttons = row.column(align=True)
        buttons.operator("shapecorr.landmark_remove", icon="REMOVE", text="")
        buttons.operator("shapecorr.landmark_clear", icon="X", text="")
        layout.operator("shapecorr.landmark_add", icon="ADD")
