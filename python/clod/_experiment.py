"""clod.experiment: the experiments' tables as dicts of columns."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import tempfile
from typing import Any, Dict, Optional, Sequence

import numpy as np

from . import _clod

# The paper experiments live in the command-line tool (apps/clod/experiments); only the degradation
# experiment is library code (include/clod/degradation.h) and runs in-process.
CLI_EXPERIMENTS = ("sampling", "sizes", "normals", "retrieval", "fidelity", "landing", "flat-contact")


def _invalid(message: str) -> _clod.InvalidArgumentError:
    error = _clod.InvalidArgumentError(message)
    error.code = _clod.error_codes["invalid_argument"]
    error.code_name = "invalid_argument"
    return error


def _find_cli(cli: Optional[str]) -> Optional[str]:
    for candidate in (cli, os.environ.get("CLOD_CLI"), shutil.which("clod")):
        if candidate and os.path.isfile(candidate) and os.access(candidate, os.X_OK):
            return candidate
    return None


def experiment(
    name: str,
    *,
    scenarios: Optional[Sequence[str]] = None,
    models: Sequence[str] = ("cfm", "exact"),
    budgets: Sequence[int] = (16, 64, 256, 1024, 0),
    budgets_us: Sequence[float] = (),
    rates: Sequence[float] = (60.0,),
    seconds: float = 0.0,
    mesh_dir: Optional[str] = None,
    cache_dir: Optional[str] = None,
    cli: Optional[str] = None,
    trials: Optional[int] = None,
    seed: Optional[int] = None,
) -> Dict[str, Any]:
    """Runs one of clod's experiments and returns its table as a dict of columns.

    ``"degradation"`` (issue 17, include/clod/degradation.h) runs in-process: every combination of
    ``scenarios`` (default: the six box scenes of ``clod.scenarios``; the ``drop-*`` scenes need
    ``mesh_dir``, the folder of bunny-1500.obj, spot.obj and fandisk.obj, or the environment variable
    CLOD_SHARED_MESH_DIR), ``models``, test ``budgets`` per frame (0 = unlimited), time
    ``budgets_us`` per frame and frame ``rates`` (Hz), for ``seconds`` of simulated time each (0 = the
    scenario's own). The runs are independent and run in parallel (TBB, GIL released). Returns one
    entry per row: ``scenario``, ``model``, ``budget_kind`` ("tests"/"us") as lists of str; ``budget``,
    ``rate_hz``, ``error`` (m, distance from the analytic outcome), ``plausible``, ``monotone_ok``
    (against the next smaller budget of the same scenario, model, rate and kind), ``displacement``,
    ``tilt_deg``, ``speed``, ``tests_spent``, ``cpu_per_sim_second``, ... as NumPy arrays; and
    ``failures`` (one "; "-joined str per row). Baked shapes are cached in ``cache_dir`` (default: a
    folder in the temporary directory).

    Every other experiment of ``clod experiment`` (``sampling``, ``sizes``, ``normals``,
    ``retrieval``, ``fidelity``, ``landing``, ``flat-contact``) lives in the command-line tool: it
    is run as ``clod experiment NAME --json`` (the tool from ``cli``, $CLOD_CLI or PATH; ``trials``
    and ``seed`` are passed on) and its JSON document is returned as a dict.
    """
    if name == "degradation":
        if scenarios is None:
            scenarios = [s for s in _clod.scenarios if not s.startswith("drop-")]
        scenarios = list(scenarios)
        if mesh_dir is None:
            mesh_dir = os.environ.get("CLOD_SHARED_MESH_DIR", "")
        if any(s.startswith("drop-") for s in scenarios) and not mesh_dir:
            raise _invalid("degradation: the drop-* scenarios need mesh_dir (the folder of bunny-1500.obj, spot.obj, "
                           "fandisk.obj) or CLOD_SHARED_MESH_DIR")
        if cache_dir is None:
            cache_dir = os.path.join(tempfile.gettempdir(), "clod-bake-cache")
        budgets = [int(b) for b in budgets]
        if any(b < 0 for b in budgets):
            raise _invalid("budgets: every test budget must be >= 0 (0 = unlimited)")
        return _clod._degradation_table(scenarios, list(models), budgets, [float(b) for b in budgets_us],
                                        [float(r) for r in rates], float(seconds), str(mesh_dir), str(cache_dir))
    if name in CLI_EXPERIMENTS:
        tool = _find_cli(cli)
        if tool is None:
            raise _invalid(f"experiment '{name}' lives in the clod command-line tool, which was not found: pass cli=, "
                           "set CLOD_CLI or put clod on PATH (only 'degradation' runs in-process)")
        command = [tool, "experiment", name, "--json"]
        if trials is not None:
            command += ["--trials", str(int(trials))]
        if seed is not None:
            command += ["--seed", str(int(seed))]
        done = subprocess.run(command, capture_output=True, text=True)
        if done.returncode != 0:
            error = _clod.Error(f"clod experiment {name} failed (exit {done.returncode}): {done.stderr.strip()}")
            error.code = _clod.error_codes["external_tool_failed"]
            error.code_name = "external_tool_failed"
            raise error
        return json.loads(done.stdout)
    raise _invalid(f"unknown experiment '{name}' (valid: degradation, {', '.join(CLI_EXPERIMENTS)})")


def _as_columns(rows: Sequence[Dict[str, Any]]) -> Dict[str, Any]:
    """Rows (dicts with equal keys) to columns: numbers become arrays, the rest lists."""
    if not rows:
        return {}
    out: Dict[str, Any] = {}
    for key in rows[0]:
        values = [row[key] for row in rows]
        if all(isinstance(v, (int, float, bool, np.number, np.bool_)) for v in values):
            out[key] = np.asarray(values)
        else:
            out[key] = values
    return out
