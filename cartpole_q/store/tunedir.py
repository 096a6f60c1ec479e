"""The tune directory: ``tune.yaml``, Optuna's journal, and the results written at the end.

``tune.yaml`` is written before the first trial and holds the resolved tune file and the
storage URL (none: the journal file ``study.journal`` here). The journal is Optuna's own
append-only log; it survives a kill -9 and lets several processes share one study.
``trials.csv``, ``best.yaml``, ``history.png`` and ``importance.png`` (each figure with its
data, ``history.csv`` and ``importance.csv``) are rewritten at the end of every ``tune``
call.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import yaml

from cartpole_q.config import Config, ConfigError, read_yaml_mapping
from cartpole_q.errors import RunError
from cartpole_q.store.atomic import atomic_write_text
from cartpole_q.store.figure_file import write_figure
from cartpole_q.store.rundir import NewDirectory, new_directory
from cartpole_q.store.sweepdir import csv_text

if TYPE_CHECKING:
    from cartpole_q.figures import DataFigure

TUNE_FILE = "tune.yaml"
JOURNAL_FILE = "study.journal"
JOURNAL_LOCK_SUFFIX = ".lock"
"""Optuna's lock of a journal file (``JournalFileSymlinkLock``): a link named the journal's
path with this suffix, there while a process writes the journal"""
TRIALS_FILE = "trials.csv"
BEST_FILE = "best.yaml"
HISTORY_FILE = "history.png"
IMPORTANCE_FILE = "importance.png"
TUNES_ROOT = Path("tunes")


def new_tune_dir(name: str, out: Path | None) -> contextlib.AbstractContextManager[NewDirectory]:
    """Claim the tune directory, holding its lock inside.

    It is ``out`` (new or empty), else ``tunes/<name>-<stamp>/``; see
    :func:`~cartpole_q.store.rundir.new_directory`.
    """
    return new_directory(name, out, runs_root=TUNES_ROOT, kind="tune")


def write_tune(directory: Path, resolved: Mapping[str, Any], storage: str | None) -> None:
    """Write ``tune.yaml``: the resolved tune file, and where the study is stored."""
    header = (
        "# Resolved tune file. `cartpole-q tune --resume DIR` goes on with the study\n"
        "# (`--trials N` raises its total); `storage: null` is the journal file here.\n"
    )
    data = {**resolved, "storage": storage}
    text = yaml.safe_dump(data, sort_keys=False, default_flow_style=None)
    atomic_write_text(directory / TUNE_FILE, header + text)


def tune_file(directory: Path) -> tuple[dict[str, Any], str | None]:
    """The resolved tune file (without ``storage``) and the storage URL of a tune directory.

    Raises:
        RunError: ``directory`` is not a tune directory.
    """
    path = directory / TUNE_FILE
    if not path.is_file():
        raise RunError(f"{directory}: is not a tune directory (it has no {TUNE_FILE}).")
    data = read_yaml_mapping(path, "tune file")
    storage = data.pop("storage", None)
    if storage is not None and not isinstance(storage, str):
        raise ConfigError(f"{path}: storage: must be an Optuna storage URL or null.")
    return data, storage


def remove_stale_journal_lock(directory: Path) -> bool:
    """Remove the lock of the tune directory's own journal; say whether there was one.

    Only the process holding the directory's lock writes its own journal, so when that
    process starts, a journal lock left behind is a killed writer's (a kill -9 in the
    middle of a write). Optuna would wait 30 seconds before taking it over, with a warning
    every ten. Call it holding the directory's lock, before any process of this command
    writes the journal; a journal in a storage given with ``--storage`` is shared, and
    not touched.
    """
    lock = directory / (JOURNAL_FILE + JOURNAL_LOCK_SUFFIX)
    if not lock.is_symlink() and not lock.exists():
        return False
    lock.unlink(missing_ok=True)
    return True


def write_trials(directory: Path, header: Sequence[str], rows: Iterable[Mapping[str, str]]) -> None:
    """Rewrite ``trials.csv``."""
    atomic_write_text(directory / TRIALS_FILE, csv_text(header, rows))


def write_best(directory: Path, config: Config, trial: int) -> None:
    """Write ``best.yaml``: the best trial's complete config (``train --config`` takes it)."""
    # A directory name that is not UTF-8 is shown with U+FFFD: the comment is for reading.
    shown = os.fsencode(directory / BEST_FILE).decode("utf-8", "replace")
    header = (
        f"# The best trial ({trial}) of this study: a complete config.\n"
        f"# cartpole-q train --config {shown}\n"
    )
    atomic_write_text(directory / BEST_FILE, header + config.to_yaml())


def write_figures(directory: Path, history: DataFigure, importance: DataFigure | None) -> None:
    """Write ``history.png`` and, when there is one, ``importance.png``, each with its data."""
    write_figure(directory / HISTORY_FILE, history)
    if importance is not None:
        write_figure(directory / IMPORTANCE_FILE, importance)
