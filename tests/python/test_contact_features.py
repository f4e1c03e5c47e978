"""Contacts' feature ids and both points (contact.h Contact::featureKind / featureA / featureB,
contactPointOnA / B) through clod.query, clod.query_batch, StepReport and the contact callback.
Oracles: NumPy brute force over the named triangles and spheres, and box faces placed analytically."""

import math

import numpy as np
import pytest

import clod
from conftest import brute_force_distance

# Pose of A: 0.9 above B along z, turned 0.4 rad about z and shifted in x, y -- overlapping by 0.1
# for two unit boxes. Turning makes the contact polygon an octagon-like clip, not a copy of a face.
POSE_A = [0.05, 0.1, 0.9, math.cos(0.2), 0.0, 0.0, math.sin(0.2)]
POSE_B = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]


def rotate(q, points):
    """Rotates points by the unit quaternion q = (w, x, y, z) (NumPy, independent of clod)."""
    w, u = q[0], np.asarray(q[1:])
    p = np.asarray(points, dtype=np.float64)
    t = 2.0 * np.cross(u, p)
    return p + w * t + np.cross(u, t)


def world_vertices(mesh, pose):
    return rotate(pose[3:], np.asarray(mesh.vertices)) + np.asarray(pose[:3])


@pytest.fixture(scope="module")
def box():
    return clod.bake(clod.Mesh.box([0.5, 0.5, 0.5]), sphere_tree="octree", levels=3, sdf_depth=5, measure_fit=False)


@pytest.fixture(scope="module")
def ball():
    # Curved and closed (320 triangles): the exact model answers it with triangle-pair contacts,
    # where two convex boxes get the separating-axis answer between the root spheres.
    return clod.bake(clod.Mesh.icosphere(0.5, 2), sphere_tree="octree", levels=3, sdf_depth=5, measure_fit=False)


def test_the_feature_constants_are_the_headers_values():
    assert (clod.CONTACT_FEATURE_NONE, clod.CONTACT_FEATURE_TRIANGLE, clod.CONTACT_FEATURE_SPHERE,
            clod.CONTACT_FEATURE_CELL) == (0, 1, 2, 3)
    assert clod.NO_CONTACT_FEATURE == 0xFFFFFFFF


def test_exact_contacts_lie_on_the_triangles_they_name(ball):
    mesh = ball.mesh
    faces = np.asarray(mesh.faces)
    result = clod.query(ball, POSE_A, ball, POSE_B, model="exact")
    assert result.finished and len(result) > 0
    assert result.feature_kind.dtype == np.uint8 and result.feature_a.dtype == np.uint32
    assert np.all(result.feature_kind == clod.CONTACT_FEATURE_TRIANGLE)
    assert np.all(result.feature_a < len(faces)) and np.all(result.feature_b < len(faces))
    va, vb = world_vertices(mesh, POSE_A), world_vertices(mesh, POSE_B)
    # A vertex inside the other ball (the ball is a convex polyhedron: docs/narrow-phase.md,
    # "exact") has its point on A on A's named triangle and its point on B on B's; a point on the
    # intersection curve lies on both. Computed in double precision: 1e-9 of the diagonal (1.0)
    # is far above rounding and far below a neighbouring triangle's distance (the 320-triangle
    # sphere's edges are ~0.1 long).
    tolerance = 1e-9 * ball.diagonal
    vertices = 0
    for i, point in enumerate(result.pos):
        ta, tb = faces[result.feature_a[i]][None], faces[result.feature_b[i]][None]
        on_curve = (brute_force_distance(point[None], va, ta)[0] < tolerance and
                    brute_force_distance(point[None], vb, tb)[0] < tolerance)
        on_surfaces = (brute_force_distance(result.point_on_a[i][None], va, ta)[0] < tolerance and
                       brute_force_distance(result.point_on_b[i][None], vb, tb)[0] < tolerance)
        assert on_curve or on_surfaces, i
        vertices += on_surfaces and not on_curve
    assert vertices > 0
    # Control: the same points are not on arbitrary triangles (the check can fail).
    shifted = (result.feature_a.astype(np.int64) + len(faces) // 2) % len(faces)
    far = [brute_force_distance(p[None], va, faces[t][None])[0] for p, t in zip(result.point_on_a, shifted)]
    assert max(far) > 100 * tolerance


@pytest.mark.parametrize("model", ["cfm", "exact"])
def test_face_corners_of_two_boxes_give_each_boxs_surface_point(box, model):
    # A's bottom face is at z = 0.4, B's top face at z = 0.5 (analytic): depth 0.1, normal +z
    # (from B toward A), point_on_a on A's bottom, point_on_b on B's top. Brute force over the
    # placed boxes' 12 triangles says the points are on the surfaces.
    result = clod.query(box, POSE_A, box, POSE_B, model=model)
    corners = result.error_bound == 0.0
    assert result.finished and np.count_nonzero(corners) >= 3
    faces = np.asarray(box.mesh.faces)
    va, vb = world_vertices(box.mesh, POSE_A), world_vertices(box.mesh, POSE_B)
    on_a, on_b = result.point_on_a[corners], result.point_on_b[corners]
    # 1e-9 of the diagonal: exact face clipping in double precision, nothing approximated.
    tolerance = 1e-9 * box.diagonal
    np.testing.assert_allclose(on_a[:, 2], 0.4, atol=tolerance)
    np.testing.assert_allclose(on_b[:, 2], 0.5, atol=tolerance)
    np.testing.assert_allclose(result.normal[corners], np.tile([0.0, 0.0, 1.0], (len(on_a), 1)), atol=1e-9)
    assert np.all(brute_force_distance(on_a, va, faces) < tolerance)
    assert np.all(brute_force_distance(on_b, vb, faces) < tolerance)
    assert np.all(result.feature_kind[corners] == clod.CONTACT_FEATURE_SPHERE)


@pytest.mark.parametrize("model", ["dos", "average"])
def test_sphere_model_contacts_lie_in_the_spheres_they_name(ball, model):
    # contact.h: a sphere-pair contact's point lies within both named spheres grown by the
    # contact's depth and error bound. The spheres come from the bake (Bake.spheres, breadth-first
    # indices), placed with NumPy.
    result = clod.query(ball, POSE_A, ball, POSE_B, model=model)
    assert len(result) > 0 and np.all(result.feature_kind == clod.CONTACT_FEATURE_SPHERE)
    centers, radii = ball.spheres()
    assert np.all(result.feature_a < len(radii)) and np.all(result.feature_b < len(radii))
    grow = result.penetration_depth + result.error_bound
    # 1e-12 of the diagonal: only the rounding of the placed centres.
    slack = 1e-12 * ball.diagonal
    for side, pose in (("a", POSE_A), ("b", POSE_B)):
        index = getattr(result, "feature_" + side)
        placed = rotate(pose[3:], centers[index]) + np.asarray(pose[:3])
        gap = np.linalg.norm(result.pos - placed, axis=1) - radii[index]
        assert np.all(gap <= grow + slack), (side, gap - grow)
    # Control: the root sphere's children are not all within reach of every contact point.
    assert len(radii) > 9


def test_every_model_says_what_its_features_index(ball):
    expected = {"dos": clod.CONTACT_FEATURE_SPHERE, "average": clod.CONTACT_FEATURE_SPHERE,
                "cfm": clod.CONTACT_FEATURE_SPHERE, "contact-tree": clod.CONTACT_FEATURE_CELL,
                "exact": clod.CONTACT_FEATURE_TRIANGLE}  # docs/narrow-phase.md, "Feature ids"
    assert sorted(expected) == sorted(clod.contact_models)
    for model, kind in expected.items():
        result = clod.query(ball, POSE_A, ball, POSE_B, model=model)
        assert len(result) > 0 and np.all(result.feature_kind == kind), model
        assert np.all(result.feature_a != clod.NO_CONTACT_FEATURE) and np.all(result.feature_b != clod.NO_CONTACT_FEATURE)
        assert result.point_on_a.shape == result.pos.shape == result.point_on_b.shape


def test_batch_rows_carry_the_same_features_as_single_queries(ball):
    lifts = [0.85, 0.9, 0.95]
    poses_a = np.array([[0.05, 0.1, z] + POSE_A[3:] for z in lifts])
    batch = clod.query_batch(ball, poses_a, ball, POSE_B, model="exact")
    for i, pose in enumerate(poses_a):
        single = clod.query(ball, pose, ball, POSE_B, model="exact")
        rows = slice(batch.offsets[i], batch.offsets[i + 1])
        for field in ("feature_kind", "feature_a", "feature_b", "point_on_a", "point_on_b"):
            np.testing.assert_array_equal(getattr(batch, field)[rows], getattr(single, field), err_msg=field)


def test_step_report_and_callback_give_features_of_a_resting_box(box):
    # A box resting on a static ground slab (top face z = 0), exact model: the ground is body a
    # (a < b), so point_on_a lies on z = 0 and point_on_b on the box's bottom face.
    ground = clod.bake(clod.Mesh.box([3.0, 3.0, 0.5]), sphere_tree="octree", levels=3, sdf_depth=5, measure_fit=False)
    world = clod.World(dt=1.0 / 60.0, model="exact")
    g = world.add_body(ground, type="static", position=[0, 0, -0.5])
    b = world.add_body(box, position=[0, 0, 0.5])
    for _ in range(30):
        world.step()
    seen = []
    world.set_contact_callback(lambda a, b_, pos, normal, depth, substep, features: seen.append((a, b_, features)) or True,
                               features=True)
    before = world.positions[b].copy()
    report = world.step()
    features = report.contact_features
    assert len(report.contact_pos) > 0 and np.all(report.contact_bodies == [g, b])
    assert np.all(features["feature_kind"] == clod.CONTACT_FEATURE_SPHERE)
    # Ground top exactly (static, exact face clipping: 1e-9 of the ground's diagonal); the box's
    # bottom where the box was at the step's start, within the step's motion at rest (1e-6 m).
    np.testing.assert_allclose(features["point_on_a"][:, 2], 0.0, atol=1e-9 * ground.diagonal)
    np.testing.assert_allclose(features["point_on_b"][:, 2], before[2] - 0.5, atol=1e-6)
    # The callback saw the same substep's contacts, with the same features.
    a_id, b_id, last = seen[-1]
    assert (a_id, b_id) == (g, b)
    for field in ("feature_kind", "feature_a", "feature_b", "point_on_a", "point_on_b"):
        np.testing.assert_array_equal(last[field], features[field], err_msg=field)
    world.set_contact_callback(None)
