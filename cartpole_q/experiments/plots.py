"""The ``plot`` command's work: load runs, draw them with :mod:`cartpole_q.figures`, write.

Each figure goes out with its data beside it (``<figure>.csv``, written by
:func:`~cartpole_q.store.figure_file.write_figure`). Nothing is drawn before both files
are known to be writable.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from cartpole_q.config import Config, format_seeds
from cartpole_q.errors import RunError, UserError
from cartpole_q.experiments.compare import Comparison, compare_figure_data
from cartpole_q.families import profile_for
from cartpole_q.figures import (
    DRAWN_POINTS,
    Curve,
    GridMap,
    MapDimensions,
    MetricBand,
    SeedBand,
    action_names,
    blackjack_policy_figure,
    default_dims,
    dimension_names,
    grid_policy_figure,
    metric_curve_figure,
    policy_figure,
    reward_and_paths_figure,
    reward_curve_figure,
)
from cartpole_q.learning_curves import (
    X_LABELS,
    aggregate_band,
    info_key_of,
    metric_label,
    record_column,
    seed_curves,
    smoothed,
)
from cartpole_q.rl.tiles import values_on_grid
from cartpole_q.store import rundir
from cartpole_q.store.figure_file import check_figure_file, write_figure
from cartpole_q.store.runsets import check_tables, load_run_set

TILE_MAP_CELLS = 80
"""a tiled table's policy map is drawn on at most this many cells per axis: 80 x 80 cells
(a few pixels each) draw what the tilings resolve, and keep the map's data under a
megabyte"""


def plot_rewards(
    run_dirs: Sequence[Path],
    out: Path,
    force: bool = False,
    on_note: Callable[[str], None] | None = None,
) -> Path:
    """Draw the reward curves of runs, multi-seed runs and sweep points on one figure.

    Args:
        run_dirs: run directories, multi-seed runs or sweep points.
        out: a ``.png``, ``.svg`` or ``.pdf`` file; its data goes beside it as ``.csv``.
        force: replace ``out`` (and its ``.csv``) if they exist.
        on_note: told what is unfinished or left out.

    Raises:
        RunError: a directory is not a complete run, or a sweep point kept no curves.
        WriteError: ``out`` or its ``.csv`` cannot be written (checked before the figure
            is drawn).
    """
    items: list[Curve | SeedBand] = []
    first_runs: list[rundir.Run] = []
    for path in run_dirs:
        run_set = load_run_set(path)
        for note in run_set.notes:
            if on_note is not None:
                on_note(note)
        runs = run_set.runs
        first_runs.append(runs[0])
        if run_set.kind == "sweep point" and not any(run.metrics.returns.size for run in runs):
            raise RunError(
                f"{path}: this sweep kept no learning curves (its sweep file says curves: "
                "false, or it predates them); there is nothing to draw."
            )
        if run_set.kind == "run":
            run = runs[0]
            items.append(Curve(
                path.name, run.metrics.returns, run.result.solved_episode,
                threshold=run.result.reward_threshold, interrupted=run.result.interrupted,
            ))  # fmt: skip
            continue
        name = path.name if run_set.kind == "multi-seed run" else f"point {path.name}"
        items.append(SeedBand(
            name, [run.metrics.returns for run in runs],
            [run.result.solved_episode for run in runs],
            threshold=run_set.reward_threshold,
            interrupted=sum(run.result.interrupted for run in runs),
            seeds=[run.config.seed for run in runs],
        ))  # fmt: skip
    check_figure_file(out, "--out", force)
    title = "Training reward" if len(items) > 1 else f"Training reward: {run_dirs[0].name}"
    if len(items) == 1 and isinstance(items[0], Curve) and items[0].interrupted:
        title += " (interrupted)"
    grid, paths = _greedy_paths(run_dirs, first_runs)
    if grid is not None:
        figure = reward_and_paths_figure(items, None, title, grid, paths)
    else:
        figure = reward_curve_figure(items, None, title)
    return write_figure(out, figure)


@dataclass(frozen=True)
class CurveStyle:
    """How :func:`plot_metric` labels and transforms the curves (a sweep's ``figure``)."""

    labels: Sequence[str] | None = None
    """one legend label per directory"""
    title: str | None = None
    y_label: str | None = None
    offset: float = 0.0
    scale: float = 1.0
    """each value is drawn as ``(value + offset) * scale``"""
    reference: tuple[float, str] | None = None
    """a dashed horizontal line and its label"""
    x_max: float | None = None
    """where the x axis ends (default: the longest seed's training)"""
    y_limits: tuple[float | None, float | None] = (None, None)
    """the y axis's ends (``None``: matplotlib's choice), as the book's figure shows it"""
    log_x: bool = False
    """a logarithmic x axis (S&B Figures 5.3 and 5.4)"""
    log_y: bool = False
    """a logarithmic y axis (S&B Figure 10.2's steps per episode)"""
    all_points: bool = False
    """draw (and write) every point of a long curve, not
    :data:`~cartpole_q.figures.DRAWN_POINTS` of them"""


@dataclass(frozen=True)
class MetricView:
    """What :func:`plot_metric` draws: a metric against an x axis, over seeds, maybe smoothed."""

    metric: str
    """one of :data:`cartpole_q.learning_curves.METRICS`, or ``info:KEY`` (runs trained with
    ``train.info_metric: KEY``)"""
    x: str
    """one of :data:`cartpole_q.learning_curves.X_AXES`"""
    aggregate: str = "mean"
    """``mean`` or ``iqm`` over seeds"""
    window: int = 1
    """a trailing moving average of per-episode values (``return``, ``length``)"""


def plot_metric(
    run_dirs: Sequence[Path],
    out: Path,
    view: MetricView,
    force: bool = False,
    on_note: Callable[[str], None] | None = None,
    style: CurveStyle | None = None,
) -> Path:
    """Draw a metric's learning curves of runs, multi-seed runs and sweep points.

    Args:
        run_dirs: Run directories, multi-seed runs or sweep points, one curve each.
        out: A ``.png``, ``.svg`` or ``.pdf`` file; its data goes beside it as ``.csv``.
        view: The metric, the x axis, the aggregate over seeds and the smoothing window.
        force: Replace ``out`` (and its ``.csv``) if they exist.
        on_note: Told what is unfinished or left out.
        style: Labels, a transform of the values, a reference line, log axes and how many
            points are drawn (a sweep file's ``figure``, ``plot --log-y``); default: the
            directories' names, the values as they are.

    Raises:
        RunError: A directory is not a complete run, a sweep point kept no curves, or
            (``info:KEY``) its runs kept no sums of ``info[KEY]``.
        WriteError: ``out`` or its ``.csv`` cannot be written (checked before the figure
            is drawn).
    """
    style = style or CurveStyle()
    metric, x, aggregate, window = view.metric, view.x, view.aggregate, view.window
    column = record_column(metric)
    bands = []
    for number, path in enumerate(run_dirs):
        run_set = load_run_set(path)
        for note in run_set.notes:
            if on_note is not None:
                on_note(note)
        runs = run_set.runs
        if not any(run.metrics.returns.size for run in runs):
            raise RunError(
                f"{path}: this sweep kept no learning curves (its sweep file says curves: "
                "false, or it predates them); there is nothing to draw."
            )
        check_record(path, runs, metric)
        curves = seed_curves(
            [run.metrics.returns for run in runs], [run.metrics.lengths for run in runs],
            metric, x, window, style.x_max,
            [None if column is None else run.record(column) for run in runs],
        )  # fmt: skip
        values = (curves.values + style.offset) * style.scale
        centre, low, high = aggregate_band(values, aggregate, np.random.default_rng(0))
        if style.labels is not None:
            label = style.labels[number]
        else:
            label = f"point {path.name}" if run_set.kind == "sweep point" else path.name
        seeds = [run.config.seed for run in runs]
        bands.append(MetricBand(label, curves.x, values, centre, low, high, aggregate, seeds))
    check_figure_file(out, "--out", force)
    y_label = style.y_label or metric_label(metric)
    if window > 1 and smoothed(metric):
        y_label += f" ({window}-episode average)"
    title = style.title or f"{metric_label(metric).capitalize()} by {X_LABELS[x]}"
    if len(run_dirs) == 1 and style.title is None:
        title += f": {run_dirs[0].name}"
    figure = metric_curve_figure(
        bands,
        X_LABELS[x],
        y_label,
        title,
        style.log_y,
        style.reference,
        style.y_limits,
        log_x=style.log_x,
        most=None if style.all_points else DRAWN_POINTS,
    )
    return write_figure(out, figure)


def check_record(path: Path, runs: Sequence[rundir.Run], metric: str) -> None:
    """Refuse runs that kept no column of what ``metric`` draws (``info:KEY``, ``rms_error``).

    Raises:
        RunError: naming the path, the metric and what its runs recorded.
    """
    column = record_column(metric)
    if column is None:
        return
    info_key = info_key_of(metric)
    for run in runs:
        if run.record(column) is not None:
            continue
        if info_key is not None:
            recorded = run.config.train.info_metric
            kept = f"train.info_metric: {recorded}" if recorded else "no train.info_metric"
            raise RunError(
                f"{path}: --metric info:{info_key}: its runs were trained with {kept}, so they "
                f"kept no per-episode sums of info[{info_key!r}]; train with train.info_metric: "
                f"{info_key} to draw it."
            )
        raise RunError(
            f"{path}: --metric {metric}: its runs kept no errors: only a prediction algorithm "
            f"(agent.algorithm {run.config.agent.algorithm} is not one, or is one on a world "
            "without a model to know the true values by) measures them."
        )


def _greedy_paths(
    run_dirs: Sequence[Path], runs: Sequence[rundir.Run]
) -> tuple[GridMap | None, list[tuple[str, list[int], bool]]]:
    """Each run's greedy path, when all runs are on one deterministic grid world."""
    envs = {(run.config.env.id, repr(sorted(run.config.env.kwargs.items()))) for run in runs}
    if len(envs) != 1 or runs[0].config.discretization is not None:
        return None, []
    if any(run.predicts for run in runs):  # V is no policy: there is no greedy path
        return None, []
    from cartpole_q.envs.models import EnvModel, env_model, grid_layout

    env = runs[0].config.env
    layout = grid_layout(env)
    found = env_model(env) if layout is not None else None
    if layout is None or not isinstance(found, EnvModel):
        return None, []
    model = found.model
    if not np.all(model.probability == 1.0) or np.count_nonzero(model.initial) != 1:
        return None, []  # paths of a slippery world are not one line
    grid = GridMap(layout.rows, layout.columns, layout.cells, layout.moves)
    paths = []
    for path, run in zip(run_dirs, runs, strict=True):
        policy = np.argmax(run.q_table.reshape(model.n_states, -1), axis=1)
        paths.append((path.name, *follow(model, policy)))
    return grid, paths


def write_compare_figure(result: Comparison, out: Path) -> Path:
    """Draw a comparison's aggregate figure (``compare --out``); write it and its data."""
    from cartpole_q.figures import compare_figure

    figure = compare_figure(compare_figure_data(result), f"{len(result.sides)} runs compared")
    return write_figure(out, figure)


def follow(model: Any, policy: np.ndarray, limit: int = 1000) -> tuple[list[int], bool]:
    """The states a deterministic model visits under ``policy`` from its start.

    Returns the states (the terminal one included) and whether the episode ends; it does
    not when the path comes back to a state it has visited (it would loop forever).
    """
    state = int(np.argmax(model.initial))
    states, seen = [state], {state}
    for _ in range(limit):
        chosen = np.flatnonzero((model.state == state) & (model.action == policy[state]))[0]
        state = int(model.next_state[chosen])
        states.append(state)
        if model.terminated[chosen]:
            return states, True
        if state in seen:
            return states, False
        seen.add(state)
    return states, False


def plot_policy(
    run_dir: Path,
    out: Path,
    dims_text: str | None,
    force: bool = False,
    seed: int | None = None,
    on_note: Callable[[str], None] | None = None,
) -> Path:
    """Draw a policy map: one run's, one seed's (``seed``), or the seeds' agreement.

    For several seeds without ``seed``, the map shows each state's majority greedy action
    and the fraction of seeds that choose it (the agreement) in place of the state value.

    Raises:
        RunError: the directory is not a complete run, or ``seed`` is not one of its seeds.
        UserError: ``dims_text`` does not name two distinct dimensions of the grid.
        WriteError: ``out`` or its ``.csv`` cannot be written (checked before the figure
            is drawn).
    """
    run_set = load_run_set(run_dir)
    check_tables(run_set)  # a table drawn as another world's would be a wrong picture
    for note in run_set.notes:
        if on_note is not None:
            on_note(note)
    runs = run_set.runs
    if seed is not None:
        chosen = [run for run in runs if run.config.seed == seed]
        if not chosen:
            shown = format_seeds(run.config.seed for run in runs)
            raise RunError(f"{run_dir}: --seed {seed}: it has no finished seed {seed} ({shown}).")
        runs = chosen
    run = runs[0]
    title = f"Policy of {run_dir.name}" + (f", seed {seed}" if seed is not None else "")
    value_name = "state value max_a Q"
    if run.config.agent.algorithm == "actor_critic":  # its table holds a policy's preferences
        value_name = "largest action preference max_a theta"
    q_table, visits = run.q_table, run.visits
    if len(runs) > 1:
        q_table, visits = agreement_table(runs)
        title = f"Policy of {run_dir.name}: majority of {len(runs)} seeds"
        value_name = "agreement (fraction of seeds)"
    elif run.result.interrupted:
        title += f" (training interrupted at episode {run.result.episodes})"
    env_id = run.config.env.id
    grid = run.config.discretization
    if grid is None:
        if dims_text is not None:
            raise UserError(
                "--dims: this run's observations are Discrete: there are no binned dimensions to pick."
            )
        return _plot_discrete_policy(run.config, q_table, visits, out, title, force)
    bins = grid.bins
    dims = parse_dims(dims_text, bins) if dims_text else default_dims(bins)
    check_figure_file(out, "--out", force)
    names = dimension_names(env_id, len(bins))
    low, high = grid.low, grid.high
    if grid.tilings > 1:
        # A tiled table has no state per cell: draw the tiles' sums on the fine grid the
        # tilings make (T cells per bin, at most TILE_MAP_CELLS), the other dimensions at
        # their centre.
        cells = (
            min(TILE_MAP_CELLS, bins[dims[0]] * grid.tilings),
            min(TILE_MAP_CELLS, bins[dims[1]] * grid.tilings),
        )
        grids = [values_on_grid(r.q_table, bins, low, high, dims, cells) for r in runs]
        q_table = grids[0]
        if len(grids) > 1:  # the seeds' votes, on the grid (a tile's weights are no state)
            n_actions = q_table.shape[-1]
            q_table = sum(np.eye(n_actions)[np.argmax(g, axis=-1)] for g in grids) / len(grids)
        visits = None
        low, high = (low[dims[0]], low[dims[1]]), (high[dims[0]], high[dims[1]])
        names, dims = [names[dims[0]], names[dims[1]]], (0, 1)
        title += f" ({grid.tilings} tilings; other dimensions at their centre)"
    figure = policy_figure(
        q_table, visits, MapDimensions(dims, low, high, names), title,
        action_names=action_names(env_id, q_table.shape[-1]), value_name=value_name,
    )  # fmt: skip
    return write_figure(out, figure)


def agreement_table(runs: Sequence[rundir.Run]) -> tuple[np.ndarray, np.ndarray | None]:
    """The seeds' votes: ``[..., a]`` is the fraction of seeds whose greedy action is ``a``.

    Its argmax is the majority action (lowest on ties) and its max the agreement; the
    visits are summed over the seeds (``None`` when a seed has none, as sweep points).

    >>> from types import SimpleNamespace as S
    >>> runs = [S(q_table=np.array([[1.0, 0.0]]), visits=None),
    ...         S(q_table=np.array([[0.0, 1.0]]), visits=None),
    ...         S(q_table=np.array([[2.0, 0.0]]), visits=None)]
    >>> votes, _ = agreement_table(runs)
    >>> votes.round(3).tolist()
    [[0.667, 0.333]]
    """
    n_actions = runs[0].q_table.shape[-1]
    votes = np.zeros(runs[0].q_table.shape, dtype=np.float64)
    for run in runs:
        votes += np.eye(n_actions)[np.argmax(run.q_table, axis=-1)]
    votes /= len(runs)
    counts = [run.visits for run in runs if run.visits is not None]
    if len(counts) < len(runs):
        return votes, None
    return votes, np.sum(counts, axis=0)


def _plot_discrete_policy(
    config: Config, q: np.ndarray, visits: np.ndarray | None, out: Path, title: str, force: bool
) -> Path:
    """Draw a Discrete policy as the environment's profile lays its states out.

    A grid world's cells, Blackjack's two panels, a Discrete state's components (Taxi: over
    the taxi's position), or a Tuple's components.
    """
    from cartpole_q.envs.models import grid_layout

    check_figure_file(out, "--out", force)
    profile = profile_for(config.env.id)
    layout = grid_layout(config.env) if profile.policy_map == "grid" else None
    actions = profile.names_actions(q.shape[-1])
    if layout is not None:
        grid = GridMap(layout.rows, layout.columns, layout.cells, layout.moves)
        figure = grid_policy_figure(q, visits, grid, title)
    elif profile.policy_map == "blackjack":
        figure = blackjack_policy_figure(q, visits, title)
    else:
        if profile.policy_map == "components" and math.prod(profile.state_components) == math.prod(
            q.shape[:-1]
        ):
            shape, names = profile.state_components, list(profile.component_names)
        elif q.ndim >= 3:
            shape = q.shape[:-1]
            names = profile.names_observations(q.ndim - 1)
            names = (
                names
                if profile.observation_names
                else [f"component {k}" for k in range(q.ndim - 1)]
            )
        else:
            raise UserError(
                f"--policy: no map for {config.env.id!r}: its observation is one Discrete "
                "whose layout its profile does not give (maps exist for grid worlds, "
                "Blackjack, Taxi and Tuple observations)."
            )
        table = q.reshape(*shape, q.shape[-1])
        counts = None if visits is None else visits.reshape(*shape, q.shape[-1])
        low = [-0.5] * len(shape)
        high = [size - 0.5 for size in shape]
        figure = policy_figure(
            table, counts, MapDimensions((0, 1), low, high, names), title, action_names=actions,
            rows_down=profile.rows_down,
        )  # fmt: skip
    return write_figure(out, figure)


def parse_dims(text: str, bins: Sequence[int]) -> tuple[int, int]:
    """Parse ``--dims`` such as ``2,3``.

    Raises:
        UserError: not two distinct dimension numbers of the grid.
    """
    parts = [part.strip() for part in text.split(",")]
    if len(parts) != 2 or not all(part.isdigit() for part in parts):
        raise UserError(f"--dims: expected two dimension numbers like 2,3, got {text!r}.")
    first, second = int(parts[0]), int(parts[1])
    if first == second or max(first, second) >= len(bins):
        raise UserError(
            f"--dims: expected two different dimensions between 0 and {len(bins) - 1}, got {text!r}."
        )
    return first, second
