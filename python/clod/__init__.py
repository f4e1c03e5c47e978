"""clod: time-critical collision detection and contact generation between rigid triangle meshes.

NumPy in, NumPy out (structure of arrays: one array per field, one row per element)::

    import clod, numpy as np
    mesh = clod.Mesh.load("bunny.obj")               # or clod.Mesh(vertices (N,3), faces (M,3))
    hits = mesh.closest(np.random.rand(1000, 3))     # .point .normal .signed_distance ... arrays
    bake = clod.bake(mesh, sphere_tree="octree")     # sphere-tree, closest feature maps, contact tree
    bake.save("bunny.clod"); bake = clod.Bake.load("bunny.clod")
    res = clod.query(bake, [0, 0, 0, 1, 0, 0, 0], bake, [0.1, 0, 0, 1, 0, 0, 0], model="cfm", budget=64)
    res.pos, res.normal, res.penetration_depth, res.budget_used, res.finished
    world = clod.World.from_scene("scenes/stack_5.json"); world.run(60)["positions"]

Errors raise clod.Error (attributes code, code_name); bad arguments clod.InvalidArgumentError (also a
ValueError); files clod.FileError (also an OSError). docs/python.md describes the package.
"""

from ._clod import (  # noqa: F401  (re-exported)
    CONTACT_FEATURE_CELL,
    CONTACT_FEATURE_NONE,
    CONTACT_FEATURE_SPHERE,
    CONTACT_FEATURE_TRIANGLE,
    FEATURE_EDGE,
    FEATURE_FACE,
    FEATURE_VERTEX,
    NO_CONTACT_FEATURE,
    Bake,
    BatchQueryResult,
    ClosestResult,
    Error,
    FileError,
    InvalidArgumentError,
    Mesh,
    QueryResult,
    StepReport,
    World,
    __version__,
    bake,
    contact_models,
    error_codes,
    query,
    query_batch,
    scenarios,
)
from ._experiment import experiment  # noqa: F401
from . import batch  # noqa: F401

__all__ = [
    "Bake",
    "BatchQueryResult",
    "CONTACT_FEATURE_CELL",
    "CONTACT_FEATURE_NONE",
    "CONTACT_FEATURE_SPHERE",
    "CONTACT_FEATURE_TRIANGLE",
    "ClosestResult",
    "Error",
    "FEATURE_EDGE",
    "FEATURE_FACE",
    "FEATURE_VERTEX",
    "FileError",
    "InvalidArgumentError",
    "Mesh",
    "NO_CONTACT_FEATURE",
    "QueryResult",
    "StepReport",
    "World",
    "__version__",
    "bake",
    "batch",
    "contact_models",
    "error_codes",
    "experiment",
    "query",
    "query_batch",
    "scenarios",
]
