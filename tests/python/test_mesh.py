"""clod.Mesh: construction, validation, mass properties, exact closest points; bad input."""

import pickle
import re
import subprocess
import sys

import numpy as np
import pytest

import clod
from conftest import box_signed_distance, brute_force_distance, write_obj


def test_version_matches_the_project_and_imports_from_any_directory(source_dir, tmp_path):
    version = re.search(r"project\(clod VERSION ([0-9.]+)", (source_dir / "CMakeLists.txt").read_text()).group(1)
    assert clod.__version__ == version
    out = subprocess.run([sys.executable, "-c", "import clod; print(clod.__version__)"], cwd=tmp_path,
                         capture_output=True, text=True, check=True)
    assert out.stdout.strip() == version


def test_mesh_from_arrays_keeps_vertices_and_faces():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float32)
    f = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]], dtype=np.int32)
    mesh = clod.Mesh(v, f)
    assert mesh.vertices.dtype == np.float64 and mesh.vertices.shape == (4, 3)
    np.testing.assert_array_equal(mesh.vertices, v.astype(np.float64))
    np.testing.assert_array_equal(mesh.faces, f)
    assert not mesh.vertices.flags.writeable
    report = mesh.inspect()
    assert report["closed"] and report["consistently_oriented"] and report["usable"]
    assert report["triangles"] == 4 and report["edges"] == 6 and report["components"] == 1
    # The tetrahedron (0, e_x, e_y, e_z) has volume 1/6 (analytic).
    assert report["signed_volume"] == pytest.approx(1 / 6, rel=1e-12)
    again = pickle.loads(pickle.dumps(mesh))
    np.testing.assert_array_equal(again.vertices, mesh.vertices)
    np.testing.assert_array_equal(again.faces, mesh.faces)


def test_open_mesh_is_reported_and_has_no_volume():
    mesh = clod.Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    report = mesh.inspect()
    assert not report["closed"] and report["boundary_edges"] == 3 and report["signed_volume"] is None
    assert any("open" in issue["message"] for issue in report["issues"])
    with pytest.raises(clod.Error) as e:
        mesh.mass_properties()
    assert e.value.code_name == "unsupported_mesh"
    # With the fallback: the (flat) bounding box has no volume either... so use a box-shaped open mesh:
    box = clod.Mesh.box([1, 2, 3])
    open_box = clod.Mesh(box.vertices, box.faces[:-1])
    props = open_box.mass_properties(density=2.0, bounding_box_fallback=True)
    assert props["volume"] == pytest.approx(48.0, rel=1e-12)


@pytest.mark.parametrize("half", [(0.5, 0.5, 0.5), (1.0, 2.0, 0.25)])
def test_mass_properties_of_a_box_are_analytic(half):
    a, b, c = half
    density = 3.0
    props = clod.Mesh.box(half).mass_properties(density=density)
    mass = density * 8 * a * b * c
    assert props["volume"] == pytest.approx(8 * a * b * c, rel=1e-12)
    assert props["mass"] == pytest.approx(mass, rel=1e-12)
    np.testing.assert_allclose(props["center_of_mass"], 0.0, atol=1e-12 * max(half))
    # Solid cuboid of side lengths 2a, 2b, 2c: I_xx = m (b^2 + c^2) / 3, etc.
    expected = np.diag([mass * (b * b + c * c) / 3, mass * (a * a + c * c) / 3, mass * (a * a + b * b) / 3])
    np.testing.assert_allclose(props["inertia"], expected, rtol=0, atol=1e-12 * expected.max())


def test_closest_on_a_box_matches_the_analytic_signed_distance():
    half = np.array([1.0, 2.0, 0.5])
    mesh = clod.Mesh.box(half)
    rng = np.random.default_rng(1)
    points = rng.uniform(-3, 3, size=(2000, 3))
    r = mesh.closest(points)
    assert r.sign_method == "pseudonormal" and len(r) == 2000
    # Exact in double precision on both sides: rounding of a few ulps of the coordinates (~1e-15 of
    # the diagonal); 1e-12 of the diagonal leaves room and still catches any wrong feature.
    tol = 1e-12 * np.linalg.norm(2 * half)
    np.testing.assert_allclose(r.signed_distance, box_signed_distance(points, half), atol=tol, rtol=0)
    np.testing.assert_allclose(r.distance, np.abs(r.signed_distance), atol=tol, rtol=0)
    np.testing.assert_allclose(np.linalg.norm(points - r.point, axis=1), r.distance, atol=tol, rtol=0)
    # Closest points lie on the box's surface: some coordinate at +-half, none beyond.
    assert np.all(np.abs(r.point) <= half + tol)
    assert np.all(np.min(np.abs(np.abs(r.point) - half), axis=1) <= tol)
    # Outside points whose nearest feature is a face: the normal is that face's axis.
    faces = r.feature_type == clod.FEATURE_FACE
    np.testing.assert_allclose(np.abs(r.normal[faces]).max(axis=1), 1.0, atol=1e-12)


def test_closest_on_bunny_matches_numpy_brute_force(mesh_dir):
    mesh = clod.Mesh.load(str(mesh_dir / "bunny-1500.obj"))
    v, f = mesh.vertices, mesh.faces.astype(np.int64)
    lo, hi = mesh.bounds
    rng = np.random.default_rng(7)
    points = rng.uniform(lo - 0.2 * (hi - lo), hi + 0.2 * (hi - lo), size=(200, 3))
    r = mesh.closest(points)
    expected = brute_force_distance(points, v, f)
    # Both are exact minima over the triangles in double precision, computed differently; the
    # differences are rounding (~1e-16 of the diagonal per operation). 1e-10 of the diagonal.
    tol = 1e-10 * mesh.diagonal
    np.testing.assert_allclose(r.distance, expected, atol=tol, rtol=0)
    # The reported point is on the surface (brute-force distance ~0) and at the reported distance.
    np.testing.assert_allclose(brute_force_distance(r.point, v, f), 0.0, atol=tol)
    # Features: a vertex feature's point is that vertex; a face feature's point is in that triangle's plane.
    vert = r.feature_type == clod.FEATURE_VERTEX
    np.testing.assert_allclose(r.point[vert], v[r.feature_index[vert]], atol=tol)
    face = r.feature_type == clod.FEATURE_FACE
    tri = f[r.feature_index[face]]
    n = np.cross(v[tri[:, 1]] - v[tri[:, 0]], v[tri[:, 2]] - v[tri[:, 0]])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    np.testing.assert_allclose(np.einsum("ij,ij->i", r.point[face] - v[tri[:, 0]], n), 0.0, atol=tol)
    # An edge feature's point lies on the segment of that edge of the edge table.
    edge = r.feature_type == clod.FEATURE_EDGE
    e = mesh.edges[r.feature_index[edge]].astype(np.int64)
    a, b = v[e[:, 0]], v[e[:, 1]]
    t = np.clip(np.einsum("ij,ij->i", r.point[edge] - a, b - a) / np.einsum("ij,ij->i", b - a, b - a), 0, 1)
    np.testing.assert_allclose(a + t[:, None] * (b - a), r.point[edge], atol=tol)
    # Open mesh (bunny-1500 has holes): winding-number signs; points outside the bounding box are
    # outside the mesh whatever its holes, so their signed distance is +distance.
    assert r.sign_method == "winding_number"
    outside = np.any((points < lo) | (points > hi), axis=1)
    assert outside.sum() > 50
    np.testing.assert_array_equal(r.signed_distance[outside], r.distance[outside])


def test_mesh_load_reads_an_obj_and_reports_missing_files(tmp_path):
    box = clod.Mesh.box([1, 1, 1])
    path = write_obj(tmp_path / "box.obj", box.vertices, box.faces)
    loaded = clod.Mesh.load(str(path))
    assert loaded.triangle_count == 12 and loaded.inspect()["closed"]
    with pytest.raises(clod.FileError) as e:
        clod.Mesh.load(str(tmp_path / "missing.obj"))
    assert e.value.code_name == "file_not_found" and e.value.code == clod.error_codes["file_not_found"]
    assert isinstance(e.value, OSError) and "missing.obj" in str(e.value)
    (tmp_path / "junk.obj").write_text("v 0 0 zero\nf 1 2 3\n")
    with pytest.raises(clod.Error):
        clod.Mesh.load(str(tmp_path / "junk.obj"))


BAD_POINTS = [
    (np.zeros((5, 2)), "expected shape (N, 3), got (5, 2)"),
    (np.zeros(3), "expected shape (N, 3), got (3,)"),
    (np.zeros((2, 3), dtype=np.complex128), "dtype complex128"),
    (np.array([["a", "b", "c"]]), "dtype <U1"),
    (np.zeros((2, 3), dtype=bool), "dtype bool"),
    (np.array([[0.0, 0.0, np.nan]]), "points[0] = (0, 0, nan) is not finite"),
    (np.array([[0.0, 0.0, 0.0], [np.inf, 0.0, 0.0]]), "points[1] = (inf, 0, 0) is not finite"),
    (np.array([[1e200, 0.0, 0.0]]), "out of range"),
    (None, "got None"),
    (object(), "expected an array of real numbers"),
]


@pytest.mark.parametrize("points,message", BAD_POINTS)
def test_bad_points_are_refused_with_a_clear_message(points, message):
    mesh = clod.Mesh.box([1, 1, 1])
    with pytest.raises(clod.InvalidArgumentError) as e:
        mesh.closest(points)
    assert message in str(e.value)
    assert e.value.code == clod.error_codes["invalid_argument"] and isinstance(e.value, ValueError)


def test_bad_meshes_raise_their_error_codes():
    tri = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]
    cases = [
        (([[0, 0, 0], [1, 0, np.nan], [0, 1, 0]], [[0, 1, 2]]), "non_finite_vertex"),
        ((tri, [[0, 1, 3]]), "index_out_of_range"),
        ((tri, [[0, 1, -1]]), "index_out_of_range"),
        ((tri, np.zeros((0, 3), dtype=int)), "no_triangles"),
        (([[0, 0, 0], [1, 0, 0], [2, 0, 0]], [[0, 1, 2]]), "all_triangles_degenerate"),
        ((tri, [[0.0, 1.0, 2.0]]), "invalid_argument"),
        ((np.zeros((3, 2)), [[0, 1, 2]]), "invalid_argument"),
        ((tri, [[0, 1]]), "invalid_argument"),
    ]
    for (v, f), code in cases:
        with pytest.raises(clod.Error) as e:
            clod.Mesh(v, f)
        assert e.value.code_name == code, (v, f, str(e.value))
