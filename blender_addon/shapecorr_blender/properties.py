"""The add-on's options, with the library's own defaults (read from libshapecorr)."""

import bpy

from .shapecorr import options as library_options

_OPTIONS = library_options()
_DEFAULTS = {name: default for name, _kind, _doc, default in _OPTIONS}
_DOCS = {name: doc for name, _kind, doc, _default in _OPTIONS}
_PLACEMENTS = {o.name: o for o in _OPTIONS}["placement"].choices
_PARTIALS = {o.name: o for o in _OPTIONS}["partial"].choices
#: What each choice of ``partial`` does, for the tooltip (docs/partial.md).
_PARTIAL_DOCS = {
    "auto": "Take the target as a part of the source when it has much more open boundary and "
    "20-80% of its area (a scan with the feet cut off, holes); otherwise both are whole",
    "off": "Both objects are whole",
    "b_in_a": "The target is a part of the source (a scan of one side): every target vertex gets "
    "a value",
    "a_in_b": "The source is a part of the target: Transfer writes only the target vertices the "
    "source covers, the others keep what they had",
}
#: What each placement does, for the tooltip (docs/placement.md).
_PLACEMENT_DOCS = {
    "auto": "Use where the two objects stand only when it is informative (one answer implies "
    "almost no turn between them, every other a large one); otherwise ignore it. Right for two "
    "objects in one scene, upright and facing alike, and safe for objects turned at random",
    "ignore": "Never use where the objects stand: the answer depends on their shapes only",
    "trust": "The objects stand alike (one scene, one scanner): take the consistent answer that "
    "implies the least turn between them",
}


class ShapecorrLandmark(bpy.types.PropertyGroup):
    """One landmark pair: a vertex of one object and its partner on another (Blender's vertex
    indices); the order of the two objects does not matter."""

    object_1: bpy.props.PointerProperty(type=bpy.types.Object, name="First Object")
    vertex_1: bpy.props.IntProperty(name="First Vertex", min=0)
    object_2: bpy.props.PointerProperty(type=bpy.types.Object, name="Second Object")
    vertex_2: bpy.props.IntProperty(name="Second Vertex", min=0)


class ShapecorrAnswer(bpy.types.PropertyGroup):
    """What the last run answered (the panel's summary; memory.write_summary)."""

    operation: bpy.props.StringProperty(name="Operation")
    source: bpy.props.StringProperty(name="Source")
    target: bpy.props.StringProperty(name="Target")
    verified: bpy.props.BoolProperty(name="Verified")
    confidence: bpy.props.FloatProperty(name="Confidence")
    warning: bpy.props.StringProperty(name="Warning")
    hypothesis: bpy.props.StringProperty(name="Hypothesis")
    decided_by: bpy.props.StringProperty(name="Decided By")
    placement_used: bpy.props.BoolProperty(name="Placement Used")
    has_turn: bpy.props.BoolProperty(name="Has Turn")
    turn: bpy.props.FloatProperty(name="Turn", description="Degrees")
    has_runner_up: bpy.props.BoolProperty(name="Has Runner-Up")
    runner_up: bpy.props.StringProperty(name="Runner-Up")
    runner_up_cost: bpy.props.FloatProperty(name="Runner-Up Cost")
    taken_as: bpy.props.StringProperty(name="Taken As", description="whole, b_in_a or a_in_b")
    covered_share: bpy.props.FloatProperty(name="Covered Share", description="Share of the source's area with a counterpart")
    uncovered_target: bpy.props.IntProperty(name="Uncovered Target Vertices")


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

    placement: bpy.props.EnumProperty(
        name="Placement",
        description="How where the two objects stand is used to choose among the answers "
        "(a half-turn or a mirror that the shapes alone cannot tell apart)",
        items=[(name, name.capitalize(), _PLACEMENT_DOCS[name]) for name in _PLACEMENTS],
        default=_PLACEMENTS[_DEFAULTS["placement"]],
    )
    partial: bpy.props.EnumProperty(
        name="Partial",
        description="Whether one object is a part of the other (a cut, holes, one side of a scan)",
        items=[(name, name.replace("_", " ").capitalize(), _PARTIAL_DOCS[name]) for name in _PARTIALS],
        default=_PARTIALS[_DEFAULTS["partial"]],
    )
    landmarks: bpy.props.CollectionProperty(type=ShapecorrLandmark)
    landmark_index: bpy.props.IntProperty(name="Active Landmark Pair", default=0, min=0)
    answer: bpy.props.PointerProperty(type=ShapecorrAnswer)

    transfer_vertex_groups: bpy.props.BoolProperty(
        name="Vertex Groups",
        description="Carry the source's vertex groups (skin weights) to the target",
        default=True,
    )
    transfer_active_group_only: bpy.props.BoolProperty(
        name="Active Group Only",
        description="Carry only the source's active vertex group",
        default=False,
    )
    transfer_normalize_weights: bpy.props.BoolProperty(
        name="Normalize Weights",
        description="Treat the vertex groups as skin weights: each target vertex's weights sum "
        "to 1 (off: every group is interpolated on its own, for masks)",
        default=True,
    )
    transfer_max_influences: bpy.props.IntProperty(
        name="Max Influences",
        description="Most vertex groups per target vertex, the largest kept (0: no limit; "
        "used with Normalize Weights)",
        default=4,
        min=0,
        max=64,
    )
    transfer_uvs: bpy.props.BoolProperty(
        name="UV Maps",
        description="Carry the source's UV maps per corner: a UV island stays one island, the "
        "target's seam runs where the source's seam lands",
        default=True,
    )
    transfer_colors: bpy.props.BoolProperty(
        name="Colour Attributes",
        description="Carry the source's colour attributes (a corner colour is averaged per vertex)",
        default=True,
    )
    transfer_attributes: bpy.props.BoolProperty(
        name="Point Attributes",
        description="Carry the source's generic point attributes (float ones interpolated, "
        "integer and boolean ones from the nearest vertex)",
        default=True,
    )
    transfer_prefix: bpy.props.StringProperty(
        name="Prefix",
        description="Prefix of the names written on the target (empty: the source's names, "
        "replacing the target's of the same name)",
        default="",
    )

    def library_options(self, one_to_one=None):
        """The options passed to shapecorr.match."""
        return {
            "k_min": self.k_min,
            "k_max": self.k_max,
            "one_to_one": self.one_to_one if one_to_one is None else one_to_one,
            "placement": self.placement,
            "partial": self.partial,
        }
