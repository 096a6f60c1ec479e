"""Sweeps: the sweep file's checks, the directory contract, and results that depend on nothing.

Every (point, seed) must be exactly ``train --config points/<p>/config.yaml --seed S``;
``results.csv`` must not depend on the number of workers, the backend, or a kill -9 and
``--resume`` (timings aside).
"""

from __future__ import annotations

import csv
import json
import math
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from cartpole_q.config import ConfigError, load_config
from cartpole_q.engines.plan import plan_run
from cartpole_q.experiments import sweep as sweeping
from cartpole_q.experiments.compiling import compile_ahead
from cartpole_q.experiments.sweep_spec import load_sweep
from cartpole_q.statistics import summarize_point
from cartpole_q.store import sweepdir
from tests.conftest import REPO, invoke, then_sigint, write_yaml

# Short runs: 60 episodes of CartPole (few solve), so a sweep of 12 runs takes a second.
BASE = {
    "name": "base",
    "train": {"episodes": 60, "eval_every": 20, "eval_episodes": 2, "stop_when_solved": True},
    "eval": {"episodes": 3},
}
SWEEP = {
    "name": "tiny",
    "base": BASE,
    "seeds": "0-2",
    "grid": {"agent.alpha": [0.1, 0.5], "agent.algorithm": ["q_learning", "sarsa"]},
}


def _results(directory: Path) -> list[dict[str, str]]:
    with (directory / sweepdir.RESULTS_FILE).open(newline="") as file:
        return list(csv.DictReader(file))


def _without_timings(rows: list[dict[str, str]]) -> list[dict[str, str]]:
    return [{k: v for k, v in row.items() if k not in sweepdir.TIMING_COLUMNS} for row in rows]


# -- the sweep file -----------------------------------------------------------------------


def test_points_are_the_grid_product_last_axis_fastest_then_the_zip_group() -> None:
    spec = load_sweep(
        {
            "seeds": "0-1",
            "grid": {"agent.alpha": [0.1, 0.2], "agent.gamma": [0.9, 0.99, 1.0]},
            "zip": {
                "discretization.bins": [[1, 1, 2, 10], [1, 1, 6, 12]],
                "agent.q_init": [0, 100],
            },
        }
    )
    assert spec.axes == ["agent.alpha", "agent.gamma", "discretization.bins", "agent.q_init"]
    assert len(spec.points) == 2 * 3 * 2
    assert [p.values["agent.gamma"] for p in spec.points[:6]] == [0.9, 0.9, 0.99, 0.99, 1.0, 1.0]
    assert spec.points[1].values == {
        "agent.alpha": 0.1, "agent.gamma": 0.9, "discretization.bins": [1, 1, 6, 12],
        "agent.q_init": 100,
    }  # fmt: skip
    assert spec.points[7].config.agent.alpha.start == 0.2
    assert spec.points[7].config.discretization.bins == (1, 1, 6, 12)
    assert spec.points[7].config.name == "sweep-007"
    assert spec.point_id(7) == "007"
    assert spec.seed_key(1) == "seed-001"
    assert spec.runs == 24


def test_no_axes_is_one_point_and_seeds_default_to_the_base_seed() -> None:
    spec = load_sweep({"base": {"seed": 5}})
    assert len(spec.points) == 1
    assert spec.seeds == (5,)


def test_the_resolved_sweep_loads_back_to_the_same_points(tmp_path: Path) -> None:
    spec = load_sweep({**SWEEP, "zip": {"agent.gamma": [0.9, 1.0], "agent.q_init": [0, 1]}})
    path = write_yaml(tmp_path / "sweep.yaml", spec.to_dict())
    again = load_sweep(path)
    assert again.to_dict() == spec.to_dict()
    assert [p.config for p in again.points] == [p.config for p in spec.points]
    assert spec.to_dict()["seeds"] == "0-2"
    assert spec.to_dict()["base"]["train"]["seeds"] is None


def test_a_base_path_is_relative_to_the_sweep_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "configs").mkdir()
    write_yaml(tmp_path / "configs" / "mine.yaml", {"agent": {"gamma": 0.95}})
    sweep = write_yaml(tmp_path / "s.yaml", {"base": "configs/mine.yaml"})
    assert load_sweep(sweep).points[0].config.agent.gamma == 0.95
    # never relative to the current directory, even where that would find a file
    (tmp_path / "sub").mkdir()
    monkeypatch.chdir(tmp_path)
    inner = write_yaml(tmp_path / "sub" / "s.yaml", {"base": "configs/mine.yaml"})
    with pytest.raises(ConfigError, match=r"sub/configs/mine\.yaml is not a file"):
        load_sweep(inner)
    shipped = write_yaml(tmp_path / "t.yaml", {"base": "blog"})
    assert load_sweep(shipped).points[0].config.discretization.bins == (10, 10, 10, 10)


BAD_SWEEPS = [
    pytest.param({"gird": {}}, "unknown key 'gird'; did you mean 'grid'?", id="top-level typo"),
    pytest.param(
        {"grid": {"agent.alpah": [0.1]}}, "did you mean 'agent.alpha'", id="axis key typo"
    ),
    pytest.param(
        {"grid": {"agent.alpha": [0.1, -1]}},
        "s.yaml: point 001 (agent.alpha=-1): agent.alpha: must be in (0, 1]",
        id="invalid value names point and key",
    ),
    pytest.param({"grid": {"agent.alpha": []}}, "grid.agent.alpha: is empty", id="empty axis"),
    pytest.param({"grid": {"agent.alpha": 0.1}}, "must be a list", id="not a list"),
    pytest.param(
        {"zip": {"agent.alpha": [0.1, 0.2], "agent.gamma": [0.9]}},
        "same number of values (agent.alpha has 2, agent.gamma has 1)",
        id="zip lengths",
    ),
    pytest.param(
        {"grid": {"agent.alpha": [0.1]}, "zip": {"agent.alpha": [0.2]}},
        "zip.agent.alpha: is a grid axis too",
        id="zip repeats grid",
    ),
    pytest.param({"grid": {"seed": [1, 2]}}, "grid.seed: cannot be an axis", id="seed axis"),
    pytest.param(
        {"grid": {"train.seeds": ["0-3"]}}, "grid.train.seeds: cannot be an axis", id="seeds axis"
    ),
    pytest.param({"seeds": "0-x"}, "seeds: must be seeds like", id="bad seeds"),
    pytest.param({"name": "a b"}, "name: must be letters", id="bad name"),
    pytest.param({"base": 3}, "base: must be a config file", id="bad base"),
    pytest.param(
        {"grid": {"agent.alpha": [0.1]}, "zip": {"agent": [{"alpha": 0.5}]}},
        "agent and agent.alpha: one key holds the other",
        id="overlapping axes",
    ),
    pytest.param(
        {"base": "configs/nothere.yaml"},
        "is not a file (a base path is relative to the sweep file)",
        id="missing base file",
    ),
]


@pytest.mark.parametrize(("data", "message"), BAD_SWEEPS)
def test_bad_sweep_files_are_refused_naming_the_key(
    tmp_path: Path, data: dict[str, Any], message: str
) -> None:
    path = write_yaml(tmp_path / "s.yaml", data)
    with pytest.raises(ConfigError) as error:
        load_sweep(path)
    assert message in str(error.value)
    assert str(path) in str(error.value)


def test_the_command_refuses_bad_input_with_exit_2_and_writes_nothing(in_tmp: Path) -> None:
    bad = write_yaml(in_tmp / "bad.yaml", {"grid": {"agent.alpha": [2.0]}})
    result = invoke("sweep", bad)
    assert result.exit_code == 2
    assert "point 000 (agent.alpha=2.0): agent.alpha" in result.output
    assert "Traceback" not in result.output
    assert not (in_tmp / "sweeps").exists()
    big = write_yaml(in_tmp / "big.yaml", {"seeds": "0-99", "grid": {"agent.alpha": [0.1, 0.2]}})
    result = invoke("sweep", big, "--max-runs", "150")
    assert result.exit_code == 2
    assert "2 points x 100 seeds = 200 runs, more than --max-runs 150; pass --yes" in result.output
    assert not (in_tmp / "sweeps").exists()
    assert invoke("sweep").exit_code == 2
    assert invoke("sweep", big, "--resume", in_tmp).exit_code == 2
    result = invoke("sweep", "--resume", in_tmp)
    assert result.exit_code == 2
    assert "is not a study directory" in result.output


# -- running a sweep ------------------------------------------------------------------------


@pytest.fixture(scope="module")
def reference(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """``SWEEP`` run by the command line in this process, one worker."""
    base = tmp_path_factory.mktemp("sweep")
    path = write_yaml(base / "tiny.yaml", SWEEP)
    result = invoke("sweep", path, "--out", base / "out", "--workers", 1)
    assert result.exit_code == 0, result.output
    assert result.output.splitlines()[-1] == str(base / "out")
    return base / "out"


def test_the_sweep_directory_has_the_contract_files(reference: Path) -> None:
    resolved = yaml.safe_load((reference / sweepdir.SWEEP_FILE).read_text())
    assert resolved["seeds"] == "0-2"
    assert load_config(resolved["base"]) == load_config(BASE).for_seed(0)
    rows = _results(reference)
    assert list(rows[0]) == [
        "point", "agent.alpha", "agent.algorithm", "seed", "solved_episode",
        "env_steps_to_solve", "first_greedy_success_env_steps", "eval_mean", "success",
        "episodes", "env_steps", "train_seconds", "mean_return", "rms_error",
    ]  # fmt: skip
    assert [(row["point"], row["seed"]) for row in rows] == [
        (f"{p:03d}", str(s)) for p in range(4) for s in range(3)
    ]
    assert [row["agent.algorithm"] for row in rows[:6]] == ["q_learning"] * 3 + ["sarsa"] * 3
    for point in range(4):
        with np.load(reference / "points" / f"{point:03d}" / "q_tables.npz") as tables:
            assert tables.files == ["seed-000", "seed-001", "seed-002"]
        assert (reference / "points" / f"{point:03d}" / "config.yaml").is_file()
    assert (reference / sweepdir.FIGURE_FILE).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize(("point", "seed"), [(0, 0), (3, 2)])
def test_each_run_is_exactly_train_with_the_point_config_and_seed(
    reference: Path, tmp_path: Path, point: int, seed: int
) -> None:
    point_dir = reference / "points" / f"{point:03d}"
    result = invoke("train", "-c", point_dir / "config.yaml", "--seed", seed, "--out",
                    tmp_path / "run", "-q")  # fmt: skip
    assert result.exit_code == 0, result.output
    trained = np.load(tmp_path / "run" / "q_table.npy")
    with np.load(point_dir / "q_tables.npz") as tables:
        assert tables[f"seed-{seed:03d}"].tobytes() == trained.tobytes()
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    row = next(
        r for r in _results(reference) if r["point"] == f"{point:03d}" and r["seed"] == str(seed)
    )
    assert float(row["eval_mean"]) == summary["eval"]["mean"]
    assert row["solved_episode"] == (
        "" if summary["solved_episode"] is None else str(summary["solved_episode"])
    )
    assert int(row["episodes"]) == summary["episodes"]
    assert int(row["env_steps"]) == summary["env_steps"]
    assert row["success"] == (
        "true" if summary["eval"]["mean"] >= summary["reward_threshold"] else "false"
    )
    greedy = summary["first_greedy_success"]
    assert row["first_greedy_success_env_steps"] == (
        "" if greedy is None else str(greedy["env_steps"])
    )
    with (tmp_path / "run" / "metrics.csv").open(newline="") as file:
        returns = [float(line["return"]) for line in csv.DictReader(file)]
    assert float(row["mean_return"]) == math.fsum(returns) / len(returns)


def test_points_csv_holds_each_points_statistics(reference: Path) -> None:
    rows = _results(reference)
    with (reference / sweepdir.POINTS_FILE).open(newline="") as file:
        points = list(csv.DictReader(file))
    assert [p["point"] for p in points] == ["000", "001", "002", "003"]
    for point in points:
        mine = [r for r in rows if r["point"] == point["point"]]
        expected = summarize_point(
            [float(r["eval_mean"]) for r in mine],
            [r["success"] == "true" for r in mine],
            [float(r["solved_episode"]) if r["solved_episode"] else None for r in mine],
            [float(r["env_steps_to_solve"]) if r["env_steps_to_solve"] else None for r in mine],
        )
        for name, value in expected.as_row().items():
            assert point[name] == sweepdir.cell(value), name


def test_results_do_not_depend_on_the_number_of_workers(reference: Path, tmp_path: Path) -> None:
    spec = load_sweep(reference / sweepdir.SWEEP_FILE)
    directory = sweeping.start_sweep(spec, tmp_path / "two")
    outcome = sweeping.run_sweep(spec, directory, workers=2)
    assert outcome.complete
    assert _without_timings(_results(directory)) == _without_timings(_results(reference))
    assert (directory / sweepdir.POINTS_FILE).read_bytes() == (
        reference / sweepdir.POINTS_FILE
    ).read_bytes()


def test_a_stopped_sweep_resumes_to_the_same_results(reference: Path, tmp_path: Path) -> None:
    spec = load_sweep(reference / sweepdir.SWEEP_FILE)
    directory = sweeping.start_sweep(spec, tmp_path / "stopped")
    calls = iter(range(1000))
    outcome = sweeping.run_sweep(spec, directory, workers=1, should_stop=lambda: next(calls) >= 5)
    assert not outcome.complete
    assert 0 < outcome.done_runs < spec.runs
    assert len(_results(directory)) == outcome.done_runs
    assert not (directory / sweepdir.POINTS_FILE).exists()
    result = invoke("sweep", "--resume", directory, "--workers", 1, "-q")
    assert result.exit_code == 0, result.output
    assert _without_timings(_results(directory)) == _without_timings(_results(reference))
    for point in range(4):
        name = Path("points") / f"{point:03d}" / "q_tables.npz"
        with np.load(directory / name) as mine, np.load(reference / name) as theirs:
            assert {k: mine[k].tobytes() for k in mine.files} == {
                k: theirs[k].tobytes() for k in theirs.files
            }


@pytest.mark.slow
def test_kill_9_at_any_moment_then_resume_loses_and_duplicates_nothing(
    reference: Path, tmp_path: Path
) -> None:
    """A real process, killed with SIGKILL (workers included) as soon as rows appear."""
    path = write_yaml(tmp_path / "kill.yaml", {**SWEEP, "seeds": "0-99"})
    directory = tmp_path / "killed"
    with (tmp_path / "err").open("wb") as err:
        process = subprocess.Popen(
            [sys.executable, "-m", "cartpole_q", "sweep", str(path), "--out", str(directory),
             "--workers", "2"],
            stdout=subprocess.DEVNULL, stderr=err, start_new_session=True, cwd=tmp_path,
        )  # fmt: skip
    try:
        deadline = time.monotonic() + 120
        while not (directory / sweepdir.RESULTS_FILE).is_file():
            assert process.poll() is None, (tmp_path / "err").read_text()
            assert time.monotonic() < deadline, "no results.csv appeared"
            time.sleep(0.02)
    finally:
        os.killpg(process.pid, signal.SIGKILL)
        process.wait()
    done = _results(directory)
    assert 0 < len(done) < 4 * 100
    result = invoke("sweep", "--resume", directory, "-q")
    assert result.exit_code == 0, result.output
    rows = _results(directory)
    assert [(r["point"], r["seed"]) for r in rows] == [
        (f"{p:03d}", str(s)) for p in range(4) for s in range(100)
    ]
    kept = {(r["point"], r["seed"]): r for r in _without_timings(rows)}
    for row in _without_timings(done):
        assert kept[(row["point"], row["seed"])] == row
    # and the same as an uninterrupted run of the first three seeds
    first = [r for r in _without_timings(rows) if int(r["seed"]) < 3]
    assert first == _without_timings(_results(reference))


@pytest.mark.slow
def test_the_ray_backend_gives_the_same_results_on_a_local_cluster(
    reference: Path, tmp_path: Path
) -> None:
    ray = pytest.importorskip("ray")
    spec = load_sweep(reference / sweepdir.SWEEP_FILE)
    directory = sweeping.start_sweep(spec, tmp_path / "ray")
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        outcome = sweeping.run_sweep(spec, directory, workers=2, backend="ray")
    finally:
        ray.shutdown()
    assert outcome.complete
    assert _without_timings(_results(directory)) == _without_timings(_results(reference))


@pytest.mark.slow
@pytest.mark.parametrize(
    ("signum", "count"),
    [
        pytest.param(signal.SIGTERM, 1, id="SIGTERM"),
        pytest.param(signal.SIGINT, 2, id="SIGINT-twice"),
    ],
)
def test_a_signal_ends_the_sweep_with_130_and_no_process_left(
    reference: Path, tmp_path: Path, signum: int, count: int
) -> None:
    from tests.test_signals import _assert_ends_cleanly, _signal, _start

    path = write_yaml(tmp_path / "sig.yaml", {**SWEEP, "seeds": "0-199"})
    directory = tmp_path / "sig"
    process = _start(tmp_path, "sweep", path, "--out", directory, "--workers", 2, "-q")
    deadline = time.monotonic() + 120
    while not (directory / sweepdir.RESULTS_FILE).is_file():
        assert process.poll() is None, (tmp_path / "stderr").read_text()
        assert time.monotonic() < deadline, "no results.csv appeared"
        time.sleep(0.02)
    _signal(process, signum, count, group=True)
    stderr = _assert_ends_cleanly(process, tmp_path)
    assert f"cartpole-q sweep --resume {directory}" in stderr
    result = invoke("sweep", "--resume", directory, "-q")
    assert result.exit_code == 0, result.output
    rows = _without_timings(_results(directory))
    assert len(rows) == 4 * 200
    assert [r for r in rows if int(r["seed"]) < 3] == _without_timings(_results(reference))


def test_an_interruption_while_saving_loses_nothing_saved_and_resumes(
    reference: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A second Ctrl-C (or a failed write) during a save: no other error hides it."""
    spec = load_sweep(reference / sweepdir.SWEEP_FILE)
    directory = sweeping.start_sweep(spec, tmp_path / "saving")
    real_write = sweepdir.write_results
    calls = []

    def write_then_interrupt(*args: Any, **kwargs: Any) -> None:
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt
        real_write(*args, **kwargs)

    monkeypatch.setattr(sweepdir, "write_results", write_then_interrupt)
    monkeypatch.setattr(sweeping, "MAX_RUNS_PER_TASK", 3)  # several saves
    monkeypatch.setattr(sweeping, "FLUSH_SECONDS", 0.0)
    with pytest.raises(KeyboardInterrupt):
        sweeping.run_sweep(spec, directory, workers=1)
    monkeypatch.setattr(sweepdir, "write_results", real_write)
    assert 0 < len(_results(directory)) < spec.runs
    outcome = sweeping.run_sweep(spec, directory, workers=1)
    assert outcome.complete
    assert _without_timings(_results(directory)) == _without_timings(_results(reference))


# -- resume: a study never mixes results ------------------------------------------------------


def _stopped_sweep(tmp_path: Path, data: dict[str, Any], after: int = 5) -> Path:
    """A sweep started by the command's code and stopped after ``after`` runs."""
    path = write_yaml(tmp_path / "s.yaml", data)
    spec = load_sweep(path)
    # Compiled first: the stop request counts runs, not the polls of a cold cache's compiling.
    compile_ahead([plan_run(point.config) for point in spec.points], workers=1)
    directory = sweeping.start_sweep(spec, tmp_path / "stopped")
    calls = iter(range(10_000))
    outcome = sweeping.run_sweep(
        spec, directory, workers=1, should_stop=lambda: next(calls) >= after
    )
    assert 0 < outcome.done_runs < spec.runs
    return directory


def _edit_sweep_yaml(directory: Path, edit: Any) -> None:
    path = directory / sweepdir.SWEEP_FILE
    data = yaml.safe_load(path.read_text())
    edit(data)
    path.write_text(yaml.safe_dump(data, sort_keys=False))


EDITS = [
    pytest.param(
        lambda d: d["grid"].update({"agent.alpha": [0.1, 0.9]}),
        "agent.alpha: point 002 started with 0.5, sweep.yaml now gives 0.9",
        id="an axis value",
    ),
    pytest.param(
        lambda d: d["base"]["train"].update({"episodes": 61}),
        "train.episodes: point 000 started with 60, sweep.yaml now gives 61",
        id="a base key",
    ),
    pytest.param(
        lambda d: d["grid"].update({"agent.alpha": [0.1, 0.5, 0.9]}),
        "the sweep started with 4 points, sweep.yaml now gives 6",
        id="one more axis value",
    ),
    pytest.param(
        lambda d: d.update({"seeds": "1-2"}),
        "seeds: it now gives 1-2, but",
        id="a finished seed taken away",
    ),
    pytest.param(
        lambda d: d.update({"name": "other"}),
        'name: point 000 started with "tiny-000", sweep.yaml now gives "other-000"',
        id="the name",
    ),
]


@pytest.mark.parametrize(("edit", "message"), EDITS)
def test_resume_refuses_a_sweep_yaml_edited_since_the_start(
    tmp_path: Path, edit: Any, message: str
) -> None:
    directory = _stopped_sweep(tmp_path, SWEEP)
    before = _results(directory)
    _edit_sweep_yaml(directory, edit)
    result = invoke("sweep", "--resume", directory, "--workers", 1, "-q")
    assert result.exit_code == 2, result.output
    assert message in result.output
    assert "Traceback" not in result.output
    assert _results(directory) == before  # nothing run, nothing rewritten
    assert not (directory / sweepdir.POINTS_FILE).exists()


def test_resume_may_add_seeds_and_then_equals_a_sweep_of_them_all(
    reference: Path, tmp_path: Path
) -> None:
    directory = _stopped_sweep(tmp_path, {**SWEEP, "seeds": "0-1"}, after=2)
    _edit_sweep_yaml(directory, lambda d: d.update({"seeds": "0-2"}))
    result = invoke("sweep", "--resume", directory, "--workers", 1, "-q")
    assert result.exit_code == 0, result.output
    assert _without_timings(_results(directory)) == _without_timings(_results(reference))


# -- one writer at a time, and what a kill or a signal leaves ------------------------------------

# Slow runs: the gymnasium engine, 100 episodes each (about a tenth of a second per run).
SLOW = {
    "name": "slow",
    "base": {
        **BASE,
        "engine": "gymnasium",
        "train": {**BASE["train"], "episodes": 100, "stop_when_solved": False, "eval_every": 0},
    },
    "seeds": "0-199",
}


def _start_sweep(tmp_path: Path, *args: object) -> subprocess.Popen[bytes]:
    from tests.test_signals import _start

    return _start(tmp_path, "sweep", *args)


def _wait_for(path: Path, process: subprocess.Popen[bytes], tmp_path: Path) -> None:
    deadline = time.monotonic() + 120
    while not path.is_file():
        assert process.poll() is None, (tmp_path / "stderr").read_text()
        assert time.monotonic() < deadline, f"{path} never appeared"
        time.sleep(0.01)


@pytest.mark.slow
def test_a_second_writer_is_refused_naming_the_holders_pid(tmp_path: Path) -> None:
    # Long enough to outlast the second writer's patience (store/lock.py waits 2 s).
    path = write_yaml(tmp_path / "slow.yaml", {**SLOW, "seeds": "0-59"})
    directory = tmp_path / "locked"
    process = _start_sweep(tmp_path, path, "--out", directory, "--workers", 1, "-q")
    try:
        _wait_for(directory / sweepdir.RESULTS_FILE, process, tmp_path)
        result = invoke("sweep", "--resume", directory, "--workers", 1, "-q")
        assert result.exit_code == 2, result.output
        assert f"another cartpole-q process (pid {process.pid}) is writing this sweep" in (
            result.output
        )
        assert process.poll() is None  # the holder goes on undisturbed
    finally:
        os.killpg(process.pid, signal.SIGKILL)
        process.wait()
    # kill -9 released the lock: the sweep resumes
    result = invoke("sweep", "--resume", directory, "--workers", 2, "-q")
    assert result.exit_code == 0, result.output
    assert len(_results(directory)) == 60


@pytest.mark.slow
def test_every_finished_run_is_saved_at_once_whatever_the_task_size(tmp_path: Path) -> None:
    """Tasks of 25 runs: the first results.csv holds the first runs, not whole tasks."""
    fast = {**SLOW, "base": {**SLOW["base"], "engine": "numba"}}
    path = write_yaml(tmp_path / "fast.yaml", fast)
    directory = tmp_path / "streamed"
    spec = load_sweep(path)
    tasks = sweeping.plan_tasks(spec, [(0, seed) for seed in spec.seeds], workers=2)
    assert len(tasks[0][0][2]) == 25  # runs per task
    process = _start_sweep(tmp_path, path, "--out", directory, "--workers", 2, "-q")
    try:
        _wait_for(directory / sweepdir.RESULTS_FILE, process, tmp_path)
        first = len(_results(directory))
    finally:
        os.killpg(process.pid, signal.SIGKILL)
        process.wait()
    assert 1 <= first < 25, "runs reach results.csv one by one, not a task at a time"
    saved = _results(directory)
    result = invoke("sweep", "--resume", directory, "--workers", 2, "-q")
    assert result.exit_code == 0, result.output
    rows = {(r["point"], r["seed"]): r for r in _without_timings(_results(directory))}
    assert len(rows) == 200
    for row in _without_timings(saved):
        assert rows[(row["point"], row["seed"])] == row


def test_a_signal_as_soon_as_the_directory_exists_is_answered_like_any_other(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A real SIGINT right after ``sweep.yaml`` is written, before any run or compilation."""
    monkeypatch.setattr(sweepdir, "write_sweep", then_sigint(sweepdir.write_sweep))
    directory = tmp_path / "early"
    result = invoke("sweep", write_yaml(tmp_path / "s.yaml", SWEEP), "--out", directory, "-q")
    assert result.exit_code == 130, result.output
    results = directory / sweepdir.RESULTS_FILE
    assert f"no run had finished, so nothing is saved in {results} yet" in result.stderr
    assert f"cartpole-q sweep --resume {directory}" in result.stderr
    resumed = invoke("sweep", "--resume", directory, "-q")
    assert resumed.exit_code == 0, resumed.output
    assert len(_results(directory)) == 12


@pytest.mark.slow
@pytest.mark.parametrize("early", [True, False], ids=["before-any-run", "after-some-runs"])
def test_a_second_sigint_says_exactly_what_is_saved(tmp_path: Path, early: bool) -> None:
    from tests.test_signals import _assert_ends_cleanly, _signal

    path = write_yaml(tmp_path / "slow.yaml", SLOW)
    directory = tmp_path / "sig"
    process = _start_sweep(tmp_path, path, "--out", directory, "--workers", 2, "-q")
    _wait_for(directory / (sweepdir.SWEEP_FILE if early else sweepdir.RESULTS_FILE), process,
              tmp_path)  # fmt: skip
    _signal(process, signal.SIGINT, 2, group=True)
    stderr = _assert_ends_cleanly(process, tmp_path)
    results = directory / sweepdir.RESULTS_FILE
    # Stopped at once, or (when the first signal ended it before the second came) politely:
    # either way the message says exactly what results.csv holds.
    saved = len(_results(directory)) if results.is_file() else 0
    if saved:
        assert f": {saved} of 200 runs are saved in {results}" in stderr
    else:
        assert f": no run had finished, so nothing is saved in {results} yet" in stderr
    assert f"cartpole-q sweep --resume {directory}" in stderr


# -- a figure drawn from results.csv (S&B Figure 6.3) ---------------------------------------

CLIFF = {
    "name": "cliff",
    "base": {
        "env": {"id": "CliffWalking-v1"},
        "agent": {"gamma": 1.0, "epsilon": 0.1, "q_init": 0.0, "tie_break": "random"},
        "train": {"episodes": 5, "stop_when_solved": False, "eval_every": 0, "checkpoint_every": 0},
        "eval": {"episodes": 1},
    },
    "seeds": "0-1",
    "curves": False,
    "grid": {
        "agent.algorithm": ["sarsa", "q_learning"],
        "train.episodes": [5, 20],
        "agent.alpha": [0.5, 1.0],
    },
    "figure": {
        "metric": "return", "against": "agent.alpha", "dashed": {"train.episodes": 5},
        "file": "fig.png",
    },
}  # fmt: skip


def test_a_sweep_without_curves_draws_the_mean_return_of_each_run_from_results(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Figure 6.3's shape: interim (a short run, dashed) and asymptotic (a long run, solid)."""
    out = tmp_path / "out"
    result = invoke("sweep", write_yaml(tmp_path / "c.yaml", CLIFF), "--out", out, "--workers", 1)
    assert result.exit_code == 0, result.output
    assert not list(out.glob("points/*/curves.npz")), "curves: false keeps no curves"
    rows = _results(out)
    # The long run of a seed, trained alone: its mean return, and the short run's (its first
    # 5 episodes: the same seed runs the same episodes), exactly.
    point = next(r["point"] for r in rows if r["agent.algorithm"] == "sarsa"
                 and r["train.episodes"] == "20" and r["agent.alpha"] == "0.5")  # fmt: skip
    run = invoke("train", "-c", out / "points" / point / "config.yaml", "--seed", 1,
                 "--out", tmp_path / "run", "-q")  # fmt: skip
    assert run.exit_code == 0, run.output
    with (tmp_path / "run" / "metrics.csv").open(newline="") as file:
        returns = [float(line["return"]) for line in csv.DictReader(file)]
    assert len(returns) == 20

    def cell(episodes: str, seed: str) -> float:
        return float(next(
            r["mean_return"] for r in rows if r["agent.algorithm"] == "sarsa"
            and r["train.episodes"] == episodes and r["agent.alpha"] == "0.5" and r["seed"] == seed
        ))  # fmt: skip

    assert cell("20", "1") == math.fsum(returns) / 20
    assert cell("5", "1") == math.fsum(returns[:5]) / 5
    # The plotted y: the mean over seeds of their mean_return.
    with (out / "fig.csv").open(newline="") as file:
        plotted = {(r["series"], r["x"]): float(r["y"]) for r in csv.DictReader(file)}
    assert sorted({series for series, _ in plotted}) == [
        "algorithm q_learning, episodes 20", "algorithm q_learning, episodes 5",
        "algorithm sarsa, episodes 20", "algorithm sarsa, episodes 5",
    ]  # fmt: skip
    assert plotted[("algorithm sarsa, episodes 5", "0.5")] == np.mean(
        [cell("5", "0"), cell("5", "1")]
    )
    # A colour per algorithm; the short runs dashed.
    drawn: dict[str, Any] = {}

    def capture(lines, *args, **kwargs):  # type: ignore[no-untyped-def]
        drawn["labels"] = [line[0] for line in lines]
        drawn["styles"] = kwargs["line_styles"]
        from cartpole_q.figures import summary_line_figure

        return summary_line_figure(lines, *args, **kwargs)

    monkeypatch.setattr(sweeping, "summary_line_figure", capture)
    spec = load_sweep(out / sweepdir.SWEEP_FILE)
    points = [out / "points" / spec.point_id(p.index) for p in spec.points]
    sweeping.plot_against(spec, points, tmp_path / "again.png")
    assert drawn["labels"] == [
        "algorithm sarsa, episodes 5", "algorithm sarsa, episodes 20",
        "algorithm q_learning, episodes 5", "algorithm q_learning, episodes 20",
    ]  # fmt: skip
    assert drawn["styles"] == [(0, True), (0, False), (1, True), (1, False)]


def test_a_figure_without_mean_return_in_results_is_refused(tmp_path: Path) -> None:
    """A results.csv older than the column (resumed) cannot draw the figure: it says so."""
    sweep = {
        **CLIFF, "seeds": "0", "grid": {"train.episodes": [3, 4], "agent.alpha": [0.5]},
        "figure": {**CLIFF["figure"], "dashed": {"train.episodes": 3}},  # type: ignore[dict-item]
    }  # fmt: skip
    out = tmp_path / "out"
    assert invoke("sweep", write_yaml(tmp_path / "c.yaml", sweep), "--out", out).exit_code == 0
    lines = (out / sweepdir.RESULTS_FILE).read_text().splitlines()
    older = "\n".join(line.rsplit(",", 2)[0] for line in lines) + "\n"  # both added columns
    (out / sweepdir.RESULTS_FILE).write_text(older)
    spec = load_sweep(out / sweepdir.SWEEP_FILE)
    points = [out / "points" / spec.point_id(p.index) for p in spec.points]
    with pytest.raises(
        sweepdir.RunError, match=r"results\.csv: point 000, seed 0 has no mean_return"
    ):
        sweeping.plot_against(spec, points, tmp_path / "again.png")


@pytest.mark.parametrize(
    ("change", "named"),
    [
        (
            {"against": None, "curves": True},
            "figure.dashed: styles the lines drawn against an axis",
        ),
        ({"dashed": {"agent.gamma": 1.0}}, "figure.dashed: 'agent.gamma' is not a grid axis"),
        ({"dashed": {"agent.alpha": 0.5}}, "figure.dashed: 'agent.alpha' is not a grid axis"),
        ({"dashed": {"train.episodes": 7}}, "figure.dashed: 7 is not a value of the axis"),
        ({"dashed": {}}, "figure.dashed: must be one grid axis and one of its values"),
        ({"dashed": 5}, "figure.dashed: 5 is not a Mapping"),
        ({"first": 3}, "figure: is drawn from the learning curves, but the sweep says curves"),
        ({"metric": "length"}, "figure: is drawn from the learning curves, but the sweep says"),
    ],
)
def test_a_figure_from_results_and_its_dashed_lines_are_checked(
    change: dict[str, Any], named: str
) -> None:
    change = dict(change)
    curves = change.pop("curves", False)
    figure = {**CLIFF["figure"], **change}  # type: ignore[dict-item]
    figure = {key: value for key, value in figure.items() if value is not None}
    with pytest.raises(ConfigError, match=re.escape(named)):
        load_sweep({**CLIFF, "curves": curves, "figure": figure})


def test_the_figure_6_3_study_file_runs_the_books_grid() -> None:
    """examples/book/fig6_3_cliff_alpha.yaml: 3 algorithms x {100, 100,000} episodes x 19 alphas."""
    spec = load_sweep(REPO / "examples" / "book" / "fig6_3_cliff_alpha.yaml")
    assert spec.grid["agent.algorithm"] == ["sarsa", "expected_sarsa", "q_learning"]
    assert spec.grid["train.episodes"] == [100, 100_000]
    assert spec.grid["agent.alpha"] == [round(0.1 + 0.05 * i, 2) for i in range(19)]
    assert spec.seeds == tuple(range(100)) and spec.runs == 11_400 and not spec.curves
    assert spec.figure is not None and spec.figure.dashed == {"train.episodes": 100}
    agent = spec.points[0].config.agent
    assert (agent.gamma, agent.epsilon.start, agent.q_init, agent.tie_break) == (
        1.0, 0.1, 0.0, "random",
    )  # fmt: skip


def test_the_shipped_figure_6_3_data_shows_the_books_findings() -> None:
    """docs/book/fig6_3_cliff_alpha.csv, as the textbook page reports it."""
    with (REPO / "docs" / "book" / "fig6_3_cliff_alpha.csv").open(newline="") as file:
        rows = list(csv.DictReader(file))
    line: dict[str, dict[float, float]] = {}
    for row in rows:
        line.setdefault(row["series"], {})[float(row["x"])] = float(row["y"])
    alphas = [round(0.1 + 0.05 * i, 2) for i in range(19)]
    assert all(list(points) == alphas for points in line.values()) and len(line) == 6

    def of(algorithm: str, episodes: int) -> dict[float, float]:
        return line[f"algorithm {algorithm}, episodes {episodes}"]

    for episodes in (100, 100_000):  # Expected SARSA above SARSA at every alpha
        assert all(of("expected_sarsa", episodes)[a] > of("sarsa", episodes)[a] for a in alphas)
    assert all(-51.0 < y < -50.5 for y in of("q_learning", 100_000).values())
    assert all(-21.0 < y < -20.5 for y in of("expected_sarsa", 100_000).values())
    sarsa = of("sarsa", 100_000)
    assert [sarsa[a] for a in alphas] == sorted((sarsa[a] for a in alphas), reverse=True)
    assert round(sarsa[1.0]) == -1029 and round(of("expected_sarsa", 100)[1.0], 1) == -44.1
