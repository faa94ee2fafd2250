"""run_experiment: the paper's protocol from a dict, as `twincal run` runs it."""

import json
import pathlib

import pytest

import twincal

CONFIG = {"case": "analytic", "analytic_dimension": 3, "locators": "all",
          "controllers": ["baseline", "active"], "runs": 2, "assemblies": 30, "seed": 7}


def test_runs_a_group_and_returns_its_summary(tmp_path):
    result = twincal.run_experiment(CONFIG, out=tmp_path, threads=1)
    rows = result["rows"]
    assert [row["controller"] for row in rows] == ["baseline", "active"]
    for row in rows:
        assert row["group"] == "analytic/all" and row["runs"] == 2 and row["diverged"] == 0
    baseline, active = rows
    assert baseline["q_evaluations_per_assembly"] == 0
    assert baseline["lost"] == 0  # the baseline's error is the rule's yardstick
    assert active["q_evaluations_per_assembly"] > 0
    assert active["median_relative_residual"] < baseline["median_relative_residual"]
    assert result["config"]["seed"] == 7 and "twin_seed" in result["config"]
    stored = json.loads((pathlib.Path(tmp_path) / "summary.json").read_text())
    assert stored  # the results directory is the CLI's


def test_results_do_not_depend_on_threads_and_resume(tmp_path):
    one = twincal.run_experiment(CONFIG, threads=1)["rows"]
    two = twincal.run_experiment(CONFIG, threads=2)["rows"]
    strip = lambda rows: [{k: v for k, v in r.items() if k != "seconds_per_assembly"} for r in rows]
    assert strip(one) == strip(two)
    first = twincal.run_experiment(CONFIG, out=tmp_path)["rows"]
    again = twincal.run_experiment(CONFIG, out=tmp_path)["rows"]  # nothing left to run
    assert first == again


def test_bad_configs_raise_value_errors_naming_the_key():
    with pytest.raises(ValueError, match="runs"):
        twincal.run_experiment(dict(CONFIG, runs=0))
    with pytest.raises(twincal.InvalidArgumentError, match="case"):
        twincal.run_experiment(dict(CONFIG, case="bicycle"))
    with pytest.raises(twincal.InvalidArgumentError, match="config"):
        twincal.run_experiment(["not", "a", "dict"])


def test_the_rows_come_as_a_pandas_frame_too():
    import pandas  # a dependency of the package's tests (scripts/debian-packages.txt)

    result = twincal.run_experiment(CONFIG)
    frame = result["frame"]
    assert isinstance(frame, pandas.DataFrame)
    assert list(frame["controller"]) == ["baseline", "active"]
    assert frame["median_relative_residual"].tolist() == [
        row["median_relative_residual"] for row in result["rows"]]
