"""What the add-on keeps between operations.

In memory, for this session only (a library result cannot be saved in a .blend file): the
last library result of each ordered pair of objects, every answer taken from it since (Use
Other Answer), and what was done with it (regions coloured, attributes carried, map shown),
so that Use Other Answer can redo that with the runner-up and Show Map and Transfer can reuse
the map instead of computing it again. In the scene (saved with the file, undone with the
operation): the summary of the answer shown (``Scene.shapecorr.answer``), which the panel
draws.
"""

import hashlib

import bpy
import numpy as np

#: (name of A, name of B) -> :class:`Entry`.
_ENTRIES = {}


def fingerprint(geometries, options=None, landmarks=()):
    """A digest of what a library call reads: every shape's world coordinates and triangles,
    and (for a result to be reused) the options and landmarks."""
    digest = hashlib.blake2b(digest_size=16)
    for world, triangles in geometries:
        for array in (world, triangles):
            array = np.ascontiguousarray(array)
            digest.update(str(array.shape).encode())
            digest.update(array.tobytes())
    if options is not None:
        digest.update(repr(sorted(options.items())).encode())
        digest.update(repr([tuple(int(i) for i in pair) for pair in landmarks]).encode())
    return digest.hexdigest()


class Entry:
    """The last result of one pair: ``answers`` (the library's result first, then each other
    answer taken), what was done with it (``views``: "regions", "transfer", "map", each with
    what redoing it needs) and the fingerprints of its input."""

    def __init__(self, names, geometry, inputs, shapes, world_a, result):
        self.names = tuple(names)
        self.geometry = geometry
        self.inputs = inputs
        self.shapes = shapes
        self.world_a = world_a
        self.answers = [result]
        self.views = {}

    def current(self, scene):
        """The answer the scene shows: the one whose hypothesis the scene's summary names
        (after an undo it may be an earlier one), else the last one taken."""
        shown = scene.shapecorr.answer
        if (shown.source, shown.target) == self.names and shown.hypothesis:
            for answer in reversed(self.answers):
                if answer.hypothesis == shown.hypothesis:
                    return answer
        return self.answers[-1]


def entry(names):
    """The entry of the ordered pair ``names`` (None when there is none)."""
    return _ENTRIES.get(tuple(names))


def remember(entry_):
    """Keeps ``entry_`` as its pair's last result (replacing an older one)."""
    _ENTRIES[entry_.names] = entry_


def forget_all():
    """Drops every result (a file was loaded: its objects are other objects)."""
    _ENTRIES.clear()


@bpy.app.handlers.persistent
def _on_load(_filepath=None):
    forget_all()


def register():
    bpy.app.handlers.load_post.append(_on_load)


def unregister():
    if _on_load in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.remove(_on_load)
    forget_all()


def _field(record, name):
    """``record.name`` or ``record[name]`` (the runner-up as an object or a dict)."""
    return record[name] if isinstance(record, dict) else getattr(record, name)


def write_summary(scene, operation, names, result):
    """Writes what the panel shows about ``result`` (a Correspondence or PointwiseMap) into
    ``scene.shapecorr.answer``."""
    shown = scene.shapecorr.answer
    shown.operation = operation
    shown.source, shown.target = names
    confidence = result.confidence
    shown.verified = confidence is not None
    shown.confidence = 0.0 if confidence is None else confidence
    shown.warning = result.warning or ""
    shown.hypothesis = result.hypothesis or ""
    shown.decided_by = result.decided_by or ""
    shown.placement_used = bool(result.placement_used)
    turn = result.turn_degrees
    shown.has_turn = turn is not None
    shown.turn = 0.0 if turn is None else turn
    runner_up = result.runner_up
    shown.has_runner_up = runner_up is not None
    shown.runner_up = "" if runner_up is None else _field(runner_up, "hypothesis")
    shown.runner_up_cost = 0.0 if runner_up is None else _field(runner_up, "cost")
    # Only a pointwise map knows whether a shape was taken as a part.
    partial = hasattr(result, "covered_b")
    shown.taken_as = result.taken_as if partial else ""
    shown.covered_share = result.covered_share if partial else 1.0
    shown.uncovered_target = int((~result.covered_b).sum()) if partial else 0


def answer_text(result):
    """The answer for a report: ``hypothesis 'answer' (decided by placement, turn 2
    degrees), runner-up 'mirror' cost 0.131``; empty when it was not verified."""
    if result.hypothesis is None:
        return ""
    turn = result.turn_degrees
    turn = "" if turn is None else f", turn {turn:.0f} degrees"
    text = f", hypothesis '{result.hypothesis}' (decided by {result.decided_by}{turn})"
    runner_up = result.runner_up
    if runner_up is not None:
        text += f", runner-up '{_field(runner_up, 'hypothesis')}' cost {_field(runner_up, 'cost'):.3g}"
    return text
