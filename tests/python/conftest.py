"""Shared fixtures of the Python tests (tests/python; ctest runs them as python/pytest).

The package under test is the one on sys.path: the build tree's (PYTHONPATH=build/python, as ctest
sets it) or an installed one. Oracles are independent of clod: NumPy brute force and analytic
answers (boxes, free fall), never clod checking itself.
"""

import os
import pathlib

import numpy as np
import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("CLOD_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
MESH_DIR = pathlib.Path(os.environ.get("CLOD_SHARED_MESH_DIR", SOURCE_DIR.parent / "shared" / "data" / "meshes"))


@pytest.fixture(scope="session")
def source_dir():
    return SOURCE_DIR


@pytest.fixture(scope="session")
def mesh_dir():
    if not (MESH_DIR / "bunny-1500.obj").is_file():
        pytest.skip(f"shared meshes not found in {MESH_DIR} (set CLOD_SHARED_MESH_DIR)")
    return MESH_DIR


@pytest.fixture(scope="session")
def box_bake():
    """A 1 m box (half extents 0.5), baked small: octree, 2 levels, shallow contact tree."""
    import clod

    return clod.bake(clod.Mesh.box([0.5, 0.5, 0.5]), sphere_tree="octree", levels=2, sdf_depth=5, measure_fit=False)


def write_obj(path, vertices, faces):
    """A Wavefront OBJ file of a mesh (1-based indices), written with NumPy only."""
    with open(path, "w") as f:
        for v in vertices:
            f.write("v %.17g %.17g %.17g\n" % tuple(v))
        for t in faces:
            f.write("f %d %d %d\n" % tuple(np.asarray(t) + 1))
    return path


def brute_force_distance(points, vertices, faces):
    """Unsigned distance from each point to a triangle mesh, brute force over every triangle.

    Per triangle: the distance to its plane where the projection falls inside the triangle (the
    signs of the three edge cross products agree with the normal), else the smallest distance to
    its three sides (clamped segment projection). A different construction from clod's Voronoi
    region walk, so agreement is a real check.
    """
    p = np.asarray(points, dtype=np.float64)[:, None, :]          # (K, 1, 3)
    a, b, c = (vertices[faces[:, k]][None, :, :] for k in range(3))  # (1, T, 3)
    n = np.cross(b - a, c - a)
    n_len = np.linalg.norm(n, axis=-1, keepdims=True)
    n_hat = np.divide(n, n_len, out=np.zeros_like(n), where=n_len > 0)
    plane = np.einsum("ktj,ktj->kt", p - a, np.broadcast_to(n_hat, (p.shape[0],) + n_hat.shape[1:]))
    q = p - plane[..., None] * n_hat
    inside = np.ones(plane.shape, dtype=bool)
    for u, v in ((a, b), (b, c), (c, a)):
        inside &= np.einsum("ktj,ktj->kt", np.cross(v - u, q - u), np.broadcast_to(n, q.shape)) >= 0
    inside &= (n_len[..., 0] > 0)
    best = np.where(inside, np.abs(plane), np.inf)
    for u, v in ((a, b), (b, c), (c, a)):
        d = v - u
        t = np.clip(np.einsum("ktj,ktj->kt", p - u, np.broadcast_to(d, q.shape))
                    / np.maximum(np.einsum("ktj,ktj->kt", d, d), 1e-300), 0.0, 1.0)
        best = np.minimum(best, np.linalg.norm(p - (u + t[..., None] * d), axis=-1))
    return best.min(axis=1)


def box_signed_distance(points, half):
    """Exact signed distance to an axis-aligned box centred at the origin (negative inside)."""
    q = np.abs(points) - np.asarray(half)
    outside = np.linalg.norm(np.maximum(q, 0.0), axis=1)
    inside = np.minimum(q.max(axis=1), 0.0)
    return outside + inside
