"""Tuning with Optuna: each trial a config, scored on every seed of the tune file.

Trials run one after another in this process (ask, run every seed, tell), the seeds of a
trial spread over the workers; so the same tune file and sampler seed give the same
trials in the same order whatever ``--workers`` is. Several processes (or machines
sharing a file system) can work on one study: each asks the storage for its next trial,
and the trial numbers the storage hands out are never duplicated.

The objective, maximised: ``success_rate`` (plus a bonus below ``0.001`` that grows with the
IQM eval return, so that among trials with the same rate, all 0 early on, the better
learner wins and the sampler has a slope) or ``iqm_eval_return`` over the seeds, minus a
tie-breaker of ``1e-9`` times the median env steps each seed trained to its solve (ten
million for a seed that never solved): smaller than one seed's share of the success rate,
so among equally good trials the faster learner wins.
"""

from __future__ import annotations

import contextlib
import datetime
import json
import math
import os
import socket
import time
import warnings
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from cartpole_q.config import ConfigError, mapping_differences, shorten, shown_value
from cartpole_q.errors import RunError, WriteError
from cartpole_q.experiments.sweep import (
    MAX_RUNS_PER_TASK,
    FinishedRun,
    check_tensorboard,
    run_task,
    write_run_events,
)
from cartpole_q.experiments.tune_spec import Dimension, TuneSpec, load_tune
from cartpole_q.experiments.workers import InProcess, chunk_size, execute
from cartpole_q.progress import NullReporter
from cartpole_q.results import SeedResult, summarize_seeds
from cartpole_q.statistics import iqm
from cartpole_q.store import sweepdir, tunedir
from cartpole_q.store.atomic import remove_stale_temporaries, write_failure
from cartpole_q.store.sweepdir import axis_cell, cell
from cartpole_q.store.tensorboard import TENSORBOARD_DIR

if TYPE_CHECKING:
    from cartpole_q.figures import DataFigure

IQM_BONUS = 1e-3
"""with objective success_rate: the most a trial's IQM eval return adds (below one seed's share)"""
TIE_BREAK = 1e-9
"""objective penalty per env step (median over seeds) to break ties between trials"""
UNSOLVED_STEPS = 1e7
"""the tie-breaker's env steps for a seed that never solved (a penalty of 0.01)"""
OWNER = "owner"
"""the user attribute naming the process (host:pid) that runs a trial"""


def optuna_module() -> Any:
    """Optuna, or a clear error if the extra is not installed."""
    try:
        import optuna
    except ImportError:
        raise ConfigError(
            "cartpole-q tune needs Optuna; install it with `pip install 'cartpole-q[tune]'` "
            "(or `pip install optuna`)."
        ) from None
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    # Optuna's matplotlib plots are marked experimental; the warning says nothing to a user.
    warnings.filterwarnings("ignore", category=optuna.exceptions.ExperimentalWarning)
    return optuna


SEARCH_ATTR = "cartpole_q_search"
"""the study's user attribute holding its search: everything of the tune file but
``name`` and ``trials``, recorded when the study is created"""


def storage_for(directory: Path, url: str | None) -> Any:
    """The study's storage: a journal file, or the Optuna storage at ``url``.

    The journal file is the tune directory's, or ``url`` when it is a path; any other
    ``url`` is an Optuna storage URL (``sqlite:///...``, ``postgresql://...``).

    A journal's last record, cut by a full disk or a kill in the middle of a write, is
    removed first (see :func:`repair_journal`).

    Raises:
        ConfigError: the URL cannot be opened.
    """
    optuna = optuna_module()
    if url is None or "://" not in url:
        from optuna.storages import JournalStorage
        from optuna.storages.journal import JournalFileBackend

        path = directory / tunedir.JOURNAL_FILE if url is None else Path(url)
        with storage_errors(path):
            check_journal(path, given=url is not None)  # before anything is cut or added
            repair_journal(path)
            try:
                return JournalStorage(JournalFileBackend(str(path)))
            except (ValueError, KeyError, TypeError, AssertionError) as error:
                # records of the right form that Optuna cannot replay
                reason = shorten(
                    f"Optuna cannot replay its records: {type(error).__name__}: {error}"
                )
                raise _not_a_journal(path, url is not None, reason) from None
    try:
        return optuna.storages.get_storage(url)
    except Exception as error:  # Optuna raises many kinds for a bad URL
        raise ConfigError(f"--storage {url}: cannot open this Optuna storage ({error}).") from None


MAX_JOURNAL_RECORD = 16 * 2**20
"""the longest journal line read as a record"""
JOURNAL_RECORD_START = b'{"op_code":'
"""how every record Optuna writes to a journal begins (``json.dumps`` with ``op_code`` first)"""


def check_journal(path: Path, *, given: bool) -> None:
    """Refuse a file that is not an Optuna journal before anything reads, cuts or appends to it.

    Every line of a journal is one JSON object with an ``op_code``; only the last may be
    cut short (a kill or a full disk mid-write, which :func:`repair_journal` then removes).
    Such a line begins as every record does, or, after complete records, is a beginning
    of that beginning: a full disk cuts a write where the file's last block ends, a few
    bytes into a record as likely as any other place. Optuna skips a last line it cannot
    read and would append its records after it, turning a file that was never a journal
    into one no reader accepts; and cutting a "half-written record" from a file that is
    not a journal would destroy its end.

    Args:
        path: the journal file (it may not exist yet).
        given: it is ``--storage`` (a refusal names the option), not the tune directory's.

    Raises:
        ConfigError: ``--storage`` names a file that is not a journal.
        RunError: a tune directory's own journal is damaged.
    """
    if not path.is_file():
        return  # a new journal: Optuna creates it
    with path.open("rb") as journal:
        # A record is a few kilobytes; a "line" of many megabytes is no record (and is not
        # read whole).
        lines = iter(lambda: journal.readline(MAX_JOURNAL_RECORD), b"")
        for number, line in enumerate(lines, start=1):
            cut_short = not line.endswith(b"\n") and len(line) < MAX_JOURNAL_RECORD
            if cut_short and (
                line.startswith(JOURNAL_RECORD_START)
                or (number > 1 and JOURNAL_RECORD_START.startswith(line))
            ):
                return  # a record cut short, the last line: repair_journal removes it
            try:
                record = json.loads(line)
            except (ValueError, RecursionError):  # not UTF-8 or not JSON
                record = None
            if not isinstance(record, dict) or not isinstance(record.get("op_code"), int):
                raise _not_a_journal(path, given, f"line {number} is not one of its records")


def _not_a_journal(path: Path, given: bool, reason: str) -> ConfigError | RunError:
    if given:
        return ConfigError(
            f"--storage {path}: is not an Optuna journal file ({reason}); nothing was written "
            "to it. Give a new file name (the journal is created), a journal an earlier "
            "`cartpole-q tune` wrote, or a storage URL such as sqlite:///study.db."
        )
    return RunError(f"{path}: the study's journal is damaged ({reason}); it cannot be read.")


def repair_journal(path: Path) -> bool:
    """Cut a half-written record from the end of an Optuna journal file; say whether one was.

    Optuna appends one JSON record per line. A write that a full disk (or a kill) cut
    short leaves a last line without its newline; the next record would be appended to
    it and make the whole journal unreadable. The cut record was never complete, so no
    reader ever saw it: dropping it loses nothing. Done under the journal's own lock, so
    another process's record in progress is never taken for a cut one.
    """
    if not path.is_file() or path.stat().st_size == 0:
        return False
    from optuna.storages.journal import JournalFileSymlinkLock

    lock = JournalFileSymlinkLock(str(path))
    lock.acquire()
    try:
        with path.open("rb+") as journal:
            size = journal.seek(0, os.SEEK_END)
            journal.seek(size - 1)
            if journal.read(1) == b"\n":
                return False
            end = size
            while end > 0:  # back to the last newline, a block at a time
                start = max(0, end - 65536)
                journal.seek(start)
                block = journal.read(end - start)
                newline = block.rfind(b"\n")
                if newline >= 0:
                    end = start + newline + 1
                    break
                end = start
            journal.truncate(end)
            return True
    finally:
        lock.release()


@contextlib.contextmanager
def storage_errors(where: Path | str) -> Iterator[None]:
    """Turn a storage that cannot be written (a full disk, say) into an error naming it.

    The study in the storage stays usable: what a failed write cut short is removed when
    the storage is opened again, and the trial that was running is marked failed by the
    next ``tune --resume``. So a full disk costs at most the trial in flight (the command
    line says so, and how to go on, once the study exists).
    """
    try:
        yield
    except OSError as error:
        path = Path(getattr(error, "filename", None) or where)
        raise WriteError(f"{path}: cannot be written: {write_failure(path, error)}.") from None
    except Exception as error:
        if type(error).__module__.split(".")[0] not in ("sqlalchemy", "optuna"):
            raise
        if "disk" not in str(error).lower() and "OperationalError" not in type(error).__name__:
            raise
        raise WriteError(
            f"--storage {where}: the database could not be written ({error})."
        ) from None


def absolute_url(url: str | None) -> str | None:
    """A storage that names the same place from any directory (SQLite, journal paths absolute).

    >>> absolute_url("sqlite:////tmp/study.db"), absolute_url(None), absolute_url("/a/s.journal")
    ('sqlite:////tmp/study.db', None, '/a/s.journal')
    """
    prefix = "sqlite:///"
    if url is None:
        return None
    if "://" not in url:
        return str(Path(url).resolve())
    if not url.startswith(prefix) or url.startswith(prefix + "/"):
        return url
    return prefix + str(Path(url[len(prefix) :]).resolve())


def search_of(spec: TuneSpec) -> dict[str, Any]:
    """What makes trials comparable: the tune file but its ``name`` and ``trials``."""
    return {key: value for key, value in spec.to_dict().items() if key not in ("name", "trials")}


def sampler_for(spec: TuneSpec, trial_number: int = 0) -> Any:
    """The sampler the tune file asks for, seeded for one trial.

    The seed is derived from the tune file's seed and the trial's number, so a resumed
    study, or a second process joining it, draws new values instead of repeating the first
    trials' (a sampler seeded once per process would), and an uninterrupted study and a
    resumed one draw the same.
    """
    optuna = optuna_module()
    seed = int(np.random.SeedSequence([spec.sampler["seed"], trial_number]).generate_state(1)[0])
    if spec.sampler["type"] == "random":
        return optuna.samplers.RandomSampler(seed=seed)
    return optuna.samplers.TPESampler(seed=seed)


def check_storage(spec: TuneSpec, storage_url: str | None, join: bool, where: str) -> None:
    """Before anything is written: refuse to join a study unasked, or one searched differently.

    Args:
        spec: the tune file.
        storage_url: ``--storage`` (``None``: the new tune directory's own journal).
        join: ``--join`` was given: add trials to the study of that name in the storage.
        where: the tune file, for messages.

    Raises:
        ConfigError: ``storage_url`` is a directory; the storage already holds a study of
            this name and ``join`` is not set; ``join`` without a study (or without
            ``--storage``) to join; or the study's search differs from the file's (naming
            the key and both values).
        WriteError: the storage cannot be opened for writing (naming it).
    """
    if storage_url is None:
        if join:
            raise ConfigError(
                "--join adds trials to a study in a shared storage: give its --storage too."
            )
        return
    if "://" not in storage_url and Path(storage_url).is_dir():
        raise ConfigError(
            f"--storage {storage_url}: is a directory; give a journal file's path (such as "
            f"{Path(storage_url) / tunedir.JOURNAL_FILE}) or an Optuna storage URL "
            "(sqlite:///study.db, postgresql://...)."
        )
    optuna = optuna_module()
    storage = storage_for(Path(), storage_url)
    with storage_errors(storage_url):
        exists = spec.name in optuna.get_all_study_names(storage)
    if exists and not join:
        raise ConfigError(
            f"{where}: --storage {storage_url} already holds a study named {spec.name!r}; pass "
            "--join to add trials to it (its search must be this file's), or give this study "
            "another `name:`."
        )
    if join and not exists:
        raise ConfigError(
            f"--join: --storage {storage_url} holds no study named {spec.name!r} to join; leave "
            "--join out to start it."
        )
    if exists:
        with storage_errors(storage_url):
            the_study = optuna.load_study(study_name=spec.name, storage=storage)
        check_search(the_study, spec, f"{where}: the study {spec.name!r} in {storage_url}")


def check_search(the_study: Any, spec: TuneSpec, where: str) -> None:
    """Refuse a tune file whose search is not the one the study started with.

    A study created before the search was recorded gets the file's recorded now.

    Raises:
        RunError: naming the first key that differs, with both values.
    """
    recorded = the_study.user_attrs.get(SEARCH_ATTR)
    search = search_of(spec)
    if recorded is None:
        the_study.set_user_attr(SEARCH_ATTR, search)
        return
    differences = mapping_differences(recorded, search)
    if differences:
        key, old, new = differences[0]
        raise RunError(
            f"{where}: {key}: the study was started with {shown_value(old)}, the tune file now "
            f"says {shown_value(new)}. A study's trials must all be scored alike, so only "
            "`trials` may change; put it back, or start a new study (another `name:`)."
        )


@contextlib.contextmanager
def new_tune(spec: TuneSpec, out: Path | None, storage_url: str | None) -> Iterator[Path]:
    """Create the tune directory, its ``tune.yaml`` and study, holding its lock inside.

    The study is created, or joined when ``--storage`` holds it already. Call
    :func:`check_storage` first: it refuses what this would do wrong. A failure before the
    study exists (a full disk) removes the directory this created; after it, the directory
    stays for ``tune --resume``.
    """
    check_tensorboard([spec.config_for({})])
    with tunedir.new_tune_dir(spec.name, out) as claim:
        tunedir.write_tune(claim.path, spec.to_dict(), storage_url)
        study(spec, claim.path, storage_url, create=True)
        claim.keep()
        yield claim.path


def start_tune(spec: TuneSpec, out: Path | None, storage_url: str | None) -> Path:
    """Create the tune directory and its study (the directory's lock released on return)."""
    with new_tune(spec, out, storage_url) as directory:
        return directory


def load_tune_dir(directory: Path) -> tuple[TuneSpec, str | None]:
    """The tune file and storage URL of a tune directory (``--resume``; hold its lock)."""
    data, storage_url = tunedir.tune_file(directory)
    remove_stale_temporaries(directory)  # the caller holds the lock: none is in use
    if storage_url is None:  # the directory's own journal: no other process writes it
        tunedir.remove_stale_journal_lock(directory)
    return load_tune(data, label=str(directory / tunedir.TUNE_FILE)), storage_url


def study(spec: TuneSpec, directory: Path, storage_url: str | None, *, create: bool = False) -> Any:
    """The study of this tune directory: created (or joined) by :func:`start_tune`, loaded after.

    A loaded study's search must be the tune file's (:func:`check_search`).

    Raises:
        RunError: the storage has no such study (e.g. a moved database file), or its
            search is not the tune file's.
    """
    optuna = optuna_module()
    storage = storage_for(directory, storage_url)
    where = storage_url or directory / tunedir.JOURNAL_FILE
    with storage_errors(where):
        if create and spec.name not in optuna.get_all_study_names(storage):
            the_study = optuna.create_study(
                study_name=spec.name, storage=storage, sampler=sampler_for(spec),
                direction="maximize",
            )  # fmt: skip
            the_study.set_user_attr(SEARCH_ATTR, search_of(spec))
            return the_study
        try:
            the_study = optuna.load_study(
                study_name=spec.name, storage=storage, sampler=sampler_for(spec)
            )
        except KeyError:
            raise RunError(
                f"{directory}: its study {spec.name!r} is not in {where}; was the storage moved?"
            ) from None
        check_search(the_study, spec, str(directory / tunedir.TUNE_FILE))
    return the_study


@dataclass
class TuneOutcome:
    """How a tune call ended."""

    directory: Path
    complete: bool
    finished_trials: int
    best: dict[str, Any] | None


def suggest(trial: Any, dimension: Dimension) -> Any:
    """The trial's value for one dimension (choices are suggested by their text)."""
    if dimension.choices:
        texts = [axis_cell(choice) for choice in dimension.choices]
        chosen = trial.suggest_categorical(dimension.key, texts)
        return dimension.choices[texts.index(chosen)]
    assert dimension.low is not None and dimension.high is not None
    if dimension.integer:
        step = int(dimension.step or 1)
        return trial.suggest_int(
            dimension.key, int(dimension.low), int(dimension.high), step=step, log=dimension.log
        )
    return trial.suggest_float(
        dimension.key, dimension.low, dimension.high, log=dimension.log, step=dimension.step
    )


def _alive_here(owner: str) -> bool:
    host, _, pid = owner.rpartition(":")
    if host != socket.gethostname():
        return True  # another machine's: it may well be running
    try:
        os.kill(int(pid), 0)
    except (ValueError, ProcessLookupError):
        return False
    except PermissionError:
        return True
    return True


def fail_abandoned(the_study: Any, exclusive: bool = False) -> int:
    """Mark running trials whose process (on this machine) is gone as failed; count them.

    Args:
        the_study: The study.
        exclusive: Only this process can be running trials (the study is in the tune
            directory's own journal, whose lock this process holds): a trial no process
            has named yet was abandoned by a killed one.
    """
    optuna = optuna_module()
    failed = 0
    now = datetime.datetime.now()
    for trial in the_study.get_trials(deepcopy=False, states=(optuna.trial.TrialState.RUNNING,)):
        owner = trial.user_attrs.get(OWNER)
        if owner is None:
            # Its process was killed between asking for it and naming itself, or (in a
            # shared storage) another is about to name itself: there, only a trial a
            # minute old is abandoned.
            started = trial.datetime_start
            old = started is not None and (now - started).total_seconds() > 60
            abandoned = exclusive or old
        else:
            abandoned = not _alive_here(owner)
        if abandoned:
            the_study._storage.set_trial_state_values(trial._trial_id, optuna.trial.TrialState.FAIL)
            failed += 1
    return failed


def counted(the_study: Any) -> list[Any]:
    """The trials that count toward ``trials``: finished, pruned or running."""
    optuna = optuna_module()
    states = (
        optuna.trial.TrialState.COMPLETE,
        optuna.trial.TrialState.PRUNED,
        optuna.trial.TrialState.RUNNING,
    )
    return list(the_study.get_trials(deepcopy=False, states=states))


def run_tune(
    spec: TuneSpec,
    directory: Path,
    storage_url: str | None,
    *,
    trials: int | None = None,
    workers: int = 1,
    backend: str = "local",
    address: str | None = None,
    should_stop: Callable[[], bool] | None = None,
    on_trial: Callable[[dict[str, Any]], None] | None = None,
) -> TuneOutcome:
    """Run trials until the study has ``trials`` (default: the tune file's) of them.

    Raises:
        ConfigError: Optuna is missing, or the storage cannot be opened.
        WriteError: the storage cannot be written (a full disk): the study keeps every
            finished trial, and ``tune --resume`` goes on with it.
    """
    check_tensorboard([spec.config_for({})])
    where = storage_url or directory / tunedir.JOURNAL_FILE
    with storage_errors(where):
        return _run_trials(
            spec, directory, storage_url, trials or spec.trials, workers, backend, address,
            should_stop, on_trial,
        )  # fmt: skip


def _run_trials(
    spec: TuneSpec, directory: Path, storage_url: str | None, total: int, workers: int,
    backend: str, address: str | None, should_stop: Callable[[], bool] | None,
    on_trial: Callable[[dict[str, Any]], None] | None,
) -> TuneOutcome:  # fmt: skip
    optuna = optuna_module()
    the_study = study(spec, directory, storage_url)
    fail_abandoned(the_study, exclusive=storage_url is None)
    owner = f"{socket.gethostname()}:{os.getpid()}"
    while not (should_stop is not None and should_stop()):
        if len(counted(the_study)) >= total:
            break
        the_study.sampler = sampler_for(spec, len(the_study.get_trials(deepcopy=False)))
        trial = the_study.ask()
        trial.set_user_attr(OWNER, owner)
        ahead = [t for t in counted(the_study) if t.number < trial.number]
        if len(ahead) >= total:  # another process took the last trial meanwhile
            the_study.tell(trial, state=optuna.trial.TrialState.FAIL)
            break
        values = {dimension.key: suggest(trial, dimension) for dimension in spec.space}
        started = time.perf_counter()
        try:
            rows = evaluate_trial(
                spec, trial, values, the_study, workers, backend, address, should_stop,
                board=directory / TENSORBOARD_DIR,
            )  # fmt: skip
        except BaseException:
            with contextlib.suppress(OSError):  # a full disk: resume fails the trial instead
                the_study.tell(trial, state=optuna.trial.TrialState.FAIL)
            raise
        if rows is None:  # pruned: it could not beat the best trial
            the_study.tell(trial, state=optuna.trial.TrialState.PRUNED)
            if on_trial is not None:
                on_trial({"number": trial.number, "values": values, "pruned": True})
            continue
        if len(rows) < len(spec.seeds):  # stopped by a signal: not a result
            the_study.tell(trial, state=optuna.trial.TrialState.FAIL)
            break
        from cartpole_q.envs.gym import config_threshold

        threshold = config_threshold(spec.config_for(values))
        figures = trial_figures(spec, rows, threshold)
        for name, value in figures.items():
            trial.set_user_attr(name, value)
        trial.set_user_attr("seconds", round(time.perf_counter() - started, 3))
        the_study.tell(trial, figures["objective"])
        if on_trial is not None:
            on_trial({"number": trial.number, "values": values, **figures})
    finished = [
        t
        for t in the_study.get_trials(deepcopy=False)
        if t.state.is_finished() and t.state.name == "COMPLETE"
    ]
    complete = len(counted(the_study)) >= total and not any(
        t.state.name == "RUNNING" for t in the_study.get_trials(deepcopy=False)
    )
    best = write_outputs(spec, directory, the_study) if finished else None
    return TuneOutcome(directory, complete, len(finished), best)


def evaluate_trial(
    spec: TuneSpec, trial: Any, values: dict[str, Any], the_study: Any, workers: int,
    backend: str, address: str | None, should_stop: Callable[[], bool] | None,
    board: Path | None = None,
) -> list[SeedResult] | None:  # fmt: skip
    """Run the trial's config on every seed; None if pruned.

    The first seed runs in this process (loading the compiled loop, which forked workers
    then share); with the pruner, seeds run in rounds and the trial stops once even all
    its remaining seeds succeeding could not beat the best trial so far. With
    ``train.tensorboard``, each seed's events go to ``board/trial-NNNN/seed-S``.
    """
    config = spec.config_for(values, f"trial {trial.number}")
    mapping = config.to_dict()
    seeds = list(spec.seeds)
    rows: list[SeedResult] = []

    def collect(index: int, finished: FinishedRun) -> None:
        rows.append(finished.result)
        if board is not None and config.train.tensorboard:
            seed = finished.result.seed
            where = board / f"trial-{trial.number:04d}" / sweepdir.seed_key(seed, spec.seeds)
            write_run_events(where, config.for_seed(seed), finished)

    here = InProcess(should_stop, NullReporter())
    for finished in run_task(here, [(trial.number, mapping, seeds[:1])]):
        collect(0, finished)
    position = 1
    round_size = max(len(seeds), 1) if not spec.pruner else max(5, 2 * workers)
    while position < len(seeds):
        if should_stop is not None and should_stop():
            break
        chunk = seeds[position : position + round_size]
        position += len(chunk)
        size = chunk_size(len(chunk), workers, most=MAX_RUNS_PER_TASK)
        jobs = [
            ([(trial.number, mapping, tuple(chunk[i : i + size]))],)
            for i in range(0, len(chunk), size)
        ]
        execute(run_task, jobs, collect, backend=backend, workers=min(workers, len(jobs)),
                address=address, should_stop=should_stop)  # fmt: skip
        if spec.pruner and position < len(seeds):
            # Reported, so that samplers can rank a pruned trial by how far it got.
            trial.report(sum(bool(row.success) for row in rows) / len(seeds), len(rows))
            if _cannot_win(the_study, rows, len(seeds)):
                return None
    rows.sort(key=lambda row: row.seed)
    return rows


def _cannot_win(the_study: Any, rows: list[SeedResult], seeds: int) -> bool:
    """Whether even all remaining seeds succeeding would leave a lower success rate than the best's.

    Equal rates are not pruned: the trial could still win on the tie-breakers.
    """
    try:
        best = the_study.best_trial.user_attrs.get("success_rate")
    except ValueError:
        return False  # no finished trial yet
    if best is None:
        return False
    successes = sum(bool(row.success) for row in rows)
    return bool((successes + seeds - len(rows)) / seeds < best)


def trial_figures(
    spec: TuneSpec, rows: Sequence[SeedResult], threshold: float | None = None
) -> dict[str, float]:
    """A trial's statistics over its seeds, and its objective value.

    Args:
        spec: the tune file.
        rows: the trial's results, one per seed.
        threshold: the reward threshold (it scales the IQM bonus; 100 when None).
    """
    means = [row.eval_mean for row in rows if row.eval_mean is not None]
    stats = summarize_seeds(rows)
    # An unsolved seed counts as UNSOLVED_STEPS, so failing fast never looks like learning fast.
    steps = [float(row.env_steps_to_solve or UNSOLVED_STEPS) for row in rows]
    tie_break = float(np.median(steps))
    figures: dict[str, float] = {
        name: value for name, value in stats.as_row().items() if value is not None
    }
    figures["tie_break_env_steps"] = tie_break
    if spec.objective == "success_rate":
        # Among trials with the same success rate (all at 0 early on), the higher IQM eval
        # return wins: a bounded bonus below one seed's share, so the sampler has a slope.
        scale = abs(threshold or 0.0) or 100.0
        bonus = IQM_BONUS * (0.5 + math.atan(iqm(means) / scale) / math.pi)
        primary = float(stats.success_rate or 0.0) + bonus
    else:
        primary = iqm(means)
    figures["objective"] = primary - TIE_BREAK * tie_break
    return figures


TRIAL_COLUMNS = (
    "success_rate", "success_rate_low", "success_rate_high", "iqm_eval_return",
    "iqm_eval_return_low", "iqm_eval_return_high", "median_solved_episode",
    "median_env_steps_to_solve", "tie_break_env_steps", "seconds",
)  # fmt: skip


def write_outputs(spec: TuneSpec, directory: Path, the_study: Any) -> dict[str, Any]:
    """Write ``trials.csv``, ``best.yaml``, ``history.png`` and ``importance.png``.

    Each figure goes out with its data beside it (``history.csv``, ``importance.csv``).

    Returns:
        The best trial: ``number``, ``values``, ``objective`` and its figures.
    """
    trials = the_study.get_trials(deepcopy=False)
    keys = [dimension.key for dimension in spec.space]
    header = ["trial", "state", *keys, "objective", *TRIAL_COLUMNS]
    rows = []
    for trial in trials:
        rows.append({
            "trial": str(trial.number),
            "state": trial.state.name.lower(),
            **{key: cell(trial.params.get(key)) if not isinstance(trial.params.get(key), str) else trial.params[key] for key in keys},
            "objective": cell(trial.value),
            **{name: cell(_attribute(trial, name)) for name in TRIAL_COLUMNS},
        })  # fmt: skip
    tunedir.write_trials(directory, header, rows)
    best_trial = the_study.best_trial
    values = {d.key: _param_value(d, best_trial.params[d.key]) for d in spec.space}
    best_config = spec.config_for(
        {**values, "name": f"{spec.name[:59]}-best"}, f"trial {best_trial.number}"
    )
    tunedir.write_best(directory, best_config, best_trial.number)
    tunedir.write_figures(directory, *_figures(the_study, spec.name))
    return {"number": best_trial.number, "values": values, "objective": best_trial.value,
            **best_trial.user_attrs}  # fmt: skip


def _attribute(trial: Any, name: str) -> Any:
    """A trial's figure (``tie_break_env_steps`` was ``median_env_steps`` before)."""
    value = trial.user_attrs.get(name)
    if value is None and name == "tie_break_env_steps":
        value = trial.user_attrs.get("median_env_steps")
    return value


def _param_value(dimension: Dimension, value: Any) -> Any:
    if dimension.choices:
        texts = [axis_cell(choice) for choice in dimension.choices]
        return dimension.choices[texts.index(value)]
    return value


def _figures(the_study: Any, name: str) -> tuple[DataFigure, DataFigure | None]:
    """The history and importance figures (no importance below 2 finished trials).

    Drawn here rather than with Optuna's plots, so that each carries the numbers it draws:
    the objectives, and the importances Optuna's default evaluator gives (what its
    ``plot_param_importances`` draws), computed once.
    """
    from optuna.importance import get_param_importances

    from cartpole_q.figures import importance_figure, tune_history_figure

    complete = [t for t in the_study.get_trials(deepcopy=False) if t.state.name == "COMPLETE"]
    history = tune_history_figure(
        [t.number for t in complete], [t.value for t in complete], f"{name}: objective per trial"
    )
    if len(complete) < 2:
        return history, None
    try:
        importances = get_param_importances(the_study)
    except (RuntimeError, ValueError):
        return history, None  # e.g. every trial had the same value
    pairs = [(key, float(value)) for key, value in importances.items()]
    return history, importance_figure(pairs, f"{name}: parameter importances")


def load_best(directory: Path) -> Path:
    """The ``best.yaml`` of a finished tune directory."""
    path = directory / tunedir.BEST_FILE
    if not path.is_file():
        raise RunError(f"{directory}: has no {tunedir.BEST_FILE} yet.")
    return path
