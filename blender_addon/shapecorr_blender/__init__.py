"""shapecorr for Blender: "Match Regions" colours the matching regions of two selected meshes
in place, "Detect Symmetry" the symmetric regions of one, "Transfer" carries vertex groups
and attributes from the active mesh to the other selected one, "Show Map" colours the map
so that a swap shows, "Use Other Answer" takes the runner-up, and landmark pairs tell the
library what corresponds (3D viewport sidebar, tab "shapecorr"). The work is done by the
bundled libshapecorr through its Python binding."""

import bpy

from . import answers, landmarks, memory, operators, panel, properties, transfer

_register_classes, _unregister_classes = bpy.utils.register_classes_factory(
    (
        properties.ShapecorrLandmark,
        properties.ShapecorrAnswer,
        properties.ShapecorrSettings,
        operators.SHAPECORR_OT_match_regions,
        operators.SHAPECORR_OT_detect_symmetry,
        transfer.SHAPECORR_OT_transfer,
        answers.SHAPECORR_OT_show_map,
        answers.SHAPECORR_OT_other_answer,
        landmarks.SHAPECORR_OT_landmark_add,
        landmarks.SHAPECORR_OT_landmark_remove,
        landmarks.SHAPECORR_OT_landmark_clear,
        landmarks.SHAPECORR_UL_landmarks,
        panel.SHAPECORR_PT_panel,
        panel.SHAPECORR_PT_answer,
        panel.SHAPECORR_PT_landmarks,
        panel.SHAPECORR_PT_transfer,
    )
)


def register():
    _register_classes()
    bpy.types.Scene.shapecorr = bpy.props.PointerProperty(type=properties.ShapecorrSettings)
    memory.register()


def unregister():
    memory.unregister()
    del bpy.types.Scene.shapecorr
    _unregister_classes()
