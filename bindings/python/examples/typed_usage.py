"""shapecorr as a typed program uses it: two shapes made from numpy arrays, their region
correspondence and point-to-point map, checked against the known answer. Needs no data files.

    python bindings/python/examples/typed_usage.py
    python -m mypy --strict bindings/python/examples/typed_usage.py

Shape A is a sphere with five arms of different lengths (no symmetry, so the answer is
unique); shape B is A with one arm bent and its vertices shuffled, so the true map is known.
Exits with status 1 when the map is far from it.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

import shapecorr

#: Unit direction and length of each arm.
ARMS = [((1.0, 0.0, 0.0), 1.0), ((-1.0, 0.0, 0.0), 0.6), ((0.0, 1.0, 0.0), 0.8),
        ((0.0, -1.0, 0.0), 0.4), ((0.0, 0.0, 1.0), 0.7)]


@dataclass
class TriangleMesh:
    """What a mesh library hands over: vertex coordinates and triangles."""

    vertices: NDArray[np.float64]
    faces: NDArray[np.int64]


def sphere(rings: int, segments: int) -> TriangleMesh:
    """A latitude-longitude sphere: two poles and rings x segments vertices between them."""
    theta = np.linspace(0.0, np.pi, rings + 2)[1:-1]
    phi = np.linspace(0.0, 2.0 * np.pi, segments, endpoint=False)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    ring_points = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1)
    vertices = np.vstack([[0.0, 0.0, 1.0], ring_points.reshape(-1, 3), [0.0, 0.0, -1.0]])
    north, south = 0, len(vertices) - 1

    def at(ring: int, segment: int) -> int:
        return 1 + ring * segments + segment % segments

    faces: list[tuple[int, int, int]] = []
    for s in range(segments):
        faces.append((north, at(0, s), at(0, s + 1)))
        faces.append((south, at(rings - 1, s + 1), at(rings - 1, s)))
        for r in range(rings - 1):
            faces.append((at(r, s), at(r + 1, s), at(r + 1, s + 1)))
            faces.append((at(r, s), at(r + 1, s + 1), at(r, s + 1)))
    return TriangleMesh(vertices, np.asarray(faces, dtype=np.int64))


def with_arms(mesh: TriangleMesh) -> TriangleMesh:
    """The sphere pushed out along each arm's direction."""
    radius = np.ones(len(mesh.vertices))
    for direction, length in ARMS:
        alignment = np.clip(mesh.vertices @ np.asarray(direction), 0.0, None)
        radius += length * 2.0 * alignment**12
    return TriangleMesh(mesh.vertices * radius[:, None], mesh.faces)


def bend_first_arm(vertices: NDArray[np.float64], degrees: float) -> NDArray[np.float64]:
    """The +x arm turned about the z axis around its root (x = 1), the rest kept."""
    angle = np.radians(degrees) * np.clip(vertices[:, 0] - 1.0, 0.0, None)
    bent = vertices.copy()
    x, y = vertices[:, 0] - 1.0, vertices[:, 1]
    beyond = vertices[:, 0] > 1.0
    bent[beyond, 0] = 1.0 + (np.cos(angle) * x - np.sin(angle) * y)[beyond]
    bent[beyond, 1] = (np.sin(angle) * x + np.cos(angle) * y)[beyond]
    return bent


def main() -> int:
    a_mesh = with_arms(sphere(rings=30, segments=48))
    a = shapecorr.Shape.mesh(a_mesh.vertices, a_mesh.faces)

    # B's vertex j is A's vertex order[j]: the answer the map should find.
    order = np.random.default_rng(7).permutation(len(a_mesh.vertices))
    where = np.argsort(order)
    b_mesh = TriangleMesh(bend_first_arm(a_mesh.vertices, 30.0)[order], where[a_mesh.faces])
    b = shapecorr.Shape.from_mesh(b_mesh)
    print(a, b, sep="\n")

    regions: shapecorr.Correspondence = shapecorr.match(a, b, k_max=8)
    matches: NDArray[np.uint32] = regions.matches_one_to_one
    confidence: float | None = regions.confidence
    print(f"{regions.k} clusters, {len(matches)} regions matched one to one, confidence "
          f"{'none' if confidence is None else f'{confidence:.2f}'}")

    # Options as a typed dict (or keyword arguments): mypy checks every name and type.
    options: shapecorr.PointwiseOptions = {"p2p_refinement": "zoomout", "p2p_fmap_size": 40}
    try:
        pointwise = shapecorr.pointwise_map(a, b, **options)
    except shapecorr.ResourceLimitError as refused:  # too big for this machine's limits
        print(f"refused by {refused.limit}: {refused.message}", file=sys.stderr)
        return 1
    map_b_to_a: NDArray[np.uint32] = pointwise.map_b_to_a
    error = np.linalg.norm(a_mesh.vertices[map_b_to_a] - a_mesh.vertices[order], axis=1)
    diameter = float(np.ptp(a_mesh.vertices, axis=0).max())
    close = float(np.mean(error < 0.05 * diameter))
    seconds: dict[str, float] = pointwise.timings
    print(f"pointwise map: {close:.0%} of B's vertices within 5% of the diameter of the true "
          f"vertex of A, in {seconds['total']:.2f} s; warning: {pointwise.warning}")
    return 0 if close >= 0.8 else 1


if __name__ == "__main__":
    sys.exit(main())
