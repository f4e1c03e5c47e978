"""clod.World editing and queries (world.h): forces, impulses, removal, filters, set_state, the
contact callback, separation and scale, against analytic answers."""

import math

import numpy as np
import pytest

import clod

DT = 1.0 / 60.0


@pytest.fixture(scope="module")
def shapes():
    ground = clod.bake(clod.Mesh.box([3.0, 3.0, 0.5]), sphere_tree="octree", levels=3, sdf_depth=5, measure_fit=False)
    box = clod.bake(clod.Mesh.box([0.5, 0.5, 0.5]), sphere_tree="octree", levels=3, sdf_depth=5, measure_fit=False)
    return ground, box


def test_force_gives_f_dt_over_m_and_impulse_j_over_m(shapes):
    _, box = shapes
    world = clod.World(gravity=[0, 0, 0], dt=DT)
    body = world.add_body(box, mass=2.0)
    world.apply_force(body, [3.0, 0.0, 0.0])
    world.step()
    np.testing.assert_allclose(world.velocities[body], [3.0 * DT / 2.0, 0, 0], rtol=1e-12, atol=1e-15)
    world.apply_impulse(body, [0.0, 4.0, 0.0])
    np.testing.assert_allclose(world.velocities[body], [3.0 * DT / 2.0, 2.0, 0], rtol=1e-12, atol=1e-15)
    with pytest.raises(clod.InvalidArgumentError):
        world.apply_force(body, [math.nan, 0, 0])
    with pytest.raises(clod.InvalidArgumentError):
        world.apply_torque(5, [0, 0, 1])


def drop(shapes, edit, steps=60):
    ground, box = shapes
    world = clod.World(dt=DT)
    g = world.add_body(ground, type="static", position=[0, 0, -0.5])  # top face at z = 0
    b = world.add_body(box, position=[0, 0, 0.51])
    edit(world, g, b)
    for _ in range(steps):
        world.step()
    return world, b


def free_fall(z0, steps):
    return z0 - 9.81 * DT * DT * steps * (steps + 1) / 2


def test_removed_and_filtered_grounds_let_the_box_fall_freely(shapes):
    world, b = drop(shapes, lambda w, g, b: None)
    assert abs(world.positions[b, 2] - 0.5) < 0.0035  # control: resting (slop 0.002 x diagonal)
    world, b = drop(shapes, lambda w, g, b: w.remove_body(g))
    assert world.types == ["removed", "dynamic"] and not world.contains(0) and world.contains(1)
    assert np.all(np.isnan(world.positions[0]))
    assert world.positions[b, 2] == pytest.approx(free_fall(0.51, 60), abs=1e-9)
    world, b = drop(shapes, lambda w, g, b: w.set_filter(b, group=2, mask=2))
    assert world.filter(b) == (2, 2)
    assert world.positions[b, 2] == pytest.approx(free_fall(0.51, 60), abs=1e-9)
    world, b = drop(shapes, lambda w, g, b: w.set_contact_callback(lambda *args: False))
    assert world.positions[b, 2] < 0.0


def test_contact_callback_gets_arrays_and_contact_points_lie_on_the_ground(shapes):
    seen = []

    def callback(a, b, pos, normal, depth, substep):
        seen.append((a, b, pos.shape, normal.shape, depth.shape))
        return True

    world, b = drop(shapes, lambda w, g, b: w.set_contact_callback(callback))
    assert seen and all(a == 0 and b == 1 and p[1] == 3 and n[1] == 3 for a, b, p, n, _ in seen)
    report = world.step()
    points = report.contact_points
    assert points.shape == (len(report.contact_pos), 2, 3)
    # Both points on the ground's top face z = 0, to within 1.2 % of the box diagonal (slop + drift).
    assert np.all(np.abs(points[:, :, 2]) < 0.012 * math.sqrt(3))


def test_set_state_and_separation_and_scale(shapes):
    _, box = shapes
    world = clod.World(gravity=[0, 0, 0])
    a = world.add_body(box, type="static")
    b = world.add_body(box, position=[1.3, 0, 0])
    assert world.separation(a, b)["distance"] == pytest.approx(0.3, abs=1e-12)
    world.set_state(b, position=[0, 0, 2.5])
    s = world.separation(a, b)
    assert s["distance"] == pytest.approx(1.5, abs=1e-12) and not s["overlapping"] and s["within_max"]
    assert s["point_a"][2] == pytest.approx(0.5) and s["point_b"][2] == pytest.approx(2.0)
    assert not world.separation(a, b, max_distance=1.0)["within_max"]
    with pytest.raises(clod.InvalidArgumentError):
        world.set_state(b, orientation=[2, 0, 0, 0])
    big = world.add_body(box, type="static", position=[4, 0, 0], scale=2.0)  # half extent 1
    assert world.separation(a, big)["distance"] == pytest.approx(4 - 1 - 0.5, abs=1e-12)
    heavy = world.add_body(box, position=[0, 5, 0], scale=2.0, density=1000.0)
    assert world.masses[heavy] == pytest.approx(8000.0, rel=1e-9)  # (2 m)^3 of water
    with pytest.raises(clod.InvalidArgumentError):
        world.add_body(box, scale=0.0)
