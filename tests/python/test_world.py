"""clod.World: built in code and from scene files, against analytic motion."""

import json

import numpy as np
import pytest

import clod

G = 9.81
DT = 1.0 / 60.0


@pytest.fixture(scope="module")
def ground_and_box():
    ground = clod.bake(clod.Mesh.box([3.0, 3.0, 0.5]), sphere_tree="octree", levels=3, sdf_depth=5, measure_fit=False)
    box = clod.bake(clod.Mesh.box([0.5, 0.5, 0.5]), sphere_tree="octree", levels=3, sdf_depth=5, measure_fit=False)
    return ground, box


def make_world(ground, box, height, **settings):
    world = clod.World(dt=DT, **settings)
    world.add_body(ground, type="static", position=[0, 0, -0.5], name="ground")  # top face at z = 0
    world.add_body(box, position=[0, 0, height], density=500.0, name="box")
    return world


def test_free_fall_follows_semi_implicit_euler_exactly(ground_and_box):
    # Far from the ground there is one substep per step, so after k steps of semi-implicit Euler
    # (v += g dt, then x += v dt): z_k = z_0 - g dt^2 k (k + 1) / 2, exactly up to rounding.
    world = make_world(*ground_and_box, height=5.0)
    assert world.body_count == 2 and world.names == ["ground", "box"] and world.types == ["static", "dynamic"]
    np.testing.assert_allclose(world.masses, [0.0, 500.0], rtol=1e-12)
    steps = 20
    run = world.run(steps)
    assert run["positions"].shape == (steps, 2, 3) and run["orientations"].shape == (steps, 2, 4)
    k = np.arange(1, steps + 1)
    expected = 5.0 - G * DT * DT * k * (k + 1) / 2
    np.testing.assert_allclose(run["positions"][:, 1, 2], expected, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(run["positions"][:, 0], np.tile([0, 0, -0.5], (steps, 1)))
    np.testing.assert_allclose(world.velocities[1], [0, 0, -G * DT * steps], atol=1e-12)
    np.testing.assert_array_equal(world.positions, run["positions"][-1])
    assert np.all(run["tests_spent"] == 0) and np.all(run["substeps"] == 1)


def test_dropped_box_comes_to_rest_on_the_ground(ground_and_box):
    # Dropped from 0.2 m above the ground: at rest on it after 1.5 s, centre 0.5 above the top face
    # (within the solver's allowed penetration, slop 0.002 x the box diagonal = 3.5 mm), upright.
    world = make_world(*ground_and_box, height=0.7, model="cfm", budget=256)
    report = None
    for _ in range(90):
        report = world.step()
        assert report.budget_spent <= 256
    assert isinstance(report, clod.StepReport)
    assert abs(world.positions[1, 2] - 0.5) < 0.0035
    assert np.linalg.norm(world.velocities[1]) < 0.05
    np.testing.assert_allclose(np.abs(world.orientations[1, 0]), 1.0, atol=1e-3)
    # The contacts are between the box and the ground, at the ground's top, normal along z.
    assert report.contact_pos.shape[0] >= 3
    np.testing.assert_array_equal(np.sort(report.contact_bodies, axis=1), np.tile([0, 1], (len(report.contact_pos), 1)))
    np.testing.assert_allclose(report.contact_pos[:, 2], 0.0, atol=0.01)
    np.testing.assert_allclose(np.abs(report.contact_normal[:, 2]), 1.0, atol=1e-3)
    assert report.pairs["bodies"].tolist() == [[0, 1]]


def test_pair_report_says_when_a_resting_manifold_is_reused(ground_and_box):
    # A box resting on the ground at an unlimited budget: each finished answer is reused while the
    # bodies have not moved against each other by 0.1 % of the smaller diagonal (docs/dynamics.md,
    # "Manifold reuse"), so once it rests the pair is not queried (no tests) yet keeps contacts.
    world = make_world(*ground_and_box, height=0.5, model="cfm", budget=0)
    reports = [world.step() for _ in range(60)]
    last = reports[-1].pairs
    assert last["bodies"].tolist() == [[0, 1]]
    assert last["reused"].tolist() == [True] and last["tests"].tolist() == [0] and last["contacts"][0] >= 4
    assert last["proven_apart"].tolist() == [False] and last["kept_finer"].tolist() == [False]
    assert last["fallback_pairs"].tolist() == [0] and last["skipped"].tolist() == [False]
    # The first step queried it (nothing to reuse yet).
    assert reports[0].pairs["reused"].tolist() == [False] and reports[0].pairs["tests"][0] > 0


def test_scene_worlds_are_deterministic_and_overridable(source_dir):
    scene = str(source_dir / "scenes" / "stack_5.json")
    a = clod.World.from_scene(scene, model="cfm", budget=64)
    b = clod.World.from_scene(scene, model="cfm", budget=64)
    assert a.model == "cfm" and a.budget == 64 and a.dt == pytest.approx(1 / 60) and a.steps == 600
    assert a.body_count == 6 and a.names[0] == "ground"
    ra, rb = a.run(15), b.run(15)
    assert a.state_hash() == b.state_hash()
    np.testing.assert_array_equal(ra["positions"], rb["positions"])
    assert np.all(ra["budget_spent"] <= 64)
    # The stack stands: every box stays within 1 cm of where it started after 0.25 s.
    start = np.array([json_body["position"] for json_body in json.load(open(scene))["bodies"]])
    np.testing.assert_allclose(a.positions, start, atol=0.01)


def test_scene_and_world_errors_carry_codes(tmp_path):
    with pytest.raises(clod.FileError) as e:
        clod.World.from_scene(str(tmp_path / "missing.json"))
    assert e.value.code_name == "file_not_found"
    with pytest.raises(clod.Error) as e:
        clod.World.from_json('{"bodies": [{"box": [1, 1, 1], "velocity": [0, "fast", 0]}]}')
    assert e.value.code_name == "scene_error" and "bodies[0].velocity[1]" in str(e.value)
    with pytest.raises(clod.InvalidArgumentError):
        clod.World(model="none")
    world = clod.World()
    with pytest.raises(clod.InvalidArgumentError):
        world.step(-1.0)
    box = clod.bake(clod.Mesh.box([1, 1, 1]), sphere_tree="octree", levels=1, contact_tree=False, measure_fit=False)
    for kwargs in (dict(position=[0, 0]), dict(orientation=[0, 0, 0, 0]), dict(velocity=[np.nan, 0, 0]),
                   dict(type="floating"), dict(mass=-1.0), dict(friction=-1.0)):
        with pytest.raises(clod.InvalidArgumentError):
            world.add_body(box, **kwargs)
