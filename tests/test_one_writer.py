"""Two commands given the same ``--out``: exactly one writes there, the other writes nothing.

Each test runs the second command, in this process, at one chosen instant of the first:

- *while the first writes its start files* (``config.yaml``, ``sweep.yaml``, ``tune.yaml``):
  the window a directory check made before the lock left open. The second must find the
  directory taken, not check it empty, write its own files over the first's and, once the
  first has finished, take the lock and overwrite its results too.
- *before the first takes the lock*: the second starts and finishes first; the first,
  getting the lock then, must find the second's files and be refused without writing.

Running the second command at these instants makes a race that real processes lose only
now and then (one time in two for ``train``, one in 25 for ``sweep``) happen every time.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import yaml
from typer.testing import Result

from cartpole_q.store import lock, rundir, sweepdir, tunedir
from tests.conftest import invoke, write_yaml

EPISODES = {"train": {"episodes": 30}, "eval": {"episodes": 3}}


@pytest.fixture(autouse=True)
def _short_patience(monkeypatch: pytest.MonkeyPatch) -> None:
    # A second writer waits this long for a holder that may be ending before it is refused.
    monkeypatch.setattr(lock, "_PATIENCE_SECONDS", 0.2)


def _second_command_at(
    monkeypatch: pytest.MonkeyPatch, owner: object, name: str, args: tuple[object, ...]
) -> list[Result]:
    """Run ``cartpole-q ARGS`` to its end when ``owner.name`` is first called."""
    real: Callable[..., Any] = getattr(owner, name)
    results: list[Result] = []
    started: list[bool] = []

    def first_the_second_command(*a: Any, **k: Any) -> Any:
        if not started:  # the second command's own calls go through
            started.append(True)
            results.append(invoke(*args))
        return real(*a, **k)

    monkeypatch.setattr(owner, name, first_the_second_command)
    return results


INSTANTS = {
    "while the first writes its start files": None,
    "before the first takes the lock": (lock, "_try_lock"),
}


def _race(
    monkeypatch: pytest.MonkeyPatch,
    instant: str,
    start_file: tuple[object, str],
    first: tuple[object, ...],
    second: tuple[object, ...],
) -> tuple[Result, Result]:
    owner, name = INSTANTS[instant] or start_file
    seconds = _second_command_at(monkeypatch, owner, name, second)
    result = invoke(*first)
    assert len(seconds) == 1, "the second command never ran"
    return result, seconds[0]


def _one_wins(directory: Path, first: Result, second: Result) -> tuple[int, str]:
    """Exactly one command succeeded; the other was refused naming the directory."""
    codes = (first.exit_code, second.exit_code)
    assert sorted(codes) == [0, 2], (first.output, second.output)
    winner = codes.index(0)
    refused = (first, second)[1 - winner]
    assert "Traceback" not in refused.output
    assert refused.stderr.startswith(f"error: {directory}: "), refused.stderr
    assert refused.stderr.count("\n") == 1, refused.stderr
    return winner, refused.stderr


@pytest.mark.parametrize("instant", INSTANTS)
def test_two_trains_on_one_out(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, instant: str
) -> None:
    config = write_yaml(tmp_path / "c.yaml", EPISODES)
    out = tmp_path / "out"
    first = ("train", "-c", config, "--seed", 1, "--out", out, "-q")
    second = ("train", "-c", config, "--seed", 2, "--episodes", 40, "--out", out, "-q")
    results = _race(monkeypatch, instant, (rundir, "write_config"), first, second)
    winner, _ = _one_wins(out, *results)
    seed, episodes = [(1, 30), (2, 40)][winner]
    run = rundir.load_run(out)  # whole: every file of one run, none of the other's
    assert (run.config.seed, run.config.train.episodes) == (seed, episodes)
    assert (run.result.seed, run.result.episodes) == (seed, episodes)
    assert len(run.metrics.returns) == episodes


SWEEP = {"base": EPISODES, "grid": {"agent.alpha": [0.1, 0.5]}}


@pytest.mark.parametrize("instant", INSTANTS)
def test_two_sweeps_on_one_out(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, instant: str
) -> None:
    files = [
        write_yaml(tmp_path / "a.yaml", {**SWEEP, "name": "a", "seeds": "0-1"}),
        write_yaml(tmp_path / "b.yaml", {**SWEEP, "name": "b", "seeds": "5", "grid": {"agent.gamma": [0.9, 0.95, 0.99]}}),
    ]  # fmt: skip
    out = tmp_path / "out"
    first, second = (("sweep", file, "--out", out, "--workers", 1, "-q") for file in files)
    results = _race(monkeypatch, instant, (sweepdir, "write_sweep"), first, second)
    winner, _ = _one_wins(out, *results)
    name, seeds, points = [("a", {"0", "1"}, 2), ("b", {"5"}, 3)][winner]
    assert yaml.safe_load((out / sweepdir.SWEEP_FILE).read_text())["name"] == name
    assert sweepdir.point_ids(out) == [f"{p:03d}" for p in range(points)]
    rows = (out / sweepdir.RESULTS_FILE).read_text().splitlines()[1:]
    assert len(rows) == points * len(seeds)
    # The winner's sweep is whole, so resuming it finds nothing left to run.
    resumed = invoke("sweep", "--resume", out, "-q")
    assert resumed.exit_code == 0, resumed.output


@pytest.mark.parametrize("instant", INSTANTS)
def test_two_tunes_on_one_out(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, instant: str
) -> None:
    pytest.importorskip("optuna")
    space = {"agent.alpha": {"low": 0.05, "high": 1.0}}
    files = [
        write_yaml(tmp_path / f"{name}.yaml", {"name": name, "base": EPISODES, "seeds": "0-1", "trials": trials, "space": space})
        for name, trials in (("a", 2), ("b", 3))
    ]  # fmt: skip
    out = tmp_path / "out"
    first, second = (("tune", file, "--out", out, "--workers", 1, "-q") for file in files)
    results = _race(monkeypatch, instant, (tunedir, "write_tune"), first, second)
    winner, _ = _one_wins(out, *results)
    name, trials = [("a", 2), ("b", 3)][winner]
    assert yaml.safe_load((out / tunedir.TUNE_FILE).read_text())["name"] == name
    assert len((out / tunedir.TRIALS_FILE).read_text().splitlines()) == 1 + trials


BOOK = Path(__file__).resolve().parents[1] / "examples" / "book"


@pytest.mark.parametrize("instant", INSTANTS)
@pytest.mark.parametrize("command", ["dp", "study"])
def test_two_studies_on_one_out(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, instant: str, command: str
) -> None:
    """Issue 47 item 6: two dp (or bandit, updates) commands on one --out both exited 0."""
    from cartpole_q.store import studydir

    files = [BOOK / "fig4_1_small_gridworld.yaml", BOOK / "fig3_2_gridworld.yaml"]
    out = tmp_path / "out"
    first, second = ((command, file, "--out", out, "-q") for file in files)
    results = _race(monkeypatch, instant, (studydir, "write_start"), first, second)
    winner, _ = _one_wins(out, *results)
    name = files[winner].stem
    assert yaml.safe_load((out / studydir.STUDY_FILE).read_text())["name"] == name
    assert sorted(path.name for path in out.glob("*.png")) == [f"{name}.png"]
    assert (out / studydir.SUMMARY_FILE).read_text().startswith(f"{name}: ")
    resumed = invoke(command, "--resume", out, "-q")  # whole: nothing left to run
    assert resumed.exit_code == 0, resumed.output


def test_a_dangling_symlink_out_is_refused_not_replaced(tmp_path: Path) -> None:
    """Issue 47 item 6: a dangling-symlink --out was replaced without --force."""
    link = tmp_path / "link"
    link.symlink_to(tmp_path / "nowhere")
    for command in ("dp", "study", "sweep"):
        result = invoke(command, BOOK / "fig4_1_small_gridworld.yaml", "--out", link, "-q")
        assert result.exit_code == 2, result.output
        assert "dangling symbolic link" in result.stderr, result.stderr
        assert link.is_symlink() and not (tmp_path / "nowhere").exists()
