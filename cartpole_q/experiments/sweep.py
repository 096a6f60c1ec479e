"""Running a sweep: every (point, seed) trained and evaluated, saved in batches, resumable.

Each (point, seed) is exactly ``cartpole-q train --config points/<p>/config.yaml --seed S``
(the same kept table, byte for byte), but a sweep does the per-process work once: a
worker loads the compiled kernels once, runs many seeds per task, draws no per-run
figure and writes nothing itself; the parent saves finished runs in few atomic writes.
Nothing in ``results.csv`` but ``train_seconds`` depends on the backend, the number of
workers or an interruption.
"""

from __future__ import annotations

import contextlib
import math
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from cartpole_q.config import (
    Config,
    ConfigError,
    config_differences,
    format_seeds,
    load_config,
    shown_value,
)
from cartpole_q.engines.plan import planned, planning
from cartpole_q.errors import RunError
from cartpole_q.experiments.compiling import compile_ahead
from cartpole_q.experiments.plots import CurveStyle, MetricView, check_record, plot_metric
from cartpole_q.experiments.study import (
    Options,
    Outcome,
    StudyFile,
    StudyInterrupted,
    register_kind,
)
from cartpole_q.experiments.sweep_spec import (
    POLICY_FIGURE,
    VALUES_FIGURE,
    SweepSpec,
    load_sweep,
    safe_name,
)
from cartpole_q.experiments.workers import JobHandle, chunk_size, execute
from cartpole_q.families import profile_for
from cartpole_q.figures import (
    DataFigure,
    ValueChanges,
    blackjack_optimal_figure,
    blackjack_values_figure,
    summary_line_figure,
    value_changes_figure,
)
from cartpole_q.learning_curves import aggregate_band, metric_label, per_episode, record_column
from cartpole_q.progress import NullSweepProgress, SweepProgress, Units
from cartpole_q.results import SeedResult, summarize_seeds
from cartpole_q.store import sweepdir
from cartpole_q.store.figure_file import write_figure
from cartpole_q.store.rundir import ERRORS_COLUMN, INFO_COLUMN_PREFIX
from cartpole_q.store.runsets import load_run_set
from cartpole_q.store.sweepdir import PointRow, ResultRow, axis_cell
from cartpole_q.store.tensorboard import TENSORBOARD_DIR

MAX_RUNS_PER_TASK = 100
"""a task is at most this many runs (about a second for the default config); each run
reaches the parent as soon as it ends, whatever the task's size"""
FLUSH_SECONDS = 1.0
"""save finished runs at most this often (a kill loses at most this much finished work)"""


def saved_text(directory: Path, saved: int, total: int) -> str:
    """What a stopped sweep has saved, exactly.

    >>> saved_text(Path("s"), 37, 400), saved_text(Path("s"), 0, 400)
    ('37 of 400 runs are saved in s/results.csv', 'no run had finished, so nothing is saved in s/results.csv yet')
    """
    results = directory / sweepdir.RESULTS_FILE
    if not saved:
        return f"no run had finished, so nothing is saved in {results} yet"
    return f"{saved:,} of {total:,} runs are saved in {results}"


@dataclass(frozen=True)
class FinishedRun:
    """A run as :func:`run_task` yields it."""

    point: int
    """the point's index"""
    result: SeedResult
    q_table: np.ndarray
    """the kept table"""
    returns: np.ndarray
    """the learning curve: each training episode's return"""
    lengths: np.ndarray
    """each training episode's length"""
    records: Mapping[str, np.ndarray] = field(default_factory=dict)
    """its further ``metrics.csv`` columns by name: ``info_KEY`` (each episode's sum of
    ``info[train.info_metric]``), ``rms_error`` (a prediction run's errors)"""
    visits: np.ndarray | None = None
    """its visits (kept by a sweep whose figure is ``metric: policy``)"""


class SweepInterrupted(KeyboardInterrupt):
    """A sweep stopped at once (a second signal), with how many runs ``results.csv`` holds."""

    def __init__(self, directory: Path, saved: int, total: int) -> None:
        super().__init__(directory, saved, total)
        self.text = saved_text(directory, saved, total)


@dataclass
class SweepOutcome:
    """How a sweep call ended."""

    directory: Path
    spec: SweepSpec
    total_runs: int
    done_runs: int
    complete: bool
    points: list[PointRow] = field(default_factory=list)
    """the ``points.csv`` rows (only when complete)"""
    figure: Path | None = None
    """the sweep file's ``figure``, drawn when complete"""


# -- the worker side ---------------------------------------------------------------------


def run_task(
    handle: JobHandle, task: Sequence[tuple[int, dict[str, Any], Sequence[int]]]
) -> Iterator[FinishedRun]:
    """Job: train and evaluate each (point, seed) of a task, as ``cartpole-q train`` would.

    Args:
        handle: its ``should_stop()`` ends the task early, after the current run.
        task: (point index, the point's config as a mapping, its seeds) groups.

    Yields:
        Each run as it ends.
    """
    from cartpole_q.training import train

    for point, mapping, seeds in task:
        config = load_config(mapping)
        plan = planned(config)
        for seed in seeds:
            if handle.should_stop():
                return
            result = train(plan.for_seed(seed))
            records = {}
            if result.info is not None:
                records[f"{INFO_COLUMN_PREFIX}{config.train.info_metric}"] = result.info
            if result.errors is not None:
                records[ERRORS_COLUMN] = result.errors
            yield FinishedRun(
                point, SeedResult.of_train(result), result.q_table, result.returns,
                result.lengths, records, result.visits,
            )  # fmt: skip


# -- the parent side ---------------------------------------------------------------------


def prepare_sweep(source: Path) -> SweepSpec:
    """Load a sweep file and check every point's config against its environment.

    Raises:
        ConfigError: naming the file, the point and the key.
    """
    spec = load_sweep(source)
    check_points(spec, str(source))
    return spec


def check_points(spec: SweepSpec, where: str) -> None:
    """Check each point's config against its environment (engine, bins, physics).

    Raises:
        ConfigError: naming the point.
    """
    check_tensorboard([point.config for point in spec.points])
    for point in spec.points:  # (inside a command's planning scope, each plan is kept)
        planned(point.config, f"{where}: point {spec.point_id(point.index)}")


def check_tensorboard(configs: Sequence[Config]) -> None:
    """Refuse ``train.tensorboard`` without the writer, before a study starts.

    Raises:
        UserError: naming the extra to install.
    """
    if any(config.train.tensorboard for config in configs):
        from cartpole_q.store.tensorboard import require_writer

        require_writer("train.tensorboard")


def write_run_events(directory: Path, config: Config, finished: FinishedRun) -> None:
    """Write a study run's TensorBoard events (``train.tensorboard``) into ``directory``.

    One event directory per (point or trial, seed), with the run's config as its
    hyperparameters, so that TensorBoard's HParams view compares the points. A study
    keeps returns and lengths only: no epsilon, step size or periodic evaluations.
    """
    from cartpole_q.store.tensorboard import Session, write_session

    write_session(
        directory,
        Session(config.to_dict(), finished.result, finished.returns, finished.lengths),
    )


@contextlib.contextmanager
def new_sweep(spec: SweepSpec, out: Path | None) -> Iterator[Path]:
    """Create the sweep directory and write its start files, holding its lock inside.

    The start files are ``sweep.yaml`` and every point's ``config.yaml``. A failure before they are all written (a full disk) removes the directory this
    created, ``points/`` included; after it, the directory stays for ``sweep --resume``.

    Raises:
        RunError: ``out`` is a file or a non-empty directory, or another command is
            writing it.
        WriteError: a start file cannot be written.
    """
    with sweepdir.new_sweep_dir(spec.name, out) as claim:
        configs = [(spec.point_id(point.index), point.config) for point in spec.points]
        sweepdir.write_sweep(claim.path, spec.to_dict(), configs)
        claim.keep()
        yield claim.path


def start_sweep(spec: SweepSpec, out: Path | None) -> Path:
    """Create the sweep directory and write its start files (its lock released on return)."""
    with new_sweep(spec, out) as directory:
        return directory


def load_sweep_dir(directory: Path) -> SweepSpec:
    """The sweep of an existing sweep directory, for ``--resume`` (hold its lock).

    Raises:
        RunError: ``directory`` is not a sweep directory.
        ConfigError: its ``sweep.yaml`` is invalid.
    """
    path = sweepdir.sweep_file(directory)
    sweepdir.remove_temporaries(directory)  # the caller holds the lock: none is in use
    spec = load_sweep(path)
    check_unchanged(spec, directory)
    check_points(spec, str(path))
    return spec


def check_unchanged(spec: SweepSpec, directory: Path) -> None:
    """Refuse a ``sweep.yaml`` that no longer describes the sweep the directory started.

    The points' ``config.yaml`` files, written when the sweep started and never after,
    are the record: every point must still exist with the same config (its name
    included), so that no finished row is labelled with values it did not run with. Only
    ``seeds`` may change, and only grow (checked against ``results.csv`` by the caller).

    Raises:
        RunError: naming the key, the point, and both values.
    """
    where = directory / sweepdir.SWEEP_FILE
    started = sweepdir.point_ids(directory)
    now = [spec.point_id(point.index) for point in spec.points]
    advice = (
        "--resume finishes a sweep exactly as it started (only `seeds` may grow); put "
        "sweep.yaml back, or start a new sweep from the edited file."
    )
    if started != now:
        raise RunError(
            f"{where}: the sweep started with {len(started)} points, sweep.yaml now gives "
            f"{len(now)} (its axes changed: {', '.join(spec.axes) or 'none'}). {advice}"
        )
    for point, point_id in zip(spec.points, now, strict=True):
        config_path = sweepdir.point_config_path(directory, point_id)
        try:
            first = load_config(config_path)
        except ConfigError as error:
            raise RunError(
                f"{config_path}: is not a valid config any more ({error}); the sweep directory "
                "was changed by hand."
            ) from None
        differences = config_differences(first, point.config)
        if differences:
            key, old, new = differences[0]
            raise RunError(
                f"{where}: {key}: point {point_id} started with {shown_value(old)}, sweep.yaml "
                f"now gives {shown_value(new)}. {advice}"
            )


@planning()  # one plan per point for all its seeds
def run_sweep(
    spec: SweepSpec,
    directory: Path,
    *,
    workers: int = 1,
    backend: str = "local",
    address: str | None = None,
    progress: SweepProgress | None = None,
    should_stop: Callable[[], bool] | None = None,
    on_compile: Callable[[int], None] | None = None,
) -> SweepOutcome:
    """Run whatever ``results.csv`` of ``directory`` does not have yet, then summarise.

    Args:
        spec: the sweep (as written in ``directory``).
        directory: the sweep directory.
        workers: worker processes (or a local Ray cluster's CPUs).
        backend: ``local`` or ``ray``.
        address: a running Ray cluster's address.
        progress: receives the count of finished runs.
        should_stop: polled between runs; when true, the finished runs are saved and
            the sweep ends, to be finished with ``--resume``.
        on_compile: told how many training loops are compiled before the runs start (on
            the local backend: see :func:`~cartpole_q.experiments.compiling.compile_ahead`).

    Returns:
        How far it got; when complete, ``points.csv`` and ``sweep.png`` are written.

    Raises:
        RunError: ``results.csv`` has rows that are not of this sweep.
    """
    progress = progress or NullSweepProgress()
    check_tensorboard([point.config for point in spec.points])
    book = _Book(spec, directory)
    missing = [
        (point.index, seed)
        for point in spec.points
        for seed in spec.seeds
        if (point.index, seed) not in book.rows
    ]
    if backend == "local":  # before the progress bar: its thread would stop forking
        points = {point for point, _ in missing}
        plans = [planned(point.config) for point in spec.points if point.index in points]
        try:
            compile_ahead(plans, workers, should_stop, on_compile)
        except KeyboardInterrupt:
            raise SweepInterrupted(directory, book.saved, spec.runs) from None
    progress.start(spec.runs, len(book.rows), len(spec.points), book.points_done())
    tasks = plan_tasks(spec, missing, workers)

    def on_item(index: int, finished: FinishedRun) -> None:
        book.add([finished])
        progress.advance(len(book.rows), book.points_done())

    try:
        execute(
            run_task, [(task,) for task in tasks], on_item,
            backend=backend, workers=workers, address=address, should_stop=should_stop,
        )  # fmt: skip
    except KeyboardInterrupt:
        book.flush(force=True)
        raise SweepInterrupted(directory, book.saved, spec.runs) from None
    finally:
        book.flush(force=True)
        progress.close()
    outcome = SweepOutcome(directory, spec, spec.runs, len(book.rows), len(book.rows) == spec.runs)
    if outcome.complete:
        outcome.points = summarize_sweep(spec, directory, book.sorted_rows())
        if spec.figure is not None:
            outcome.figure = draw_sweep_figure(spec, directory)
    return outcome


def draw_sweep_figure(spec: SweepSpec, directory: Path) -> Path:
    """Draw the sweep file's ``figure`` of every point into the sweep directory, its data beside it."""
    figure = spec.figure
    assert figure is not None
    labels = [
        ", ".join(
            f"{key.rsplit('.', 1)[-1]} {axis_cell(value)}" for key, value in point.values.items()
        )
        or spec.name
        for point in spec.points
    ]
    reference = None
    if figure.reference is not None:
        reference = (figure.reference, figure.reference_label)
    style = CurveStyle(
        labels, figure.title, figure.y_label, figure.offset, figure.scale, reference,
        figure.x_max, (figure.y_min, figure.y_max), log_x=figure.log_x, log_y=figure.log_y,
    )  # fmt: skip
    paths = [directory / "points" / spec.point_id(point.index) for point in spec.points]
    if figure.against is not None:
        return plot_against(spec, paths, directory / figure.file)
    if figure.metric == VALUES_FIGURE:
        return plot_values(spec, paths, labels, directory / figure.file)
    if figure.metric == POLICY_FIGURE:
        return plot_policy(spec, paths, labels, directory / figure.file)
    view = MetricView(figure.metric, figure.x, figure.aggregate, figure.smooth)
    return plot_metric(paths, directory / figure.file, view, force=True, style=style)


def plot_against(spec: SweepSpec, paths: Sequence[Path], out: Path) -> Path:
    """The ``figure.against`` figure: each point's per-episode mean against an axis.

    A seed's value is the mean of the metric over its first ``figure.first`` episodes (after
    ``(value + offset) * scale``); a point's is the mean over seeds, with a 95% bootstrap
    interval; points that share the other axes' values form one line, ordered by the axis.
    A sweep that keeps no curves (``curves: false``) draws the mean return over all
    episodes, each seed's from ``results.csv``'s ``mean_return``. With ``figure.dashed``
    the lines at its axis value are dashed, and lines that differ only in that axis share a
    colour. With ``figure.best: {AXIS: min|max}`` the points that differ only in AXIS are
    one line, drawn at each value of ``against`` through the best of them (by the mean over
    seeds; the first in file order on a tie), and the figure's data says which.
    """
    figure = spec.figure
    assert figure is not None and figure.against is not None
    dashed = figure.dashed or {}
    best_axis, best_rule = next(iter((figure.best or {"": "min"}).items()))
    groups: dict[str, list[tuple[float, np.ndarray, Any]]] = {}
    styles: dict[str, tuple[str, bool]] = {}
    for point, path in zip(spec.points, paths, strict=True):
        per_seed = [(value + figure.offset) * figure.scale for value in _seed_means(spec, path)]
        others = ", ".join(
            f"{key.rsplit('.', 1)[-1]} {axis_cell(value)}"
            for key, value in point.values.items()
            if key not in (figure.against, best_axis)
        )
        groups.setdefault(others or spec.name, []).append(
            (
                float(point.values[figure.against]),
                np.array(per_seed)[:, None],
                point.values.get(best_axis),
            )
        )
        colour_key = ", ".join(
            f"{key}={axis_cell(value)}"
            for key, value in point.values.items()
            if key not in (figure.against, best_axis) and key not in dashed
        )
        at_dashed = bool(dashed) and all(
            axis_cell(point.values[key]) == axis_cell(value) for key, value in dashed.items()
        )
        styles[others or spec.name] = (colour_key, at_dashed)
    if figure.best is not None:
        groups = {label: _best_members(members, best_rule) for label, members in groups.items()}
    lines = []
    rng = np.random.default_rng(0)
    for label, members in groups.items():
        members.sort(key=lambda member: member[0])
        bands = [aggregate_band(values, "mean", rng) for _, values, _ in members]
        lines.append((
            label, [x for x, _, _ in members], np.array([b[0][0] for b in bands]),
            np.array([b[1][0] for b in bands]), np.array([b[2][0] for b in bands]),
        ))  # fmt: skip
    first = f"first {figure.first} episodes" if figure.first is not None else "all episodes"
    how = "sum" if figure.total else "mean"
    y_label = figure.y_label or f"{metric_label(figure.metric)}, {how} over the {first}"
    title = figure.title or spec.name
    line_styles = None
    if figure.dashed is not None:
        colours = list(dict.fromkeys(styles[label][0] for label in groups))
        line_styles = [(colours.index(styles[label][0]), styles[label][1]) for label in groups]
    drawn = summary_line_figure(
        lines, figure.against.rsplit(".", 1)[-1], y_label, title, figure.log_y,
        (figure.y_min, figure.y_max), line_styles=line_styles,
    )  # fmt: skip
    if figure.best is not None:  # which value of the axis each drawn point is
        record = drawn.data.panel("")
        name = best_axis.rsplit(".", 1)[-1]
        for label, members in groups.items():
            record.line(
                f"{label}: best {name} ({best_rule})" if label != spec.name else f"best {name}",
                [x for x, _, _ in members], [float(value) for _, _, value in members],
            )  # fmt: skip
    return write_figure(out, drawn)


def _best_members(
    members: list[tuple[float, np.ndarray, Any]], rule: str
) -> list[tuple[float, np.ndarray, Any]]:
    """Of the members at each x, the one whose mean over seeds is best (``min`` or ``max``).

    On a tie the first in the points' order is kept; a mean that is not a number (a seed
    that diverged) is never chosen over one that is.

    >>> members = [(0.0, np.array([[np.nan]]), 0.05), (0.0, np.array([[3.0]]), 0.1),
    ...            (0.0, np.array([[2.0]]), 0.2)]
    >>> [(x, value) for x, _, value in _best_members(members, "min")]
    [(0.0, 0.2)]
    """
    chosen: dict[float, tuple[float, np.ndarray, Any]] = {}
    sign = 1.0 if rule == "min" else -1.0
    for member in members:
        x, values, _ = member
        mean = sign * float(np.mean(values))
        held = sign * float(np.mean(chosen[x][1])) if x in chosen else math.nan
        if x not in chosen or (mean < held) or (math.isnan(held) and not math.isnan(mean)):
            chosen[x] = member
    return list(chosen.values())


def _seed_means(spec: SweepSpec, path: Path) -> list[float]:
    """A point's per-seed means of the figure's metric, before the figure's transform.

    From the curves (the first ``figure.first`` episodes), or, in a sweep that keeps none,
    from ``results.csv``'s ``mean_return`` (the mean return over all episodes).

    Raises:
        RunError: a run has no ``mean_return`` (its row was written before the column).
    """
    figure = spec.figure
    assert figure is not None
    if not spec.curves:
        rows = sweepdir.point_results(path) or []
        missing = next((row for row in rows if row.result.mean_return is None), None)
        if missing is not None:
            raise RunError(
                f"{path.parent.parent / sweepdir.RESULTS_FILE}: point {missing.point}, seed "
                f"{missing.result.seed} has no mean_return (its row is older than the column); "
                "run the sweep anew to draw the figure."
            )
        return [float(row.result.mean_return or 0.0) for row in rows]
    runs = load_run_set(path).runs
    check_record(path, runs, figure.metric)
    column = record_column(figure.metric)
    means = []
    for run in runs:
        record = None if column is None else run.record(column)
        values = per_episode(run.metrics.returns, run.metrics.lengths, figure.metric, record)
        values = values[: figure.first] if figure.first is not None else values
        means.append(float(np.sum(values)) if figure.total else float(np.mean(values)))
    return means


def plot_values(spec: SweepSpec, paths: Sequence[Path], labels: Sequence[str], out: Path) -> Path:
    """The ``figure.metric: values`` figure: each point's learned ``V`` against the state.

    One line per point (the mean of its seeds' ``V`` on the measured states, a 95% bootstrap
    interval over seeds), the evaluated policy's true values, and the values every run
    started from (``agent.q_init``, when the points share it): Sutton & Barto Example 6.2's
    left panel. The x axis is the world's true state (:attr:`Truth.states`): where the world
    aggregates states, each state shows ``V`` of its group (Figures 9.1, 9.2), a staircase.
    With ``figure.distribution`` the on-policy distribution is shaded on a second axis.
    Each point's environment facts are its plan's (the one it ran with, in this command's
    planning scope, or made here).
    """
    from cartpole_q.engines.base import prediction_distribution, prediction_truth

    figure = spec.figure
    assert figure is not None
    facts = [planned(point.config).env_info for point in spec.points]
    first, info = spec.points[0].config, facts[0]
    if profile_for(first.env.id).policy_map == "blackjack":  # Figure 5.1's value surfaces
        maps = []
        for label, path in zip(labels, paths, strict=True):
            runs = load_run_set(path).runs
            tables = np.array([run.q_table.reshape(info.state_shape) for run in runs])
            maps.append((label, tables.mean(axis=0)))
        return write_figure(out, blackjack_values_figure(maps, figure.title or spec.name))
    truth = prediction_truth(first, info)
    if not truth.measured:
        raise RunError(
            f"figure.metric: values draws V beside the true values, but {first.env.id} has no "
            "model to compute them from (a world with a transition table has one)."
        )
    states = [float(state) for state in truth.states]
    second = None
    if figure.distribution:
        mu = prediction_distribution(first, info)
        second = ("on-policy distribution mu (shaded, right axis)", states, mu)
    rng = np.random.default_rng(0)
    learned, starts = [], []
    for point, point_info, label, path in zip(spec.points, facts, labels, paths, strict=True):
        # Each point reads its own tables' rows (its discretization: tiles, groups).
        rows = prediction_truth(point.config, point_info).rows
        if rows.shape[0] != len(states):
            raise RunError(
                f"figure.metric: values draws every point against the same true states, but "
                f"point {label} measures {rows.shape[0]} states and the first {len(states)}: "
                "give the points one world."
            )
        runs = load_run_set(path).runs
        per_seed = np.array([_state_values(run.q_table, rows) for run in runs])
        learned.append(aggregate_band(per_seed, "mean", rng))
        starts.append(_initial_state_values(point.config, rows))
    from cartpole_q.envs.models import state_labels

    named = state_labels(first.env)  # where the world names every state drawn, by name
    names = {x: named[int(x)] for x in states} if all(int(x) in named for x in states) else None
    if figure.arrows:
        panels = [
            ValueChanges(label, start, centre)
            for label, start, (centre, _, _) in zip(labels, starts, learned, strict=True)
        ]
        drawn = value_changes_figure(
            panels, states, truth.values, names, figure.y_label or "estimated value",
            figure.title or spec.name,
        )  # fmt: skip
        return write_figure(out, drawn)
    lines = []
    if all(np.array_equal(start, starts[0]) for start in starts):
        lines.append(("initial values", states, starts[0], starts[0], starts[0]))
    lines += [
        (label, states, centre, low, high)
        for label, (centre, low, high) in zip(labels, learned, strict=True)
    ]
    lines.append(("true values", states, truth.values, truth.values, truth.values))
    drawn = summary_line_figure(
        lines, "state", figure.y_label or "estimated value", figure.title or spec.name,
        figure.log_y, (figure.y_min, figure.y_max), second, x_names=names,
    )  # fmt: skip
    return write_figure(out, drawn)


INDIFFERENT = 1e-12
"""below this gap between the exact values of stick and hit a state counts as indifferent:
either action is optimal"""


@dataclass(frozen=True)
class PolicyMatch:
    """A greedy policy against the exact optimal one, on the states Figure 5.2 draws."""

    states: int
    """the states compared: player sums 12-21, every dealer card, usable ace or not (200)"""
    matching: int
    """the states whose greedy action is the optimal one (or either, where indifferent)"""
    indifferent: int
    """the states where both actions are optimal (their exact values within
    :data:`INDIFFERENT`)"""
    differing: tuple[tuple[int, int, int], ...]
    """``(player sum, dealer card, usable ace)`` of each state that differs"""
    largest_value_error: float
    """the largest ``|max_b Q(s, b) - v*(s)|`` over the states compared"""


def blackjack_optimum(config: Config) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Blackjack's exact optimal action values from the rules, as ``(32, 11, 2, 2)`` tables.

    Returns:
        ``q*`` per observation row and action, the optimal policy (the lowest action among
        the maxima: stick on ties) and ``v*``, each shaped by the observation.
    """
    from cartpole_q.envs.models import env_model
    from cartpole_q.families.blackjack.model import BLACKJACK_SHAPE
    from cartpole_q.rl.solvers import finite_horizon

    exact = env_model(config.env)
    if isinstance(exact, str):
        raise RunError(f"figure.metric: policy needs the exact model of {config.env.id}: {exact}.")
    solution = finite_horizon(exact.model, exact.horizon)
    rows = int(np.prod(BLACKJACK_SHAPE))  # model states 0..rows-1 are the observation rows
    q_star = solution.q[:rows].reshape(*BLACKJACK_SHAPE, -1)
    return q_star, np.argmax(q_star, axis=-1), q_star.max(axis=-1)


def policy_match(q_table: np.ndarray, q_star: np.ndarray) -> PolicyMatch:
    """Compare the greedy actions of ``q_table`` with ``q_star``'s on the 200 states."""
    greedy = np.argmax(q_table, axis=-1)
    optimal = np.argmax(q_star, axis=-1)
    matching = indifferent = 0
    differing = []
    error = 0.0
    for player_sum in range(12, 22):
        for card in range(1, 11):
            for usable in (0, 1):
                state = (player_sum, card, usable)
                tie = abs(float(q_star[state][0] - q_star[state][1])) < INDIFFERENT
                indifferent += int(tie)
                if tie or greedy[state] == optimal[state]:
                    matching += 1
                else:
                    differing.append(state)
                error = max(error, abs(float(q_table[state].max() - q_star[state].max())))
    return PolicyMatch(200, matching, indifferent, tuple(differing), error)


def plot_policy(spec: SweepSpec, paths: Sequence[Path], labels: Sequence[str], out: Path) -> Path:
    """The ``figure.metric: policy`` figure: greedy policies and ``max_b Q`` beside the optimum.

    Each point's table is the mean of its seeds' ``Q``; its greedy policy (lowest action on
    ties) and ``max_b Q`` are drawn beside the exact optimal policy and ``v*`` of the first
    point's world, from its rules (Sutton & Barto Figure 5.2). Each point's label says how
    many of the 200 states' greedy actions are optimal.
    """
    figure = spec.figure
    assert figure is not None
    first = spec.points[0].config
    if profile_for(first.env.id).policy_map == "racetrack":
        return _plot_racetrack(spec, paths, labels, out)
    if profile_for(first.env.id).grid is not None:
        return _plot_grid_arrows(spec, paths, labels, out)
    info = planned(first).env_info
    q_star, optimal, v_star = blackjack_optimum(first)
    maps = []
    for label, path in zip(labels, paths, strict=True):
        runs = load_run_set(path).runs
        tables = np.array([run.q_table.reshape(*info.state_shape, -1) for run in runs])
        q_table = tables.mean(axis=0)
        match = policy_match(q_table, q_star)
        name = f"{label}: {match.matching} of {match.states} optimal"
        maps.append((name, np.argmax(q_table, axis=-1), q_table.max(axis=-1)))
    maps.append(("exact optimum (the rules)", optimal, v_star))
    return write_figure(out, blackjack_optimal_figure(maps, figure.title or spec.name))


RACETRACK_PATHS = 6
"""how many start cells Figure 5.5 drives from (spread evenly along the start line)"""


def _plot_racetrack(
    spec: SweepSpec, paths: Sequence[Path], labels: Sequence[str], out: Path
) -> Path:
    """Figure 5.5: per point, its first seed's greedy policy and the optimal one on its track.

    Trajectories without failed increments from :data:`RACETRACK_PATHS` start cells; each
    panel gives the policy's exact expected return from the start line (weighted by the
    start distribution; the optimum's by value iteration on the world's model).
    """
    from cartpole_q.envs.gym import make_env
    from cartpole_q.figures.maps import racetrack_figure

    figure = spec.figure
    assert figure is not None
    panels = []
    for point, label, path in zip(spec.points, labels, paths, strict=True):
        env = make_env(point.config.env)
        world: Any = env.unwrapped
        env.close()
        run = load_run_set(path).runs[0]
        learned = np.argmax(run.q_table.reshape(len(world.P), -1), axis=1)
        panels.extend(_racetrack_panels(world, learned, f"{label}, seed {run.config.seed}"))
    return write_figure(out, racetrack_figure(panels, figure.title or spec.name))


def _racetrack_panels(
    world: Any, learned: np.ndarray, label: str
) -> list[tuple[str, Sequence[str], list[tuple[str, Any, str]]]]:
    """A learned greedy policy's panel and the optimal policy's, on one track."""
    from cartpole_q.families.book_mdps.racetrack import noiseless_path
    from cartpole_q.rl.mdp import FiniteMDP
    from cartpole_q.rl.solvers import evaluate_policy, reachable_states, value_iteration

    model = FiniteMDP.from_transitions(
        world.P, world.initial_state_distrib, int(world.action_space.n)
    )
    optimum = value_iteration(model, 1.0)
    starts = world.starts
    most = min(RACETRACK_PATHS, len(starts))
    chosen = sorted({starts[round(i * (len(starts) - 1) / max(1, most - 1))] for i in range(most)})

    def drive(policy: np.ndarray) -> list[tuple[str, Any, str]]:
        found = []
        for start in chosen:
            cells, how = noiseless_path(world, policy, start)
            found.append((f"from column {world.cells[start][1]}", cells, how))
        return found

    pi = np.zeros((model.n_states, model.n_actions))
    pi[np.arange(model.n_states), learned] = 1.0
    reached = np.flatnonzero(reachable_states(model, pi))  # solved on these alone: fast
    try:
        values = evaluate_policy(model, pi, 1.0, reached)
        told = f"expected return {float(model.initial[reached] @ values):.2f}"
    except ValueError:
        told = "never finishes from some state it reaches"
    size = "x".join(str(n) for n in world.track_size)
    return [
        (f"{label}: greedy policy,\n{told}", world.track_rows, drive(learned)),
        (f"{size} track, optimal policy (value iteration),\nexpected return "
         f"{optimum.start_value:.2f}", world.track_rows, drive(optimum.policy)),
    ]  # fmt: skip


def _plot_grid_arrows(
    spec: SweepSpec, paths: Sequence[Path], labels: Sequence[str], out: Path
) -> Path:
    """Figures 7.4 and 8.3: each point's first seed, arrows where its greedy action is set."""
    from cartpole_q.envs.models import grid_layout
    from cartpole_q.figures.maps import GridMap, grid_arrows_figure

    figure = spec.figure
    assert figure is not None
    layout = grid_layout(spec.points[0].config.env)
    assert layout is not None
    grid = GridMap(layout.rows, layout.columns, layout.cells, layout.moves)
    panels = []
    for label, path in zip(labels, paths, strict=True):
        run = load_run_set(path).runs[0]
        panels.append((f"{label}, seed {run.config.seed}", run.q_table, run.visits))
    return write_figure(out, grid_arrows_figure(panels, grid, figure.title or spec.name))


def plan_tasks(
    spec: SweepSpec, missing: Sequence[tuple[int, int]], workers: int
) -> list[list[tuple[int, dict[str, Any], tuple[int, ...]]]]:
    """Cut the missing (point, seed) runs, in order, into tasks of consecutive runs.

    A task holds up to :data:`MAX_RUNS_PER_TASK` runs, fewer when that leaves fewer than
    four tasks per worker; consecutive seeds of a point stay together.
    """
    if not missing:
        return []
    size = chunk_size(len(missing), workers, most=MAX_RUNS_PER_TASK)
    mappings: dict[int, dict[str, Any]] = {}
    tasks = []
    for start in range(0, len(missing), size):
        groups: list[tuple[int, dict[str, Any], tuple[int, ...]]] = []
        for point, seed in missing[start : start + size]:
            if groups and groups[-1][0] == point:
                groups[-1] = (point, groups[-1][1], (*groups[-1][2], seed))
                continue
            if point not in mappings:
                mappings[point] = spec.points[point].config.to_dict()
            groups.append((point, mappings[point], (seed,)))
        tasks.append(groups)
    return tasks


class _Book:
    """The finished rows and the tables of unfinished points, saved in batches."""

    def __init__(self, spec: SweepSpec, directory: Path) -> None:
        self._spec = spec
        self._directory = directory
        self.rows: dict[tuple[int, int], ResultRow] = {}
        seeds = set(spec.seeds)
        results = directory / sweepdir.RESULTS_FILE
        for row in sweepdir.read_results(directory, spec.axes):
            key = self._key(row)
            if key[0] >= len(spec.points) or key in self.rows:
                raise RunError(
                    f"{results}: has a row (point {row.point}, seed {row.result.seed}) that is "
                    "not of this sweep, or twice; the sweep directory was changed by hand. Start "
                    "a new sweep."
                )
            if key[1] not in seeds:
                raise RunError(
                    f"{directory / sweepdir.SWEEP_FILE}: seeds: it now gives "
                    f"{format_seeds(spec.seeds)}, but {results} holds finished runs of seed "
                    f"{key[1]}; seeds may be added to a sweep, not taken away. Put them back."
                )
            self._check_axis_cells(row, key[0])
            self.rows[key] = row
        self._per_point = {point.index: 0 for point in spec.points}
        for point, _ in self.rows:
            self._per_point[point] += 1
        self._tables: dict[int, dict[str, np.ndarray]] = {}
        self._curves: dict[int, dict[str, tuple[np.ndarray, np.ndarray]]] = {}
        self._records: dict[int, dict[str, dict[str, np.ndarray]]] = {}
        """by point and seed key, the runs' further columns (``FinishedRun.records``)"""
        figure = spec.figure
        self._keeps_visits = figure is not None and figure.metric == POLICY_FIGURE
        self._visits: dict[int, dict[str, np.ndarray]] = {}
        """by point and seed key, the runs' visits (a ``metric: policy`` figure's paths)"""
        self._dirty: set[int] = set()
        self._last_flush = -math.inf  # the first results are saved at once
        self.saved = len(self.rows)
        """how many rows ``results.csv`` holds"""

    def _key(self, row: ResultRow) -> tuple[int, int]:
        try:
            return int(row.point), row.result.seed
        except ValueError:
            raise RunError(
                f"{self._directory / sweepdir.RESULTS_FILE}: has a damaged row (point "
                f"{row.point}); start a new sweep."
            ) from None

    def _check_axis_cells(self, row: ResultRow, point: int) -> None:
        """Refuse a finished row whose axis cells are not the point's values any more."""
        values = self._spec.points[point].values
        for key in self._spec.axes:
            now = axis_cell(values[key])
            if row.axes[key] != now:
                raise RunError(
                    f"{self._directory / sweepdir.SWEEP_FILE}: {key}: the finished runs of point "
                    f"{row.point} ran with {row.axes[key]}, sweep.yaml now gives {now}; --resume "
                    "finishes a sweep exactly as it started (only `seeds` may grow)."
                )

    def points_done(self) -> int:
        return sum(1 for count in self._per_point.values() if count == len(self._spec.seeds))

    def add(self, finished: Sequence[FinishedRun]) -> None:
        spec = self._spec
        for run in finished:
            point, seed = run.point, run.result.seed
            if point not in self._tables:
                point_id = spec.point_id(point)
                self._tables[point] = sweepdir.read_tables(self._directory, point_id)
                if spec.curves:
                    self._curves[point] = sweepdir.read_curves(self._directory, point_id)
                    self._records[point] = sweepdir.read_records(self._directory, point_id)
                if self._keeps_visits:
                    self._visits[point] = sweepdir.read_visits(self._directory, point_id)
            self._tables[point][spec.seed_key(seed)] = run.q_table
            if self._keeps_visits and run.visits is not None:
                self._visits[point][spec.seed_key(seed)] = run.visits
            config = spec.points[point].config
            if config.train.tensorboard:
                board = self._directory / TENSORBOARD_DIR / spec.point_id(point)
                write_run_events(board / spec.seed_key(seed), config.for_seed(seed), run)
            if spec.curves:
                self._curves[point][spec.seed_key(seed)] = (run.returns, run.lengths)
                if run.records:
                    self._records[point][spec.seed_key(seed)] = dict(run.records)
            values = spec.points[point].values
            self.rows[(point, seed)] = ResultRow(
                spec.point_id(point), {key: axis_cell(values[key]) for key in spec.axes}, run.result
            )
            self._per_point[point] += 1
            self._dirty.add(point)
        self.flush()

    def flush(self, *, force: bool = False) -> None:
        """Save the tables of the points that changed, then ``results.csv``."""
        if not self._dirty or (not force and time.monotonic() - self._last_flush < FLUSH_SECONDS):
            return
        for point in sorted(self._dirty):
            point_id = self._spec.point_id(point)
            sweepdir.write_tables(self._directory, point_id, self._tables[point])
            if self._keeps_visits:
                visits = self._visits[point]
                sweepdir.write_tables(self._directory, point_id, visits, sweepdir.VISITS_FILE)
            if self._spec.curves:
                sweepdir.write_curves(
                    self._directory, point_id, self._curves[point], self._records.get(point)
                )
        rows = self.sorted_rows()
        sweepdir.write_results(self._directory, self._spec.axes, rows)
        self.saved = len(rows)
        # Only once both are written: an interruption above leaves everything to save again.
        for point in self._dirty:
            if self._per_point[point] == len(self._spec.seeds):
                del self._tables[point]  # complete: its files hold every seed
                self._visits.pop(point, None)
                self._curves.pop(point, None)
                self._records.pop(point, None)
        self._dirty.clear()
        self._last_flush = time.monotonic()

    def sorted_rows(self) -> list[ResultRow]:
        return [self.rows[key] for key in sorted(self.rows)]


def summarize_sweep(spec: SweepSpec, directory: Path, rows: Sequence[ResultRow]) -> list[PointRow]:
    """Write ``points.csv`` and ``sweep.png`` from the finished rows; return the point rows."""
    by_point: dict[str, list[ResultRow]] = {}
    for row in rows:
        by_point.setdefault(row.point, []).append(row)
    point_rows = []
    for point in spec.points:
        point_id = spec.point_id(point.index)
        results = [row.result for row in by_point.get(point_id, [])]
        point_rows.append(
            PointRow(
                point_id,
                {key: axis_cell(point.values[key]) for key in spec.axes},
                summarize_seeds(results),
            )
        )
    sweepdir.write_points(directory, spec.axes, point_rows)
    sweepdir.write_figure(directory, sweep_png(spec, point_rows, by_point))
    return point_rows


def sweep_png(
    spec: SweepSpec, point_rows: Sequence[PointRow], by_point: dict[str, list[ResultRow]]
) -> DataFigure:
    """Draw ``sweep.png``: the statistics against the axes, and the performance profiles."""
    from cartpole_q.figures import SweepAxis, sweep_figure

    axes = [SweepAxis(key, [axis_cell(v) for v in values]) for key, values in spec.grid.items()]
    if spec.zip:  # the zip group is one more axis, each value naming all its keys' values
        labels = [
            ", ".join(axis_cell(v) for v in values)
            for values in zip(*spec.zip.values(), strict=True)
        ]
        axes.append(SweepAxis(" + ".join(spec.zip), labels))
    if point_rows and all(row.statistics.mean_rms_error is not None for row in point_rows):
        from cartpole_q.figures import prediction_sweep_figure

        ids = [spec.point_id(point.index) for point in spec.points]
        return prediction_sweep_figure(
            spec.name, axes, ids, [row.statistics.as_row() for row in point_rows]
        )
    eval_means = []
    for point in spec.points:
        rows = by_point.get(spec.point_id(point.index), [])
        eval_means.append(
            np.array([row.result.eval_mean for row in rows if row.result.eval_mean is not None])
        )
    threshold = _threshold(spec)
    return sweep_figure(
        spec.name,
        axes,
        [spec.point_id(point.index) for point in spec.points],
        [row.statistics.as_row() for row in point_rows],
        eval_means,
        threshold,
    )


def _threshold(spec: SweepSpec) -> float | None:
    """The base config's reward threshold (for the profile's reference line)."""
    try:
        return planned(spec.points[0].config).env_info.reward_threshold
    except ConfigError:
        return None


def _initial_state_values(config: Config, rows: np.ndarray) -> np.ndarray:
    """``V`` of each measured state before the run: ``agent.initial_values``, or ``q_init``.

    (``agent.initial_values`` is never given on tiles, so each state is its row.)
    """
    if config.agent.initial_values is None:
        return np.full(rows.shape[0], config.agent.q_init)
    starts: np.ndarray = np.array(config.agent.initial_values)[rows[:, 0]]
    return starts


def _state_values(table: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """``V`` of each measured state: its row, or its ``T`` tiles summed in tiling order.

    ``rows`` is a :class:`~cartpole_q.engines.base.Truth`'s ``(k, T)``.
    """
    weights = table.reshape(-1)
    values = np.zeros(rows.shape[0])
    for t in range(rows.shape[1]):
        values = values + weights[rows[:, t]]
    return values


# -- the sweep as a study kind -------------------------------------------------------------


SWEEP_TABLE_ROWS = 15
"""``sweep`` prints at most this many points, the best first"""


def _interval(value: float | None, low: float | None, high: float | None, digits: int) -> str:
    if value is None or low is None or high is None:
        return "-"
    return f"{value:.{digits}f} [{low:.{digits}f}, {high:.{digits}f}]"


def sweep_table(
    axes: Sequence[str], point_rows: Sequence[PointRow], limit: int = SWEEP_TABLE_ROWS
) -> list[str]:
    """The points as text lines, best first (success rate, then IQM eval return).

    >>> from cartpole_q.statistics import PointStatistics
    >>> stats = PointStatistics(2, 1.0, 0.34, 1.0, 500.0, 500.0, 500.0, 175.0, 170.0, 180.0,
    ...     9000.0, 8000.0, 10000.0)
    >>> for line in sweep_table(["agent.alpha"], [PointRow("000", {"agent.alpha": "0.1"}, stats)]):
    ...     print(line)
    point  agent.alpha  seeds  success rate [95%]  IQM eval return [95%]  median solve episode [95%]
    000    0.1          2      1.00 [0.34, 1.00]   500.0 [500.0, 500.0]   175 [170, 180]
    """
    if point_rows and all(row.statistics.mean_rms_error is not None for row in point_rows):
        return _prediction_table(axes, point_rows, limit)

    def rank(row: PointRow) -> tuple[float, float]:
        stats = row.statistics
        rate = -1.0 if stats.success_rate is None else stats.success_rate
        iqm = -math.inf if stats.iqm_eval_return is None else stats.iqm_eval_return
        return (-rate, -iqm)

    ordered = sorted(point_rows, key=rank)[:limit]
    header = ["point", *axes, "seeds", "success rate [95%]", "IQM eval return [95%]",
              "median solve episode [95%]"]  # fmt: skip
    table = [header]
    for row in ordered:
        s = row.statistics
        table.append([
            row.point, *(row.axes[axis] for axis in axes), str(s.seeds),
            _interval(s.success_rate, s.success_rate_low, s.success_rate_high, 2),
            _interval(s.iqm_eval_return, s.iqm_eval_return_low, s.iqm_eval_return_high, 1),
            _interval(s.median_solved_episode, s.median_solved_episode_low,
                      s.median_solved_episode_high, 0),
        ])  # fmt: skip
    return _aligned(table)


def _prediction_table(axes: Sequence[str], point_rows: Sequence[PointRow], limit: int) -> list[str]:
    """Prediction points, the lowest final RMS error first.

    >>> from cartpole_q.statistics import PointStatistics
    >>> stats = PointStatistics(100, *[None] * 12, 0.0512, 0.049, 0.0533)
    >>> for line in sweep_table(["agent.alpha"], [PointRow("000", {"agent.alpha": "0.1"}, stats)]):
    ...     print(line)
    point  agent.alpha  seeds  RMS error after the last episode, mean [95%]
    000    0.1          100    0.0512 [0.0490, 0.0533]
    """
    ordered = sorted(point_rows, key=lambda row: row.statistics.mean_rms_error or 0.0)[:limit]
    table = [["point", *axes, "seeds", "RMS error after the last episode, mean [95%]"]]
    for row in ordered:
        s = row.statistics
        table.append([
            row.point, *(row.axes[axis] for axis in axes), str(s.seeds),
            _interval(s.mean_rms_error, s.mean_rms_error_low, s.mean_rms_error_high, 4)
            if s.mean_rms_error is None or math.isfinite(s.mean_rms_error)
            else f"{s.mean_rms_error} (a run diverged)",
        ])  # fmt: skip
    return _aligned(table)


def _aligned(table: list[list[str]]) -> list[str]:
    """The rows of a table as lines, each column as wide as its widest cell."""
    header = table[0]
    widths = [max(len(line[i]) for line in table) for i in range(len(header))]
    return ["  ".join(text.ljust(width) for text, width in zip(line, widths, strict=True)).rstrip()
            for line in table]  # fmt: skip


def summary_lines(outcome: SweepOutcome) -> list[str]:
    """A finished sweep's points (the best first) and where its files are."""
    spec, directory = outcome.spec, outcome.directory
    rows = outcome.points
    shown = min(len(rows), SWEEP_TABLE_ROWS)
    title = f"{len(rows)} points x {len(spec.seeds)} seeds"
    if shown < len(rows):
        title += f" (the best {shown} shown; all in points.csv)"
    lines = [
        title,
        *sweep_table(spec.axes, rows),
        f"points.csv, results.csv and sweep.png in {directory}",
    ]
    if outcome.figure is not None:
        lines.append(f"the sweep file's figure: {outcome.figure}")
    return lines


class SweepKind:
    """``kind: sweep`` (the default): a grid of configs, each trained on every seed.

    Its directory keeps the sweep layout (``sweep.yaml``, ``points/``, ``results.csv``,
    design.md's "Sweep directory"); the machinery is this module's.
    """

    name = "sweep"
    figure_kinds: tuple[str, ...] = ()

    def read(self, study: StudyFile) -> SweepSpec:
        """Check the file and every point's config against its environment."""
        spec = load_sweep(
            study.body, label=study.where, base_dir=study.base_dir,
            default_name=safe_name(study.stem),
        )  # fmt: skip
        check_points(spec, study.where)
        return spec

    def describe(self, spec: SweepSpec) -> tuple[int, str]:
        """Points times seeds."""
        points = f"{len(spec.points):,} point{'' if len(spec.points) == 1 else 's'}"
        seeds = f"{len(spec.seeds):,} seed{'' if len(spec.seeds) == 1 else 's'}"
        alone = "" if spec.axes else " (no grid or zip axes: every seed runs the base config)"
        runs = f"{spec.runs:,} run{'' if spec.runs == 1 else 's'}"
        return spec.runs, f"a sweep: {points} x {seeds} = {runs}{alone}"

    def start(
        self, spec: SweepSpec, study: StudyFile, out: Path | None
    ) -> contextlib.AbstractContextManager[Path]:
        """Claim the sweep directory (:func:`new_sweep`)."""
        return new_sweep(spec, out)

    def is_directory(self, directory: Path) -> bool:
        """A directory with a ``sweep.yaml``."""
        return (directory / sweepdir.SWEEP_FILE).is_file()

    def load(self, directory: Path) -> SweepSpec:
        """The sweep of a sweep directory (:func:`load_sweep_dir`)."""
        return load_sweep_dir(directory)

    def run(self, spec: SweepSpec, directory: Path, options: Options) -> Outcome:
        """Run the sweep (:func:`run_sweep`); when complete, its table of points."""
        from cartpole_q.experiments.workers import default_workers

        def say_compiling(loops: int) -> None:
            options.note(
                f"compiling {loops} training loop{'s' if loops > 1 else ''} first: once per "
                "machine and version, a few seconds each..."
            )

        make = options.progress or (lambda units: NullSweepProgress())
        try:
            found = run_sweep(
                spec, directory, workers=options.workers or default_workers(spec.runs),
                backend=options.backend, address=options.address, progress=make(Units()),
                should_stop=options.should_stop, on_compile=say_compiling,
            )  # fmt: skip
        except SweepInterrupted as error:
            stopped = StudyInterrupted(error.text)
            raise stopped from None
        outcome = Outcome(directory, found.total_runs, found.done_runs, found.complete)
        outcome.saved = saved_text(directory, found.done_runs, found.total_runs)
        if found.complete:
            outcome.lines = summary_lines(found)
            outcome.files = [directory / sweepdir.POINTS_FILE, directory / sweepdir.FIGURE_FILE]
            if found.figure is not None:
                outcome.files.append(found.figure)
        return outcome


SWEEP = register_kind(SweepKind())
"""the sweep kind (registered)"""
