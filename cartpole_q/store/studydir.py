"""A study directory (``cartpole-q study``) of a kind made of runs: its files, written atomically.

| file | content |
| --- | --- |
| ``study.yaml`` | the study file as it was read, ``kind`` included; written when the study starts, never after |
| ``results.csv`` | one row per finished run, in run order: ``run`` (its number), ``study`` (the digest of ``study.yaml``), the run's key columns (which learner, seed, size...) and its scalar results |
| ``runs/<run>.npz`` | a finished run's arrays (its curve, ...), when it has any |
| ``summary.txt`` | the lines the command printed at the end: what ran and the book's numbers beside ours |
| the figure and ``<figure>.csv`` | the study's figure and the numbers it draws (and a kind's further files) |

A run is done if and only if it has a row: its arrays are written before the row, and
``results.csv`` is rewritten whole (temporary file, then ``os.replace``) after each batch,
so a study killed at any instant resumes (``--resume DIR``) with every finished run and
runs only the others. The figure, its data, ``summary.txt`` and a kind's further files are
written together at the end: a failure (a full disk) leaves none of them changed.
(A sweep keeps its own layout: :mod:`cartpole_q.store.sweepdir`.)
"""

from __future__ import annotations

import csv
import hashlib
import io
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from cartpole_q.config import read_yaml_mapping, shown
from cartpole_q.errors import RunError
from cartpole_q.store.atomic import (
    atomic_write_bytes,
    atomic_write_text,
    make_directory,
    remove_stale_temporaries,
)
from cartpole_q.store.reading import load_npz

STUDY_FILE = "study.yaml"
RESULTS_FILE = "results.csv"
RUNS_DIR = "runs"
SUMMARY_FILE = "summary.txt"
STUDIES_ROOT = Path("studies")
"""where ``cartpole-q study`` puts a new study directory without ``--out``"""
DIGEST_LENGTH = 16
"""hex digits of ``study.yaml``'s SHA-256 kept in each row"""

Cell = str | int | float | bool | None
"""a value of a ``results.csv`` cell"""


@dataclass(frozen=True)
class RunRecord:
    """What one run of a study produced: its scalar results and its arrays."""

    row: Mapping[str, Cell] = field(default_factory=dict)
    """by column, the run's figures (written in ``results.csv``)"""
    arrays: Mapping[str, np.ndarray] = field(default_factory=dict)
    """by name, its arrays (written in ``runs/<run>.npz``)"""


def study_text(raw: Mapping[str, Any]) -> str:
    """``study.yaml``'s text: the file's mapping as read, with a header."""
    header = (
        "# The study as it was started. `cartpole-q study --resume DIR` finishes it exactly\n"
        "# so: it runs whatever results.csv does not hold yet.\n"
    )
    return header + yaml.safe_dump(dict(raw), sort_keys=False, allow_unicode=True)


def digest(text: str) -> str:
    """The first :data:`DIGEST_LENGTH` hex digits of ``text``'s SHA-256.

    >>> digest("kind: bandit")
    '7de80f3917bb4975'
    """
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:DIGEST_LENGTH]


def write_start(directory: Path, raw: Mapping[str, Any]) -> str:
    """Write ``study.yaml``; return its digest.

    Raises:
        WriteError: it cannot be written.
    """
    text = study_text(raw)
    atomic_write_text(directory / STUDY_FILE, text)
    return digest(text)


def study_path(directory: Path) -> Path:
    """The ``study.yaml`` of a study directory.

    Raises:
        RunError: ``directory`` is not a study directory.
    """
    path = directory / STUDY_FILE
    if not path.is_file():
        raise RunError(
            f"{directory}: is not a study directory (it has no {STUDY_FILE}); `--resume` takes "
            "a directory `cartpole-q study` made."
        )
    return path


def read_start(directory: Path) -> tuple[Mapping[str, Any], str]:
    """``study.yaml``'s mapping and the digest of its text.

    Raises:
        RunError: it is missing or not a YAML mapping.
    """
    path = study_path(directory)
    remove_stale_temporaries(directory)  # the caller holds the lock: none is in use
    remove_stale_temporaries(directory / RUNS_DIR)
    raw = read_yaml_mapping(path, "study file")
    return raw, digest(path.read_text(encoding="utf-8"))


def header(key_columns: Sequence[str], result_columns: Sequence[str]) -> list[str]:
    """The ``results.csv`` header."""
    return ["run", "study", *key_columns, *result_columns]


def cell_text(value: Cell) -> str:
    """A cell: empty for missing, ``true``/``false``, floats round-trip (``repr``).

    >>> [cell_text(v) for v in (None, True, 0.1, 7, "td", float("inf"))]
    ['', 'true', '0.1', '7', 'td', 'inf']
    """
    if value is None:
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value)
    return str(value)


def run_id(index: int) -> str:
    """A run's file name stem: its number, zero-padded to at least 4 digits.

    >>> run_id(7), run_id(12345)
    ('0007', '12345')
    """
    return f"{index:04d}"


def write_arrays(directory: Path, index: int, arrays: Mapping[str, np.ndarray]) -> None:
    """Write a finished run's arrays as ``runs/<run>.npz`` (before its row)."""
    make_directory(directory / RUNS_DIR)
    buffer = io.BytesIO()
    named: dict[str, Any] = {name: np.asarray(array) for name, array in arrays.items()}
    np.savez(buffer, **named)
    atomic_write_bytes(directory / RUNS_DIR / f"{run_id(index)}.npz", buffer.getvalue())


def read_arrays(directory: Path, index: int) -> dict[str, np.ndarray]:
    """A finished run's arrays (none if it has no file).

    Raises:
        RunError: the file is damaged.
    """
    path = directory / RUNS_DIR / f"{run_id(index)}.npz"
    if not path.is_file():
        return {}
    return load_npz(path, str(path))


def write_results(
    directory: Path,
    columns: Sequence[str],
    rows: Sequence[tuple[int, str, Mapping[str, Cell]]],
) -> None:
    """Rewrite ``results.csv`` whole: ``(run, digest, cells)`` rows, in run order."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(columns)
    for index, study, cells in rows:
        writer.writerow([index, study, *(cell_text(cells.get(name)) for name in columns[2:])])
    atomic_write_text(directory / RESULTS_FILE, buffer.getvalue())


def read_results(directory: Path, columns: Sequence[str]) -> list[tuple[int, str, dict[str, str]]]:
    """The rows of ``results.csv`` as ``(run, digest, cells)`` (none if it does not exist).

    Raises:
        RunError: its header is not ``columns``, or a row is damaged.
    """
    path = directory / RESULTS_FILE
    if not path.is_file():
        return []
    with path.open(newline="", encoding="utf-8") as file:
        reader = csv.reader(file)
        found = next(reader, None)
        if found != list(columns):
            raise RunError(
                f"{path}: its columns are not the ones {STUDY_FILE} gives; the study directory "
                "was changed by hand. Start a new study."
            )
        rows = []
        for line in reader:
            if len(line) != len(columns) or not line[0].isdigit():
                raise RunError(
                    f"{path}: has a damaged row ({shown(line)}); the study directory was changed "
                    "by hand. Start a new study."
                )
            rows.append((int(line[0]), line[1], dict(zip(columns[2:], line[2:], strict=True))))
    return rows


def parse_cell(text: str) -> Cell:
    """A cell back as the value it was: empty as ``None``, booleans, numbers, else text.

    >>> [parse_cell(t) for t in ("", "true", "7", "0.5", "inf", "td")]
    [None, True, 7, 0.5, inf, 'td']
    """
    if text == "":
        return None
    if text in ("true", "false"):
        return text == "true"
    try:
        return int(text)
    except ValueError:
        pass
    try:
        number = float(text)
    except ValueError:
        return text
    return number if not math.isnan(number) or text == "nan" else text
