"""shapecorr for Blender: "Match Regions" colours the matching regions of two selected meshes
in place, "Detect Symmetry" the symmetric regions of one, "Transfer" carries vertex groups
and attributes from the active mesh to the other selected one (3D viewport sidebar, tab
"shapecorr"). The work is done by the bundled libshapecorr through its Python binding."""

import bpy

from . import operators, panel, properties, transfer

_register_classes, _unregister_classes = bpy.utils.register_classes_factory(
    (
        properties.ShapecorrSettings,
        operators.SHAPECORR_OT_match_regions,
        operators.SHAPECORR_OT_detect_symmetry,
        transfer.SHAPECORR_OT_transfer,
        panel.SHAPECORR_PT_panel,
        panel.SHAPECORR_PT_transfer,
    )
)


def register():
    _register_classes()
    bpy.types.Scene.shapecorr = bpy.props.PointerProperty(type=properties.ShapecorrSettings)


def unregister():
    del bpy.types.Scene.shapecorr
    _unregister_classes()
