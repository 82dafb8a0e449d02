"""Shape.from_trimesh, Shape.from_open3d and Shape.from_mesh, on stand-ins that hand over
what those libraries' objects do (array types included), and on trimesh itself when it is
installed (tests/python/run.sh installs it)."""

import numpy as np
import pytest

import shapecorr

FIGURE = shapecorr.Shape.figure("star4", 0, 800)
VERTICES, TRIANGLES = FIGURE.vertices, FIGURE.triangles


# ------------------------------------------------------------------------ trimesh stand-ins


class TrackedArray(np.ndarray):
    """trimesh's arrays: an ndarray subclass (it hashes its contents on change)."""


class Trimesh:
    """trimesh.Trimesh: float64 (n, 3) ``vertices``, int64 (m, 3) ``faces``."""

    def __init__(self, vertices, faces):
        self.vertices = np.asarray(vertices, dtype=np.float64).view(TrackedArray)
        self.faces = np.asarray(faces, dtype=np.int64).reshape(-1, 3).view(TrackedArray)


class TrimeshPointCloud:
    """trimesh.PointCloud: ``vertices`` and no ``faces`` attribute."""

    def __init__(self, vertices):
        self.vertices = np.asarray(vertices, dtype=np.float64).view(TrackedArray)


class Scene:
    """trimesh.Scene (what trimesh.load gives for a file of several parts): named
    geometries, no ``vertices``."""

    def __init__(self, **geometry):
        self.geometry = dict(geometry)


# ------------------------------------------------------------------------ Open3D stand-ins


class Vector3dVector:
    """open3d.utility.Vector3dVector: a sequence of 3-vectors, not an ndarray
    (``numpy.asarray`` converts it; it has no ``shape`` or ``dtype``)."""

    dtype_of_rows = np.float64

    def __init__(self, rows):
        self._rows = [np.asarray(row, dtype=self.dtype_of_rows) for row in rows]

    def __len__(self):
        return len(self._rows)

    def __getitem__(self, index):
        return self._rows[index]


class Vector3iVector(Vector3dVector):
    """open3d.utility.Vector3iVector: int32 rows."""

    dtype_of_rows = np.int32


class O3dTriangleMesh:
    """open3d.geometry.TriangleMesh: ``vertices`` and ``triangles`` (empty when it has none)."""

    def __init__(self, vertices, triangles=()):
        self.vertices = Vector3dVector(vertices)
        self.triangles = Vector3iVector(triangles)


class O3dPointCloud:
    """open3d.geometry.PointCloud: ``points``."""

    def __init__(self, points):
        self.points = Vector3dVector(points)


class O3dTensorGeometry:
    """open3d.t.geometry's TriangleMesh or PointCloud: converted with ``to_legacy()``."""

    def __init__(self, legacy):
        self._legacy = legacy

    def to_legacy(self):
        return self._legacy


def assert_mesh_of_the_figure(shape):
    assert not shape.is_point_cloud
    np.testing.assert_array_equal(shape.vertices, VERTICES)
    np.testing.assert_array_equal(shape.triangles, TRIANGLES)


def assert_point_cloud_of_the_figure(shape):
    assert shape.is_point_cloud
    np.testing.assert_array_equal(shape.vertices, VERTICES)
    assert shape.triangles.shape == (0, 3)


# ------------------------------------------------------------------------ the constructors


def test_from_trimesh_takes_meshes_and_point_clouds():
    assert_mesh_of_the_figure(shapecorr.Shape.from_trimesh(Trimesh(VERTICES, TRIANGLES)))
    assert_point_cloud_of_the_figure(shapecorr.Shape.from_trimesh(TrimeshPointCloud(VERTICES)))
    # A Trimesh without faces is its vertices, as a file without faces is.
    assert_point_cloud_of_the_figure(shapecorr.Shape.from_trimesh(Trimesh(VERTICES, [])))


def test_from_trimesh_refuses_a_scene_and_says_how_to_get_one_mesh():
    scene = Scene(body=Trimesh(VERTICES, TRIANGLES), hat=Trimesh(VERTICES, TRIANGLES))
    with pytest.raises(TypeError, match=r'scene of 2 geometries.*force="mesh"'):
        shapecorr.Shape.from_trimesh(scene)


def test_from_open3d_takes_legacy_and_tensor_geometry():
    mesh = O3dTriangleMesh(VERTICES, TRIANGLES)
    assert_mesh_of_the_figure(shapecorr.Shape.from_open3d(mesh))
    assert_mesh_of_the_figure(shapecorr.Shape.from_open3d(O3dTensorGeometry(mesh)))
    cloud = O3dPointCloud(VERTICES)
    assert_point_cloud_of_the_figure(shapecorr.Shape.from_open3d(cloud))
    assert_point_cloud_of_the_figure(shapecorr.Shape.from_open3d(O3dTensorGeometry(cloud)))
    assert_point_cloud_of_the_figure(shapecorr.Shape.from_open3d(O3dTriangleMesh(VERTICES)))


def test_from_mesh_takes_any_object_with_vertices_and_faces():
    class Plain:
        def __init__(self, **attributes):
            self.__dict__.update(attributes)

    lists = Plain(vertices=VERTICES.tolist(), faces=TRIANGLES.tolist())
    assert_mesh_of_the_figure(shapecorr.Shape.from_mesh(lists))
    assert_mesh_of_the_figure(shapecorr.Shape.from_mesh(Plain(vertices=VERTICES, triangles=TRIANGLES)))
    assert_point_cloud_of_the_figure(shapecorr.Shape.from_mesh(Plain(vertices=VERTICES, faces=None)))
    assert_point_cloud_of_the_figure(shapecorr.Shape.from_mesh(Plain(vertices=VERTICES)))
    # float32 coordinates stay float32 on the way in, as for Shape.mesh.
    single = shapecorr.Shape.from_mesh(Plain(vertices=VERTICES.astype(np.float32), faces=TRIANGLES))
    np.testing.assert_array_equal(single.vertices, VERTICES.astype(np.float32).astype(np.float64))


def test_repair_is_passed_on():
    corners = TRIANGLES.reshape(-1)
    soup = Trimesh(VERTICES[corners], np.arange(len(corners)).reshape(-1, 3))
    assert any("welded" in r for r in shapecorr.Shape.from_trimesh(soup).repairs)
    assert shapecorr.Shape.from_trimesh(soup, repair=False).repairs == []
    assert shapecorr.Shape.from_open3d(O3dTriangleMesh(soup.vertices, soup.faces), repair=False).repairs == []


@pytest.mark.parametrize(
    "constructor", [shapecorr.Shape.from_mesh, shapecorr.Shape.from_trimesh, shapecorr.Shape.from_open3d]
)
@pytest.mark.parametrize("thing", [object(), "mesh.ply", VERTICES, {"vertices": VERTICES}])
def test_objects_without_geometry_are_type_errors(constructor, thing):
    with pytest.raises(TypeError, match="expected an") as raised:
        constructor(thing)
    assert type(thing).__name__ in str(raised.value)


def test_from_mesh_points_an_open3d_point_cloud_to_from_open3d():
    with pytest.raises(TypeError, match="from_open3d"):
        shapecorr.Shape.from_mesh(O3dPointCloud(VERTICES))


def test_malformed_arrays_are_value_errors():
    with pytest.raises(ValueError, match=r"shape \(n, 3\)"):
        shapecorr.Shape.from_trimesh(Trimesh(VERTICES[:, :2], TRIANGLES))
    with pytest.raises(ValueError, match=r"shape \(n, 3\)"):
        shapecorr.Shape.from_open3d(O3dPointCloud(VERTICES[:, :2]))
    quads = type("Quads", (), {"vertices": VERTICES, "faces": np.zeros((10, 4), dtype=np.int64)})()
    with pytest.raises(ValueError, match=r"shape \(m, 3\)"):
        shapecorr.Shape.from_mesh(quads)


def test_the_real_trimesh():
    trimesh = pytest.importorskip("trimesh")
    sphere = trimesh.creation.icosphere(subdivisions=3)
    shape = shapecorr.Shape.from_trimesh(sphere)
    assert not shape.is_point_cloud
    np.testing.assert_array_equal(shape.vertices, sphere.vertices)
    np.testing.assert_array_equal(shape.triangles, sphere.faces)
    cloud = shapecorr.Shape.from_trimesh(trimesh.PointCloud(sphere.vertices))
    assert cloud.is_point_cloud and cloud.n_vertices == len(sphere.vertices)
    with pytest.raises(TypeError, match="scene of 2 geometries"):
        shapecorr.Shape.from_trimesh(trimesh.Scene([sphere, sphere.copy()]))
