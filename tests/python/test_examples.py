"""examples/python run (in their --quick form, all three at once) and write their plots."""

import os
import subprocess
import sys

import pytest


def test_examples_run_and_write_their_plots(source_dir, mesh_dir, tmp_path):
    pytest.importorskip("matplotlib")
    runs = {}
    for name in ("closest_points", "budget_sweep", "falling_stack"):
        script = source_dir / "examples" / "python" / f"{name}.py"
        args = [sys.executable, str(script), "--quick", "-o", str(tmp_path / f"{name}.png")]
        if name != "falling_stack":
            args.insert(2, str(mesh_dir / "bunny-1500.obj"))
        runs[name] = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                      env=dict(os.environ, MPLBACKEND="Agg"))
    for name, run in runs.items():
        out, _ = run.communicate(timeout=120)
        assert run.returncode == 0, f"{name}:\n{out}"
        assert (tmp_path / f"{name}.png").stat().st_size > 10_000, name
    assert "rests at z" in out  # falling_stack's report
