"""clod.experiment: the degradation table, checked against the slide's analytic stopping distance."""

import numpy as np
import pytest

import clod


def test_degradation_table_has_one_row_per_run_and_the_analytic_slide(tmp_path):
    table = clod.experiment("degradation", scenarios=["slide", "stack5"], models=["cfm"], budgets=[0, 64],
                            seconds=0.25, cache_dir=str(tmp_path))
    assert table["scenario"] == ["slide", "slide", "stack5", "stack5"]
    assert table["model"] == ["cfm"] * 4 and table["budget_kind"] == ["tests"] * 4
    np.testing.assert_array_equal(table["budget"], [64, 0, 64, 0])  # ascending, unlimited last
    assert table["monotone_ok"].dtype == bool and table["monotone_ok"][0]
    n = len(table["scenario"])
    for key, value in table.items():
        assert len(value) == n, key
    # A box sliding at 2 m/s with friction 0.3 stops after v^2 / (2 mu g) (degradation.h).
    np.testing.assert_allclose(table["expected_distance"][:2], 2.0 ** 2 / (2 * 0.3 * 9.81), rtol=1e-12)
    assert np.all(table["tests_spent"][[0, 2]] <= 64 * 15 * 8)  # budget per frame x frames (x substeps cap)


def test_unknown_experiments_and_missing_tools_are_clear_errors(monkeypatch):
    with pytest.raises(clod.InvalidArgumentError, match="unknown experiment"):
        clod.experiment("nonsense")
    monkeypatch.setenv("PATH", "")
    monkeypatch.delenv("CLOD_CLI", raising=False)
    with pytest.raises(clod.InvalidArgumentError, match="command-line tool"):
        clod.experiment("sizes")
    with pytest.raises(clod.InvalidArgumentError, match="drop"):
        monkeypatch.delenv("CLOD_SHARED_MESH_DIR", raising=False)
        clod.experiment("degradation", scenarios=["drop-bunny"])
