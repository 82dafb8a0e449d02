"""The reference for `--example cloud_spectrum` (docs/scans.md, "Point clouds").

For every OFF mesh given, the relative difference between the eigenvalues of
Sharp and Crane's point-cloud Laplacian of its vertices and those of their mesh
Laplacian (`robust_laplacian`, both at unit area): how far a good point-cloud
Laplacian departs from the mesh's on the same points.

    python3 -m venv /tmp/rl && /tmp/rl/bin/pip install robust_laplacian scipy
    /tmp/rl/bin/python crates/eval/scripts/cloud_spectrum_reference.py MESH.off ...
"""

import sys

import numpy as np
import robust_laplacian
import scipy.sparse.linalg as sla

SHOWN = [1, 2, 5, 10, 20, 40, 59]


def read_off(path):
    """Vertices and triangles of an OFF file (header on its own line or not)."""
    words = []
    for line in open(path):
        line = line.split("#")[0].strip()
        if line:
            words.extend(line.split())
    if words[0].startswith("OFF"):
        words = ([words[0][3:]] if len(words[0]) > 3 else []) + words[1:]
    n_vertices, n_faces = int(words[0]), int(words[1])
    at = 3
    vertices = np.array(words[at : at + 3 * n_vertices], dtype=float).reshape(-1, 3)
    at += 3 * n_vertices
    faces = []
    for _ in range(n_faces):
        n = int(words[at])
        faces.append([int(x) for x in words[at + 1 : at + 4]])
        at += n + 1
    return vertices, np.array(faces)


def unit_area_eigenvalues(laplacian, mass, k=60):
    values = sla.eigsh(laplacian, k, mass, sigma=1e-8)[0]
    return np.sort(values) * mass.diagonal().sum()


for path in sys.argv[1:]:
    vertices, faces = read_off(path)
    mesh = unit_area_eigenvalues(*robust_laplacian.mesh_laplacian(vertices, faces))
    cloud = unit_area_eigenvalues(*robust_laplacian.point_cloud_laplacian(vertices))
    relative = (cloud - mesh) / mesh
    print(path + ": " + "  ".join(f"{k}: {relative[k]:+.3f}" for k in SHOWN))
