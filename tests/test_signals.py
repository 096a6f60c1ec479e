"""Real signals to real multi-seed commands: exit 130 within seconds, no process left behind.

Each command runs in its own session (``start_new_session``), so the test can signal the
whole process group as a terminal's Ctrl-C does, and find every process the command
started (workers, multiprocessing's resource tracker) by their session id, even after
they have been orphaned.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

from cartpole_q.cli.report import print_multi_summary
from cartpole_q.config import load_config
from cartpole_q.experiments.multiseed import aggregate, run_seeds, seed_dir
from cartpole_q.experiments.run import prepare, start_run
from cartpole_q.store import rundir
from tests.conftest import invoke, write_yaml

SEEDS = (0, 1, 2)
# Two workers for three seeds: when the first checkpoint appears, seeds 0 and 1 are
# training and seed 2 waits, so a stop always leaves work for --resume.
MULTI_SEED = {
    "name": "sig",
    "engine": "numba",
    "train": {
        "episodes": 4000, "seeds": "0-2", "stop_when_solved": False,
        "eval_every": 0, "checkpoint_every": 500,
    },
    "eval": {"episodes": 10},
}  # fmt: skip
RESULT_FILES = ("q_table.npy", "visits.npy", "metrics.csv")


@pytest.fixture(scope="module")
def reference(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """An uninterrupted multi-seed run of ``MULTI_SEED``, trained in this process."""
    base = tmp_path_factory.mktemp("signals")
    config = write_yaml(base / "multi.yaml", MULTI_SEED)
    prepared = prepare(load_config(config), str(config))
    parent = start_run(prepared, base / "reference")
    summary = run_seeds(prepared, parent, workers=1)
    assert summary.finished == len(SEEDS)
    return parent


_STARTED: list[subprocess.Popen[bytes]] = []
"""the commands this module's tests started (each in its own session)"""


@pytest.fixture(autouse=True)
def no_command_left_running() -> Iterator[None]:
    """A test that fails before it ends its command still ends it (and its workers)."""
    yield
    while _STARTED:
        process = _STARTED.pop()
        if process.poll() is None:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(process.pid, signal.SIGKILL)
            process.wait()


def _start(
    tmp_path: Path, *args: object, env: dict[str, str] | None = None
) -> subprocess.Popen[bytes]:
    """Start ``cartpole-q ARGS`` in a new session; its output goes to files in ``tmp_path``.

    ``env`` replaces the environment (default: this one, so the numba cache stays warm).
    """
    with (tmp_path / "stdout").open("wb") as out, (tmp_path / "stderr").open("wb") as err:
        process = subprocess.Popen(
            [sys.executable, "-m", "cartpole_q", *map(str, args)],
            stdout=out, stderr=err, start_new_session=True, cwd=tmp_path,
            env=env if env is not None else {**os.environ},
        )  # fmt: skip
    _STARTED.append(process)
    return process


def _session(sid: int) -> dict[int, str]:
    """Live (not zombie) processes of session ``sid``: pid -> command line."""
    found = {}
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
            cmdline = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode()
        except OSError:
            continue  # it ended meanwhile
        state, _ppid, _pgrp, session = stat.rsplit(")", 1)[1].split()[:4]
        if int(session) == sid and state != "Z":
            found[int(entry.name)] = cmdline
    return found


def _wait_until(condition: Callable[[], bool], what: str, timeout: float = 60.0) -> None:
    deadline = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < deadline, f"{what} never happened"
        time.sleep(0.05)


def _signal(process: subprocess.Popen[bytes], signum: int, count: int, group: bool) -> None:
    for number in range(count):
        if number:
            time.sleep(0.2)  # two signals at once would reach the handler as one
        if group:
            os.killpg(process.pid, signum)
        else:
            process.send_signal(signum)


def _assert_ends_cleanly(process: subprocess.Popen[bytes], tmp_path: Path) -> str:
    """Exit code 130, no traceback, and no process of its session survives it."""
    try:
        process.wait(timeout=30)
    finally:
        if process.returncode is None:
            # Still running: every thread's stack to its stderr (cartpole-q's faulthandler
            # on SIGUSR1), so the failure says where it was, then the end.
            os.kill(process.pid, signal.SIGUSR1)
            time.sleep(1.0)
            os.killpg(process.pid, signal.SIGKILL)
            process.wait()
            print((tmp_path / "stderr").read_text())  # in the test's report
    stderr = (tmp_path / "stderr").read_text()
    left: dict[int, str] = {}
    deadline = time.monotonic() + 5
    while time.monotonic() < deadline:
        left = _session(process.pid)
        if not left:
            break
        time.sleep(0.1)
    for pid in left:  # do not leave them running after a failure either
        os.kill(pid, signal.SIGKILL)
    assert not left, f"processes left behind: {left}\n{stderr}"
    assert process.returncode == 130, stderr
    assert "Traceback" not in stderr, stderr
    return stderr


SIGNALS = [
    pytest.param(signal.SIGTERM, 1, True, id="SIGTERM-group"),
    pytest.param(signal.SIGINT, 2, True, id="SIGINT-twice-group"),
    pytest.param(signal.SIGTERM, 2, False, id="SIGTERM-twice-parent"),
]


def _workers_running(process: subprocess.Popen[bytes]) -> Callable[[], bool]:
    def running() -> bool:
        # Workers are forked (same command line as the parent) or spawned (spawn_main).
        session = _session(process.pid)
        workers = [
            cmdline for pid, cmdline in session.items()
            if pid != process.pid and "resource_tracker" not in cmdline
        ]  # fmt: skip
        return len(workers) >= 2

    return running


@pytest.mark.slow
@pytest.mark.parametrize(
    ("signum", "count", "group", "starting"),
    [
        *[pytest.param(*param.values, False, id=param.id) for param in SIGNALS],
        # While the workers are still starting (importing): they must ignore it already.
        pytest.param(signal.SIGTERM, 1, True, True, id="SIGTERM-group-at-start"),
    ],
)
def test_train_seeds_ends_on_signals_and_resumes_byte_identically(
    reference: Path, tmp_path: Path, signum: int, count: int, group: bool, starting: bool
) -> None:
    config = write_yaml(tmp_path / "multi.yaml", MULTI_SEED)
    parent = tmp_path / "run"
    process = _start(tmp_path, "train", "-c", config, "--workers", 2, "--out", parent, "-q")
    if starting:
        _wait_until(_workers_running(process), "two worker processes starting")
    else:
        first = seed_dir(parent, SEEDS[0], SEEDS) / rundir.CHECKPOINT_FILE
        _wait_until(first.exists, f"{first} appearing")
        assert len(_session(process.pid)) >= 3, "the parent and its workers should be running"
    _signal(process, signum, count, group)
    stderr = _assert_ends_cleanly(process, tmp_path)
    assert f"cartpole-q train --resume {parent}" in stderr
    if count == 1:  # stopped at the end of an episode: the aggregate says what finished
        summary = json.loads((parent / rundir.SUMMARY_FILE).read_text())
        assert summary["interrupted"] is True and summary["finished"] < len(SEEDS)

    resumed = subprocess.run(
        [sys.executable, "-m", "cartpole_q", "train", "--resume", parent, "-q", "--workers", "2"],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert resumed.returncode == 0, resumed.stderr
    assert json.loads((parent / rundir.SUMMARY_FILE).read_text())["finished"] == len(SEEDS)
    for seed in SEEDS:
        for name in RESULT_FILES:
            got = (seed_dir(parent, seed, SEEDS) / name).read_bytes()
            assert got == (seed_dir(reference, seed, SEEDS) / name).read_bytes(), (seed, name)


@pytest.mark.slow
@pytest.mark.parametrize(("signum", "count", "group"), SIGNALS)
def test_multi_seed_eval_ends_on_signals(
    reference: Path, tmp_path: Path, signum: int, count: int, group: bool
) -> None:
    # Long enough never to finish: 10^6 greedy episodes of up to 500 steps per seed.
    process = _start(tmp_path, "eval", reference, "--episodes", 10**6, "--workers", 2)

    _wait_until(_workers_running(process), "two worker processes starting")
    time.sleep(0.5)  # into their imports or their episodes
    _signal(process, signum, count, group)
    _assert_ends_cleanly(process, tmp_path)


@pytest.mark.slow
def test_sigusr1_prints_where_a_command_is_and_it_goes_on(reference: Path, tmp_path: Path) -> None:
    process = _start(tmp_path, "eval", reference, "--episodes", 10**6, "--workers", 2)
    _wait_until(_workers_running(process), "two worker processes starting")
    os.kill(process.pid, signal.SIGUSR1)  # wherever it is, it is evaluating the seeds
    _wait_until(lambda: "in evaluate_seeds" in (tmp_path / "stderr").read_text(), "the dump")
    assert process.poll() is None  # it goes on
    _signal(process, signal.SIGINT, 1, True)
    _assert_ends_cleanly(process, tmp_path)


@pytest.mark.slow
@pytest.mark.parametrize(
    "algorithms", [["q_learning"], ["q_learning", "sarsa"]], ids=["one-loop", "two-loops"]
)
def test_a_signal_while_a_sweep_compiles_ends_it_within_a_second_or_two(
    tmp_path: Path, algorithms: list[str]
) -> None:
    """On an empty numba cache a sweep compiles its loops first, for tens of seconds.

    A Ctrl-C then abandons them: the command answers once, exits 130 at once, and no
    process it started (workers, the child compiling beside one) survives it.
    """
    sweep = write_yaml(
        tmp_path / "s.yaml",
        {"base": {"train": {"episodes": 5}}, "grid": {"agent.algorithm": algorithms},
         "seeds": "0-1"},
    )  # fmt: skip
    cold = {key: value for key, value in os.environ.items() if key != "NUMBA_CACHE_DIR"}
    cold["XDG_CACHE_HOME"] = str(tmp_path / "empty-cache")
    process = _start(tmp_path, "sweep", sweep, "--out", "out", "--workers", 2, env=cold)
    stderr = tmp_path / "stderr"
    _wait_until(lambda: "compiling" in stderr.read_text(), "the compile notice")
    time.sleep(1.0)  # into the compilation, which takes several seconds at least
    _signal(process, signal.SIGINT, 1, group=True)
    sent = time.monotonic()
    with contextlib.suppress(subprocess.TimeoutExpired):
        process.wait(timeout=30)
    took = time.monotonic() - sent
    text = _assert_ends_cleanly(process, tmp_path)
    assert took < 5, f"it took {took:.1f} s to stop"
    assert text.count("SIGINT: stopping") == 1, text
    assert "cartpole-q sweep --resume out" in text


# -- an interrupted multi-seed run: what its summary and its evaluation say ---------------


def _mark_interrupted(run: Path) -> None:
    path = run / rundir.SUMMARY_FILE
    summary = json.loads(path.read_text())
    path.write_text(json.dumps({**summary, "interrupted": True}))


def test_interrupted_multi_seed_summary_is_over_the_finished_seeds(
    reference: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    parent = tmp_path / "parent"
    shutil.copytree(reference, parent)
    _mark_interrupted(seed_dir(parent, 1, SEEDS))
    (seed_dir(parent, 2, SEEDS) / rundir.SUMMARY_FILE).unlink()  # killed: no result

    summary = aggregate(parent, SEEDS, 1.0, interrupted=True)
    assert summary.finished == 1 and summary.unfinished == 2
    assert summary.successes == 1 and summary.success_rate == 1.0
    assert summary.eval_mean is not None and summary.eval_mean.mean == 500.0
    assert summary.interrupted_seeds == "1" and summary.no_result_seeds == "2"
    print_multi_summary(parent, summary)
    out = capsys.readouterr().out
    assert "success                    1/1 greedy eval mean >= 475.0 (over the 1 finished" in out
    assert "eval mean                  mean 500.0, min 500.0" in out
    assert (
        "unfinished                 2 of 3: seed 1 interrupted (greedy eval mean so far 500.0), "
        "seed 2 without a result"
    ) in out

    _mark_interrupted(seed_dir(parent, 0, SEEDS))
    summary = aggregate(parent, SEEDS, 1.0, interrupted=True)
    assert summary.finished == 0 and summary.success_rate is None
    print_multi_summary(parent, summary)
    out = capsys.readouterr().out
    assert "nan" not in out and "0/3" not in out
    assert "success                    - (no seed has finished)" in out
    assert "unfinished                 3 of 3: seeds 0-1 interrupted" in out


def test_a_seed_that_is_a_file_is_named_as_such(reference: Path, tmp_path: Path) -> None:
    """Not "summary.json is not valid JSON": the seed-NNN itself is what is wrong."""
    parent = tmp_path / "parent"
    shutil.copytree(reference, parent)
    child = seed_dir(parent, 1, SEEDS)
    shutil.rmtree(child)
    child.write_text("not a run\n")
    (parent / rundir.SUMMARY_FILE).unlink()
    expected = f"error: {child}: is a file, but a run directory was expected here.\n"
    for args in (("eval", parent), ("plot", parent), ("train", "--resume", parent, "-q")):
        result = invoke(*args)
        assert (result.exit_code, result.stderr) == (2, expected), args


def test_multi_seed_eval_names_missing_and_unfinished_seeds(
    reference: Path, tmp_path: Path
) -> None:
    parent = tmp_path / "parent"
    shutil.copytree(reference, parent)
    shutil.rmtree(seed_dir(parent, 1, SEEDS))
    _mark_interrupted(seed_dir(parent, 2, SEEDS))
    note = (
        f"{parent}: 2 of 3 seeds left out: seed-001 is missing; seed-002 has not "
        f"finished (finish them with `cartpole-q train --resume {parent}`)"
    )

    result = invoke("eval", parent, "--episodes", 2, "--workers", 1)
    assert result.exit_code == 0, result.output
    lines = result.stdout.splitlines()
    assert [line.split(":")[0] for line in lines[:-1]] == ["seed 0"]
    assert lines[-1].startswith(f"{parent}: 1/1 finished seeds with greedy mean >= 475")
    assert result.stderr.strip() == f"note: {note}"

    result = invoke("eval", parent, "--episodes", 2, "--workers", 1, "--json")
    assert result.exit_code == 0, result.output
    report = json.loads(result.stdout)
    assert [run["run_seed"] for run in report["runs"]] == [0] and report["seeds"] == 3
    assert report["missing"] == ["seed-001"] and report["unfinished"] == ["seed-002"]
    assert result.stderr.strip() == f"note: {note}"

    shutil.rmtree(seed_dir(parent, 0, SEEDS))
    result = invoke("eval", parent, "--episodes", 2)
    assert result.exit_code == 2
    assert "none of its seed runs has finished" in result.stderr
    assert "seed-000, seed-001 are missing" in result.stderr
