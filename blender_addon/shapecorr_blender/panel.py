"""The sidebar panel (View3D > Sidebar > shapecorr)."""

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
