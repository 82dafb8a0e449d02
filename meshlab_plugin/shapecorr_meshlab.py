"""Colour the matching regions of two meshes for MeshLab, with pymeshlab and libshapecorr.

    python meshlab_plugin/shapecorr_meshlab.py A.ply B.stl --out-a A_col.ply --out-b B_col.ply

loads both files with pymeshlab's MeshSet (every format MeshLab reads), matches their
regions, and saves each mesh with vertex colours (matched regions share a colour, unmatched
ones are dark grey) and the region id of every vertex as its quality (a per-vertex scalar,
shown by MeshLab's "Colorize by vertex quality") and as the custom attribute
``shapecorr_region``. As a function::

    import pymeshlab, shapecorr_meshlab
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh("A.ply")
    ms.load_new_mesh("B.ply")
    coloured = shapecorr_meshlab.match_regions(ms)     # a new MeshSet: mesh 0 is A, 1 is B
    coloured, result = shapecorr_meshlab.match(ms)     # ... and the shapecorr result
    print("\n".join(shapecorr_meshlab.report(result)))  # its confidence (and warning)

The command prints the answer's confidence (in [0, 1], or "not verified") in its report,
and when the answer is doubtful a warning on stderr (``shapecorr_meshlab: warning: ...``).

The command's options are generated from the library's option table
(``shapecorr.options()``, the same as the ``shapecorr`` command line's): one per region
option, named as the option with ``-`` for ``_`` (``--k-min 5``, ``--gap-ratio 0.85``,
``--one-to-one false``, ``--placement trust``), plus ``--set NAME=VALUE`` (repeatable, the
table's spelling, applied after them). ``--landmarks FILE`` gives landmark pairs (a vertex
of A, then its partner on B, a line each; the format of ``shapecorr --landmarks``,
docs/placement.md).

The report names the hypothesis chosen, what decided it (the cost, the shapes' placement,
the landmarks), the turn it implies between B and A, and the runner-up's cost.

Transfer (docs/transfer.md) carries A's vertex colours, quality and per-vertex texture coordinates
to B through the correspondence, whatever their poses and bodies::

    python meshlab_plugin/shapecorr_meshlab.py transfer A.ply B.ply --out B_from_A.ply
    out, pointwise = shapecorr_meshlab.transfer(ms)    # a MeshSet with B carrying A's data

Per-wedge texture coordinates (a UV layout with seams, as OBJ files carry it) are carried
per corner, seams kept: a UV island of A stays one island on B (``SurfaceMap.transfer_corners``).
(A file named ``transfer`` as the first mesh is spelt ``./transfer``.)
"""

import argparse
import re
import sys
from pathlib import Path

import numpy as np
import pymeshlab

try:
    import shapecorr
except ImportError:  # a source checkout: use the binding next to this script
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "bindings" / "python"))
    import shapecorr

#: Name of the per-vertex custom scalar attribute holding the region id.
REGION_ATTRIBUTE = "shapecorr_region"


def shape_of(mesh, as_point_cloud=False):
    """A shapecorr shape from a pymeshlab mesh (same vertex order)."""
    vertices = mesh.vertex_matrix()
    faces = mesh.face_matrix()
    if as_point_cloud or len(faces) == 0:
        return shapecorr.Shape.point_cloud(vertices)
    return shapecorr.Shape.mesh(vertices, faces)


def coloured(mesh, regions, rgba):
    """A copy of ``mesh`` with vertex colours, the region id as vertex quality and as the
    custom attribute ``shapecorr_region``."""
    faces = mesh.face_matrix()
    result = pymeshlab.Mesh(
        vertex_matrix=mesh.vertex_matrix(),
        face_matrix=faces if len(faces) else np.zeros((0, 3), dtype=np.int32),
        v_color_matrix=rgba.astype(np.float64) / 255.0,
        v_scalar_array=regions.astype(np.float64),
    )
    result.add_vertex_custom_scalar_attribute(regions.astype(np.float64), REGION_ATTRIBUTE)
    return result


def match_regions(ms, id_a=0, id_b=1, one_to_one=True, as_point_cloud=False, progress=None, **options):
    """Matches meshes ``id_a`` and ``id_b`` of the MeshSet ``ms`` and returns a new MeshSet
    holding their coloured copies (A first, then B). ``options`` are shapecorr's named
    options (``k_min``, ``k_max``, ``placement``, ...; ``shapecorr.options()`` lists them)
    and ``landmarks=[(vertex of A, vertex of B), ...]``. Raises shapecorr.ShapecorrError on
    bad input (a landmark out of range too)."""
    return match(ms, id_a, id_b, one_to_one, as_point_cloud, progress, **options)[0]


def _field(record, name):
    """``record.name``, or ``record[name]`` for a runner-up given as a dict."""
    return record[name] if isinstance(record, dict) else getattr(record, name)


def choice_text(result):
    """How the answer was chosen, for the report: ``hypothesis 'answer' decided by placement
    (placement used), turn 9 degrees, runner-up 'mirror' cost 0.0757`` (``no runner-up``
    when every other hypothesis gives the same map); empty when it was not verified."""
    if result.hypothesis is None:
        return ""
    used = "used" if result.placement_used else "not used"
    text = f"hypothesis '{result.hypothesis}' decided by {result.decided_by} (placement {used})"
    if result.turn_degrees is not None:
        text += f", turn {result.turn_degrees:.0f} degrees"
    runner_up = result.runner_up
    if runner_up is None:
        return text + ", no runner-up"
    return text + f", runner-up '{_field(runner_up, 'hypothesis')}' cost {_field(runner_up, 'cost'):.4g}"


#: What to do about a doubtful answer (docs/placement.md).
ADVICE = (
    "to check or correct it: give two landmark pairs with --landmarks FILE (say a left hand and a left "
    "foot, a vertex of A then its partner on B), or use --placement trust when the shapes stand alike"
)


def report(result, shapes=()):
    """The lines of the report on a match: the confidence of the answer (``confidence
    0.74``, or ``not verified`` when it has none) and how it was chosen (:func:`choice_text`),
    ``warning: ...`` and what to do (:data:`ADVICE`) when it is doubtful, ``repaired A:
    ...`` for every repair the library made to ``shapes`` (A, then B; pieces joined for
    matching among them), and what a side was matched on when not its input
    (:func:`working_lines`)."""
    confidence = result.confidence
    first = "not verified" if confidence is None else f"confidence {confidence:.2f}"
    choice = choice_text(result)
    lines = [f"{first}, {choice}" if choice else first]
    if result.warning is not None:
        lines.append(f"warning: {result.warning}")
        lines.append(ADVICE)
    lines.extend(partial_lines(result))
    for side, shape in zip("AB", shapes):
        lines.extend(f"repaired {side}: {repair}" for repair in shape.repairs)
    lines.extend(working_lines(result, shapes))
    return lines


def partial_lines(result):
    """What a pointwise map took as a part (docs/partial.md): ``partial: B is a part of A
    (measured), 45% of A covered``, and for A a part of B how many vertices of B have no
    counterpart; nothing for two whole shapes or a region answer."""
    taken_as = getattr(result, "taken_as", "whole")
    if taken_as == "whole":
        return []
    how = "given" if result.partial_given else "measured"
    part, whole = ("B", "A") if taken_as == "b_in_a" else ("A", "B")
    lines = [f"partial: {part} is a part of {whole} ({how}), {100 * result.covered_share:.0f}% of A covered"]
    uncovered = int((~result.covered_b).sum())
    if uncovered:
        lines.append(f"partial: {uncovered} vertices of B have no counterpart on A; a transfer keeps B's own values there")
    return lines


def working_lines(result, shapes=()):
    """``A was matched on a refined copy of 1,204 vertices (the input has 290)`` (or ``a
    proxy of``) for each side the library ran on a refined copy of a low-poly mesh or a proxy
    of a dense one (``result.working``), ``A looks noisy ...`` for one matched on a smoothed
    copy of a noisy mesh, ``A: 866 vertices of an object touching the figure ... left out``
    for a prop the pair job left out; nothing for a side matched on its input as it is."""
    lines = []
    for index, shape in enumerate(getattr(result, "working", ())):
        kind, vertices, smoothed = shape[0], shape[1], getattr(shape, "smoothed", False)
        side = "ab"[index]
        left_out = getattr(shape, "objects_left_out", 0)
        if left_out:
            lines.append(f"{side.upper()}: {left_out:,} vertices of an object touching the figure (a prop) were left out: the pair matched better without them; they take the answer of the nearest kept vertex")
        not_tried = getattr(shape, "objects_not_tried", 0)
        if not_tried:
            lines.append(f"{side.upper()}: {not_tried} object(s) touching the figure were matched as part of it: the time limit passed before the pair could try without them (raise the time limit to try)")
        if kind == "input" and not smoothed:
            continue
        if kind == "input":
            lines.append(f"{side.upper()} looks noisy (scanner noise): it was matched on a smoothed copy; the answers are on its own vertices")
            continue
        what = "a refined copy" if kind == "refined" else "a proxy"
        if smoothed:
            what = what.replace("a ", "a smoothed ", 1)
        inputs = shapes[index].n_vertices if shapes else getattr(result, f"n_vertices_{side}", None)
        inputs = len(result.regions(side)) if inputs is None else inputs
        lines.append(f"{side.upper()} was matched on {what} of {vertices:,} vertices (the input has {inputs:,})")
    return lines


def read_landmarks(path):
    """The landmark pairs of a text file, ``[(vertex of A, vertex of B), ...]``: two 0-based
    vertex indices a line, separated by spaces, tabs or one comma; ``#`` starts a comment,
    blank lines are skipped (the format ``shapecorr --landmarks`` reads). Raises ValueError
    naming the file, the line and the column of a malformed line; the library checks the
    pairs against the shapes (out of range, left out by its repairs, contradicting)."""
    limit = 1 << 20
    with open(path, "rb") as file:
        data = file.read(limit + 1)
    if len(data) > limit:
        raise ValueError(f"{path}: more than {limit} bytes: not a landmarks file")
    text = data.removeprefix(b"\xef\xbb\xbf").decode("ascii", errors="replace")
    pairs = []
    for number, line in enumerate(text.split("\n"), start=1):
        line = line.removesuffix("\r").split("#", 1)[0]
        try:
            pair = _landmark_line(line)
        except _LineError as error:
            column, reason = error.args
            raise ValueError(f"{path}: line {number}, column {column}: {reason}") from None
        if pair is not None:
            pairs.append(pair)
    return pairs


class _LineError(Exception):
    """A malformed line of a landmarks file: ``(column, reason)``."""


def _landmark_line(line):
    """The pair on one line (comment removed), None for a blank one; raises _LineError."""
    fields = [(m.group(), m.start() + 1) for m in re.finditer(r"[^ \t,]+", line)]
    commas = [k + 1 for k, c in enumerate(line) if c == ","]
    if not fields:
        if commas:
            raise _LineError(commas[0], "a comma with no vertex index")
        return None
    if len(commas) > 1:
        raise _LineError(commas[1], "a second comma: a line is two vertex indices separated by spaces, tabs or one comma")
    if len(fields) > 2:
        raise _LineError(fields[2][1], f"a third value `{fields[2][0]}`: a line is two vertex indices, A's then B's")
    if len(fields) < 2:
        raise _LineError(len(line.rstrip(" \t,")) + 1, "B's vertex is missing: a line is two vertex indices, A's then B's")
    if commas and not fields[0][1] < commas[0] < fields[1][1]:
        raise _LineError(commas[0], "a comma that is not between the two vertex indices")
    for (value, column), side in zip(fields, "AB"):
        if re.fullmatch(r"-[0-9]+", value):
            raise _LineError(column, f"{side}'s vertex `{value}` is negative: vertex indices start at 0")
        if not re.fullmatch(r"[0-9]+", value):
            raise _LineError(column, f"{side}'s vertex `{value}` is not a vertex index (a whole number from 0)")
        if int(value) >= 2**32:
            raise _LineError(column, f"{side}'s vertex `{value}` is larger than any vertex index")
    return int(fields[0][0]), int(fields[1][0])


def match(ms, id_a=0, id_b=1, one_to_one=True, as_point_cloud=False, progress=None, **options):
    """As :func:`match_regions`, returning ``(meshset, result)``: also the
    shapecorr.Correspondence, for its ``confidence`` and ``warning`` (see :func:`report`)."""
    return match_with_shapes(ms, id_a, id_b, one_to_one, as_point_cloud, progress, **options)[:2]


def match_with_shapes(ms, id_a=0, id_b=1, one_to_one=True, as_point_cloud=False, progress=None, **options):
    """As :func:`match`, returning ``(meshset, result, (shape_a, shape_b))``: also the
    shapecorr shapes, for the repairs the library made to them (see :func:`report`)."""
    mesh_a, mesh_b = ms.mesh(id_a), ms.mesh(id_b)
    shapes = (shape_of(mesh_a, as_point_cloud), shape_of(mesh_b, as_point_cloud))
    result = shapecorr.match(*shapes, progress=progress, one_to_one=one_to_one, **options)
    out = pymeshlab.MeshSet()
    for mesh, side in ((mesh_a, "a"), (mesh_b, "b")):
        out.add_mesh(coloured(mesh, result.regions(side), result.colors(side, one_to_one=one_to_one)))
    return out, result, shapes


def transfer(ms, id_a=0, id_b=1, colors=True, quality=True, texcoords=True, progress=None, **options):
    """Carries per-vertex data of mesh ``id_a`` of the MeshSet ``ms`` to mesh ``id_b``
    through the correspondence (any pose and body): vertex colours, quality and texture
    coordinates interpolated on A's surface; per-wedge texture coordinates carried per
    corner with A's seams kept. Returns ``(meshset, pointwise)``: a
    new MeshSet holding a copy of B with what A has of these (``colors``, ``quality``,
    ``texcoords`` say which), and the shapecorr.PointwiseMap (its ``confidence`` and
    ``warning``: see :func:`report`). ``options`` as :func:`match_regions`'. Raises
    shapecorr.ShapecorrError on bad input, ValueError when A has none of what is asked."""
    mesh_a, mesh_b = ms.mesh(id_a), ms.mesh(id_b)
    if len(mesh_a.face_matrix()) == 0 or len(mesh_b.face_matrix()) == 0:
        raise ValueError("transfer needs two meshes with faces")
    carried = {}
    if colors and mesh_a.has_vertex_color():
        carried["v_color_matrix"] = mesh_a.vertex_color_matrix()
    if quality and mesh_a.has_vertex_scalar():
        carried["v_scalar_array"] = mesh_a.vertex_scalar_array()
    if texcoords and mesh_a.has_vertex_tex_coord():
        carried["v_tex_coords_matrix"] = mesh_a.vertex_tex_coord_matrix()
    wedges = texcoords and mesh_a.has_wedge_tex_coord()
    if not carried and not wedges:
        raise ValueError("mesh A has none of what was asked (vertex colours, quality, texture coordinates)")
    shapes = (shape_of(mesh_a), shape_of(mesh_b))
    pointwise = shapecorr.pointwise_map(*shapes, progress=progress, **options)
    onto = shapecorr.surface_map(*shapes, pointwise, progress=progress)
    values = {name: onto.transfer(array) for name, array in carried.items()}
    # A vertex of B without a counterpart on A (A a part of B) keeps what B has of it.
    uncovered = ~pointwise.covered_b
    own = {"v_color_matrix": (mesh_b.has_vertex_color, mesh_b.vertex_color_matrix),
           "v_scalar_array": (mesh_b.has_vertex_scalar, mesh_b.vertex_scalar_array),
           "v_tex_coords_matrix": (mesh_b.has_vertex_tex_coord, mesh_b.vertex_tex_coord_matrix)}
    for name, array in values.items():
        has, read = own[name]
        if uncovered.any() and has():
            array[uncovered] = read()[uncovered]
    if wedges:
        corners = mesh_a.wedge_tex_coord_matrix().reshape(-1, 3, 2)
        carried_corners = onto.transfer_corners(shapes[0], mesh_a.face_matrix(), corners, mesh_b.face_matrix())
        values["w_tex_coords_matrix"] = carried_corners.reshape(-1, 2)
    if "v_color_matrix" in values:
        values["v_color_matrix"] = np.clip(values["v_color_matrix"], 0.0, 1.0)
    out = pymeshlab.MeshSet()
    out.add_mesh(pymeshlab.Mesh(vertex_matrix=mesh_b.vertex_matrix(), face_matrix=mesh_b.face_matrix(), **values))
    return out, pointwise


#: Text read as True and as False for a boolean option (as the command line reads them).
_TRUE, _FALSE = ("true", "yes", "1"), ("false", "no", "0")


def region_options():
    """The library's region options (the pointwise map's are named ``p2p_*``), as
    ``(name, type, description, default)``."""
    return [option for option in shapecorr.options() if not option[0].startswith("p2p_")]


def parse_value(name, kind, text, choices=()):
    """A value of option ``name`` of type ``kind`` ("int", "float" or "bool") from text; a
    choice (``placement``) also by one of its names ``choices``, kept as the name."""
    word = text.strip().lower()
    if word in choices:
        return word
    try:
        if kind == "bool":
            if word in _TRUE or word in _FALSE:
                return word in _TRUE
            raise ValueError
        return int(word) if kind == "int" else float(word)
    except ValueError:
        expected = {"int": "an integer", "float": "a number", "bool": "true or false (yes/no, 1/0)"}[kind]
        if choices:
            expected = "one of " + ", ".join(f"{choice} ({i})" for i, choice in enumerate(choices))
        raise argparse.ArgumentTypeError(f"option `{name}` expects {expected}, got {text!r}") from None


def _option_parser(name, kind, choices):
    return lambda text: parse_value(name, kind, text, choices)


def _set_parser(table):
    kinds = {option.name: option.kind for option in table}
    choices = {option.name: option.choices for option in table}

    def parse(text):
        name, equals, value = text.partition("=")
        name = name.strip()
        if not equals:
            raise argparse.ArgumentTypeError(f"expected NAME=VALUE (e.g. k_max=8), got {text!r}")
        if name not in kinds:
            raise argparse.ArgumentTypeError(f"unknown option `{name}`; the options are: {', '.join(kinds)}")
        return name, parse_value(name, kinds[name], value, choices[name])

    return parse


def argument_parser():
    """The command's arguments; the options come from the library's table."""
    parser = argparse.ArgumentParser(description="Colour the matching regions of two meshes (shapecorr).")
    parser.add_argument("a", help="first mesh (any format MeshLab reads)")
    parser.add_argument("b", help="second mesh")
    parser.add_argument("--out-a", required=True, help="coloured copy of A (e.g. A_col.ply)")
    parser.add_argument("--out-b", required=True, help="coloured copy of B")
    parser.add_argument("--symmetric", action="store_true", help="colour by symmetric matches (no one-to-one)")
    parser.add_argument("--points", action="store_true", help="treat both as point clouds")
    table = region_options()
    group = parser.add_argument_group("region options (the library's option table)")
    for option in table:
        name, kind, doc, default = option
        metavar = {"int": "INT", "float": "NUMBER", "bool": "true|false"}[kind]
        shown = str(default).lower() if kind == "bool" else default
        if option.choices:
            metavar, shown = "|".join(option.choices), option.choices[default]
        group.add_argument(
            "--" + name.replace("_", "-"),
            dest=f"option:{name}",
            metavar=metavar,
            type=_option_parser(name, kind, option.choices),
            default=argparse.SUPPRESS,
            help=f"{doc} (default: {shown})".replace("%", "%%"),
        )
    group.add_argument(
        "--set",
        dest="set",
        metavar="NAME=VALUE",
        action="append",
        default=[],
        type=_set_parser(table),
        help="set any of the options above by its table name (k_max=8), after them; repeatable",
    )
    _landmarks_argument(parser)
    return parser


def _landmarks_argument(parser):
    parser.add_argument(
        "--landmarks", metavar="FILE",
        help="landmark pairs: a vertex of A, then its partner on B, a line each (0-based; spaces, tabs or "
        "one comma; # comments); the answer carrying them nearest their partners is chosen (docs/placement.md)",
    )


def landmarks_of(args):
    """``{"landmarks": pairs}`` from ``--landmarks FILE`` (:func:`read_landmarks`), or ``{}``."""
    return {} if args.landmarks is None else {"landmarks": read_landmarks(args.landmarks)}


def options_of(args):
    """The named options given on the command line: the flags, then ``--set``."""
    options = {key[len("option:"):]: value for key, value in vars(args).items() if key.startswith("option:")}
    options.update(args.set)
    return options


def transfer_parser():
    """The arguments of ``transfer`` (the options as the matching command's)."""
    parser = argparse.ArgumentParser(
        prog="shapecorr_meshlab.py transfer",
        description="Carry vertex colours, quality and texture coordinates from mesh A to mesh B (shapecorr).",
    )
    parser.add_argument("a", help="source mesh (any format MeshLab reads)")
    parser.add_argument("b", help="target mesh")
    parser.add_argument("--out", required=True, help="B with A's data (e.g. B_from_A.ply)")
    for name in ("colors", "quality", "texcoords"):
        parser.add_argument(f"--no-{name}", action="store_true", help=f"do not carry the vertex {name}")
    parser.add_argument(
        "--set", dest="set", metavar="NAME=VALUE", action="append", default=[],
        type=_set_parser(shapecorr.options()), help="a library option by its table name (k_max=8); repeatable",
    )
    _landmarks_argument(parser)
    return parser


def load_pair(a, b):
    """A MeshSet holding the files ``a`` and ``b`` (mesh 0 and 1), or None with the reason
    printed on stderr."""
    ms = pymeshlab.MeshSet()
    try:
        ms.load_new_mesh(str(a))
        ms.load_new_mesh(str(b))
    except pymeshlab.PyMeshLabException as error:
        print(f"shapecorr_meshlab: cannot load: {error}", file=sys.stderr)
        return None
    return ms


def save_current(ms, path, **wanted):
    """Saves the current mesh of ``ms`` to ``path`` with the ``save_*`` flags its format
    has (an OBJ or OFF file has no vertex quality: pymeshlab refuses the flag, so it is
    left out). False, with the reason on stderr, when the file cannot be written."""
    wanted = dict(wanted)
    while True:
        try:
            ms.save_current_mesh(str(path), **wanted)
            return True
        except pymeshlab.PyMeshLabException as error:
            unknown = re.search(r"Parameter (\w+) not found", str(error))
            if unknown is None or unknown.group(1) not in wanted:
                print(f"shapecorr_meshlab: cannot save {path}: {error}", file=sys.stderr)
                return False
            del wanted[unknown.group(1)]


def print_report(wrote, lines):
    """The report's first line after what was written (stdout), the warnings on stderr."""
    summary, *warnings = lines
    print(f"shapecorr_meshlab: wrote {wrote} ({summary})")
    for line in warnings:
        print(f"shapecorr_meshlab: {line}", file=sys.stderr)


def main_transfer(argv):
    args = transfer_parser().parse_args(argv)
    try:
        landmarks = landmarks_of(args)
    except (OSError, ValueError) as error:
        print(f"shapecorr_meshlab: {error}", file=sys.stderr)
        return 1
    ms = load_pair(args.a, args.b)
    if ms is None:
        return 1
    try:
        out, pointwise = transfer(
            ms, colors=not args.no_colors, quality=not args.no_quality, texcoords=not args.no_texcoords,
            **dict(args.set), **landmarks,
        )
    except (shapecorr.ShapecorrError, ValueError) as error:
        print(f"shapecorr_meshlab: {error}", file=sys.stderr)
        return 1
    mesh = out.current_mesh()
    if not save_current(
        out, args.out, save_vertex_color=mesh.has_vertex_color(), save_vertex_quality=mesh.has_vertex_scalar(),
        save_vertex_coord=mesh.has_vertex_tex_coord(), save_wedge_texcoord=mesh.has_wedge_tex_coord(),
    ):
        return 1
    print_report(args.out, report(pointwise))
    return 0


def main(argv=None):
    argv = sys.argv[1:] if argv is None else list(argv)
    if argv[:1] == ["transfer"]:
        return main_transfer(argv[1:])
    args = argument_parser().parse_args(argv)
    options = options_of(args)
    one_to_one = options.pop("one_to_one", True) and not args.symmetric
    try:
        options.update(landmarks_of(args))
    except (OSError, ValueError) as error:
        print(f"shapecorr_meshlab: {error}", file=sys.stderr)
        return 1
    ms = load_pair(args.a, args.b)
    if ms is None:
        return 1
    try:
        out, result, shapes = match_with_shapes(
            ms, one_to_one=one_to_one, as_point_cloud=args.points, **options
        )
    except shapecorr.ShapecorrError as error:
        print(f"shapecorr_meshlab: {error}", file=sys.stderr)
        return 1
    for mesh_id, path in ((0, args.out_a), (1, args.out_b)):
        out.set_current_mesh(mesh_id)
        if not save_current(out, path, save_vertex_color=True, save_vertex_quality=True):
            return 1
    print_report(f"{args.out_a} and {args.out_b}", report(result, shapes))
    return 0


if __name__ == "__main__":
    sys.exit(main())
