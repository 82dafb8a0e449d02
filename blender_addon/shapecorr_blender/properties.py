"""The add-on's options, with the library's own defaults (read from libshapecorr)."""

import bpy

from .shapecorr import options as library_options

_OPTIONS = library_options()
_DEFAULTS = {name: default for name, _kind, _doc, default in _OPTIONS}
_DOCS = {name: doc for name, _kind, doc, _default in _OPTIONS}


class ShapecorrSettings(bpy.types.PropertyGroup):
    k_min: bpy.props.IntProperty(
        name="Min Clusters",
        description="Smallest number of joint clusters tried: " + _DOCS["k_min"],
        default=_DEFAULTS["k_min"],
        min=2,
        max=30,
    )
    k_max: bpy.props.IntProperty(
        name="Max Clusters",
        description="Largest number of joint clusters tried (more clusters, more and smaller regions)",
        default=_DEFAULTS["k_max"],
        min=2,
        max=30,
    )
    one_to_one: bpy.props.BoolProperty(
        name="One-to-One",
        description="Break symmetries so that each region matches one region (otherwise a "
        "region may match all its symmetric copies, e.g. both hands)",
        default=_DEFAULTS["one_to_one"],
    )
    point_cloud: bpy.props.BoolProperty(
        name="Point Cloud",
        description="Use only the vertices, ignoring faces (meshes without faces are always "
        "treated as point clouds)",
        default=False,
    )

    def library_options(self, one_to_one=None):
        """The options passed to shapecorr.match."""
        return {
            "k_min": self.k_min,
            "k_max": self.k_max,
            "one_to_one": self.one_to_one if one_to_one is None else one_to_one,
        }
