"""Typed results: summary.json both ways, old files, sweep rows, one summary for many seeds."""

from __future__ import annotations

import csv
import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from cartpole_q.results import MultiSeedSummary, RunSummary, SeedResult, is_success, mean_return
from cartpole_q.store import rundir, sweepdir
from tests.conftest import invoke, write_yaml

SMALL = {"train": {"episodes": 40, "eval_every": 10, "eval_episodes": 2}, "eval": {"episodes": 5}}

# What design.md's run directory contract lists for summary.json: an old run has only these.
CONTRACT_KEYS = (
    "episodes", "env_steps", "wall_seconds", "steps_per_second", "solved_episode", "eval",
    "engine", "seed", "versions",
)  # fmt: skip


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A single run and a multi-seed run of the same small config."""
    base = tmp_path_factory.mktemp("results")
    config = write_yaml(base / "small.yaml", SMALL)
    for args in (("--out", base / "one"), ("--seeds", "0-3", "--out", base / "many")):
        result = invoke("train", "-c", config, "-q", "--workers", "1", *args)
        assert result.exit_code == 0, result.output
    return base


def _json(path: Path) -> dict[str, object]:
    data = json.loads(path.read_text(encoding="utf-8"))
    assert isinstance(data, dict)
    return data


def test_summaries_read_back_to_the_same_json(runs: Path) -> None:
    single = _json(runs / "one" / rundir.SUMMARY_FILE)
    assert RunSummary.from_json(single, "x").to_json() == single
    assert list(RunSummary.from_json(single, "x").to_json()) == list(single)  # key order too
    multi = _json(runs / "many" / rundir.SUMMARY_FILE)
    assert MultiSeedSummary.from_json(multi, "x").to_json() == multi
    for key in ("runs", "finished", "success_rate", "solved_episode", "per_seed", "statistics"):
        assert key in multi


def test_a_single_run_summary_has_every_key_it_had_before(runs: Path) -> None:
    """The file format is unchanged: the keys, their order and their types."""
    single = _json(runs / "one" / rundir.SUMMARY_FILE)
    assert list(single) == [
        "episodes", "env_steps", "wall_seconds", "train_seconds", "steps_per_second",
        "solved_episode", "env_steps_to_solve", "reward_threshold", "q_table", "eval",
        "first_greedy_success", "engine", "seed", "interrupted", "versions", "finished_at",
    ]  # fmt: skip
    evaluation = single["eval"]
    assert isinstance(evaluation, dict)
    assert list(evaluation) == ["mean", "std", "min", "max", "episodes", "seed", "played_in"]
    assert isinstance(single["episodes"], int) and isinstance(evaluation["mean"], float)


def test_unknown_keys_are_kept_and_written_back() -> None:
    data = {
        "episodes": 3, "env_steps": 30, "wall_seconds": 0.1, "steps_per_second": 300.0,
        "solved_episode": None, "eval": None, "engine": "numba", "seed": 1, "versions": {},
        "from_a_newer_version": [1, 2],
    }  # fmt: skip
    summary = RunSummary.from_json(data, "x")
    assert summary.extra == {"from_a_newer_version": [1, 2]}
    assert summary.to_json()["from_a_newer_version"] == [1, 2]


def _as_old_run(run: Path) -> None:
    """Cut a run's summary.json down to design.md's keys: a run from the first version."""
    data = _json(run / rundir.SUMMARY_FILE)
    old = {key: data[key] for key in CONTRACT_KEYS}
    evaluation = old["eval"]
    assert isinstance(evaluation, dict)
    evaluation.pop("played_in")
    (run / rundir.SUMMARY_FILE).write_text(json.dumps(old), encoding="utf-8")


def test_old_summaries_are_read_by_eval_plot_and_compare(runs: Path, tmp_path: Path) -> None:
    import shutil

    old = tmp_path / "old"
    shutil.copytree(runs / "one", old)
    _as_old_run(old)
    many = tmp_path / "many"
    shutil.copytree(runs / "many", many)
    for child in many.glob("seed-*"):
        _as_old_run(child)

    summary = rundir.read_summary(old)
    assert summary is not None and summary.interrupted is False
    assert summary.result().eval_mean == _json(runs / "one" / rundir.SUMMARY_FILE)["eval"]["mean"]  # type: ignore[index]
    for args in (
        ("eval", old, "--episodes", "2"),
        ("eval", many, "--episodes", "2", "--workers", "1"),
        ("plot", old, "--out", tmp_path / "old.png"),
        ("plot", many, "--out", tmp_path / "many.png"),
        ("compare", old, runs / "one"),
        ("compare", many, runs / "many"),
    ):
        result = invoke(*args)
        assert result.exit_code == 0, (args, result.output)
    # The compared figures are the old files' own: the same run against itself is even.
    assert "P(A better than B) = 0.500" in invoke("compare", old, runs / "one").stdout


def test_a_damaged_summary_is_an_error_naming_the_file_and_key(runs: Path, tmp_path: Path) -> None:
    import shutil

    run = tmp_path / "bad"
    shutil.copytree(runs / "one", run)
    data = _json(run / rundir.SUMMARY_FILE)
    data["episodes"] = "many"
    (run / rundir.SUMMARY_FILE).write_text(json.dumps(data), encoding="utf-8")
    result = invoke("eval", run, "--episodes", "1")
    assert result.exit_code == 2
    assert (
        f"{run / rundir.SUMMARY_FILE}: episodes: must be an integer, got 'many'." in result.output
    )
    assert "Traceback" not in result.output


def test_a_multi_seed_run_is_summarised_as_a_sweep_point(runs: Path, tmp_path: Path) -> None:
    """The same seeds of the same config: the multi-seed statistics equal points.csv's row."""
    sweep = write_yaml(
        tmp_path / "sweep.yaml",
        {"name": "one-point", "base": SMALL, "seeds": "0-3", "grid": {"agent.gamma": [0.995]}},
    )
    result = invoke("sweep", sweep, "--out", tmp_path / "sweep", "--workers", "1", "--quiet")
    assert result.exit_code == 0, result.output
    with (tmp_path / "sweep" / sweepdir.POINTS_FILE).open(newline="") as file:
        (point,) = list(csv.DictReader(file))
    statistics = _json(runs / "many" / rundir.SUMMARY_FILE)["statistics"]
    assert isinstance(statistics, dict)
    assert {key: sweepdir.cell(value) for key, value in statistics.items()} == {
        key: point[key] for key in statistics
    }


_optional_int = st.none() | st.integers(0, 10**9)
_results = st.builds(
    SeedResult,
    seed=st.integers(0, 2**32 - 1),
    episodes=st.integers(0, 10**7),
    env_steps=st.integers(0, 10**12),
    solved_episode=_optional_int,
    env_steps_to_solve=_optional_int,
    first_greedy_success_env_steps=_optional_int,
    eval_mean=st.none() | st.floats(allow_nan=False, allow_infinity=False),
    success=st.none() | st.booleans(),
    train_seconds=st.floats(0, 1e6, allow_nan=False),
    mean_return=st.none() | st.floats(allow_nan=False, allow_infinity=False),
)


@given(_results, st.sampled_from(["000", "017"]), st.text(min_size=0, max_size=8))
def test_a_results_row_reads_back_to_the_same_result(
    result: SeedResult, point: str, axis: str
) -> None:
    row = sweepdir.ResultRow(point, {"agent.alpha": axis}, result)
    cells = sweepdir.row_cells(row)
    assert all(isinstance(value, str) for value in cells.values())
    assert sweepdir.parse_row(cells, ["agent.alpha"], Path("results.csv")) == row


def test_a_damaged_results_row_names_the_file() -> None:
    row = sweepdir.ResultRow("000", {}, SeedResult(0, 1, 1, None, None, None, 1.0, None))
    cells = {**sweepdir.row_cells(row), "episodes": "one"}
    with pytest.raises(sweepdir.RunError, match=r"results.csv: has a damaged row"):
        sweepdir.parse_row(cells, [], Path("results.csv"))


def test_the_mean_return_is_exactly_rounded_whatever_the_order() -> None:
    """``results.csv``'s ``mean_return``: fsum then one division, not a running float sum."""
    # a plain running sum would give 0.09999999999999999 here
    assert mean_return([0.1] * 10) == 0.1
    assert mean_return(np.array([1e16, 1.0, -1e16, 1.0])) == 0.5
    assert mean_return([-13.0, -113.0, -17.0]) == -143.0 / 3
    assert mean_return([]) is None


def test_a_results_csv_from_before_mean_return_is_read_with_it_empty(tmp_path: Path) -> None:
    """An older sweep directory (no ``mean_return`` column) still reads, and resumes."""
    rows = [sweepdir.ResultRow("000", {"agent.alpha": "0.1"},
                               SeedResult(3, 10, 90, None, None, None, -13.0, None,
                                          mean_return=-20.5))]  # fmt: skip
    sweepdir.write_results(tmp_path, ["agent.alpha"], rows)
    text = (tmp_path / sweepdir.RESULTS_FILE).read_text()
    assert text.splitlines()[0].endswith(",train_seconds,mean_return,rms_error")
    assert text.splitlines()[1].endswith(",-20.5,")
    assert sweepdir.read_results(tmp_path, ["agent.alpha"]) == rows
    # before rms_error (prediction runs' errors), then before mean_return too
    for cut, dropped in ((1, {"rms_error": None}), (2, {"mean_return": None})):
        older = "\n".join(line.rsplit(",", cut)[0] for line in text.splitlines()) + "\n"
        (tmp_path / sweepdir.RESULTS_FILE).write_text(older)
        (row,) = sweepdir.read_results(tmp_path, ["agent.alpha"])
        assert row.result == dataclasses.replace(rows[0].result, **dropped)


def test_success_is_reaching_the_threshold_exactly() -> None:
    assert is_success(475.0, 475.0) is True
    assert is_success(474.999, 475.0) is False
    assert is_success(None, 475.0) is None and is_success(500.0, None) is None
