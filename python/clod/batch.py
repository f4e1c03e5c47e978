"""Independent jobs in bulk: baking an asset library, sweeping a scene over models and budgets.

Both functions run their jobs on a ``dask.distributed.Client`` when given one (any cluster: a
``LocalCluster``, or ``Client("tcp://scheduler:8786")``) and on local threads otherwise (clod releases
the GIL, so threads run in parallel). The results do not depend on where the jobs ran: every job is
deterministic (bakes are; worlds are under test budgets), and the caller assembles the results in
input order. On a cluster the workers must be able to ``import clod`` and read the input files (a
shared file system, or a LocalCluster); the outputs come back to the caller, which writes them.
"""

from __future__ import annotations

import concurrent.futures
import itertools
import os
import time
from typing import Any, Callable, Dict, List, Optional, Sequence

import numpy as np

from . import _clod


def _run(function: Callable[..., Any], jobs: Sequence[tuple], client: Any, max_workers: Optional[int]) -> List[Any]:
    """function(*job) for every job, in job order: on the Dask client, or on a local thread pool."""
    if client is not None:
        futures = [client.submit(function, *job, pure=False) for job in jobs]
        return client.gather(futures)
    workers = max_workers or os.cpu_count() or 1
    with concurrent.futures.ThreadPoolExecutor(max_workers=workers) as pool:
        return list(pool.map(lambda job: function(*job), jobs))


def _bake_one(path: str, options: Dict[str, Any]) -> Dict[str, Any]:
    start = time.perf_counter()
    mesh = _clod.Mesh.load(path)
    baked = _clod.bake(mesh, source_name=os.path.basename(path), **options)
    data = baked.to_bytes()
    return {"bytes": data, "mesh_hash": baked.mesh_hash, "triangles": mesh.triangle_count,
            "seconds": time.perf_counter() - start}


def bake_all(paths: Sequence[str], out_dir: str, client: Any = None, *, max_workers: Optional[int] = None,
             **options: Any) -> Dict[str, Any]:
    """Bakes every mesh file of ``paths`` into ``out_dir/<file stem>.clod``.

    ``options`` are those of :func:`clod.bake` (e.g. ``sphere_tree="octree", levels=3``). With a Dask
    ``client`` each mesh is a task on the cluster (the workers read the mesh files and send the bake
    file's bytes back); without one, ``max_workers`` local threads (default: the CPU count) do the
    work. Files are written atomically by the caller, in input order. Two paths with the same stem,
    or an ``out_dir`` that does not exist, raise clod.InvalidArgumentError before any work starts;
    a mesh that fails to load or bake raises its clod.Error.

    Returns a table (dict of columns, one row per path): ``source`` and ``output`` (lists of str),
    ``file_bytes``, ``mesh_hash`` (uint64), ``triangles`` and ``seconds`` (the job's wall time, the
    only column that differs between runs) as NumPy arrays.
    """
    paths = [os.fspath(p) for p in paths]
    stems = [os.path.splitext(os.path.basename(p))[0] for p in paths]
    if len(set(stems)) != len(stems):
        duplicates = sorted({s for s in stems if stems.count(s) > 1})
        raise _invalid(f"bake_all: several inputs would write the same file: {', '.join(duplicates)}")
    if not os.path.isdir(out_dir):
        raise _invalid(f"bake_all: out_dir '{out_dir}' is not a directory")
    results = _run(_bake_one, [(p, dict(options)) for p in paths], client, max_workers)
    outputs = []
    for stem, result in zip(stems, results):
        output = os.path.join(out_dir, stem + ".clod")
        _clod.Bake.from_bytes(result["bytes"]).save(output)  # checked decode, then an atomic write
        outputs.append(output)
    return {
        "source": paths,
        "output": outputs,
        "file_bytes": np.array([len(r["bytes"]) for r in results], dtype=np.int64),
        "mesh_hash": np.array([r["mesh_hash"] for r in results], dtype=np.uint64),
        "triangles": np.array([r["triangles"] for r in results], dtype=np.int64),
        "seconds": np.array([r["seconds"] for r in results], dtype=np.float64),
    }


def _sweep_one(scene_text: str, base_dir: str, model: str, budget: int, steps: Optional[int],
               cache_dir: str) -> Dict[str, Any]:
    start = time.perf_counter()
    world = _clod.World.from_json(scene_text, base_dir, model=model, budget=budget, cache_dir=cache_dir)
    run = world.run(steps)
    return {
        "state_hash": world.state_hash(),
        "positions": world.positions,
        "orientations": world.orientations,
        "tests_spent": int(run["tests_spent"].sum()),
        "max_budget_spent": int(run["budget_spent"].max()) if len(run["budget_spent"]) else 0,
        "mean_budget_spent": float(run["budget_spent"].mean()) if len(run["budget_spent"]) else 0.0,
        "contacts": int(run["contacts"][-1]) if len(run["contacts"]) else 0,
        "kinetic_energy": world.kinetic_energy(),
        "seconds": time.perf_counter() - start,
    }


def sweep(scene: str, models: Sequence[str], budgets: Sequence[int], client: Any = None, *,
          steps: Optional[int] = None, cache_dir: str = "", max_workers: Optional[int] = None) -> Dict[str, Any]:
    """Runs a scene once per (model, budget) pair and tabulates the outcomes.

    ``scene`` is a JSON scene file (scenes/*.json; its text is sent to the workers, its meshes are
    read there, relative to the file's folder). ``models`` are contact models (clod.contact_models),
    ``budgets`` tests per step (0 = unlimited); each run lasts ``steps`` steps (default: the scene's).
    Runs are Dask tasks with a ``client``, local threads otherwise. ``cache_dir`` caches the bakes
    (shared by the runs; writes are atomic).

    Returns a table (dict of columns, one row per pair, models outer, budgets inner): ``model`` (list),
    ``budget``, ``state_hash`` (uint64: equal hashes, bit-identical final states), ``positions``
    (R, n, 3) and ``orientations`` (R, n, 4) after the last step, ``tests_spent`` (all steps),
    ``max_budget_spent``, ``mean_budget_spent`` (per step), ``contacts`` (last step),
    ``kinetic_energy`` (final) and ``seconds`` (wall time of the run: the only column that is not
    repeatable) as NumPy arrays.
    """
    scene = os.fspath(scene)
    try:
        with open(scene, encoding="utf-8") as f:
            text = f.read()
    except OSError as e:
        error = _clod.FileError(f"{scene}: {e.strerror}")
        error.code = _clod.error_codes["file_not_found" if isinstance(e, FileNotFoundError) else "file_unreadable"]
        error.code_name = "file_not_found" if isinstance(e, FileNotFoundError) else "file_unreadable"
        raise error from e
    base_dir = os.path.dirname(os.path.abspath(scene))
    for model in models:
        if model not in _clod.contact_models:
            raise _invalid(f"sweep: unknown contact model '{model}' (valid: {', '.join(_clod.contact_models)})")
    budgets = [int(b) for b in budgets]
    if any(b < 0 for b in budgets):
        raise _invalid("sweep: budgets are tests per step, >= 0 (0 = unlimited)")
    pairs = list(itertools.product(models, budgets))
    results = _run(_sweep_one, [(text, base_dir, m, b, steps, cache_dir) for m, b in pairs], client, max_workers)
    table: Dict[str, Any] = {
        "model": [m for m, _ in pairs],
        "budget": np.array([b for _, b in pairs], dtype=np.uint64),
        "state_hash": np.array([r["state_hash"] for r in results], dtype=np.uint64),
        "positions": np.stack([r["positions"] for r in results]) if results else np.zeros((0, 0, 3)),
        "orientations": np.stack([r["orientations"] for r in results]) if results else np.zeros((0, 0, 4)),
    }
    for key, dtype in (("tests_spent", np.uint64), ("max_budget_spent", np.uint64), ("mean_budget_spent", np.float64),
                       ("contacts", np.int64), ("kinetic_energy", np.float64), ("seconds", np.float64)):
        table[key] = np.array([r[key] for r in results], dtype=dtype)
    return table


def _invalid(message: str) -> Exception:
    error = _clod.InvalidArgumentError(message)
    error.code = _clod.error_codes["invalid_argument"]
    error.code_name = "invalid_argument"
    return error
