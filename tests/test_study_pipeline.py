"""One way in for every study: ``cartpole-q study`` runs sweeps, bandits, dp and updates alike.

Each kind of study gets what sweeps had (issue 48): a directory claimed under a lock, its
runs saved as they end, ``--resume`` after a stop or a kill finishing it byte for byte as
one run in one go, ``--check``, progress, and its figures written all together or not at all
(issue 47, item 6: ``dp`` on a full disk left two of its three files).
"""

from __future__ import annotations

import csv
import os
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
import yaml

from cartpole_q.store import studydir
from tests.conftest import REPO, invoke, write_yaml
from tests.test_cli import assert_refused

BOOK = REPO / "examples" / "book"
STUDY_FILES = sorted([*BOOK.glob("*.yaml"), REPO / "examples" / "alpha_by_bins.yaml"])


def test_every_shipped_study_file_passes_check_and_runs_nothing(in_tmp: Path) -> None:
    for path in STUDY_FILES:
        result = invoke("study", path, "--check")
        assert result.exit_code == 0, result.output
        assert result.stdout.endswith("; nothing was run (--check).\n"), result.stdout
        kind = yaml.safe_load(path.read_text(encoding="utf-8"))["kind"]
        assert f": a {kind}" in result.stdout or f": an {kind}" in result.stdout
    assert list(in_tmp.iterdir()) == []  # no directory was made


def test_check_refuses_a_bad_file_naming_the_key(tmp_path: Path) -> None:
    study = yaml.safe_load((BOOK / "fig2_2_epsilon_greedy.yaml").read_text(encoding="utf-8"))
    path = write_yaml(tmp_path / "s.yaml", {**study, "steps": 0})
    assert_refused(invoke("study", path, "--check"), f"{path}: steps: must be a whole number")
    path = write_yaml(tmp_path / "k.yaml", {**study, "kind": "bandits"})
    assert_refused(
        invoke("study", path, "--check"),
        "kind: must be one of average_reward, bandit, dp, linear, panels, policy_gradient, sweep",
    )


def small(tmp_path: Path, name: str, **change: object) -> Path:
    """A shipped study file, smaller."""
    study = yaml.safe_load((BOOK / f"{name}.yaml").read_text(encoding="utf-8"))
    study.update(change)
    return write_yaml(tmp_path / f"{name}.yaml", study)


def _bandit(tmp_path: Path, **change: object) -> Path:
    return small(
        tmp_path, "fig2_2_epsilon_greedy", **{"seeds": "0-19", "steps": 50, "book": [], **change}
    )


def _files(directory: Path) -> dict[str, bytes]:
    """Every file of a study directory but its lock, by its path inside."""
    return {
        path.relative_to(directory).as_posix(): path.read_bytes()
        for path in sorted(directory.rglob("*"))
        if path.is_file() and path.name != ".lock"
    }


def test_a_study_directory_holds_the_contract_files(tmp_path: Path) -> None:
    out = tmp_path / "out"
    result = invoke("study", _bandit(tmp_path), "--out", out, "--workers", 1)
    assert result.exit_code == 0, result.output
    assert result.stdout.splitlines()[-1] == str(out)
    assert "a bandit study: 3 learners x 20 seeds" in result.stderr
    started = (out / studydir.STUDY_FILE).read_text(encoding="utf-8")
    assert yaml.safe_load(started)["kind"] == "bandit"
    with (out / studydir.RESULTS_FILE).open(newline="") as file:
        rows = list(csv.DictReader(file))
    assert list(rows[0]) == ["run", "study", "curve", "learner", "mean_reward"]
    assert [row["run"] for row in rows] == ["0", "1", "2"]
    assert {row["study"] for row in rows} == {studydir.digest(started)}
    assert sorted(path.name for path in (out / studydir.RUNS_DIR).iterdir()) == [
        "0000.npz", "0001.npz", "0002.npz",
    ]  # fmt: skip
    summary = (out / studydir.SUMMARY_FILE).read_text(encoding="utf-8")
    assert summary.startswith("fig2_2_epsilon_greedy: 20 runs x 50 steps")
    assert summary in result.stdout
    assert (out / "fig2_2_epsilon_greedy.png").is_file()
    assert (out / "fig2_2_epsilon_greedy.csv").is_file()


RESUMED = {
    "bandit": lambda tmp: _bandit(tmp),
    "dp": lambda tmp: BOOK / "fig4_1_small_gridworld.yaml",
    "until_optimal": lambda tmp: small(
        tmp, "example8_4_prioritized_sweeping", seeds="0-2", scales=[1, 2]
    ),
    "trajectory_sampling": lambda tmp: small(
        tmp, "fig8_8_trajectory_sampling", seeds="0-2",
        panels=[{"states": 20, "branching": [1, 3], "updates": 200, "every": 50}],
    ),
    "expected_vs_sample": lambda tmp: small(
        tmp, "fig8_7_expected_vs_sample", seeds="0-4", branching=[2, 10, 100]
    ),
    "linear": lambda tmp: small(tmp, "fig9_10_tile_coding", seeds="0-2", episodes=40, book=[]),
    "policy_gradient": lambda tmp: small(tmp, "fig13_2_reinforce_baseline", seeds="0-2", episodes=60),
    "average_reward": lambda tmp: small(
        tmp, "fig10_5_access_control", seeds="0-2", steps=20_000, record_every=1_000,
        figure={"kind": "average_reward"},
    ),
}  # fmt: skip


@pytest.mark.parametrize("which", RESUMED)
def test_a_partly_done_study_resumes_to_the_same_bytes(tmp_path: Path, which: str) -> None:
    path = RESUMED[which](tmp_path)
    whole, part = tmp_path / "whole", tmp_path / "part"
    assert invoke("study", path, "--out", whole, "--workers", 2, "-q").exit_code == 0
    # As a stop or a kill leaves it: the first runs saved, the rest and the figures not.
    shutil.copytree(whole, part)
    keep = 1 if which in ("bandit", "expected_vs_sample") else 2
    lines = (part / studydir.RESULTS_FILE).read_text(encoding="utf-8").splitlines()
    (part / studydir.RESULTS_FILE).write_text("\n".join(lines[: 1 + keep]) + "\n")
    for name in _files(whole):
        run = name.removeprefix(f"{studydir.RUNS_DIR}/").removesuffix(".npz")
        if (
            name == studydir.SUMMARY_FILE
            or (name.startswith("runs/") and int(run) >= keep)
            or ("/" not in name and not name.endswith((".yaml", "results.csv")))
        ):
            (part / name).unlink()
    resumed = invoke("study", "--resume", part, "--workers", 1)
    assert resumed.exit_code == 0, resumed.output
    assert _files(part) == _files(whole)


def test_resume_refuses_an_edited_study_file(tmp_path: Path) -> None:
    out = tmp_path / "out"
    assert invoke("study", _bandit(tmp_path), "--out", out, "-q").exit_code == 0
    started = out / studydir.STUDY_FILE
    started.write_text(started.read_text(encoding="utf-8").replace("steps: 50", "steps: 60"))
    assert_refused(
        invoke("study", "--resume", out),
        f"{started}: was changed after the runs in {out / studydir.RESULTS_FILE} were made",
    )
    assert_refused(invoke("study", "--resume", tmp_path), "is not a study directory")


def test_a_failure_the_first_run_finds_leaves_no_directory(tmp_path: Path) -> None:
    # Only the run finds that policy evaluation does not converge in 11 sweeps.
    path = small(tmp_path, "fig4_1_small_gridworld", max_sweeps=11)
    result = invoke("dp", path, "--out", tmp_path / "out")
    assert result.exit_code == 2 and "Traceback" not in result.output
    # the note that the study started, then the one-paragraph error
    note, error = result.stderr.splitlines()
    assert note.endswith("(one run)") and error.startswith(f"error: {path}: policy evaluation")
    assert "did not converge in 11 sweeps" in error
    assert not (tmp_path / "out").exists()


@pytest.mark.slow
def test_a_killed_study_resumes_to_the_same_bytes(tmp_path: Path) -> None:
    """kill -9 while the second learner plays: the first stays saved, the rest resumes."""
    path = _bandit(tmp_path, seeds="0-199", steps=300, engine="gymnasium")
    killed, whole = tmp_path / "killed", tmp_path / "whole"
    process = subprocess.Popen(
        [sys.executable, "-m", "cartpole_q", "study", str(path), "--out", str(killed),
         "--workers", "1", "-q"],
        env={**os.environ, "PYTHONPATH": str(REPO)}, start_new_session=True,
        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
    )  # fmt: skip
    results = killed / studydir.RESULTS_FILE
    deadline = time.monotonic() + 120
    while not (results.is_file() and len(results.read_text().splitlines()) >= 2):
        assert process.poll() is None, process.stderr.read() if process.stderr else ""
        assert time.monotonic() < deadline, "no run was saved"
        time.sleep(0.02)
    os.killpg(process.pid, signal.SIGKILL)
    process.wait()
    assert not (killed / "fig2_2_epsilon_greedy.png").exists()
    resumed = invoke("study", "--resume", killed, "-q")
    assert resumed.exit_code == 0, resumed.output
    assert invoke("study", path, "--out", whole, "-q").exit_code == 0
    assert _files(killed) == _files(whole)


@pytest.fixture
def small_disk(tmp_path: Path) -> Iterator[Path]:
    """A real 256 KiB file system (tmpfs; needs root, else skipped)."""
    if shutil.which("mount") is None or os.geteuid() != 0:
        pytest.skip("mounting a tmpfs needs root")
    disk = tmp_path / "disk"
    disk.mkdir()
    mounted = subprocess.run(
        ["mount", "-t", "tmpfs", "-o", "size=256k", "tmpfs", str(disk)],
        capture_output=True, check=False,
    )  # fmt: skip
    if mounted.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {mounted.stderr.decode().strip()}")
    try:
        yield disk
    finally:
        subprocess.run(["umount", str(disk)], check=False)


def test_a_full_disk_at_the_end_changes_no_figure_and_resume_draws_them(
    small_disk: Path, tmp_path: Path
) -> None:
    """Issue 47 item 6: dp on a full disk left two of its three files."""
    study = BOOK / "fig4_1_small_gridworld.yaml"
    out = small_disk / "out"
    result = invoke("dp", study, "--out", out)
    assert result.exit_code == 2, result.output
    assert "no space is left on the device" in result.stderr
    names = {path.name for path in out.iterdir()}
    assert names >= {studydir.STUDY_FILE, studydir.RESULTS_FILE}  # the run is kept
    assert not names & {"fig4_1_small_gridworld.png", "fig4_1_small_gridworld.csv",
                        "fig4_1_small_gridworld_sweeps.csv", studydir.SUMMARY_FILE}  # fmt: skip
    assert not list(out.glob(".*.tmp"))
    subprocess.run(["mount", "-o", "remount,size=4m", str(small_disk)], check=True)
    resumed = invoke("dp", "--resume", out, "-q")
    assert resumed.exit_code == 0, resumed.output
    assert invoke("dp", study, "--out", tmp_path / "whole", "-q").exit_code == 0
    assert _files(out) == _files(tmp_path / "whole")


@pytest.mark.slow
def test_studies_of_every_kind_run_on_a_local_ray_cluster_to_the_same_bytes(
    tmp_path: Path,
) -> None:
    ray = pytest.importorskip("ray")
    from cartpole_q.experiments import study as studies
    from cartpole_q.experiments.study_kinds import registered

    files = {name: RESUMED[name](tmp_path) for name in ("bandit", "dp", "until_optimal", "linear")}
    local = {}
    for name, path in files.items():
        local[name] = tmp_path / f"local-{name}"
        assert invoke("study", path, "--out", local[name], "--workers", 1, "-q").exit_code == 0
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        for name, path in files.items():
            study = studies.read_study_file(path)
            kind = registered()[study.kind]
            spec = kind.read(study)
            with kind.start(spec, study, tmp_path / f"ray-{name}") as directory:
                outcome = kind.run(spec, directory, studies.Options(workers=2, backend="ray"))
            assert outcome.complete, name
            assert _files(directory) == _files(local[name]), name
    finally:
        ray.shutdown()


@pytest.mark.slow
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_a_signal_inside_a_long_maze_run_ends_the_study_within_two_seconds(
    tmp_path: Path, signum: int
) -> None:
    """Issue 47 item 1: Ctrl-C and SIGTERM did nothing during a run of Example 8.4.

    One prioritized-sweeping run on the 6,016-state maze lasts seconds inside compiled
    code; the signal comes while it runs, and the study ends within two seconds (exit 130),
    saying how to go on; resumed, it ends as a study run in one go.
    """
    from cartpole_q.engines.until_optimal import Settings, maze_arrays, until_optimal
    from cartpole_q.families.gridworlds.worlds import DynaMazeEnv

    tiny = maze_arrays(DynaMazeEnv(1))  # the loop compiled (or loaded) here: the run starts at once
    until_optimal(
        tiny, Settings("prioritized_sweeping", 0.5, 0.95, 0.1, 5, 1e-5, "random", 10**9, 10**6), 0
    )
    path = write_yaml(tmp_path / "big.yaml", {
        "kind": "updates", "name": "big", "seeds": "0", "scales": [[16, 8]], "theta": 0.00001,
        "methods": ["prioritized_sweeping"], "figure": {"kind": "until_optimal"},
    })  # fmt: skip
    out = tmp_path / "out"
    process = subprocess.Popen(
        [sys.executable, "-m", "cartpole_q", "study", str(path), "--out", str(out),
         "--workers", "1", "-q"],
        env={**os.environ, "PYTHONPATH": str(REPO)}, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
    )  # fmt: skip
    deadline = time.monotonic() + 60
    while not (out / studydir.STUDY_FILE).is_file():
        assert process.poll() is None and time.monotonic() < deadline
        time.sleep(0.02)
    time.sleep(1.0)  # inside the run (about 3 s on this machine)
    process.send_signal(signum)
    sent = time.monotonic()
    _, stderr = process.communicate(timeout=30)
    assert process.returncode == 130, stderr
    assert time.monotonic() - sent < 2.0, time.monotonic() - sent
    assert f"finish it with `cartpole-q study --resume {out}`".encode() in stderr
    assert b"Traceback" not in stderr
    assert invoke("study", "--resume", out, "-q").exit_code == 0
    assert invoke("study", path, "--out", tmp_path / "whole", "-q").exit_code == 0
    assert _files(out) == _files(tmp_path / "whole")


def _panel_files(tmp_path: Path) -> Path:
    """A panels file of two small sweeps (the 5-state walk, TD(0)) beside it."""
    sweep = {
        "kind": "sweep",
        "base": {
            "env": {"id": "cartpole_q/RandomWalk5-v0"},
            "agent": {"algorithm": "td", "policy": "random", "gamma": 1.0, "q_init": 0.5},
            "train": {"episodes": 5, "eval_every": 0, "checkpoint_every": 0},
            "eval": {"episodes": 1},
        },
        "seeds": "0-1",
    }
    write_yaml(tmp_path / "a.yaml", {**sweep, "grid": {"agent.alpha": [0.1, 0.2]},
                                     "figure": {"metric": "rms_error", "file": "a.png"}})  # fmt: skip
    write_yaml(tmp_path / "b.yaml", {**sweep, "grid": {"agent.alpha": [0.3]},
                                     "figure": {"metric": "rms_error", "file": "b.png"}})  # fmt: skip
    return write_yaml(
        tmp_path / "p.yaml", {"kind": "panels", "panels": ["a.yaml", "b.yaml"], "title": "two"}
    )


def test_a_panels_study_draws_its_sweeps_as_one_figure_and_resumes_to_the_same_bytes(
    tmp_path: Path,
) -> None:
    """Figure 12.14's four tasks by one command: each panel a sweep, run in turn."""
    from cartpole_q.experiments.study import Options, read_study_file
    from cartpole_q.experiments.study_kinds import registered

    path = _panel_files(tmp_path)
    checked = invoke("study", path, "--check")
    assert checked.exit_code == 0 and "a panels study of 2 sweeps, 6 runs in all" in checked.stdout
    whole = tmp_path / "whole"
    result = invoke("study", path, "--out", whole, "--workers", 1)
    assert result.exit_code == 0, result.output
    assert (
        "panel a:" in result.stdout
        and f"the figure of its 2 panels: {whole / 'p.png'}" in result.stdout
    )
    rows = (whole / "p.csv").read_text(encoding="utf-8").splitlines()
    for name in ("a", "b"):  # each panel's own data, its panel column named
        own = (whole / "panels" / name / f"{name}.csv").read_text(encoding="utf-8").splitlines()
        assert [row.split(",", 1)[1] for row in rows if row.split(",", 1)[0] == name] == [
            row.split(",", 1)[1] for row in own[1:]
        ]
    assert rows[0] == own[0]
    # Stopped after its first panel, as a signal there leaves it; --resume runs the second.
    kind = registered()["panels"]
    study = read_study_file(path)
    spec = kind.read(study)
    part = tmp_path / "part"
    with kind.start(spec, study, part) as directory:
        stop = Options(
            workers=1, quiet=True, should_stop=lambda: (part / "panels/a/a.png").exists()
        )
        stopped = kind.run(spec, directory, stop)
    assert not stopped.complete and stopped.done_runs == 4 and stopped.total_runs == 6
    assert not (part / "p.png").exists() and not (part / "panels/b/b.png").exists()
    resumed = invoke("study", "--resume", part, "--workers", 1, "-q")
    assert resumed.exit_code == 0, resumed.output
    for name in ("p.png", "p.csv", "panels/a/a.csv", "panels/b/b.csv", "panels/b/b.png"):
        assert (part / name).read_bytes() == (whole / name).read_bytes(), name


@pytest.mark.parametrize(
    ("change", "words"),
    [
        ({"panels": ["a.yaml", "c.yaml"]}, "panels: c.yaml: no such file beside it"),
        ({"panels": []}, "panels: must be a non-empty list of sweep files"),
        ({"panels": ["a.yaml", "bandit.yaml"]}, "panels: bandit.yaml: is a bandit study"),
        ({"panels": ["a.yaml", "a.yaml"]}, "panels: two panels are named a"),
        ({"columns": 0}, "columns: must be a whole number of at least 1"),
        ({"colour": "red"}, "colour: is not a key of a panels file"),
        ({"file": "../p.png"}, "file: '../p.png' must be a file name"),
        ({"name": "../x"}, "name: must be letters, digits, '-' or '_'"),
    ],
)
def test_a_bad_panels_file_is_refused_naming_the_key(
    tmp_path: Path, change: dict, words: str
) -> None:
    path = _panel_files(tmp_path)
    shutil.copy(BOOK / "fig2_2_epsilon_greedy.yaml", tmp_path / "bandit.yaml")
    bad = write_yaml(tmp_path / "bad.yaml", {"kind": "panels", "panels": ["a.yaml"], **change})
    assert path.is_file()
    result = invoke("study", bad, "--out", tmp_path / "out")
    assert_refused(result, f"{bad}: ", words)
    assert not (tmp_path / "out").exists()
