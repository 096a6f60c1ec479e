"""The sweep directory (design.md, "Sweep directory"): its files, written atomically, and read back.

``sweep.yaml`` and every ``points/<p>/config.yaml`` are written before any run starts.
After each batch of finished runs, the touched points' ``q_tables.npz`` and then
``results.csv`` are rewritten whole: a (point, seed) is done if and only if it has a row,
so a sweep killed at any moment resumes without losing or duplicating a finished row.
``points.csv`` and ``sweep.png`` are written at the end.
"""

from __future__ import annotations

import contextlib
import csv
import io
import json
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import yaml

from cartpole_q.config import MAX_EPISODES, parse_seeds, read_yaml_mapping, shown
from cartpole_q.errors import RunError
from cartpole_q.results import SeedResult
from cartpole_q.statistics import PointStatistics
from cartpole_q.store.atomic import (
    atomic_write_bytes,
    atomic_write_text,
    make_directory,
    remove_stale_temporaries,
)
from cartpole_q.store.figure_file import write_figure as write_figure_file
from cartpole_q.store.reading import ShapeCheck, load_npz
from cartpole_q.store.rundir import CONFIG_FILE, NewDirectory, new_directory, write_config

if TYPE_CHECKING:
    from cartpole_q.figures import DataFigure

SWEEP_FILE = "sweep.yaml"
RESULTS_FILE = "results.csv"
POINTS_FILE = "points.csv"
POINTS_DIR = "points"
TABLES_FILE = "q_tables.npz"
VISITS_FILE = "visits.npz"
"""a point's seeds' visits (``figure.metric: policy`` sweeps only: the path a grid world's
figure shades)"""
CURVES_FILE = "curves.npz"
"""a point's learning curves: ``seed-NNN.returns`` (float64) and ``seed-NNN.lengths``
(int64) per finished seed, one value per training episode, compressed; with
``train.info_metric: KEY`` also ``seed-NNN.info_KEY`` (float64, the per-episode sums), and a
prediction run's ``seed-NNN.rms_error`` (float64, its error after each episode)"""
FIGURE_FILE = "sweep.png"
SWEEPS_ROOT = Path("sweeps")
RESULT_COLUMNS = (
    "seed",
    "solved_episode",
    "env_steps_to_solve",
    "first_greedy_success_env_steps",
    "eval_mean",
    "success",
    "episodes",
    "env_steps",
    "train_seconds",
    "mean_return",
    "rms_error",
)
"""the ``results.csv`` columns after ``point`` and the axes"""
ADDED_COLUMNS = ("mean_return", "rms_error")
"""columns added since the first ``results.csv``, in the order they were added: a file
that stops before one of them (an older sweep) is read, and resumed, with their cells
empty"""
TIMING_COLUMNS = ("train_seconds",)
"""the only columns that depend on the machine, the backend or an interruption"""


def new_sweep_dir(name: str, out: Path | None) -> contextlib.AbstractContextManager[NewDirectory]:
    """Claim the sweep directory, holding its lock inside.

    It is ``out`` (new or empty), else ``sweeps/<name>-<stamp>/``; see
    :func:`~cartpole_q.store.rundir.new_directory`.

    Raises:
        RunError: ``out`` is a file or a non-empty directory, or cannot be created.
    """
    return new_directory(name, out, runs_root=SWEEPS_ROOT, kind="sweep")


def write_sweep(
    directory: Path, resolved: Mapping[str, Any], configs: Sequence[tuple[str, Any]]
) -> None:
    """Write ``sweep.yaml`` and each point's ``config.yaml`` (``configs``: point id, Config)."""
    header = (
        "# Resolved sweep: `base` is the full config every point starts from.\n"
        "# `cartpole-q sweep --resume DIR` runs whatever results.csv does not have yet.\n"
    )
    text = yaml.safe_dump(dict(resolved), sort_keys=False, default_flow_style=None)
    for point_id, config in configs:
        point_dir = directory / POINTS_DIR / point_id
        make_directory(point_dir)
        write_config(point_dir, config)
    atomic_write_text(directory / SWEEP_FILE, header + text)


def sweep_file(directory: Path) -> Path:
    """The ``sweep.yaml`` of a sweep directory.

    Raises:
        RunError: ``directory`` is not a sweep directory.
    """
    path = directory / SWEEP_FILE
    if not path.is_file():
        raise RunError(f"{directory}: is not a sweep directory (it has no {SWEEP_FILE}).")
    return path


def remove_temporaries(directory: Path) -> None:
    """Delete the temporary files a killed sweep left (call it holding the sweep's lock)."""
    remove_stale_temporaries(directory)
    for point_dir in (directory / POINTS_DIR).glob("*"):
        remove_stale_temporaries(point_dir)


def point_config_path(directory: Path, point_id: str) -> Path:
    """A point's ``config.yaml``: written when the sweep starts, never rewritten."""
    return directory / POINTS_DIR / point_id / CONFIG_FILE


def point_ids(directory: Path) -> list[str]:
    """The ids of the points the sweep started with (those with a ``config.yaml``), sorted."""
    root = directory / POINTS_DIR
    if not root.is_dir():
        return []
    return sorted(entry.name for entry in root.iterdir() if (entry / CONFIG_FILE).is_file())


def result_header(axes: Sequence[str]) -> list[str]:
    """The ``results.csv`` header: ``point``, the axes, then :data:`RESULT_COLUMNS`."""
    return ["point", *axes, *RESULT_COLUMNS]


@dataclass(frozen=True)
class ResultRow:
    """One finished run of a sweep: its point, the point's axis values and its figures."""

    point: str
    """the point's id (``000``)"""
    axes: Mapping[str, str]
    """each axis key's value at the point, as its cell (:func:`axis_cell`)"""
    result: SeedResult


def axis_cell(value: object) -> str:
    """An axis value as its CSV cell: strings as they are, everything else as JSON.

    >>> axis_cell(0.1), axis_cell("sarsa"), axis_cell([1, 1, 6, 12]), axis_cell(True)
    ('0.1', 'sarsa', '[1, 1, 6, 12]', 'true')
    """
    if isinstance(value, str):
        return value
    return json.dumps(value)


def cell(value: object) -> str:
    """A value as a CSV cell: empty for missing, ``true``/``false``, floats round-trip.

    >>> cell(None), cell(True), cell(0.1), cell(7)
    ('', 'true', '0.1', '7')
    """
    if value is None:
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value)
    return str(value)


def result_cells(result: SeedResult) -> dict[str, str]:
    """A run's figures as its ``results.csv`` cells (:data:`RESULT_COLUMNS`)."""
    return {column: cell(getattr(result, column)) for column in RESULT_COLUMNS}


def row_cells(row: ResultRow) -> dict[str, str]:
    """A row as its ``results.csv`` cells, by column."""
    return {"point": row.point, **row.axes, **result_cells(row.result)}


def parse_row(cells: Mapping[str, str], axes: Sequence[str], where: Path) -> ResultRow:
    """A ``results.csv`` row back from its cells.

    Raises:
        RunError: a cell is not what its column holds; the sweep directory is damaged.
    """
    try:
        return ResultRow(
            point=cells["point"],
            axes={key: cells[key] for key in axes},
            result=SeedResult(
                seed=int(cells["seed"]),
                episodes=int(cells["episodes"]),
                env_steps=int(cells["env_steps"]),
                solved_episode=_integer(cells["solved_episode"]),
                env_steps_to_solve=_integer(cells["env_steps_to_solve"]),
                first_greedy_success_env_steps=_integer(cells["first_greedy_success_env_steps"]),
                eval_mean=_finite(cells["eval_mean"]) if cells["eval_mean"] else None,
                success=_flag(cells["success"]),
                train_seconds=_finite(cells["train_seconds"] or "0"),
                mean_return=_finite(mean) if (mean := cells.get("mean_return")) else None,
                # a diverged prediction run's error is inf (or nan): a figure it produced
                rms_error=float(error) if (error := cells.get("rms_error")) else None,
            ),
        )
    except (KeyError, ValueError, TypeError, OverflowError):
        raise RunError(
            f"{where}: has a damaged row ({shown(dict(cells))}); the sweep directory was "
            "changed by hand. Start a new sweep."
        ) from None


def _finite(text: str) -> float:
    """A finite number: NaN or an infinity is no figure a run produced."""
    value = float(text)
    if not math.isfinite(value):
        raise ValueError(text)
    return value


def _integer(text: str) -> int | None:
    # float first: results.csv from before typed rows may hold "12.0"
    return None if not text else int(float(text))


def _flag(text: str) -> bool | None:
    if text in ("", "true", "false"):
        return None if not text else text == "true"
    raise ValueError(text)


def csv_text(header: Sequence[str], rows: Iterable[Mapping[str, str]]) -> str:
    """CSV text (Unix line ends) of rows whose cells are already strings."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(header)
    for row in rows:
        writer.writerow([row[column] for column in header])
    return buffer.getvalue()


def write_results(directory: Path, axes: Sequence[str], rows: Iterable[ResultRow]) -> None:
    """Rewrite ``results.csv`` whole (rows already in (point, seed) order)."""
    text = csv_text(result_header(axes), (row_cells(row) for row in rows))
    atomic_write_text(directory / RESULTS_FILE, text)


def read_results(directory: Path, axes: Sequence[str]) -> list[ResultRow]:
    """The rows of ``results.csv`` (none if it does not exist yet).

    Raises:
        RunError: the file's header is not the sweep's, or a row is damaged.
    """
    path = directory / RESULTS_FILE
    if not path.is_file():
        return []
    with path.open(newline="", encoding="utf-8") as file:
        reader = csv.DictReader(file)
        if reader.fieldnames not in _readable_headers(axes):
            raise RunError(
                f"{path}: its columns are not the ones {SWEEP_FILE} gives; the sweep directory "
                "was changed by hand. Start a new sweep."
            )
        return [parse_row(cells, axes, path) for cells in reader]


def _readable_headers(axes: Sequence[str]) -> list[list[str]]:
    """This version's ``results.csv`` header and each older one (stopping before an added column).

    >>> [header[-1] for header in _readable_headers([])]
    ['rms_error', 'mean_return', 'train_seconds']
    """
    header = result_header(axes)
    older = [header[: header.index(column)] for column in reversed(ADDED_COLUMNS)]
    return [header, *older]


def seed_key(seed: int, seeds: Sequence[int]) -> str:
    """The key of a seed in ``q_tables.npz``, padded like ``train --seeds`` directories.

    >>> seed_key(7, range(100)), seed_key(7, [7, 1000])
    ('seed-007', 'seed-0007')
    """
    return f"seed-{seed:0{max(3, len(str(max(seeds))))}d}"


def sweep_seeds(directory: Path) -> tuple[int, ...]:
    """The seeds ``sweep.yaml`` gives every point.

    Raises:
        RunError: ``sweep.yaml`` is missing or its seeds are not readable.
    """
    data = read_yaml_mapping(sweep_file(directory), "sweep file")
    try:
        return parse_seeds(data.get("seeds"))
    except ValueError as error:
        raise RunError(f"{directory / SWEEP_FILE}: seeds: {error}") from None


def curves_path(directory: Path, point_id: str) -> Path:
    """Where a point's ``curves.npz`` goes."""
    return directory / POINTS_DIR / point_id / CURVES_FILE


def write_curves(
    directory: Path,
    point_id: str,
    curves: Mapping[str, tuple[np.ndarray, np.ndarray]],
    records: Mapping[str, Mapping[str, np.ndarray]] | None = None,
) -> None:
    """Rewrite a point's ``curves.npz`` whole: each seed's returns and lengths, compressed.

    ``records`` (by seed key, the seed's further ``metrics.csv`` columns by name:
    ``info_KEY``, ``rms_error``) go in as ``seed-NNN.<column>`` too.
    """
    arrays: dict[str, Any] = {}
    for key in sorted(curves):
        returns, lengths = curves[key]
        arrays[f"{key}.returns"] = np.asarray(returns, dtype=np.float64)
        arrays[f"{key}.lengths"] = np.asarray(lengths, dtype=np.int64)
        for column, values in sorted((records or {}).get(key, {}).items()):
            arrays[f"{key}.{column}"] = np.asarray(values, dtype=np.float64)
    buffer = io.BytesIO()
    np.savez_compressed(buffer, **arrays)
    atomic_write_bytes(curves_path(directory, point_id), buffer.getvalue())


def read_curves(directory: Path, point_id: str) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """A point's kept learning curves by seed key (none if it kept none).

    Raises:
        RunError: the file is damaged.
    """
    path = curves_path(directory, point_id)
    if not path.is_file():
        return {}
    archive = load_npz(path, str(path), check=_one_dimensional)
    keys = sorted({name.rpartition(".")[0] for name in archive})
    try:
        return {key: (archive[f"{key}.returns"], archive[f"{key}.lengths"]) for key in keys}
    except KeyError as error:
        raise RunError(f"{path}: has no array {error}; the sweep directory is damaged.") from None


def _one_dimensional(where: str, dtype: np.dtype[Any], shape: tuple[int, ...]) -> None:
    """A learning curve's header: one value per episode, at most the most episodes a run has."""
    if len(shape) != 1 or shape[0] > MAX_EPISODES:
        raise RunError(
            f"{where}: has shape {shape}, not one value per episode; the sweep directory is "
            "damaged."
        )


def read_records(directory: Path, point_id: str) -> dict[str, dict[str, np.ndarray]]:
    """A point's kept further columns (``info_KEY``, ``rms_error``) by seed key, then column.

    Raises:
        RunError: the file is damaged.
    """
    path = curves_path(directory, point_id)
    if not path.is_file():
        return {}
    archive = load_npz(path, str(path), check=_one_dimensional)
    records: dict[str, dict[str, np.ndarray]] = {}
    for name, array in archive.items():
        key, _, column = name.partition(".")
        if column not in ("returns", "lengths"):
            records.setdefault(key, {})[column] = array
    return records


def tables_path(directory: Path, point_id: str) -> Path:
    """Where a point's ``q_tables.npz`` goes."""
    return directory / POINTS_DIR / point_id / TABLES_FILE


def write_tables(
    directory: Path, point_id: str, tables: Mapping[str, np.ndarray], name: str = TABLES_FILE
) -> None:
    """Rewrite a point's ``q_tables.npz`` (or ``visits.npz``) whole, keys in order (``seed-000``, ...)."""
    buffer = io.BytesIO()
    arrays: dict[str, Any] = {key: tables[key] for key in sorted(tables)}
    np.savez(buffer, **arrays)
    atomic_write_bytes(directory / POINTS_DIR / point_id / name, buffer.getvalue())


def read_visits(directory: Path, point_id: str) -> dict[str, np.ndarray]:
    """A point's saved visits by seed key (none if the sweep keeps none).

    Raises:
        RunError: the file is damaged.
    """
    path = directory / POINTS_DIR / point_id / VISITS_FILE
    if not path.is_file():
        return {}
    return load_npz(path, str(path))


def read_tables(
    directory: Path, point_id: str, check: ShapeCheck | None = None
) -> dict[str, np.ndarray]:
    """A point's saved tables by key (none if it has no file yet).

    Args:
        directory: the sweep directory.
        point_id: the point (``p000``).
        check: each table's header check (the shape its config implies), before it is
            allocated.

    Raises:
        RunError: the file is damaged, or a table is refused by ``check``.
    """
    path = tables_path(directory, point_id)
    if not path.is_file():
        return {}
    return load_npz(path, str(path), check=check)


@dataclass(frozen=True)
class PointRow:
    """One ``points.csv`` row: a point, its axis values and its statistics."""

    point: str
    axes: Mapping[str, str]
    """each axis key's value at the point, as its cell (:func:`axis_cell`)"""
    statistics: PointStatistics


def points_header(axes: Sequence[str]) -> list[str]:
    """The ``points.csv`` header: ``point``, the axes, then the statistics."""
    return ["point", *axes, *PointStatistics.columns()]


def write_points(directory: Path, axes: Sequence[str], rows: Iterable[PointRow]) -> None:
    """Write ``points.csv``."""
    cells = (
        {
            "point": row.point,
            **row.axes,
            **{name: cell(value) for name, value in row.statistics.as_row().items()},
        }
        for row in rows
    )
    atomic_write_text(directory / POINTS_FILE, csv_text(points_header(axes), cells))


def write_figure(directory: Path, figure: DataFigure) -> None:
    """Write ``sweep.png`` and its data, ``sweep.csv``."""
    write_figure_file(directory / FIGURE_FILE, figure)


def point_results(point_dir: Path) -> list[ResultRow] | None:
    """The ``results.csv`` rows of a sweep point (``<sweep>/points/<p>``); None if not one.

    Raises:
        RunError: it is a sweep point without any result yet.
    """
    point_dir = Path(point_dir)
    sweep = point_dir.parent.parent
    if point_dir.parent.name != POINTS_DIR or not (sweep / SWEEP_FILE).is_file():
        return None
    if point_dir.name not in point_ids(sweep):
        known = point_ids(sweep)
        shown = f"{known[0]} to {known[-1]}" if known else "none"
        raise RunError(
            f"{point_dir}: is not a point of the sweep {sweep} (its points are {shown})."
        )
    path = sweep / RESULTS_FILE
    rows = []
    if path.is_file():
        with path.open(newline="", encoding="utf-8") as file:
            reader = csv.DictReader(file)
            axes = [
                name
                for name in (reader.fieldnames or [])
                if name != "point" and name not in RESULT_COLUMNS
            ]
            rows = [
                parse_row(cells, axes, path)
                for cells in reader
                if cells.get("point") == point_dir.name
            ]
    if not rows:
        raise RunError(f"{point_dir}: this sweep point has no finished run in {path} yet.")
    return rows
