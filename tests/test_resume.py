"""Interruption and resume: nothing finished is lost, and resuming changes nothing."""

from __future__ import annotations

import dataclasses
import json
import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import yaml
from PIL import Image
from typer.testing import CliRunner

from cartpole_q.cli import app
from cartpole_q.config import load_config
from cartpole_q.experiments.run import execute_run, prepare, start_run
from cartpole_q.store import rundir
from cartpole_q.store.checkpoint import load_checkpoint, write_checkpoint
from cartpole_q.store.lock import LOCK_FILE
from tests.conftest import write_yaml

RESULT_FILES = ("q_table.npy", "visits.npy", "metrics.csv", "evaluations.csv")


def _reference(tmp_path: Path, overrides: dict) -> Path:
    """An uninterrupted run of the same config."""
    prepared = prepare(load_config(overrides=overrides), "test")
    reference = start_run(prepared, tmp_path / "reference")
    execute_run(reference, prepared)
    return reference


def _assert_same_results(run: Path, reference: Path) -> None:
    for name in RESULT_FILES:
        assert (run / name).read_bytes() == (reference / name).read_bytes(), name
    summary = json.loads((run / "summary.json").read_text())
    expected = json.loads((reference / "summary.json").read_text())
    for key in (
        "episodes",
        "env_steps",
        "solved_episode",
        "q_table",
        "eval",
        "first_greedy_success",
    ):
        assert summary[key] == expected[key], key
    assert summary["interrupted"] is False
    # a run that reached train.episodes keeps its checkpoint, so that it can be extended
    settings = load_config(run / "config.yaml").train
    extendable = (summary["solved_episode"] is None or not settings.stop_when_solved) and (
        settings.max_env_steps is None or summary["env_steps"] < settings.max_env_steps
    )
    assert (run / rundir.CHECKPOINT_FILE).exists() == extendable


@pytest.mark.parametrize(
    ("engine", "algorithm"),
    [
        ("numba", "q_learning"),
        ("gymnasium", "q_learning"),
        ("numba", "sarsa"),
        ("gymnasium", "expected_sarsa"),
        ("numba", "double_q_learning"),
        ("gymnasium", "double_q_learning"),
    ],
)
@pytest.mark.parametrize(
    ("episodes", "stop_after_polls"),
    [(120, 1), (120, 7), (230, 19)],  # the last run solves (about episode 175) before it stops
)
def test_interrupted_run_is_complete_and_resumes_byte_identically(
    tmp_path: Path, engine: str, algorithm: str, episodes: int, stop_after_polls: int
) -> None:
    overrides = {
        "engine": engine, "seed": 2, "train.episodes": episodes, "train.stop_when_solved": False,
        "train.checkpoint_every": 25, "train.eval_every": 10, "agent.algorithm": algorithm,
    }  # fmt: skip
    reference = _reference(tmp_path, overrides)
    prepared = prepare(load_config(overrides=overrides), "test")
    run = start_run(prepared, tmp_path / "run")
    polls = iter(range(10**9))
    outcome = execute_run(run, prepared, should_stop=lambda: next(polls) >= stop_after_polls - 1)

    assert outcome.result.interrupted
    summary = json.loads((run / "summary.json").read_text())
    assert summary["interrupted"] is True and 0 < summary["episodes"] < episodes
    loaded = rundir.load_run(run)  # the interrupted run is a complete, usable run directory
    assert len(loaded.metrics.returns) == summary["episodes"]
    assert (run / rundir.CHECKPOINT_FILE).is_file()

    result = CliRunner().invoke(app, ["train", "--resume", str(run), "-q"], catch_exceptions=False)
    assert result.exit_code == 0, result.output
    assert result.stdout.strip() == str(run)
    _assert_same_results(run, reference)


@pytest.mark.parametrize(
    ("engine", "algorithm"),
    [("numba", "q_learning"), ("gymnasium", "q_learning"), ("numba", "double_q_learning")],
)
def test_a_sample_average_run_resumes_byte_identically(
    tmp_path: Path, engine: str, algorithm: str
) -> None:
    """``agent.alpha: sample_average``: the update counts are checkpointed with the memory."""
    overrides = {
        "engine": engine, "seed": 3, "env.id": "FrozenLake-v1", "discretization": None,
        "agent.algorithm": algorithm, "agent.alpha": "sample_average", "agent.epsilon": 0.2,
        "agent.q_init": 0.0, "agent.gamma": 0.95, "train.episodes": 300,
        "train.stop_when_solved": False, "train.checkpoint_every": 25, "train.eval_every": 0,
    }  # fmt: skip
    reference = _reference(tmp_path, overrides)
    prepared = prepare(load_config(overrides=overrides), "test")
    run = start_run(prepared, tmp_path / "run")
    polls = iter(range(10**9))
    outcome = execute_run(run, prepared, should_stop=lambda: next(polls) >= 2)
    assert outcome.result.interrupted
    checkpoint = np.load(run / rundir.CHECKPOINT_FILE)
    visits = checkpoint["visits"].reshape(16, 4).astype(np.float64)
    # each step updates its pair once: in Q-learning's one table (its counts, the only
    # memory), in one of Double Q's two (B's counts memory_1, A's the last, memory_2)
    if algorithm == "q_learning":
        counts = checkpoint["memory_0"]
    else:
        counts = checkpoint["memory_1"] + checkpoint["memory_2"]
        assert checkpoint["memory_1"].sum() > 0 and checkpoint["memory_2"].sum() > 0
    assert counts.shape == (16, 4) and counts.sum() > 0
    assert counts.tolist() == visits.tolist()

    result = CliRunner().invoke(app, ["train", "--resume", str(run), "-q"], catch_exceptions=False)
    assert result.exit_code == 0, result.output
    _assert_same_results(run, reference)


def test_resume_refuses_a_finished_run_and_other_options(tmp_path: Path) -> None:
    reference = _reference(tmp_path, {"train.episodes": 5})
    runner = CliRunner()
    result = runner.invoke(app, ["train", "--resume", str(reference)])
    assert result.exit_code == 2 and "already finished all 5 episodes" in result.stderr
    assert "--episodes N" in result.stderr
    result = runner.invoke(app, ["train", "--resume", str(reference), "--episodes", "5"])
    assert result.exit_code == 2 and "already finished" in result.stderr
    for option in (["--seed", "3"], ["--set", "seed=3"], ["-c", "blog"]):
        result = runner.invoke(app, ["train", "--resume", str(reference), *option])
        assert result.exit_code == 2 and option[0] in result.stderr
    result = runner.invoke(app, ["train", "--resume", str(tmp_path / "nothing")])
    assert result.exit_code == 2 and "not a run directory" in result.stderr


def test_damaged_checkpoint_is_refused(tmp_path: Path) -> None:
    prepared = prepare(
        load_config(overrides={"train.episodes": 50, "train.checkpoint_every": 10}), "t"
    )
    run = start_run(prepared, tmp_path / "run")
    execute_run(run, prepared, should_stop=lambda: True)
    (run / rundir.CHECKPOINT_FILE).write_bytes(b"PK\x03\x04 truncated")
    result = CliRunner().invoke(app, ["train", "--resume", str(run)])
    assert result.exit_code == 2 and "checkpoint is damaged" in result.stderr


# -- resume checks the config it continues; a finished run can be extended (issue 8) ----


def _interrupted(tmp_path: Path, overrides: dict, polls: int = 2) -> Path:
    prepared = prepare(load_config(overrides=overrides), "test")
    run = start_run(prepared, tmp_path / "run")
    remaining = iter(range(polls, 0, -1))
    execute_run(run, prepared, should_stop=lambda: next(remaining) <= 1)
    assert (run / rundir.CHECKPOINT_FILE).is_file()
    return run


def _edit_config(run: Path, section: str, key: str, value: object) -> None:
    path = run / "config.yaml"
    data = yaml.safe_load(path.read_text())
    data[section][key] = value
    path.write_text(yaml.safe_dump(data, sort_keys=False))


INTERRUPTIBLE = {
    "seed": 4, "train.episodes": 120, "train.stop_when_solved": False,
    "train.checkpoint_every": 20, "train.eval_every": 10,
}  # fmt: skip


@pytest.mark.parametrize(
    ("section", "key", "value", "named"),
    [
        ("agent", "gamma", 0.9, "agent.gamma: the run was trained with 0.995, config.yaml now says 0.9"),
        ("discretization", "bins", [1, 1, 6, 12], "discretization.bins: the run was trained with [1, 1, 2, 10]"),
        ("train", "eval_every", 5, "train.eval_every"),
        ("train", "episodes", 30, "cannot be shortened to 30"),
    ],
)  # fmt: skip
def test_resume_refuses_an_edited_config(
    tmp_path: Path, section: str, key: str, value: object, named: str
) -> None:
    run = _interrupted(tmp_path, INTERRUPTIBLE)
    checkpoint = (run / rundir.CHECKPOINT_FILE).read_bytes()
    _edit_config(run, section, key, value)
    result = CliRunner().invoke(app, ["train", "--resume", str(run)])
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output and named in result.stderr, result.stderr
    assert result.stderr.strip().count("\n") == 0
    # nothing was touched: put the value back and the run resumes
    assert (run / rundir.CHECKPOINT_FILE).read_bytes() == checkpoint
    assert (run / "summary.json").is_file()


def test_a_checkpoint_without_a_recorded_config_still_refuses_other_bins(tmp_path: Path) -> None:
    run = _interrupted(tmp_path, INTERRUPTIBLE)
    checkpoint = load_checkpoint(run)
    write_checkpoint(run, dataclasses.replace(checkpoint, config=None))
    _edit_config(run, "discretization", "bins", [1, 1, 6, 12])
    result = CliRunner().invoke(app, ["train", "--resume", str(run)])
    assert result.exit_code == 2 and "discretization.bins" in result.stderr, result.output


def test_an_interrupted_run_resumes_to_more_episodes_byte_identically(tmp_path: Path) -> None:
    run = _interrupted(tmp_path, INTERRUPTIBLE)
    _edit_config(run, "train", "episodes", 200)
    result = CliRunner().invoke(app, ["train", "--resume", str(run), "-q"])
    assert result.exit_code == 0, result.output
    _assert_same_results(run, _reference(tmp_path, {**INTERRUPTIBLE, "train.episodes": 200}))


@pytest.mark.parametrize("engine", ["numba", "gymnasium"])
@pytest.mark.parametrize("how", ["option", "config"])
def test_a_finished_run_extends_byte_identically(tmp_path: Path, engine: str, how: str) -> None:
    # episodes 120 stops before the solve (about episode 175); 230 goes past it
    overrides = {**INTERRUPTIBLE, "engine": engine, "train.checkpoint_every": 25}
    prepared = prepare(load_config(overrides=overrides), "test")
    run = start_run(prepared, tmp_path / "run")
    execute_run(run, prepared)
    assert json.loads((run / "summary.json").read_text())["episodes"] == 120
    assert (run / rundir.CHECKPOINT_FILE).is_file()
    if how == "option":
        args = ["train", "--resume", str(run), "--episodes", "230", "-q"]
    else:
        _edit_config(run, "train", "episodes", 230)
        args = ["train", "--resume", str(run), "-q"]
    result = CliRunner().invoke(app, args, catch_exceptions=False)
    assert result.exit_code == 0, result.output
    assert load_config(run / "config.yaml").train.episodes == 230
    reference = _reference(tmp_path, {**overrides, "train.episodes": 230})
    _assert_same_results(run, reference)
    assert (run / "config.yaml").read_bytes() == (reference / "config.yaml").read_bytes()


def test_a_run_stopped_at_its_solve_point_cannot_be_extended(tmp_path: Path) -> None:
    reference = _reference(tmp_path, {"seed": 2, "train.episodes": 300})
    summary = json.loads((reference / "summary.json").read_text())
    assert summary["solved_episode"] == summary["episodes"] < 300
    assert not (reference / rundir.CHECKPOINT_FILE).exists()
    result = CliRunner().invoke(app, ["train", "--resume", str(reference), "--episodes", "400"])
    assert result.exit_code == 2
    assert "where it solved (train.stop_when_solved)" in result.stderr, result.stderr


def test_a_multi_seed_resume_refuses_a_config_its_seeds_were_not_trained_with(
    tmp_path: Path,
) -> None:
    run = tmp_path / "seeds"
    result = CliRunner().invoke(
        app,
        ["train", "--seeds", "0-1", "--episodes", "5", "--workers", "1", "--out", str(run), "-q"],
    )
    assert result.exit_code == 0, result.output
    (run / "summary.json").unlink()  # as if killed before the aggregate was written
    _edit_config(run, "agent", "gamma", 0.9)
    result = CliRunner().invoke(app, ["train", "--resume", str(run)])
    assert result.exit_code == 2, result.output
    assert "agent.gamma: seed-000 was trained with 0.995" in result.stderr, result.stderr
    result = CliRunner().invoke(app, ["train", "--resume", str(run), "--episodes", "9"])
    assert result.exit_code == 2 and "seed-NNN --episodes N" in result.stderr, result.stderr


def test_write_run_refuses_a_non_empty_directory(tmp_path: Path) -> None:
    import cartpole_q

    result = cartpole_q.train({"seed": 3, "train": {"episodes": 5}})
    assert result.config.seed == 3
    run = tmp_path / "run"
    cartpole_q.write_run(run, result)
    before = {path.name: path.read_bytes() for path in run.iterdir()}
    with pytest.raises(rundir.RunError, match="is not empty"):
        cartpole_q.write_run(run, result)
    (tmp_path / "other").mkdir()
    (tmp_path / "other" / "notes.txt").write_text("mine")
    with pytest.raises(rundir.RunError, match="is not empty"):
        cartpole_q.write_run(str(tmp_path / "other"), result)
    assert {path.name: path.read_bytes() for path in run.iterdir()} == before
    cartpole_q.write_run(run, result, overwrite=True)


def test_train_takes_a_path_a_name_or_a_mapping(tmp_path: Path) -> None:
    import cartpole_q

    path = write_yaml(tmp_path / "c.yaml", {"seed": 3, "train": {"episodes": 4}})
    by_path = cartpole_q.train(path, final_eval=False)
    by_mapping = cartpole_q.train({"seed": 3, "train": {"episodes": 4}}, final_eval=False)
    assert by_path.config == by_mapping.config
    assert np.array_equal(by_path.q_table, by_mapping.q_table)
    assert cartpole_q.train("sutton_barto", final_eval=False).config.name == "sutton-barto"


# -- a real signal while an evaluation plays ----------------------------------------------


def _signal_in_evaluation(monkeypatch: pytest.MonkeyPatch, which: int) -> list[int]:
    """A real SIGINT to this process inside the ``which``-th evaluation a stop may cut (1-based).

    It is sent when that evaluation first asks whether to stop (after its first chunk of
    greedy episodes), and the question is answered only once the command's own handler has
    seen it. Returns the list the evaluations' episode counts are appended to.
    """
    import cartpole_q.training as training

    make_engine = training.make_engine
    asked: list[int] = []

    def with_signal(should_stop):  # type: ignore[no-untyped-def]
        sent = False

        def look() -> bool:
            nonlocal sent
            if not sent:
                sent = True
                os.kill(os.getpid(), signal.SIGINT)
                deadline = time.monotonic() + 10
                while not should_stop() and time.monotonic() < deadline:
                    time.sleep(0.001)  # until the handler has run
            return bool(should_stop())

        return look

    def engine(*args, **kwargs):  # type: ignore[no-untyped-def]
        made = make_engine(*args, **kwargs)
        evaluate = made.evaluate

        def evaluate_with_signal(q, episodes, seed, should_stop=None):  # type: ignore[no-untyped-def]
            if should_stop is not None:
                asked.append(episodes)
                if len(asked) == which:
                    should_stop = with_signal(should_stop)
            return evaluate(q, episodes, seed, should_stop)

        made.evaluate = evaluate_with_signal
        return made

    monkeypatch.setattr(training, "make_engine", engine)
    return asked


def _train_args(overrides: dict, out: Path) -> list[str]:
    return ["train", *(f"--set={key}={value}" for key, value in overrides.items()), "--out",
            str(out), "-q"]  # fmt: skip


@pytest.mark.parametrize("engine", ["numba", "gymnasium"])
def test_a_signal_in_the_final_evaluation_stops_it_and_resume_finishes_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, engine: str
) -> None:
    # Solves (about episode 170) and stops there: no checkpoint is due before the evaluation.
    overrides = {"engine": engine, "seed": 1, "train.eval_every": 0, "eval.episodes": 250}
    reference = _reference(tmp_path, overrides)
    run = tmp_path / "run"
    asked = _signal_in_evaluation(monkeypatch, which=1)
    result = CliRunner().invoke(app, _train_args(overrides, run), catch_exceptions=False)

    assert asked == [250]
    assert result.exit_code == 130, result.output
    assert f"interrupted: resume with `cartpole-q train --resume {run}`" in result.stderr
    summary = json.loads((run / "summary.json").read_text())
    expected = json.loads((reference / "summary.json").read_text())
    assert (
        summary["interrupted"] is True and summary["solved_episode"] == expected["solved_episode"]
    )
    assert summary["eval"]["interrupted"] is True and summary["eval"]["episodes"] == 100
    for name in RESULT_FILES:  # what training had finished is all there
        assert (run / name).read_bytes() == (reference / name).read_bytes(), name
    assert (run / rundir.CHECKPOINT_FILE).is_file()

    monkeypatch.undo()
    resumed = CliRunner().invoke(app, ["train", "--resume", str(run), "-q"], catch_exceptions=False)
    assert resumed.exit_code == 0, resumed.output
    _assert_same_results(run, reference)
    assert "interrupted" not in json.loads((run / "summary.json").read_text())["eval"]


def test_a_signal_in_a_periodic_evaluation_drops_it_and_resume_plays_it_again(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    overrides = {
        "seed": 2, "train.episodes": 40, "train.stop_when_solved": False,
        "train.eval_every": 10, "train.eval_episodes": 250, "train.checkpoint_every": 0,
        "eval.episodes": 150,
    }  # fmt: skip
    reference = _reference(tmp_path, overrides)
    run = tmp_path / "run"
    asked = _signal_in_evaluation(monkeypatch, which=2)  # the evaluation after episode 20
    result = CliRunner().invoke(app, _train_args(overrides, run), catch_exceptions=False)

    assert asked == [250, 250, 150]  # two periodic evaluations, then the final one
    assert result.exit_code == 130, result.output
    summary = json.loads((run / "summary.json").read_text())
    assert summary["interrupted"] is True and summary["episodes"] == 20
    assert summary["eval"]["episodes"] == 100 and summary["eval"]["interrupted"] is True
    assert [row.split(",")[0] for row in (run / "evaluations.csv").read_text().split()[1:]] == [
        "10"
    ]

    monkeypatch.undo()
    resumed = CliRunner().invoke(app, ["train", "--resume", str(run), "-q"], catch_exceptions=False)
    assert resumed.exit_code == 0, resumed.output
    _assert_same_results(run, reference)


# -- real signals, in a subprocess ---------------------------------------------------------

# Long enough that a signal sent at the first checkpoint lands in training on a fast machine.
SLOW_EPISODES = 600
SLOW_TRAINING = {
    "name": "slow",
    "engine": "gymnasium",
    "train": {
        "episodes": SLOW_EPISODES,
        "stop_when_solved": False,
        "checkpoint_every": 5,
        "eval_every": 0,
    },
    "eval": {"episodes": 5},
}


def _command(*args: object) -> list[str]:
    return [sys.executable, "-m", "cartpole_q", *map(str, args)]


def _wait_for(path: Path, timeout: float = 120.0) -> None:
    deadline = time.monotonic() + timeout
    while not path.exists():
        assert time.monotonic() < deadline, f"{path} never appeared"
        time.sleep(0.05)


def _check_every_file_loads(run: Path) -> int:
    """Every file in the run directory is absent or complete; return how many were checked."""
    checked = 0
    for path in sorted(run.iterdir()):
        if path.name.startswith(".") and path.name.endswith(".tmp"):
            continue  # a temporary file a kill interrupted: never a contract file, removed on resume
        if path.name == LOCK_FILE:
            continue  # the one-writer lock (empty or a process id), not a result
        if path.suffix == ".yaml":
            load_config(path)
        elif path.name == rundir.CHECKPOINT_FILE:
            load_checkpoint(run)
        elif path.suffix == ".npy":
            assert np.load(path, allow_pickle=False).size > 0
        elif path.suffix == ".csv":
            rows = [line.split(",") for line in path.read_text().splitlines()]
            assert rows and len({len(row) for row in rows}) == 1, path
        elif path.suffix == ".json":
            json.loads(path.read_text())
        elif path.suffix == ".png":
            with Image.open(path) as image:
                image.verify()
        else:
            raise AssertionError(f"unexpected file {path}")
        checked += 1
    return checked


@pytest.mark.slow
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_sigint_or_sigterm_completes_the_run_directory_and_exits_130(
    tmp_path: Path, signum: int
) -> None:
    config = write_yaml(tmp_path / "slow.yaml", SLOW_TRAINING)
    run = tmp_path / "run"
    process = subprocess.Popen(_command("train", "-c", config, "--out", run), stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)  # fmt: skip
    _wait_for(run / rundir.CHECKPOINT_FILE)
    process.send_signal(signum)
    stdout, stderr = process.communicate(timeout=120)
    assert process.returncode == 130, stderr
    name = signal.Signals(signum).name
    assert "Traceback" not in stderr and f"{name}: stopping after the current episode" in stderr
    assert stdout.strip().splitlines()[-1] == str(run)
    summary = json.loads((run / "summary.json").read_text())
    assert summary["interrupted"] is True and 5 <= summary["episodes"] < SLOW_EPISODES
    assert _check_every_file_loads(run) >= 7
    assert len(rundir.load_run(run).metrics.returns) == summary["episodes"]

    resumed = subprocess.run(
        _command("train", "--resume", run, "-q"), capture_output=True, text=True, timeout=300
    )
    assert resumed.returncode == 0, resumed.stderr
    _assert_same_results(run, _reference_of(config, tmp_path))


@pytest.mark.slow
def test_sigint_in_a_long_final_evaluation_ends_it_within_seconds(tmp_path: Path) -> None:
    """Two million greedy episodes (tens of seconds): a SIGINT ends them, the run is kept."""
    config = write_yaml(
        tmp_path / "long-eval.yaml",
        {
            # The run's only checkpoint is written as training ends, right before the evaluation.
            "train": {"episodes": 200, "stop_when_solved": False, "checkpoint_every": 200,
                      "eval_every": 0},
            "eval": {"episodes": 2_000_000},
        },
    )  # fmt: skip
    run = tmp_path / "run"
    process = subprocess.Popen(_command("train", "-c", config, "--out", run, "-q"),
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               start_new_session=True)  # fmt: skip
    _wait_for(run / rundir.CHECKPOINT_FILE)
    time.sleep(0.5)  # into the evaluation
    os.killpg(process.pid, signal.SIGINT)  # as Ctrl-C does
    sent = time.monotonic()
    _, stderr = process.communicate(timeout=120)
    assert process.returncode == 130, stderr
    assert time.monotonic() - sent < 10, "the evaluation should end within seconds"
    assert "Traceback" not in stderr and stderr.count("SIGINT: stopping") == 1, stderr
    summary = json.loads((run / "summary.json").read_text())
    assert summary["interrupted"] is True and summary["episodes"] == 200
    assert summary["eval"]["interrupted"] is True
    assert 100 <= summary["eval"]["episodes"] < 2_000_000
    reference = tmp_path / "reference"
    quick = write_yaml(
        tmp_path / "quick.yaml", {**yaml.safe_load(config.read_text()), "eval": {"episodes": 1}}
    )
    assert subprocess.run(_command("train", "-c", quick, "--out", reference, "-q")).returncode == 0
    for name in ("q_table.npy", "visits.npy", "metrics.csv"):
        assert (run / name).read_bytes() == (reference / name).read_bytes(), name


def _reference_of(config: Path, tmp_path: Path) -> Path:
    prepared = prepare(load_config(config), str(config))
    reference = start_run(prepared, tmp_path / "reference")
    execute_run(reference, prepared)
    return reference


@pytest.mark.slow
def test_sigkill_at_random_instants_never_leaves_a_broken_file(tmp_path: Path) -> None:
    config = write_yaml(tmp_path / "slow.yaml", SLOW_TRAINING)
    run = tmp_path / "run"
    # Each process is killed at a random instant after it has written a new checkpoint, so
    # the kills interrupt training (not only start-up) however fast this machine is.
    delays = [random.Random(seed).uniform(0.0, 0.4) for seed in range(6)]
    resumed_from_checkpoint = 0
    for delay in delays:
        started = (run / rundir.CONFIG_FILE).is_file()
        checkpoint = run / rundir.CHECKPOINT_FILE
        resumed_from_checkpoint += checkpoint.is_file()
        before = checkpoint.stat().st_mtime_ns if checkpoint.is_file() else 0
        args = ("train", "--resume", run) if started else ("train", "-c", config, "--out", run)
        process = subprocess.Popen(
            _command(*args, "-q"), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
        )
        deadline = time.monotonic() + 120
        while process.poll() is None and time.monotonic() < deadline:
            if checkpoint.is_file() and checkpoint.stat().st_mtime_ns > before:
                break
            time.sleep(0.01)
        time.sleep(delay)
        os.kill(process.pid, signal.SIGKILL)
        process.wait()
        if run.exists():
            _check_every_file_loads(run)
        if (run / rundir.SUMMARY_FILE).is_file():
            break  # it finished before the kill
    assert resumed_from_checkpoint >= 2, "the kills should interrupt training, not only start-up"
    final = subprocess.run(
        _command("train", "--resume", run, "-q"), capture_output=True, text=True, timeout=300
    )
    assert final.returncode in (0, 2), final.stderr  # 2: it had already finished
    _assert_same_results(run, _reference_of(config, tmp_path))


@pytest.mark.parametrize("engine", ["numba", "gymnasium"])
def test_a_run_with_a_budget_of_steps_resumes_byte_identically_and_is_not_extended(
    tmp_path: Path, engine: str
) -> None:
    """train.max_env_steps: interrupted before it, the resumed run ends where one run ends."""
    overrides = {
        **INTERRUPTIBLE, "engine": engine, "train.episodes": 300, "train.checkpoint_every": 25,
        "train.max_env_steps": 9_999,
    }  # fmt: skip
    reference = _reference(tmp_path, overrides)
    summary = json.loads((reference / "summary.json").read_text())
    assert summary["env_steps"] == 9_999 and summary["episodes"] < 300
    assert not (reference / rundir.CHECKPOINT_FILE).exists()  # cut: nothing to extend
    run = _interrupted(tmp_path, overrides, polls=3)
    assert json.loads((run / "summary.json").read_text())["env_steps"] < 9_999
    result = CliRunner().invoke(app, ["train", "--resume", str(run), "-q"], catch_exceptions=False)
    assert result.exit_code == 0, result.output
    _assert_same_results(run, reference)
    refused = CliRunner().invoke(app, ["train", "--resume", str(reference), "--episodes", "400"])
    assert refused.exit_code == 2
    assert "it stopped at train.max_env_steps (9,999 env steps)" in refused.stderr


def test_a_budget_reached_with_the_last_episode_keeps_no_checkpoint(tmp_path: Path) -> None:
    """Driving home: 5 steps an episode, 10 episodes, a budget of 50: nothing to extend."""
    overrides = {
        "env.id": "cartpole_q/DrivingHome-v0", "discretization": None, "agent.algorithm": "td",
        "agent.gamma": 1.0, "train.episodes": 10, "train.checkpoint_every": 5,
        "train.eval_every": 0, "train.max_env_steps": 50,
    }  # fmt: skip
    run = _reference(tmp_path, overrides)
    assert json.loads((run / "summary.json").read_text())["env_steps"] == 50
    assert not (run / rundir.CHECKPOINT_FILE).exists()  # the episode-5 checkpoint is gone
    for extra in ([], ["--episodes", "20"]):
        refused = CliRunner().invoke(app, ["train", "--resume", str(run), *extra])
        assert refused.exit_code == 2
        assert "it stopped at train.max_env_steps (50 env steps)" in refused.stderr
