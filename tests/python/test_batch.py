"""clod.batch on a Dask LocalCluster (2 worker processes) equals the serial, local-thread run bit for bit."""

import os

import numpy as np
import pytest

import clod
import clod.batch
from conftest import write_obj

distributed = pytest.importorskip("distributed")

BAKE_OPTIONS = dict(sphere_tree="octree", levels=2, sdf_depth=5, measure_fit=False)


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                       dashboard_address=None, silence_logs=40)
    with distributed.Client(cluster) as dask_client:
        yield dask_client
    cluster.close()


@pytest.fixture(scope="module")
def mesh_files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("meshes")
    files = []
    for name, mesh in (("box", clod.Mesh.box([0.5, 1.0, 0.25])), ("ball", clod.Mesh.icosphere(0.7, 2)),
                       ("slab", clod.Mesh.box([2.0, 2.0, 0.1]))):
        files.append(str(write_obj(folder / f"{name}.obj", mesh.vertices, mesh.faces)))
    return files


def test_bake_all_on_dask_equals_local_threads(client, mesh_files, tmp_path):
    (tmp_path / "serial").mkdir()
    (tmp_path / "dask").mkdir()
    serial = clod.batch.bake_all(mesh_files, str(tmp_path / "serial"), **BAKE_OPTIONS)
    remote = clod.batch.bake_all(mesh_files, str(tmp_path / "dask"), client=client, **BAKE_OPTIONS)
    assert [os.path.basename(p) for p in serial["output"]] == ["box.clod", "ball.clod", "slab.clod"]
    for a, b in zip(serial["output"], remote["output"]):
        assert open(a, "rb").read() == open(b, "rb").read()
    for key in ("file_bytes", "mesh_hash", "triangles"):
        np.testing.assert_array_equal(serial[key], remote[key])
    assert serial["source"] == remote["source"] == mesh_files
    # The files are bakes of those meshes (independent check: the triangle counts of the inputs).
    np.testing.assert_array_equal(serial["triangles"], [12, 320, 12])
    assert clod.Bake.load(serial["output"][1]).mesh.triangle_count == 320


def test_bake_all_refuses_clashing_outputs(mesh_files, tmp_path):
    with pytest.raises(clod.InvalidArgumentError, match="same file"):
        clod.batch.bake_all([mesh_files[0], mesh_files[0]], str(tmp_path))
    with pytest.raises(clod.InvalidArgumentError, match="not a directory"):
        clod.batch.bake_all(mesh_files, str(tmp_path / "nowhere"))


def test_sweep_on_dask_equals_local_threads(client, source_dir):
    scene = str(source_dir / "scenes" / "stack_5.json")
    models, budgets = ["cfm", "dos"], [32, 0]
    serial = clod.batch.sweep(scene, models, budgets, steps=10)
    remote = clod.batch.sweep(scene, models, budgets, client=client, steps=10)
    assert serial["model"] == remote["model"] == ["cfm", "cfm", "dos", "dos"]
    for key, value in serial.items():
        if key in ("model", "seconds"):  # seconds: wall time, the one column that is not repeatable
            continue
        assert value.dtype == remote[key].dtype
        np.testing.assert_array_equal(value, remote[key], err_msg=key)
    assert serial["positions"].shape == (4, 6, 3)
    # Each row is the run of a world with that model and budget (independent: a World run here).
    world = clod.World.from_scene(scene, model="dos", budget=32)
    world.run(10)
    assert world.state_hash() == serial["state_hash"][2]
    np.testing.assert_array_equal(world.positions, serial["positions"][2])
