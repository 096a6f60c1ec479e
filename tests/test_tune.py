"""Tuning: bad tune files, a real Optuna journal and SQLite storage, kill -9, shared studies."""

from __future__ import annotations

import csv
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from cartpole_q.config import ConfigError, load_config
from cartpole_q.experiments.tune_spec import load_tune
from cartpole_q.store import tunedir
from tests.conftest import invoke, then_sigint, write_yaml

pytest.importorskip("optuna")

BASE = {
    "name": "base",
    "train": {"episodes": 60, "eval_every": 20, "eval_episodes": 2},
    "eval": {"episodes": 3},
}
TUNE = {
    "name": "small",
    "base": BASE,
    "seeds": "0-3",
    "trials": 6,
    "space": {
        "agent.alpha": {"low": 0.05, "high": 1.0, "log": True},
        "agent.q_init": {"low": 0, "high": 300},
        "agent.algorithm": {"choices": ["q_learning", "sarsa"]},
        "discretization.bins": {"choices": [[1, 1, 2, 10], [1, 1, 6, 12]]},
    },
    "sampler": {"type": "tpe", "seed": 3},
}


def _trials(directory: Path) -> list[dict[str, str]]:
    with (directory / tunedir.TRIALS_FILE).open(newline="") as file:
        return [{k: v for k, v in row.items() if k != "seconds"} for row in csv.DictReader(file)]


BAD_TUNES = [
    pytest.param({"spaces": {}}, "unknown key 'spaces'; did you mean 'space'?", id="typo"),
    pytest.param({"space": {"agent.alpah": {"low": 0.1, "high": 1}}}, "did you mean 'agent.alpha'", id="key"),
    pytest.param({"space": {"agent.alpha": {"low": 0.5, "high": 0.1}}}, "low (0.5) is above high (0.1)", id="reversed"),
    pytest.param({"space": {"agent.alpha": {"low": 0.5, "high": 0.5}}}, "the range is empty", id="empty"),
    pytest.param({"space": {"agent.q_init": {"low": 0, "high": 5, "log": True}}}, "a log range must stay above 0", id="log-0"),
    pytest.param({"space": {"agent.alpha": {"low": 0.1, "high": 2.0}}}, "agent.alpha: must be in (0, 1]", id="invalid high"),
    pytest.param({"space": {"agent.algorithm": {"choices": ["q_learning", "dqn"]}}}, "space.agent.algorithm (dqn)", id="bad choice"),
    pytest.param({"space": {"agent.alpha": {"choices": []}}}, "choices: must be a non-empty list", id="no choices"),
    pytest.param({"space": {"seed": {"low": 0, "high": 9}}}, "space.seed: cannot be searched", id="seed"),
    pytest.param({"space": {}}, "space: must map dotted config keys", id="no space"),
    pytest.param({"objective": "speed", "space": {"agent.alpha": {"low": 0.1, "high": 1}}}, "objective: must be one of", id="objective"),
    pytest.param({"trials": 0, "space": {"agent.alpha": {"low": 0.1, "high": 1}}}, "trials: must be an integer", id="trials"),
    pytest.param({"sampler": {"type": "cmaes"}, "space": {"agent.alpha": {"low": 0.1, "high": 1}}}, "sampler.type", id="sampler"),
    pytest.param({"space": {"agent.q_init": {"low": 0, "high": 10, "int": True, "step": 0.5}}}, "needs a whole step", id="int step"),
    pytest.param({"space": {"train.episodes": {"low": 10, "high": 30}}}, "train.episodes: must be an integer", id="float on int key"),
    pytest.param({"space": {"agent.epsilon": {"choices": [0.1]}, "agent.epsilon.end": {"low": 0, "high": 0.1}}}, "one key holds the other", id="overlap"),
]  # fmt: skip


@pytest.mark.parametrize(("data", "message"), BAD_TUNES)
def test_bad_tune_files_are_refused_naming_the_key(
    tmp_path: Path, data: dict[str, Any], message: str
) -> None:
    path = write_yaml(tmp_path / "t.yaml", data)
    with pytest.raises(ConfigError) as error:
        load_tune(path)
    assert message in str(error.value)
    assert str(path) in str(error.value)
    result = invoke("tune", path, "--out", tmp_path / "out")
    assert result.exit_code == 2
    assert not (tmp_path / "out").exists()


@pytest.fixture(scope="module")
def reference(tmp_path_factory: pytest.TempPathFactory) -> Path:
    base = tmp_path_factory.mktemp("tune")
    path = write_yaml(base / "small.yaml", TUNE)
    result = invoke("tune", path, "--out", base / "out", "--workers", 1)
    assert result.exit_code == 0, result.output
    assert result.output.splitlines()[-1] == str(base / "out")
    return base / "out"


def test_a_study_writes_its_files_and_a_best_config_train_takes(
    reference: Path, tmp_path: Path
) -> None:
    rows = _trials(reference)
    assert [row["trial"] for row in rows] == [str(n) for n in range(6)]
    assert {row["state"] for row in rows} == {"complete"}
    for name in (tunedir.TUNE_FILE, tunedir.JOURNAL_FILE, tunedir.BEST_FILE, tunedir.HISTORY_FILE):
        assert (reference / name).is_file(), name
    best = max(rows, key=lambda row: float(row["objective"]))
    # each figure's data beside it: the objectives and the best so far; the importances
    with (reference / "history.csv").open(newline="") as file:
        history = list(csv.DictReader(file))
    drawn = [(r["x"], r["y"]) for r in history if r["series"] == "objective"]
    assert drawn == [(row["trial"], row["objective"]) for row in rows]
    best_so_far = [float(r["y"]) for r in history if r["series"] == "best so far"]
    assert best_so_far == np.maximum.accumulate([float(y) for _, y in drawn]).tolist()
    with (reference / "importance.csv").open(newline="") as file:
        importances = {r["x"]: float(r["y"]) for r in csv.DictReader(file)}
    assert set(importances) == set(TUNE["space"]) and sum(importances.values()) == pytest.approx(1)
    config = load_config(reference / tunedir.BEST_FILE)
    assert config.agent.algorithm == best["agent.algorithm"]
    assert config.agent.alpha.start == float(best["agent.alpha"])
    assert config.train.episodes == 60
    result = invoke(
        "train",
        "-c",
        reference / tunedir.BEST_FILE,
        "--seeds",
        "0-3",
        "--out",
        tmp_path / "run",
        "-q",
    )
    assert result.exit_code == 0, result.output
    means = [float(row["eval_mean"]) for row in _seed_rows(tmp_path / "run")]
    successes = sum(mean >= 475 for mean in means)
    assert successes / 4 == float(best["success_rate"])


def _seed_rows(parent: Path) -> list[dict[str, Any]]:
    import json

    return [
        {"eval_mean": json.loads((child / "summary.json").read_text())["eval"]["mean"]}
        for child in sorted(parent.glob("seed-*"))
    ]


def test_the_same_tune_file_gives_the_same_trials_whatever_the_workers(
    reference: Path, tmp_path: Path
) -> None:
    path = write_yaml(tmp_path / "small.yaml", TUNE)
    result = invoke("tune", path, "--out", tmp_path / "two", "--workers", 2, "-q")
    assert result.exit_code == 0, result.output
    assert _trials(tmp_path / "two") == _trials(reference)


def test_resume_with_more_trials_raises_the_total_and_sqlite_works(tmp_path: Path) -> None:
    path = write_yaml(tmp_path / "small.yaml", {**TUNE, "trials": 2})
    url = f"sqlite:///{tmp_path / 'study.db'}"
    result = invoke("tune", path, "--out", tmp_path / "out", "--storage", url, "-q")
    assert result.exit_code == 0, result.output
    assert len(_trials(tmp_path / "out")) == 2
    assert not (tmp_path / "out" / tunedir.JOURNAL_FILE).exists()
    result = invoke("tune", "--resume", tmp_path / "out", "--trials", 4, "-q")
    assert result.exit_code == 0, result.output
    rows = _trials(tmp_path / "out")
    assert [row["trial"] for row in rows] == ["0", "1", "2", "3"]
    # the resumed process draws new values, not the first trials' again
    drawn = [tuple(row[key] for key in TUNE["space"]) for row in rows]
    assert len(set(drawn)) == 4
    assert invoke("tune", "--resume", tmp_path / "out", "--storage", url).exit_code == 2


def _start(tmp_path: Path, *args: object) -> subprocess.Popen[bytes]:
    return subprocess.Popen(
        [sys.executable, "-m", "cartpole_q", "tune", *map(str, args), "-q"],
        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, start_new_session=True, cwd=tmp_path,
    )  # fmt: skip


def _journal_trials(directory: Path) -> list[Any]:
    import optuna

    spec_data, _ = tunedir.tune_file(directory)
    storage = optuna.storages.JournalStorage(
        optuna.storages.journal.JournalFileBackend(str(directory / tunedir.JOURNAL_FILE))
    )
    return optuna.load_study(study_name=spec_data["name"], storage=storage).get_trials()


@pytest.mark.slow
def test_a_study_killed_with_sigkill_resumes_to_the_requested_trials(tmp_path: Path) -> None:
    path = write_yaml(tmp_path / "k.yaml", {**TUNE, "trials": 6, "seeds": "0-9"})
    out = tmp_path / "out"
    process = _start(tmp_path, path, "--out", out, "--workers", 1)
    try:
        deadline = time.monotonic() + 120
        while _completed_in_journal(out / tunedir.JOURNAL_FILE) < 2:
            assert process.poll() is None, process.stderr.read() if process.stderr else ""
            assert time.monotonic() < deadline
            time.sleep(0.05)
    finally:
        os.killpg(process.pid, signal.SIGKILL)
        process.wait()
    assert len([t for t in _journal_trials(out) if t.state.name == "COMPLETE"]) < 6
    result = invoke("tune", "--resume", out, "-q")
    assert result.exit_code == 0, result.output
    trials = _journal_trials(out)
    assert sum(t.state.name == "COMPLETE" for t in trials) == 6
    assert not [t for t in trials if t.state.name == "RUNNING"]


def test_a_killed_writers_journal_lock_is_taken_over_at_once_on_resume(tmp_path: Path) -> None:
    """A kill -9 in the middle of a journal write leaves Optuna's lock behind: the resume
    removes it (Optuna would wait 30 s for it); a shared journal's lock is left alone."""
    from optuna.storages.journal import JournalFileSymlinkLock

    from cartpole_q.experiments.tune import load_tune_dir

    path = write_yaml(tmp_path / "t.yaml", {**TUNE, "trials": 1})
    shared = tmp_path / "shared.journal"
    for out, storage in ((tmp_path / "own", None), (tmp_path / "shared", shared)):
        extra = () if storage is None else ("--storage", storage)
        assert invoke("tune", path, "--out", out, *extra, "-q").exit_code == 0
        journal = out / tunedir.JOURNAL_FILE if storage is None else storage
        JournalFileSymlinkLock(str(journal)).acquire()  # a writer killed while it held it
        lock = journal.with_name(journal.name + tunedir.JOURNAL_LOCK_SUFFIX)
        assert lock.is_symlink()  # (the suffix is Optuna's)
        load_tune_dir(out)
        assert lock.is_symlink() == (storage is not None)
        lock.unlink(missing_ok=True)
    result = invoke("tune", "--resume", tmp_path / "own", "--trials", 2, "-q")
    assert result.exit_code == 0, result.output
    assert "taking longer" not in result.output


def _journal_entries(path: Path) -> list[dict[str, Any]]:
    """A journal file's operations, read from its lines as they are written (a line being
    written is skipped). Loading the study instead, twenty times a second, took a core
    from the study it watched."""
    if not path.is_file():
        return []
    entries = []
    for line in path.read_text(encoding="utf-8").splitlines():
        try:
            entries.append(json.loads(line))
        except ValueError:
            continue
    return entries


def _completed_in_journal(path: Path) -> int:
    """How many trials a journal file marks complete."""
    from optuna.storages.journal._storage import JournalOperation
    from optuna.trial import TrialState

    return sum(
        entry.get("op_code") == JournalOperation.SET_TRIAL_STATE_VALUES.value
        and entry.get("state") == TrialState.COMPLETE.value
        for entry in _journal_entries(path)
    )


def _created_in_journal(path: Path) -> int:
    """How many trials a journal file has created."""
    from optuna.storages.journal._storage import JournalOperation

    created = JournalOperation.CREATE_TRIAL.value
    return sum(entry.get("op_code") == created for entry in _journal_entries(path))


@pytest.mark.slow
def test_two_processes_share_one_study_without_duplicating_trials(tmp_path: Path) -> None:
    """Two tune directories, one study in a shared journal file: the second one joins."""
    # Enough work that the first process is still running trials when the second has
    # started, however warm the cache: 40 trials of 1,000 episodes on 10 seeds, about 0.2 s
    # each, against the second's 2-3 s start-up (16 trials of 60 episodes once all finished
    # within it).
    slow = {**BASE, "train": {"episodes": 1000, "eval_every": 0, "eval_episodes": 2}}
    path = write_yaml(tmp_path / "s.yaml", {**TUNE, "base": slow, "trials": 40, "seeds": "0-9"})
    journal = tmp_path / "shared.journal"
    first = _start(tmp_path, path, "--out", tmp_path / "one", "--storage", journal, "--workers", 1)
    deadline = time.monotonic() + 120
    while not _created_in_journal(journal):
        assert first.poll() is None
        assert time.monotonic() < deadline
        time.sleep(0.05)
    second = _start(
        tmp_path, path, "--out", tmp_path / "two", "--storage", journal, "--join", "--workers", 1
    )
    for process in (first, second):
        assert process.wait(timeout=300) == 0, process.stderr.read() if process.stderr else ""
    trials = _storage_trials(journal, "small")
    complete = [t for t in trials if t.state.name == "COMPLETE"]
    assert len(complete) == 40
    assert len({t.number for t in complete}) == 40
    owners = {t.user_attrs["owner"] for t in complete}
    assert len(owners) == 2, "both processes ran trials"
    assert not [t for t in trials if t.state.name == "RUNNING"]
    assert _trials(tmp_path / "one")[:1] == _trials(tmp_path / "two")[:1]


def _storage_trials(storage: Path | str, name: str) -> list[Any]:
    import optuna

    if isinstance(storage, Path):
        if not storage.is_file():
            return []
        storage = optuna.storages.JournalStorage(
            optuna.storages.journal.JournalFileBackend(str(storage))
        )
    try:
        return optuna.load_study(study_name=name, storage=storage).get_trials()
    except KeyError:  # not created yet
        return []


@pytest.mark.slow
def test_sigterm_ends_a_study_with_130_and_resume_finishes_it(tmp_path: Path) -> None:
    from tests.test_signals import _assert_ends_cleanly, _signal
    from tests.test_signals import _start as start_command

    path = write_yaml(tmp_path / "s.yaml", {**TUNE, "trials": 40, "seeds": "0-19"})
    out = tmp_path / "out"
    process = start_command(tmp_path, "tune", path, "--out", out, "--workers", 2, "-q")
    deadline = time.monotonic() + 120
    while _completed_in_journal(out / tunedir.JOURNAL_FILE) < 1:
        assert process.poll() is None, (tmp_path / "stderr").read_text()
        assert time.monotonic() < deadline
        time.sleep(0.05)
    _signal(process, signal.SIGTERM, 1, group=True)
    stderr = _assert_ends_cleanly(process, tmp_path)
    assert f"cartpole-q tune --resume {out}" in stderr
    assert (out / tunedir.TRIALS_FILE).is_file()  # the finished trials are summarised
    result = invoke("tune", "--resume", out, "-q")
    assert result.exit_code == 0, result.output
    trials = _journal_trials(out)
    assert sum(t.state.name == "COMPLETE" for t in trials) == 40


def test_the_pruner_stops_a_trial_only_when_it_cannot_reach_the_best_rate() -> None:
    from types import SimpleNamespace

    from cartpole_q.experiments.tune import _cannot_win
    from cartpole_q.results import SeedResult

    def run(success: bool) -> SeedResult:
        return SeedResult(0, 10, 100, None, None, None, 480.0 if success else 9.0, success)

    study = SimpleNamespace(best_trial=SimpleNamespace(user_attrs={"success_rate": 0.5}))
    rows = [run(True)] + [run(False)] * 5  # 6 of 10 seeds run
    assert not _cannot_win(study, rows, 10)  # 1 + 4 more = 0.5: a tie may still win
    assert _cannot_win(study, [run(False)] * 6, 10)  # at most 0.4
    assert not _cannot_win(study, [run(False)] * 5, 10)  # 0.5 still possible

    class NoTrialYet:
        @property
        def best_trial(self) -> None:
            raise ValueError("no trial")

    assert not _cannot_win(NoTrialYet(), [run(False)] * 9, 10)


def test_a_trial_that_cannot_reach_the_best_rate_is_pruned(tmp_path: Path) -> None:
    """A good trial first (every seed succeeds), then one that learns nothing: pruned."""
    from cartpole_q.experiments import tune as tuning

    data = {"name": "prune", "seeds": "0-9", "trials": 2, "pruner": True,
            "space": {"agent.alpha": {"choices": [0.3, 0.0001]}}}  # fmt: skip
    spec = load_tune(write_yaml(tmp_path / "p.yaml", data))
    directory = tuning.start_tune(spec, tmp_path / "out", None)
    the_study = tuning.study(spec, directory, None)
    the_study.enqueue_trial({"agent.alpha": "0.3"})
    the_study.enqueue_trial({"agent.alpha": "0.0001"})
    outcome = tuning.run_tune(spec, directory, None, workers=1)
    assert outcome.complete
    rows = _trials(directory)
    assert [(row["state"], row["agent.alpha"]) for row in rows] == [
        ("complete", "0.3"),
        ("pruned", "0.0001"),
    ]
    assert rows[0]["success_rate"] == "1.0"
    assert rows[1]["success_rate"] == ""


@pytest.mark.slow
def test_trials_on_a_local_ray_cluster_are_the_same(reference: Path, tmp_path: Path) -> None:
    ray = pytest.importorskip("ray")
    from cartpole_q.experiments import tune as tuning

    spec = load_tune(write_yaml(tmp_path / "small.yaml", TUNE))
    directory = tuning.start_tune(spec, tmp_path / "ray", None)
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        outcome = tuning.run_tune(spec, directory, None, workers=2, backend="ray")
    finally:
        ray.shutdown()
    assert outcome.complete
    assert _trials(directory) == _trials(reference)


# -- a study never mixes results ---------------------------------------------------------------


TUNE_EDITS = [
    pytest.param(
        lambda d: d.update({"objective": "iqm_eval_return"}),
        'objective: the study was started with "success_rate", the tune file now says '
        '"iqm_eval_return"',
        id="objective",
    ),
    pytest.param(
        lambda d: d.update({"seeds": "0-9"}),
        'seeds: the study was started with "0-3", the tune file now says "0-9"',
        id="seeds",
    ),
    pytest.param(
        lambda d: d["space"]["agent.q_init"].update({"high": 500}),
        "space.agent.q_init.high: the study was started with 300.0, the tune file now says 500.0",
        id="a range",
    ),
    pytest.param(
        lambda d: d["base"]["train"].update({"episodes": 61}),
        "base.train.episodes: the study was started with 60, the tune file now says 61",
        id="a base key",
    ),
]


@pytest.mark.parametrize(("edit", "message"), TUNE_EDITS)
def test_resume_refuses_a_tune_yaml_edited_since_the_start(
    tmp_path: Path, edit: Any, message: str
) -> None:
    import yaml

    path = write_yaml(tmp_path / "small.yaml", {**TUNE, "trials": 1})
    out = tmp_path / "out"
    assert invoke("tune", path, "--out", out, "--workers", 1, "-q").exit_code == 0
    before = _trials(out)
    tune_yaml = out / tunedir.TUNE_FILE
    data = yaml.safe_load(tune_yaml.read_text())
    edit(data)
    tune_yaml.write_text(yaml.safe_dump(data, sort_keys=False))
    result = invoke("tune", "--resume", out, "--trials", 2, "-q")
    assert result.exit_code == 2, result.output
    assert message in result.output
    assert str(tune_yaml) in result.output
    assert _trials(out) == before


def _set_trials(directory: Path, trials: int) -> None:
    """Set ``trials`` in a tune directory's ``tune.yaml`` (a resume then runs up to it)."""
    import yaml

    tune_yaml = directory / tunedir.TUNE_FILE
    data = yaml.safe_load(tune_yaml.read_text())
    data["trials"] = trials
    tune_yaml.write_text(yaml.safe_dump(data, sort_keys=False))


def test_resume_fails_a_trial_its_killed_process_never_named(tmp_path: Path) -> None:
    """Killed between asking for a trial and naming itself: resume must not count it."""
    import optuna

    path = write_yaml(tmp_path / "small.yaml", {**TUNE, "trials": 1})
    out = tmp_path / "out"
    assert invoke("tune", path, "--out", out, "--workers", 1, "-q").exit_code == 0
    storage = optuna.storages.JournalStorage(
        optuna.storages.journal.JournalFileBackend(str(out / tunedir.JOURNAL_FILE))
    )
    optuna.load_study(study_name=TUNE["name"], storage=storage).ask()  # RUNNING, no owner
    _set_trials(out, 2)
    assert invoke("tune", "--resume", out, "-q").exit_code == 0
    states = [trial.state.name for trial in _journal_trials(out)]
    assert states == ["COMPLETE", "FAIL", "COMPLETE"]


@pytest.mark.parametrize("cut", [b'{"op_code":5,"worker_id":"w', b'{"op_c', b"{"])
def test_resume_cuts_a_record_a_full_disk_cut_a_few_bytes_in(tmp_path: Path, cut: bytes) -> None:
    """A full disk cuts a write where the journal's last block ends, as early in a record
    as anywhere: the resume drops what was cut and runs the trials left."""
    path = write_yaml(tmp_path / "small.yaml", {**TUNE, "trials": 1})
    out = tmp_path / "out"
    assert invoke("tune", path, "--out", out, "--workers", 1, "-q").exit_code == 0
    journal = out / tunedir.JOURNAL_FILE
    whole = journal.read_bytes()
    journal.write_bytes(whole + cut)
    _set_trials(out, 2)
    result = invoke("tune", "--resume", out, "-q")
    assert result.exit_code == 0, result.output
    assert journal.read_bytes().startswith(whole)  # only the cut record was dropped
    assert [trial.state.name for trial in _journal_trials(out)] == ["COMPLETE", "COMPLETE"]


def test_resume_may_raise_the_trials_in_tune_yaml(tmp_path: Path) -> None:
    path = write_yaml(tmp_path / "small.yaml", {**TUNE, "trials": 1})
    out = tmp_path / "out"
    assert invoke("tune", path, "--out", out, "--workers", 1, "-q").exit_code == 0
    _set_trials(out, 2)
    assert invoke("tune", "--resume", out, "-q").exit_code == 0
    assert len(_trials(out)) == 2


@pytest.mark.parametrize("storage", ["sqlite", "journal"])
def test_a_study_in_a_storage_is_joined_only_when_asked_and_alike(
    tmp_path: Path, storage: str
) -> None:
    url = f"sqlite:///{tmp_path / 'study.db'}" if storage == "sqlite" else str(tmp_path / "s.jl")
    path = write_yaml(tmp_path / "small.yaml", {**TUNE, "trials": 1})
    assert invoke("tune", path, "--out", tmp_path / "o1", "--storage", url, "-q").exit_code == 0
    # the same name again: refused unless asked, nothing written
    result = invoke("tune", path, "--out", tmp_path / "o2", "--storage", url, "-q")
    assert result.exit_code == 2, result.output
    assert "already holds a study named 'small'; pass --join" in result.output
    assert not (tmp_path / "o2").exists()
    # asked, but searching another space: refused, nothing written
    other = write_yaml(
        tmp_path / "other.yaml",
        {**TUNE, "trials": 1, "space": {**TUNE["space"], "agent.q_init": {"low": 0, "high": 9}}},
    )
    result = invoke("tune", other, "--out", tmp_path / "o3", "--storage", url, "--join", "-q")
    assert result.exit_code == 2, result.output
    assert "space.agent.q_init.high: the study was started with 300" in result.output
    assert not (tmp_path / "o3").exists()
    # asked, and alike: it adds trials to the same study
    result = invoke(
        "tune", path, "--out", tmp_path / "o4", "--storage", url, "--join", "--trials", 2, "-q"
    )
    assert result.exit_code == 0, result.output
    assert [row["trial"] for row in _trials(tmp_path / "o4")] == ["0", "1"]
    # --join without a study to join, or without --storage
    lonely = write_yaml(tmp_path / "lonely.yaml", {**TUNE, "name": "lonely", "trials": 1})
    result = invoke("tune", lonely, "--out", tmp_path / "o5", "--storage", url, "--join")
    assert result.exit_code == 2
    assert "holds no study named 'lonely' to join" in result.output
    assert invoke("tune", path, "--out", tmp_path / "o6", "--join").exit_code == 2
    assert not (tmp_path / "o5").exists() and not (tmp_path / "o6").exists()


def test_a_storage_that_cannot_be_used_is_refused_before_anything_starts(tmp_path: Path) -> None:
    """No "the study is kept ... make room": nothing has started."""
    path = write_yaml(tmp_path / "small.yaml", TUNE)
    out = tmp_path / "out"
    result = invoke("tune", path, "--out", out, "--storage", tmp_path)
    assert result.exit_code == 2, result.output
    assert result.stderr == (
        f"error: --storage {tmp_path}: is a directory; give a journal file's path (such as "
        f"{tmp_path / tunedir.JOURNAL_FILE}) or an Optuna storage URL (sqlite:///study.db, "
        "postgresql://...).\n"
    )
    nowhere = tmp_path / "no" / "such.journal"
    result = invoke("tune", path, "--out", out, "--storage", nowhere)
    assert result.exit_code == 2, result.output
    assert "kept" not in result.stderr and "--resume" not in result.stderr, result.stderr
    assert f"the directory {nowhere.parent} does not exist" in result.stderr
    assert not out.exists()


@pytest.mark.slow
def test_a_second_writer_of_a_tune_directory_is_refused_naming_its_pid(tmp_path: Path) -> None:
    # So many trials that the first writer is still writing when the second one starts (it
    # is killed below); 40 could all finish first on a warm cache, and the resume succeed.
    path = write_yaml(tmp_path / "s.yaml", {**TUNE, "trials": 10_000, "seeds": "0-19"})
    out = tmp_path / "out"
    process = _start(tmp_path, path, "--out", out, "--workers", 1)
    try:
        deadline = time.monotonic() + 120
        while not (out / ".lock").is_file() or not _created_in_journal(out / tunedir.JOURNAL_FILE):
            assert process.poll() is None
            assert time.monotonic() < deadline
            time.sleep(0.05)
        result = invoke("tune", "--resume", out, "-q")
        assert result.exit_code == 2, result.output
        assert f"another cartpole-q process (pid {process.pid}) is writing this tune" in (
            result.output
        )
    finally:
        os.killpg(process.pid, signal.SIGKILL)
        process.wait()


ENV_CHOICES = [
    pytest.param(
        {"env.id": {"choices": ["CartPole-v1", "CartPol-v1"]}},
        "space.env.id (CartPol-v1): env.id: 'CartPol-v1' is not a registered Gymnasium environment",
        id="env id typo",
    ),
    pytest.param(
        {"discretization.bins": {"choices": [[1, 1, 6, 12], [1, 6, 12]]}},
        "space.discretization.bins ([1, 6, 12]): discretization.low: has 4 entries",
        id="bins of the wrong length",
    ),
    pytest.param(
        {"env.kwargs.max_episode_steps": {"low": 0, "high": 500, "int": True}},
        "space.env.kwargs.max_episode_steps (0): env.kwargs.max_episode_steps: the time "
        "limit must be a positive whole number",
        id="a range end",
    ),
    pytest.param(
        {"agent.alpha": {"low": 0.1, "high": 0.5, "step": 0.3}},
        "space.agent.alpha: step 0.3 does not divide the range 0.1 to 0.5",
        id="step does not divide",
    ),
    pytest.param(
        {"agent.alpha": {"low": 0.1, "high": 0.5, "step": 1.0}},
        "space.agent.alpha: step 1 does not divide the range 0.1 to 0.5",
        id="step above the range",
    ),
]


@pytest.mark.parametrize(("space", "message"), ENV_CHOICES)
def test_every_choice_and_range_end_is_checked_before_anything_is_written(
    tmp_path: Path, space: dict[str, Any], message: str
) -> None:
    path = write_yaml(tmp_path / "t.yaml", {**TUNE, "space": space})
    result = invoke("tune", path, "--out", tmp_path / "out")
    assert result.exit_code == 2, result.output
    assert f"{path}: {message}" in result.output
    assert not (tmp_path / "out").exists()


def test_a_study_of_too_many_runs_needs_yes(tmp_path: Path) -> None:
    path = write_yaml(tmp_path / "t.yaml", {**TUNE, "seeds": "0-9999", "trials": 1000})
    result = invoke("tune", path, "--out", tmp_path / "out")
    assert result.exit_code == 2
    assert "1,000 trials x 10,000 seeds = 10,000,000 runs, more than --max-runs" in result.output
    assert not (tmp_path / "out").exists()


def test_best_yaml_is_named_after_the_study(reference: Path) -> None:
    assert load_config(reference / tunedir.BEST_FILE).name == "small-best"
    header = (reference / tunedir.TRIALS_FILE).read_text().splitlines()[0]
    assert "tie_break_env_steps" in header.split(",")


FULL_DISK = r"""
set -u
mount -t tmpfs -o size=512k tmpfs "$MNT"
"$CLI" tune "$TUNE" --out "$MNT/t" --workers 1 -q > "$LOG/out1" 2> "$LOG/err1" &
pid=$!
# fill the disk once three trials are complete
until [ "$(grep -o '"state":1' "$MNT/t/study.journal" 2>/dev/null | wc -l)" -ge 3 ]; do
  kill -0 $pid 2>/dev/null || break
  sleep 0.05
done
dd if=/dev/zero of="$MNT/filler" bs=4k > /dev/null 2>&1
wait $pid; echo $? > "$LOG/rc1"
grep -o '"state":1' "$MNT/t/study.journal" | wc -l > "$LOG/complete_before"
rm "$MNT/filler"
"$CLI" tune --resume "$MNT/t" --workers 1 -q > "$LOG/out2" 2> "$LOG/err2"; echo $? > "$LOG/rc2"
cp "$MNT/t/trials.csv" "$LOG/trials.csv" 2>/dev/null
"""


def _in_private_mount(script: str, env: dict[str, str]) -> subprocess.CompletedProcess[bytes]:
    """Run a shell script in its own mount namespace (root, or a user namespace)."""
    import shutil

    unshare = shutil.which("unshare")
    if unshare is None:
        pytest.skip("no unshare(1) here to mount a small file system")
    options = ["-m"] if os.geteuid() == 0 else ["-r", "-m"]
    probe = subprocess.run([unshare, *options, "true"], capture_output=True)
    if probe.returncode != 0:
        pytest.skip(f"cannot make a mount namespace here: {probe.stderr.decode().strip()}")
    return subprocess.run(
        [unshare, *options, "bash", "-c", script], env={**os.environ, **env},
        capture_output=True, timeout=600,
    )  # fmt: skip


@pytest.mark.slow
def test_a_full_disk_costs_at_most_the_trial_in_flight_and_resume_recovers(
    tmp_path: Path,
) -> None:
    """A real 512 KiB file system, filled up while the study runs."""
    path = write_yaml(tmp_path / "t.yaml", {**TUNE, "trials": 12, "seeds": "0-3"})
    (tmp_path / "mnt").mkdir()
    (tmp_path / "log").mkdir()
    done = _in_private_mount(
        FULL_DISK,
        {
            "MNT": str(tmp_path / "mnt"), "LOG": str(tmp_path / "log"), "TUNE": str(path),
            "CLI": str(Path(sys.executable).with_name("cartpole-q")),
        },
    )  # fmt: skip
    log = tmp_path / "log"
    assert done.returncode == 0, done.stderr.decode()
    err1 = (log / "err1").read_text()
    assert (log / "rc1").read_text().strip() == "2", err1
    assert "Traceback" not in err1
    assert "study.journal: cannot be written: no space is left on the device" in err1
    assert "cartpole-q tune --resume" in err1
    assert (log / "rc2").read_text().strip() == "0", (log / "err2").read_text()
    before = int((log / "complete_before").read_text())
    with (log / "trials.csv").open(newline="") as file:
        rows = list(csv.DictReader(file))
    states = [row["state"] for row in rows]
    assert states.count("complete") == 12
    assert states.count("fail") <= 1, "at most the trial in flight is lost"
    assert before >= 3


def test_a_signal_as_soon_as_the_directory_exists_is_answered_like_any_other(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A real SIGINT right after ``tune.yaml`` is written, before the study or any trial."""
    monkeypatch.setattr(tunedir, "write_tune", then_sigint(tunedir.write_tune))
    directory = tmp_path / "early"
    path = write_yaml(tmp_path / "t.yaml", {**TUNE, "trials": 2, "seeds": "0-1"})
    result = invoke("tune", path, "--out", directory, "-q")
    assert result.exit_code == 130, result.output
    assert f"go on with `cartpole-q tune --resume {directory}`" in result.stderr
    resumed = invoke("tune", "--resume", directory, "-q")
    assert resumed.exit_code == 0, resumed.output
    assert len(_trials(directory)) == 2
