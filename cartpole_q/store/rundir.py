"""The run directory: what training leaves behind, written atomically, read back strictly.

| file | content |
| --- | --- |
| ``config.yaml`` | the resolved config; ``train --config`` on it reproduces the run |
| ``q_table.npy`` | float64, shape ``(*bins, n_actions)``; greedy action = argmax of last axis |
| ``visits.npy`` | int64, same shape: how often training took each (state, action) |
| ``metrics.csv`` | ``episode,return,length,epsilon,alpha`` (and ``info_KEY`` with ``train.info_metric``), one row per training episode |
| ``evaluations.csv`` | periodic greedy evaluations: ``episode,env_steps,mean,std,min,max`` |
| ``reward_curve.png`` | returns, their 100-episode moving average, the threshold |
| ``summary.json`` | figures of the run; written last, so its presence means complete |
| ``checkpoint.npz`` | what ``--resume`` needs, with the config it was trained with: kept while a run is unfinished or interrupted, and after a run that reached ``train.episodes`` (to extend it) |
| ``tensorboard/`` | with ``train.tensorboard``: TensorBoard event files (:mod:`cartpole_q.store.tensorboard`) |

Every file is written to a temporary file in the same directory and moved into place with
``os.replace``, so a reader (or a process killed at any instant) never sees half a file.
Arrays are read with ``allow_pickle=False`` only.
"""

from __future__ import annotations

import contextlib
import csv
import dataclasses
import functools
import io
import os
import platform
import shutil
import time
from collections.abc import Iterator
from dataclasses import dataclass
from importlib import metadata
from pathlib import Path
from typing import Any

import numpy as np

from cartpole_q.config import Config, ConfigError, load_config
from cartpole_q.engines.base import EpisodeMetrics
from cartpole_q.errors import RunError, WriteError
from cartpole_q.evaluation import check_q_table, check_q_table_shape
from cartpole_q.results import MultiSeedSummary, RunSummary, SeedResult, is_success
from cartpole_q.rl.algorithms import get as get_algorithm
from cartpole_q.store import lock
from cartpole_q.store.atomic import (
    atomic_save_npy,
    atomic_write_text,
    make_directory,
    write_failure,
    write_json,
)
from cartpole_q.store.checkpoint import CHECKPOINT_FILE
from cartpole_q.store.reading import ShapeCheck, load_npy, read_json
from cartpole_q.training import TrainResult

CONFIG_FILE = "config.yaml"
Q_TABLE_FILE = "q_table.npy"
V_TABLE_FILE = "v_table.npy"
"""a prediction run's table: the state values ``V``, in place of ``q_table.npy``"""
VISITS_FILE = "visits.npy"
METRICS_FILE = "metrics.csv"
EVALUATIONS_FILE = "evaluations.csv"
CURVE_FILE = "reward_curve.png"
SUMMARY_FILE = "summary.json"
METRICS_HEADER = ("episode", "return", "length", "epsilon", "alpha")
ERRORS_COLUMN = "rms_error"
"""``metrics.csv``'s last column in a prediction run that measures its error"""
INFO_COLUMN_PREFIX = "info_"
"""``metrics.csv``'s last column with ``train.info_metric: KEY`` is ``info_KEY``"""
EVALUATIONS_HEADER = ("episode", "env_steps", "mean", "std", "min", "max")


# -- creating a run directory ---------------------------------------------------------


@dataclass
class NewDirectory:
    """A directory claimed for a new run, sweep or tune: created (or found empty), locked."""

    path: Path
    created: bool
    """this command created it (``--out`` may also name an existing empty directory)"""
    kept: bool = False
    """it holds what ``--resume`` needs, and stays whatever happens next"""

    def keep(self) -> None:
        """Say that the directory now holds what ``--resume`` needs (its start files)."""
        self.kept = True


_CLAIM_ATTEMPTS = 20
"""how often a directory removed by a failed start, while waiting for it, is made anew"""


@contextlib.contextmanager
def new_directory(
    name: str, out: Path | None, runs_root: Path = Path("runs"), kind: str = "run"
) -> Iterator[NewDirectory]:
    """Claim the directory a new run (or sweep, or study) writes to, holding its lock inside.

    The directory is created (``out``, or ``<runs_root>/<name>-<YYYYmmdd-HHMMSS>``) and
    locked before anything looks into it, and only then checked to be empty (but for its
    lock file). So of two commands given the same ``--out``, exactly one writes there:
    the other is refused without writing anything, whether it finds the first still
    writing (refused by the lock) or already finished (refused by its files).

    Until :meth:`NewDirectory.keep` is called, the directory holds nothing a command can
    go on with: if the block fails (a full disk, a signal, bad input), what this command
    wrote is removed, the directory too if it created it, so that nothing half-started is
    left behind. After ``keep`` a failure leaves the directory for ``--resume``.

    Args:
        name: the config's (or study's) name, the prefix of a directory under ``runs_root``.
        out: the directory asked for with ``--out``; it must not exist, or be empty.
        runs_root: where ``<name>-<YYYYmmdd-HHMMSS>`` goes when ``out`` is ``None``.
        kind: what the directory holds, for messages ("run", "sweep", "tune").

    Raises:
        RunError: ``out`` is a file or a non-empty directory, another command is writing
            it, or it cannot be created.
        WriteError: its lock file cannot be written (a full disk).
    """
    if out is not None:
        check_output_dir(out, runs_root, kind)  # a user's own directory stays untouched
    advice = (
        f"cartpole-q never writes a new {kind} into a directory another command writes. Choose "
        f"a new directory (or leave --out out for a fresh one under {runs_root}/)."
    )
    for _ in range(_CLAIM_ATTEMPTS):
        path, created = _make_directory(name, out, runs_root, kind)
        held = lock.acquire_lock(path, kind, advice)
        if held is not None:
            break
    else:
        raise RunError(f"{path}: was removed again and again while this command started; retry.")
    try:
        # Under the lock: a writer that got here first has left its files.
        _check_still_empty(path, runs_root, kind)
        claim = NewDirectory(path, created)
        try:
            held.name_holder()
            yield claim
        except BaseException as error:
            if claim.kept:
                raise
            _undo_start(claim, held.created)
            if isinstance(error, WriteError):
                undone = "was removed" if created else "was emptied again"
                raise WriteError(f"{error} The new {kind} directory {undone}.") from None
            raise
    finally:
        held.release()


def check_output_dir(out: Path, runs_root: Path = Path("runs"), kind: str = "run") -> None:
    """Refuse an output path that is a file or a non-empty directory (a lock file aside).

    Raises:
        RunError: naming the path and what is wrong with it.
    """
    if out.is_symlink() and not out.exists():
        raise RunError(
            f"{out}: --out is a dangling symbolic link (to {os.readlink(out)}); cartpole-q "
            "creates no directory through one. Give a new directory, or make the link's target."
        )
    if out.exists() and not out.is_dir():
        raise RunError(f"{out}: --out must be a directory, but this is a file.")
    if out.is_dir() and any(entry.name != lock.LOCK_FILE for entry in out.iterdir()):
        raise RunError(
            f"{out}: --out points at a non-empty directory; cartpole-q never writes a new "
            f"{kind} into one. Choose a new directory (or leave --out out for a fresh one "
            f"under {runs_root}/)."
        )


def _make_directory(name: str, out: Path | None, runs_root: Path, kind: str) -> tuple[Path, bool]:
    """Create the directory (or find ``out`` there already): the path and whether it was made."""
    where = out if out is not None else runs_root
    try:
        if out is not None:
            try:
                out.mkdir(parents=True)
            except FileExistsError:
                if not out.is_dir():
                    raise RunError(
                        f"{out}: --out must be a directory, but this is a file."
                    ) from None
                return out, False
            return out, True
        stamp = time.strftime("%Y%m%d-%H%M%S")
        runs_root.mkdir(parents=True, exist_ok=True)
        for attempt in range(1000):
            path = runs_root / (f"{name}-{stamp}" if attempt == 0 else f"{name}-{stamp}-{attempt}")
            try:
                path.mkdir()
            except FileExistsError:
                continue
            return path, True
    except OSError as error:
        reason = write_failure(where / "x", error)
        raise RunError(f"{where}: cannot create the {kind} directory: {reason}.") from None
    raise RunError(f"{runs_root}: could not find a free {kind} directory name for {name!r}.")


def _check_still_empty(out: Path, runs_root: Path, kind: str) -> None:
    """Refuse, holding the lock, a directory another command wrote into meanwhile."""
    found = sorted(entry.name for entry in out.iterdir() if entry.name != lock.LOCK_FILE)
    if found:
        raise RunError(
            f"{out}: another command wrote into this directory while this one was starting "
            f"(it now holds {', '.join(found[:3])}{', ...' if len(found) > 3 else ''}); "
            f"cartpole-q never writes a new {kind} into a non-empty directory. Choose a new "
            f"directory (or leave --out out for a fresh one under {runs_root}/)."
        )


def _undo_start(claim: NewDirectory, created_lock_file: bool) -> None:
    """Remove what a failed start wrote (the caller still holds the lock)."""
    with contextlib.suppress(OSError):
        if claim.created:
            shutil.rmtree(claim.path)
            return
        for entry in claim.path.iterdir():
            if entry.name == lock.LOCK_FILE and not created_lock_file:
                continue
            if entry.is_dir() and not entry.is_symlink():
                shutil.rmtree(entry)
            else:
                entry.unlink()


def write_config(run_dir: Path, config: Config) -> None:
    """Write the resolved config (every key) as ``config.yaml``."""
    header = (
        "# Resolved config of this run: every key, defaults filled in.\n"
        "# `cartpole-q train --resume` continues the run only while nothing here changes\n"
        "# but train.episodes (which may grow, to extend the run).\n"
    )
    text = header + config.to_yaml()
    path = run_dir / CONFIG_FILE
    with contextlib.suppress(OSError, UnicodeDecodeError):
        if path.read_text(encoding="utf-8") == text:
            return  # already written (a new run's directory gets it before training)
    atomic_write_text(path, text)


# -- writing a finished (or interrupted) run ------------------------------------------


def versions() -> dict[str, str]:
    """The versions of Python and the packages that produce a run."""
    return dict(_versions())


@functools.cache
def _versions() -> dict[str, str]:
    # Read once per process: importlib.metadata parses each package's METADATA file.
    found = {"python": platform.python_version()}
    for package in ("numpy", "gymnasium", "numba", "cartpole-q"):
        try:
            found[package.replace("-", "_")] = metadata.version(package)
        except metadata.PackageNotFoundError:
            found[package.replace("-", "_")] = "unknown"
    return found


def summarize(result: TrainResult) -> RunSummary:
    """The ``summary.json`` of a training result, stamped with versions and the time."""
    return RunSummary.of_train(result, versions(), time.strftime("%Y-%m-%dT%H:%M:%S%z"))


def metrics_csv(
    metrics: EpisodeMetrics,
    info: np.ndarray | None = None,
    info_key: str | None = None,
    errors: np.ndarray | None = None,
) -> str:
    """Per-episode metrics as CSV; floats written with ``repr`` so they round-trip exactly.

    With ``info`` (the sums of ``info[info_key]``), a column ``info_<info_key>``; with
    ``errors`` (a prediction run's), a last column ``rms_error``.

    >>> one = EpisodeMetrics(np.array([1.0]), np.array([2]), np.array([0.1]), np.array([0.5]))
    >>> print(metrics_csv(one, np.array([1.0]), "left_from_a"), end="")
    episode,return,length,epsilon,alpha,info_left_from_a
    1,1.0,2,0.1,0.5,1.0
    >>> print(metrics_csv(one, errors=np.array([0.25])), end="")
    episode,return,length,epsilon,alpha,rms_error
    1,1.0,2,0.1,0.5,0.25
    """
    header = [*METRICS_HEADER]
    extra: list[np.ndarray] = []
    if info is not None:
        header.append(f"{INFO_COLUMN_PREFIX}{info_key}")
        extra.append(info)
    if errors is not None:
        header.append(ERRORS_COLUMN)
        extra.append(errors)
    lines = [",".join(header)]
    for i, (r, n, e, a, *more) in enumerate(zip(*metrics, *extra, strict=True)):
        tail = "".join(f",{float(value)!r}" for value in more)
        lines.append(f"{i + 1},{float(r)!r},{int(n)},{float(e)!r},{float(a)!r}{tail}")
    return "\n".join(lines) + "\n"


def evaluations_csv(evaluations: list[dict[str, Any]]) -> str:
    """Periodic evaluations as CSV."""
    lines = [",".join(EVALUATIONS_HEADER)]
    lines.extend(
        ",".join(repr(record[key]) for key in EVALUATIONS_HEADER) for record in evaluations
    )
    return "\n".join(lines) + "\n"


def write_run(
    run_dir: str | Path, result: TrainResult, *, plot: bool = True, overwrite: bool = False
) -> RunSummary:
    """Write a :class:`~cartpole_q.training.TrainResult` into ``run_dir``.

    Files go in the contract's order: data first, ``summary.json`` last. An interrupted
    result keeps its ``checkpoint.npz`` for ``--resume``, and so does one that reached
    ``train.episodes`` (so that it can be extended); a run stopped at its solve point
    removes it.

    Args:
        run_dir: the directory to write; it must not exist or be empty.
        result: the training result.
        plot: draw ``reward_curve.png``.
        overwrite: write into a non-empty ``run_dir``, replacing its run files (the
            command line does this in the directory it created, and on ``--resume``).

    Returns:
        The summary that was written.

    Raises:
        RunError: ``run_dir`` is a file, or a non-empty directory and not ``overwrite``.
    """
    run_dir = Path(run_dir)
    if run_dir.exists() and not run_dir.is_dir():
        raise RunError(f"{run_dir}: is a file; a run directory must be a new or empty directory.")
    if not overwrite and run_dir.is_dir() and any(run_dir.iterdir()):
        raise RunError(
            f"{run_dir}: is not empty; write_run never overwrites a run. Choose a new "
            "directory, or pass overwrite=True to replace this run's files."
        )
    make_directory(run_dir)
    write_config(run_dir, result.config)
    if result.predicts:
        atomic_save_npy(run_dir / V_TABLE_FILE, result.v_table)
    else:
        atomic_save_npy(run_dir / Q_TABLE_FILE, result.q_table)
    atomic_save_npy(run_dir / VISITS_FILE, result.visits)
    atomic_write_text(
        run_dir / METRICS_FILE,
        metrics_csv(result.metrics, result.info, result.config.train.info_metric, result.errors),
    )
    atomic_write_text(run_dir / EVALUATIONS_FILE, evaluations_csv(result.evaluations))
    if plot:
        from cartpole_q.figures import Curve, reward_curve_figure
        from cartpole_q.store.figure_file import write_figure

        curve = Curve(
            run_dir.name, result.returns, result.solved_episode, interrupted=result.interrupted
        )
        title = f"Training reward: {run_dir.name}" + (
            " (interrupted)" if result.interrupted else ""
        )
        figure = reward_curve_figure([curve], result.reward_threshold, title=title)
        write_figure(run_dir / CURVE_FILE, figure)
    summary = summarize(result)
    if result.config.train.tensorboard:
        from cartpole_q.store.tensorboard import write_tensorboard

        write_tensorboard(run_dir, result, summary.steps_per_second)
    write_json(run_dir / SUMMARY_FILE, summary.to_json())
    if not result.interrupted and not result.extendable:
        (run_dir / CHECKPOINT_FILE).unlink(missing_ok=True)
    return summary


# -- reading a run back ---------------------------------------------------------------


@dataclass(frozen=True)
class Run:
    """A complete run directory, loaded and checked."""

    path: Path
    config: Config
    q_table: np.ndarray
    visits: np.ndarray | None
    metrics: EpisodeMetrics
    """the columns of ``metrics.csv`` (episodes are numbered from 1 in order)"""
    result: SeedResult
    """what it achieved (from ``summary.json``, or a sweep's ``results.csv`` row)"""
    info: np.ndarray | None = None
    """each episode's sum of ``info[config.train.info_metric]`` (``metrics.csv``'s
    ``info_KEY`` column; ``None`` without ``train.info_metric``, or a sweep point that kept
    no curves)"""
    errors: np.ndarray | None = None
    """a prediction run's RMS error after each episode (``metrics.csv``'s ``rms_error``)"""
    predicts: bool = False
    """a prediction run: ``q_table`` is its ``V`` (``v_table.npy``) with one column, and it
    has no greedy policy"""

    @property
    def name(self) -> str:
        """The directory's name."""
        return self.path.name

    def record(self, column: str) -> np.ndarray | None:
        """Its per-episode ``metrics.csv`` column beyond the five every run has, if kept.

        ``info_KEY`` (with ``train.info_metric: KEY``) or ``rms_error`` (a prediction run's).
        """
        info_key = self.config.train.info_metric
        if info_key is not None and column == f"{INFO_COLUMN_PREFIX}{info_key}":
            return self.info
        return self.errors if column == ERRORS_COLUMN else None


def is_multi_seed(path: Path) -> bool:
    """Whether ``path`` is the parent directory of a multi-seed run."""
    return (path / CONFIG_FILE).is_file() and _config_of(path).train.seeds is not None


def load_run(path: str | Path) -> Run:
    """Load a single run directory, checking every file it needs.

    Raises:
        RunError: the directory is not a complete run, or a file is missing, truncated,
            of the wrong shape or dtype, or holds NaN values; the message names the file.
    """
    path = Path(path)
    if not path.exists():
        raise RunError(
            f"{path}: does not exist (expected a run directory from `cartpole-q train`)."
        )
    if not path.is_dir():
        raise RunError(
            f"{path}: is not a directory (expected a run directory from `cartpole-q train`)."
        )
    if not (path / CONFIG_FILE).is_file():
        raise RunError(f"{path}: is not a run directory (it has no {CONFIG_FILE}).")
    config = _config_of(path)
    if config.train.seeds is not None:
        raise RunError(
            f"{path}: is a multi-seed run; its runs are the seed-* directories inside it."
        )
    summary = read_summary(path)
    if summary is None:
        hint = (
            f"; resume it with `cartpole-q train --resume {path}`"
            if (path / CHECKPOINT_FILE).is_file()
            else ""
        )
        raise RunError(f"{path}: training did not finish (no {SUMMARY_FILE}){hint}.")
    grid = config.discretization
    predicts = get_algorithm(config.agent.algorithm).predicts
    states = None if grid is None else grid.table_shape
    if predicts:  # V: the states' values, as the one-column table the algorithms learnt
        table_file = V_TABLE_FILE
        table = load_array(path / table_file, np.float64, _values_check(states))
        table = table.reshape(*table.shape, 1)
    else:
        table_file = Q_TABLE_FILE
        table = load_array(path / table_file, np.float64, table_check(states))
    check_q_table(table, states, None, str(path / table_file))
    visits = None
    if (path / VISITS_FILE).is_file():
        whose = f"{table_file}'s states" if predicts else "the Q-table's"
        visits = load_array(
            path / VISITS_FILE,
            np.int64,
            _same_shape(table.shape[:-1] if predicts else table.shape, whose, predicts),
        )
    metrics, info, errors = read_metric_columns(
        path / METRICS_FILE, config.train.info_metric, errors=predicts
    )
    return Run(
        path=path,
        config=config,
        q_table=table,
        visits=visits,
        metrics=metrics,
        result=_with_threshold(summary.result(config.seed), config),
        info=info,
        errors=errors,
        predicts=predicts,
    )


def _with_threshold(result: SeedResult, config: Config) -> SeedResult:
    """A result judged by its config's threshold when its summary predates recording it."""
    if result.reward_threshold is not None:
        return result
    threshold = config_threshold(config)
    return dataclasses.replace(
        result, reward_threshold=threshold, success=is_success(result.eval_mean, threshold)
    )


def config_threshold(config: Config) -> float | None:
    """The reward threshold a config's runs are judged by (``None`` without one).

    From the config and Gymnasium's registry: reading a run directory makes no environment.
    """
    from cartpole_q.envs.gym import config_threshold as threshold

    return threshold(config)


def load_array(path: Path, dtype: type, check: ShapeCheck | None = None) -> np.ndarray:
    """Load an ``.npy`` file without pickle, checking its dtype (and shape) before allocating it.

    Raises:
        RunError: the file is missing, truncated, an object array, of another dtype, or
            refused by ``check`` (see :func:`~cartpole_q.store.reading.load_npy`).
    """
    return load_npy(path, dtype, check)


def table_check(states: tuple[int, ...] | None) -> ShapeCheck:
    """The check of a Q-table's header: float64, ``(*states, n_actions)`` (any states when ``None``)."""

    def check(where: str, dtype: np.dtype[Any], shape: tuple[int, ...]) -> None:
        if dtype != np.float64:
            raise RunError(f"{where}: must hold float64 values, found {dtype}.")
        check_q_table_shape(shape, states, None, where)

    return check


def _values_check(states: tuple[int, ...] | None) -> ShapeCheck:
    """The check of ``v_table.npy``'s header: float64, ``states`` (any shape when ``None``)."""

    def check(where: str, dtype: np.dtype[Any], shape: tuple[int, ...]) -> None:
        if dtype != np.float64:
            raise RunError(f"{where}: must hold float64 values, found {dtype}.")
        if states is not None and tuple(shape) != tuple(states):
            raise RunError(
                f"{where}: has shape {tuple(shape)}, but the config's states are {states}."
            )

    return check


def _same_shape(expected: tuple[int, ...], whose: str, leading: bool = False) -> ShapeCheck:
    """The check of an array's header against a shape (``leading``: all but its last axis)."""

    def check(where: str, dtype: np.dtype[Any], shape: tuple[int, ...]) -> None:
        found = tuple(shape)[:-1] if leading else tuple(shape)
        if found != tuple(expected):
            raise RunError(f"{where}: has shape {tuple(shape)}, but {whose} is {tuple(expected)}.")

    return check


def read_metrics(path: Path) -> EpisodeMetrics:
    """Read ``metrics.csv`` (without an ``info_KEY`` column).

    Raises:
        RunError: the file is missing, has another header, or a row is not numeric.
    """
    return read_metric_columns(path, None)[0]


def read_metric_columns(
    path: Path, info_key: str | None, errors: bool = False
) -> tuple[EpisodeMetrics, np.ndarray | None, np.ndarray | None]:
    """Read ``metrics.csv``: its metrics and its ``info_KEY`` and ``rms_error`` columns.

    The ``info_<info_key>`` column is read when ``info_key`` is given, the ``rms_error``
    column when there may be one (``errors``: a prediction run's, if it measured them).

    Raises:
        RunError: the file is missing, has another header (``info_KEY`` exactly when
            ``info_key`` is given), or a row is not numeric.
    """
    header: tuple[str, ...] = METRICS_HEADER
    if info_key is not None:
        header = (*header, f"{INFO_COLUMN_PREFIX}{info_key}")
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise RunError(f"{path}: is missing.") from None
    except IsADirectoryError:
        raise RunError(f"{path}: is a directory, not a CSV file.") from None
    except (OSError, UnicodeDecodeError) as error:
        raise RunError(f"{path}: cannot be read ({error}).") from None
    rows = list(csv.reader(io.StringIO(text)))
    if errors and rows and tuple(rows[0]) == (*header, ERRORS_COLUMN):
        header = (*header, ERRORS_COLUMN)  # measured (a world with a model)
    if not rows or tuple(rows[0]) != header:
        because = ""
        if info_key is not None:
            because = f" (its config's train.info_metric is {info_key})"
        elif rows and len(rows[0]) > len(header):
            because = " (its config sets no train.info_metric)"
        raise RunError(f"{path}: must start with the header {','.join(header)}{because}.")
    try:
        columns = np.array([[float(value) for value in row] for row in rows[1:]], dtype=np.float64)
    except ValueError:
        raise RunError(f"{path}: has a row that is not {len(header)} numbers.") from None
    if columns.size and (columns.ndim != 2 or columns.shape[1] != len(header)):
        raise RunError(f"{path}: every row must have {len(header)} values.")
    columns = columns.reshape(-1, len(header))
    if not np.array_equal(columns[:, 0], np.arange(1, len(columns) + 1)):
        raise RunError(f"{path}: its episodes must be numbered 1, 2, 3, ... in order.")
    metrics = EpisodeMetrics(
        returns=columns[:, 1],
        lengths=columns[:, 2].astype(np.int64),
        epsilons=columns[:, 3],
        alphas=columns[:, 4],
    )
    info = columns[:, 5].copy() if info_key is not None else None
    measured = columns[:, -1].copy() if header[-1] == ERRORS_COLUMN else None
    return metrics, info, measured


def read_summary(run_dir: Path) -> RunSummary | None:
    """A single run's ``summary.json``: the one reader of it.

    Returns:
        The summary, or ``None`` when there is none (the run has not finished).

    Raises:
        RunError: the file exists but is not a run's summary (naming the file and key).
    """
    path = run_dir / SUMMARY_FILE
    data = read_json(path)
    return None if data is None else RunSummary.from_json(data, str(path))


def read_multi_seed_summary(parent: Path) -> MultiSeedSummary | None:
    """A multi-seed run's ``summary.json`` (``None`` until the command has ended).

    Raises:
        RunError: the file exists but is not a multi-seed summary.
    """
    path = parent / SUMMARY_FILE
    data = read_json(path)
    return None if data is None else MultiSeedSummary.from_json(data, str(path))


def _config_of(path: Path) -> Config:
    return read_config_file(path / CONFIG_FILE)


def read_config_file(path: Path) -> Config:
    """The ``config.yaml`` of a directory cartpole-q wrote (a run, a multi-seed run, a sweep point).

    Read as data: an ``env.id`` that would import a module is refused
    (:func:`~cartpole_q.envs.gym.check_recorded_env_id`).

    Raises:
        RunError: the file is not a valid config, or its ``env.id`` names a module to import.
    """
    from cartpole_q.envs.gym import check_recorded_env_id

    try:
        config = load_config(path)
    except ConfigError as error:
        raise RunError(f"{path.parent}: its {path.name} is not a valid config. {error}") from None
    check_recorded_env_id(config.env.id, str(path))
    return config
