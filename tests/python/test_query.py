"""clod.bake / clod.Bake / clod.query / clod.query_batch against analytic contacts."""

import pickle

import numpy as np
import pytest

import clod
from conftest import brute_force_distance

IDENTITY = np.array([0, 0, 0, 1, 0, 0, 0], dtype=np.float64)


def quat_to_matrix(pose7):
    """4x4 matrix of a (tx ty tz qw qx qy qz) pose (the textbook formula, unit quaternion)."""
    t, (w, x, y, z) = pose7[:3], pose7[3:] / np.linalg.norm(pose7[3:])
    r = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                  [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                  [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    m = np.eye(4)
    m[:3, :3], m[:3, 3] = r, t
    return m


@pytest.fixture(scope="module")
def sphere_bake():
    """Unit icosphere (1,280 triangles), octree sphere-tree 4 levels deep: a real traversal."""
    return clod.bake(clod.Mesh.icosphere(1.0, 3), sphere_tree="octree", levels=4, sdf_depth=6, measure_fit=False)


def test_bake_saves_loads_and_pickles_to_identical_bytes(box_bake, tmp_path):
    path = tmp_path / "box.clod"
    written = box_bake.save(str(path))
    assert written == path.stat().st_size
    loaded = clod.Bake.load(str(path))
    assert loaded.to_bytes() == path.read_bytes() == box_bake.to_bytes()
    assert loaded.mesh_hash == box_bake.mesh_hash and loaded.report() is None
    assert loaded.has_closest_feature_map and loaded.has_contact_tree and loaded.level_count == 3
    assert pickle.loads(pickle.dumps(box_bake)).to_bytes() == box_bake.to_bytes()
    np.testing.assert_array_equal(loaded.mesh.vertices, box_bake.mesh.vertices)
    centers, radii = loaded.spheres(0)
    # The root sphere bounds the box: every corner within the radius (the root may be any bounding sphere).
    assert np.all(np.linalg.norm(loaded.mesh.vertices - centers[0], axis=1) <= radii[0] * (1 + 1e-12))


def test_corrupt_and_truncated_bakes_raise_their_codes(box_bake, tmp_path):
    data = bytearray(box_bake.to_bytes())
    with pytest.raises(clod.Error) as e:
        clod.Bake.from_bytes(bytes(data[: len(data) // 2]))
    assert e.value.code_name in ("bake_truncated", "bake_corrupt")
    data[len(data) // 2] ^= 0xFF
    with pytest.raises(clod.Error) as e:
        clod.Bake.from_bytes(bytes(data))
    assert e.value.code_name == "bake_corrupt"
    (tmp_path / "zero.clod").write_bytes(b"")
    with pytest.raises(clod.FileError) as e:
        clod.Bake.load(str(tmp_path / "zero.clod"))
    assert e.value.code_name == "empty_file"


def test_bake_options_are_checked():
    mesh = clod.Mesh.box([1, 1, 1])
    for kwargs in ({"sphere_tree": "kd"}, {"branching": 1}, {"levels": 9}, {"sdf_error": -1.0}, {"sampling": "x"}):
        with pytest.raises(clod.InvalidArgumentError):
            clod.bake(mesh, **kwargs)


@pytest.mark.parametrize("model", ["cfm", "exact", "contact-tree"])
def test_overlapping_boxes_give_the_analytic_contact(box_bake, model):
    # B (unit box) above A, overlapping by d = 0.05 along z and shifted by (0.3, 0.2): the contact
    # region is the rectangle x in [-0.2, 0.5], y in [-0.3, 0.5] between z = 0.45 and z = 0.5, the
    # normal from B toward A is -z and the penetration depth is 0.05.
    res = clod.query(box_bake, IDENTITY, box_bake, [0.3, 0.2, 0.95, 1, 0, 0, 0], model=model)
    assert res.colliding and res.finished and res.stop == "finished" and len(res) >= 3
    assert res.pos.shape == (len(res), 3) and res.normal.shape == (len(res), 3)
    # cfm and exact are exact for box pairs (1e-9 of the diagonal for rounding); the contact tree's
    # depths are exact to its error bound (the error_bound column), and its points are samples spread
    # over the frontier cells, which reach past the region's rim by up to a cell (1/32 of the root
    # cube at sdf_depth 5: about 0.035 m here).
    tol = 1e-9 * box_bake.diagonal + res.error_bound.max()
    rim = 0.035 if model == "contact-tree" else 0.0
    # The contact tree stores its distances on a grid of at most 1/8 of its error bound
    # (docs/contact-tree.md), so a face's field gradient may tilt by a step over a cell: measured
    # 1.7e-5 rad here (1e-3 of the diagonal / 8 over a 1/32 cell bounds it by ~1e-4).
    np.testing.assert_allclose(res.normal[0], [0, 0, -1], atol=1e-4 if model == "contact-tree" else 1e-9)
    assert res.penetration_depth[0] == pytest.approx(0.05, abs=tol)
    assert np.all(res.penetration_depth <= 0.05 + tol)
    lo, hi = np.array([-0.2, -0.3, 0.45]), np.array([0.5, 0.5, 0.5])
    assert np.all(res.pos >= lo - tol - rim) and np.all(res.pos <= hi + tol + rim)
    # Well spread over the region: the manifold spans most of the rectangle.
    span = res.pos.max(axis=0) - res.pos.min(axis=0)
    assert span[0] > 0.5 * 0.7 and span[1] > 0.5 * 0.8


def test_separated_boxes_give_no_contacts(box_bake):
    res = clod.query(box_bake, IDENTITY, box_bake, [3, 0, 0, 1, 0, 0, 0], model="cfm")
    assert not res.colliding and len(res) == 0 and res.pos.shape == (0, 3)


@pytest.mark.parametrize("model", ["cfm", "contact-tree", "exact"])
def test_margin_gives_boxes_apart_their_gap_as_a_speculative_contact(box_bake, model):
    """Two 1 m boxes 0.03 apart face to face: with margin 0.05 one contact at depth -0.03 (the
    analytic gap), normal from B toward A, its points on the two faces; margin 0.02: none."""
    pose_b = np.array([0.2, 0.1, 1.03, 1, 0, 0, 0], dtype=np.float64)
    res = clod.query(box_bake, IDENTITY, box_bake, pose_b, model=model, margin=0.05)
    assert len(res.penetration_depth) == 1 and not res.colliding
    assert res.penetration_depth[0] == pytest.approx(-0.03, abs=1e-9)
    np.testing.assert_allclose(res.normal[0], [0, 0, -1], atol=1e-9)
    assert res.point_on_a[0][2] == pytest.approx(0.5, abs=1e-9) and res.point_on_b[0][2] == pytest.approx(0.53, abs=1e-9)
    assert len(clod.query(box_bake, IDENTITY, box_bake, pose_b, model=model, margin=0.02).penetration_depth) == 0
    with pytest.raises(clod.InvalidArgumentError):
        clod.query(box_bake, IDENTITY, box_bake, pose_b, model=model, margin=-1.0)


def test_spheres_give_the_centre_line_normal_and_depth(sphere_bake):
    # Two unit spheres 1.9 apart along a tilted axis: they penetrate by 0.1 along the centre line and
    # their surfaces cross on the circle of radius sqrt(1 - 0.95^2) in the plane 0.95 along the axis.
    # The icosphere's faces lie between radius cos(theta) and 1 (theta < 4.6 degrees, the angular
    # circumradius of a face at 3 subdivisions), i.e. up to 0.0033 inside the sphere: 0.007 for two.
    axis = np.array([1.0, 2.0, 2.0]) / 3.0
    pose_b = np.r_[1.9 * axis, 1, 0, 0, 0]
    exact = clod.query(sphere_bake, IDENTITY, sphere_bake, pose_b, model="exact")
    assert exact.finished and len(exact) >= 3
    np.testing.assert_allclose(exact.normal @ -axis, 1.0, atol=0.01)
    # Exact contacts are the vertices of each sphere inside the other (a convex polyhedron:
    # docs/narrow-phase.md, "exact"), their two points where the normal line leaves each surface
    # (NumPy brute force), their point midway: on the lens's middle plane.
    mesh = sphere_bake.mesh
    faces = mesh.faces.astype(np.int64)
    tol = 1e-9 * sphere_bake.diagonal
    np.testing.assert_allclose(brute_force_distance(exact.point_on_a, mesh.vertices, faces), 0.0, atol=tol)
    np.testing.assert_allclose(brute_force_distance(exact.point_on_b - 1.9 * axis, mesh.vertices, faces), 0.0, atol=tol)
    np.testing.assert_allclose(exact.pos @ axis, 0.95, atol=0.007)
    # Each depth is the run of its normal line inside both spheres (the analytic chords'
    # overlap), to the faces' sag inside the sphere (0.007 for two).
    for point, normal, depth in zip(exact.pos, exact.normal, exact.penetration_depth):
        runs = []
        for centre in (np.zeros(3), 1.9 * axis):
            b = normal @ (point - centre)
            half = np.sqrt(max(0.0, b * b - ((point - centre) @ (point - centre) - 1.0)))
            runs.append((-b - half, -b + half))
        overlap = min(runs[0][1], runs[1][1]) - max(runs[0][0], runs[1][0])
        assert abs(depth - overlap) <= 0.007, (depth, overlap)
    # The contact tree's deepest contact is the penetration depth to its error bound.
    tree = clod.query(sphere_bake, IDENTITY, sphere_bake, pose_b, model="contact-tree")
    deepest = np.argmax(tree.penetration_depth)
    assert abs(tree.penetration_depth[deepest] - 0.1) <= 0.007 + tree.error_bound[deepest]


def test_budgets_bound_the_tests_and_refine_monotonically(sphere_bake):
    pose_b = [1.9, 0.1, 0.05, 1, 0, 0, 0]
    previous_level = -1
    for budget in (1, 4, 16, 64, 256, 4096):
        res = clod.query(sphere_bake, IDENTITY, sphere_bake, pose_b, model="cfm", budget=budget)
        assert res.budget_used <= budget
        assert res.finished == (res.stop == "finished")
        assert res.max_level >= previous_level
        previous_level = res.max_level
        assert res.colliding and np.all(res.level <= res.max_level)
    unlimited = clod.query(sphere_bake, IDENTITY, sphere_bake, pose_b, model="cfm")
    assert unlimited.finished and unlimited.max_level == sphere_bake.level_count - 1
    small = clod.query(sphere_bake, IDENTITY, sphere_bake, pose_b, model="cfm", budget=1)
    assert not small.finished and small.stop == "test_budget"
    # A deadline already passed: at most one batch of tests (kDeadlineBatch = 32, budget.h).
    late = clod.query(sphere_bake, IDENTITY, sphere_bake, pose_b, model="exact", deadline_us=0)
    assert late.budget_used <= 32


def test_query_batch_equals_single_queries(sphere_bake):
    rng = np.random.default_rng(3)
    count = 40
    poses_b = np.zeros((count, 7))
    poses_b[:, :3] = rng.normal(size=(count, 3))
    poses_b[:, :3] *= (1.7 + 0.4 * rng.random(count))[:, None] / np.linalg.norm(poses_b[:, :3], axis=1, keepdims=True)
    poses_b[:, 3:] = rng.normal(size=(count, 4))
    batch = clod.query_batch(sphere_bake, IDENTITY, sphere_bake, poses_b, model="cfm", budget=64)
    assert len(batch) == count and batch.offsets[0] == 0 and batch.offsets[-1] == len(batch.pos)
    for i in range(count):
        one = clod.query(sphere_bake, IDENTITY, sphere_bake, poses_b[i], model="cfm", budget=64)
        rows = slice(batch.offsets[i], batch.offsets[i + 1])
        np.testing.assert_array_equal(batch.pos[rows], one.pos)
        np.testing.assert_array_equal(batch.normal[rows], one.normal)
        np.testing.assert_array_equal(batch.penetration_depth[rows], one.penetration_depth)
        np.testing.assert_array_equal(batch.level[rows], one.level)
        np.testing.assert_array_equal(batch.error_bound[rows], one.error_bound)
        assert batch.budget_used[i] == one.budget_used and batch.finished[i] == one.finished


def test_matrix_and_quaternion_poses_agree(sphere_bake):
    pose7 = np.array([1.2, 0.9, 0.3, 0.9, 0.1, -0.3, 0.2])
    a = clod.query(sphere_bake, IDENTITY, sphere_bake, pose7, model="exact")
    b = clod.query(sphere_bake, np.eye(4), sphere_bake, quat_to_matrix(pose7), model="exact")
    assert len(a) == len(b)
    # The matrix goes back to a quaternion: the same pose up to rounding (1e-12 of the diagonal).
    np.testing.assert_allclose(a.pos, b.pos, atol=1e-12 * sphere_bake.diagonal)


def test_quaternions_of_any_finite_nonzero_magnitude_are_their_rotation(sphere_bake):
    # (0.9e200, 0.1e200, ...) overflowed the norm and was refused: it is the unit pose's rotation.
    unit = np.array([1.2, 0.9, 0.3, 0.9, 0.1, -0.3, 0.2])
    for scale in (1e200, 1e-200):
        scaled = np.concatenate([unit[:3], unit[3:] * scale])
        a = clod.query(sphere_bake, IDENTITY, sphere_bake, unit, model="exact")
        b = clod.query(sphere_bake, IDENTITY, sphere_bake, scaled, model="exact")
        assert len(a) == len(b) > 0
        # The scaled decimals round differently: the same rotation to a few ulps (1e-12 of the diagonal).
        np.testing.assert_allclose(a.pos, b.pos, atol=1e-12 * sphere_bake.diagonal)


def test_bad_query_arguments_are_refused(box_bake):
    no_cfm = clod.bake(clod.Mesh.box([1, 1, 1]), sphere_tree="octree", levels=1, closest_feature_map=False,
                       contact_tree=False, measure_fit=False)
    with pytest.raises(clod.Error) as e:
        clod.query(no_cfm, IDENTITY, box_bake, IDENTITY, model="cfm")
    assert e.value.code_name == "bake_missing_section"
    bad = [
        dict(pose_a=[0, 0, 0, 0, 0, 0, 0]),                       # zero quaternion
        dict(pose_a=[0, 0, 0, 1, 0, 0]),                          # 6 numbers
        dict(pose_a=np.diag([1.0, 2.0, 1.0, 1.0])),               # not a rotation
        dict(pose_a=[np.nan, 0, 0, 1, 0, 0, 0]),                  # NaN
        dict(model="best"),
        dict(budget=0),
        dict(deadline_us=-1.0),
        dict(max_contacts=0),
    ]
    for kwargs in bad:
        args = dict(pose_a=IDENTITY, pose_b=IDENTITY)
        args.update({k: v for k, v in kwargs.items() if k.startswith("pose")})
        options = {k: v for k, v in kwargs.items() if not k.startswith("pose")}
        with pytest.raises(clod.InvalidArgumentError):
            clod.query(box_bake, args["pose_a"], box_bake, args["pose_b"], **options)
    with pytest.raises(clod.InvalidArgumentError, match="same count"):
        clod.query_batch(box_bake, np.tile(IDENTITY, (3, 1)), box_bake, np.tile(IDENTITY, (2, 1)))
