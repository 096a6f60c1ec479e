"""Figures, drawn with matplotlib's object API (no pyplot state) on the Agg canvas.

The ``*_figure`` functions take arrays and return a :class:`matplotlib.figure.Figure`;
:func:`plot_rewards` and :func:`plot_policy` are what ``cartpole-q plot`` runs: they load
run directories, draw, and write the figure (PNG, SVG or PDF) atomically.
"""

from __future__ import annotations

import io
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import BoundaryNorm, ListedColormap, LogNorm
from matplotlib.figure import Figure

from cartpole_q.rl.solve import SOLVE_WINDOW

DPI = 100
CURVE_SIZE = (8.0, 4.5)
"""inches; at 100 dpi a reward curve is 800 x 450 pixels"""
POLICY_SIZE = (13.5, 4.2)
"""inches; at 100 dpi a policy map is 1350 x 420 pixels"""
BOOTSTRAP_RESAMPLES = 1000
FIGURE_FORMATS = {".png": "png", ".svg": "svg", ".pdf": "pdf"}
"""the extensions ``plot --out`` writes, and matplotlib's format for each"""
DIMENSION_NAMES = {
    "CartPole": (
        "cart position (m)",
        "cart velocity (m/s)",
        "pole angle (rad)",
        "pole angular velocity (rad/s)",
    ),
    "MountainCar": ("position", "velocity"),
    "Acrobot": (
        "cos θ1",
        "sin θ1",
        "cos θ2",
        "sin θ2",
        "θ1 velocity (rad/s)",
        "θ2 velocity (rad/s)",
    ),
}
"""observation names of the known environments, by the id's name before ``-v``"""
ACTION_NAMES = {
    "CartPole": ("push left", "push right"),
    "MountainCar": ("accelerate left", "don't accelerate", "accelerate right"),
    "Acrobot": ("torque -1", "torque 0", "torque +1"),
}
"""what each action does in the known environments"""


@dataclass(frozen=True)
class Curve:
    """One run's training returns, as drawn on a reward-curve figure."""

    label: str
    returns: np.ndarray
    solved_episode: int | None = None
    threshold: float | None = None
    """its reward threshold (``None``: the figure's)"""
    interrupted: bool = False
    """training was stopped before its configured episodes"""


@dataclass(frozen=True)
class SeedBand:
    """Several seeds' training returns, drawn as a mean with a confidence band."""

    label: str
    returns: list[np.ndarray]
    solved_episodes: list[int | None]
    threshold: float | None = None
    """the seeds' reward threshold (``None``: the figure's)"""
    interrupted: int = 0
    """how many of the seeds were stopped before their configured episodes"""


def moving_average(values: np.ndarray, window: int = SOLVE_WINDOW) -> np.ndarray:
    """Trailing mean over the last ``window`` values (fewer at the start).

    >>> moving_average(np.array([1.0, 3.0, 5.0, 7.0]), window=2).tolist()
    [1.0, 2.0, 4.0, 6.0]
    """
    values = np.asarray(values, dtype=np.float64)
    if values.size == 0:
        return values
    cumulative = np.concatenate([[0.0], np.cumsum(values)])
    index = np.arange(1, values.size + 1)
    start = np.maximum(index - window, 0)
    return np.asarray((cumulative[index] - cumulative[start]) / (index - start))


def bootstrap_band(
    curves: np.ndarray, rng: np.random.Generator, resamples: int = BOOTSTRAP_RESAMPLES
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Mean over seeds per episode and its 95% percentile-bootstrap confidence band.

    Args:
        curves: ``(n_seeds, n_episodes)``; NaN where a seed has no value (it stopped).
        rng: the generator that draws the resamples.
        resamples: bootstrap resamples.

    Returns:
        ``(mean, low, high)``, each of length ``n_episodes``.
    """
    n_seeds = curves.shape[0]
    mean = np.nanmean(curves, axis=0)
    picks = rng.integers(0, n_seeds, size=(resamples, n_seeds))
    resampled = np.nanmean(curves[picks], axis=1)
    low, high = np.nanpercentile(resampled, [2.5, 97.5], axis=0)
    return mean, low, high


def reward_curve_figure(
    curves: Sequence[Curve | SeedBand], threshold: float | None, title: str = "Training reward"
) -> Figure:
    """Training returns: per run, the returns (faint) and their 100-episode moving average.

    A :class:`SeedBand` is drawn as its seeds' moving averages (faint), their mean, and a
    95% bootstrap confidence band, with the median solve episode marked. One dashed
    threshold line when the runs share their threshold (``threshold`` stands for a run
    without its own); otherwise each run's in its colour. An interrupted run says so in
    its legend entry.
    """
    figure = Figure(figsize=CURVE_SIZE, dpi=DPI, layout="constrained")
    axes = figure.add_subplot()
    colours = _colours(len(curves))
    for item, colour in zip(curves, colours, strict=True):
        if isinstance(item, SeedBand):
            _draw_band(axes, item, colour)
            continue
        episodes = np.arange(1, len(item.returns) + 1)
        axes.plot(episodes, item.returns, color=colour, alpha=0.25, linewidth=0.8)
        suffix = f" (solved at {item.solved_episode})" if item.solved_episode else ""
        if item.interrupted:
            suffix += f" (interrupted at episode {len(item.returns)})"
        axes.plot(episodes, moving_average(item.returns), color=colour, linewidth=2.0,
                  label=f"{item.label}{suffix}")  # fmt: skip
        if item.solved_episode:
            axes.axvline(item.solved_episode, color=colour, linestyle=":", linewidth=1.0)
    thresholds = [threshold if item.threshold is None else item.threshold for item in curves]
    if len(set(thresholds)) == 1:
        shared = thresholds[0]
        if shared is not None:
            axes.axhline(shared, color="black", linestyle="--", linewidth=1.0,
                         label=f"reward threshold {shared:g}")  # fmt: skip
    else:
        for item, colour, own in zip(curves, colours, thresholds, strict=True):
            if own is not None:
                axes.axhline(own, color=colour, linestyle="--", linewidth=1.0,
                             label=f"{item.label}: reward threshold {own:g}")  # fmt: skip
    axes.set_xlabel("training episode")
    axes.set_ylabel(_return_label(curves))
    axes.set_title(title)
    axes.grid(alpha=0.3)
    axes.legend(loc="best", fontsize="small")
    return figure


def _return_label(curves: Sequence[Curve | SeedBand]) -> str:
    bands = sum(isinstance(item, SeedBand) for item in curves)
    average = f"{SOLVE_WINDOW}-episode average"
    if bands == 0:
        return f"return (faint: each episode; bold: {average})"
    if bands == len(curves):
        return f"return, {average} (faint: each seed; bold: mean of seeds)"
    return f"return (bold: {average}, of a run or mean of seeds; faint: episodes or seeds)"


def _draw_band(axes: object, band: SeedBand, colour: tuple[float, ...]) -> None:
    length = max(len(r) for r in band.returns)
    curves = np.full((len(band.returns), length), np.nan)
    for i, returns in enumerate(band.returns):
        curves[i, : len(returns)] = moving_average(returns)
        # A run that stopped when solved keeps its last average for the rest of the plot.
        if len(returns):
            curves[i, len(returns) :] = curves[i, len(returns) - 1]
    episodes = np.arange(1, length + 1)
    for row in curves:
        axes.plot(episodes, row, color=colour, alpha=0.12, linewidth=0.6)  # type: ignore[attr-defined]
    mean, low, high = bootstrap_band(curves, np.random.default_rng(0))
    solved = [s for s in band.solved_episodes if s is not None]
    note = f", median solve {np.median(solved):g}" if solved else ""
    if band.interrupted:
        note += f", {band.interrupted} interrupted"
    axes.fill_between(episodes, low, high, color=colour, alpha=0.3, linewidth=0)  # type: ignore[attr-defined]
    axes.plot(episodes, mean, color=colour, linewidth=2.0,  # type: ignore[attr-defined]
              label=f"{band.label}: mean of {len(curves)} seeds, 95% CI{note}")  # fmt: skip
    if solved:
        axes.axvline(float(np.median(solved)), color=colour, linestyle=":", linewidth=1.2)  # type: ignore[attr-defined]


def policy_figure(
    q_table: np.ndarray,
    visits: np.ndarray | None,
    dims: tuple[int, int],
    low: Sequence[float],
    high: Sequence[float],
    names: Sequence[str],
    title: str,
    action_names: Sequence[str] | None = None,
) -> Figure:
    """Greedy action, state value ``max_a Q`` and visit counts over two binned dimensions.

    The other dimensions are averaged out, weighted by how often training visited each
    state (uniformly where it never did); with one bin there, the maps are exact.
    States training never visited are shown blank. The greedy action has one colour per
    action, labelled ``"0: push left"`` and so on when ``action_names`` are given.
    """
    q_map, value_map, visit_map = project_policy(q_table, visits, dims)
    action_map = np.argmax(q_map, axis=-1).astype(float)
    unvisited = visit_map == 0 if visits is not None else np.zeros_like(value_map, dtype=bool)
    figure = Figure(figsize=POLICY_SIZE, dpi=DPI, layout="constrained")
    panels = figure.subplots(1, 3)
    d_row, d_col = dims
    extent = (low[d_col], high[d_col], low[d_row], high[d_row])
    n_actions = q_table.shape[-1]
    action_colours = ListedColormap(_action_colours(n_actions))
    action_norm = BoundaryNorm(np.arange(n_actions + 1) - 0.5, n_actions)
    # Visits span orders of magnitude (most time is spent near upright): log colour scale.
    visit_norm = LogNorm(vmin=1, vmax=max(float(visit_map.max()), 10.0))
    layers = (
        ("greedy action", np.ma.masked_where(unvisited, action_map), action_colours, action_norm),
        ("state value max_a Q", np.ma.masked_where(unvisited, value_map), "viridis", None),
        ("training visits (log scale)", np.ma.masked_where(visit_map == 0, visit_map), "magma", visit_norm),
    )  # fmt: skip
    for axes, (name, data, cmap, norm) in zip(panels, layers, strict=True):
        image = axes.imshow(data, origin="lower", aspect="auto", extent=extent, cmap=cmap,
                            norm=norm, interpolation="nearest")  # fmt: skip
        axes.set_title(name)
        axes.set_xlabel(names[d_col])
        axes.set_ylabel(names[d_row])
        bar = figure.colorbar(image, ax=axes)
        if name == "greedy action":
            bar.set_ticks(list(range(n_actions)))
            if action_names is not None and len(action_names) == n_actions:
                bar.set_ticklabels([f"{a}: {text}" for a, text in enumerate(action_names)])
            bar.minorticks_off()
    figure.suptitle(title)
    return figure


def _action_colours(count: int) -> list[tuple[float, ...]]:
    """Two actions: blue and red (left and right); more: evenly spread over coolwarm."""
    from matplotlib import colormaps

    palette = colormaps["coolwarm"]
    return (
        [tuple(palette(x)) for x in np.linspace(0.1, 0.9, count)] if count > 1 else [palette(0.1)]
    )


def project_policy(
    q_table: np.ndarray, visits: np.ndarray | None, dims: tuple[int, int]
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Reduce a ``(*bins, n_actions)`` table to the two chosen dimensions.

    Returns:
        ``(q, value, visits)`` with shapes ``(bins[d0], bins[d1], n_actions)``,
        ``(bins[d0], bins[d1])`` and ``(bins[d0], bins[d1])``: Q averaged over the other
        dimensions (weighted by state visits where there are any), ``max_a`` of it, and
        the visits summed.
    """
    n_dims = q_table.ndim - 1
    order = (*dims, *[d for d in range(n_dims) if d not in dims], n_dims)
    q = np.transpose(q_table, order).reshape(
        q_table.shape[dims[0]], q_table.shape[dims[1]], -1, q_table.shape[-1]
    )
    if visits is None:
        state_visits = np.zeros(q.shape[:3])
    else:
        state_visits = np.transpose(visits, order).reshape(q.shape).sum(axis=-1).astype(float)
    weights = np.where(state_visits.sum(axis=2, keepdims=True) > 0, state_visits, 1.0)
    weights = weights / weights.sum(axis=2, keepdims=True)
    q_map = np.einsum("ijk,ijka->ija", weights, q)
    return q_map, q_map.max(axis=-1), state_visits.sum(axis=2)


def figure_png(figure: Figure) -> bytes:
    """Render a figure to PNG bytes."""
    canvas = FigureCanvasAgg(figure)
    buffer = io.BytesIO()
    canvas.print_png(buffer)  # type: ignore[no-untyped-call]
    return buffer.getvalue()


def figure_bytes(figure: Figure, file_format: str) -> bytes:
    """Render a figure as ``png``, ``svg`` or ``pdf`` bytes."""
    if file_format == "png":
        return figure_png(figure)
    buffer = io.BytesIO()
    # The date would make every SVG or PDF of the same run differ.
    metadata = {"Date": None}
    figure.savefig(buffer, format=file_format, dpi=DPI, metadata=metadata)
    return buffer.getvalue()


def _colours(count: int) -> list[tuple[float, ...]]:
    from matplotlib import colormaps

    if count <= 10:
        palette = colormaps["tab10"]
        return [tuple(palette(i)) for i in range(count)]
    palette = colormaps["turbo"]
    return [tuple(palette(x)) for x in np.linspace(0.05, 0.95, count)]


def default_dims(bins: Sequence[int]) -> tuple[int, int]:
    """The two dimensions with the most bins, in order (later ones win ties).

    For CartPole's usual grids this is pole angle (2) and angular velocity (3).

    >>> default_dims([1, 3, 6, 12]), default_dims([10, 10, 10, 10])
    ((2, 3), (2, 3))
    """
    ranked = sorted(range(len(bins)), key=lambda d: (bins[d], d), reverse=True)
    first, second = sorted(ranked[:2])
    return first, second


def _known_environment(env_id: str) -> str:
    """The name of a Gymnasium id without namespace and version: ``CartPole-v1`` → ``CartPole``."""
    return env_id.rsplit("/", 1)[-1].split("-v")[0]


def dimension_names(env_id: str, n_dims: int) -> list[str]:
    """Axis names of the observation dimensions; ``observation N`` for unknown ones.

    >>> dimension_names("CartPole-v1", 4)[2], dimension_names("Other-v0", 2)
    ('pole angle (rad)', ['observation 0', 'observation 1'])
    """
    names = DIMENSION_NAMES.get(_known_environment(env_id))
    if names is not None and len(names) == n_dims:
        return list(names)
    return [f"observation {d}" for d in range(n_dims)]


def action_names(env_id: str, n_actions: int) -> list[str] | None:
    """What each action does, for the known environments.

    >>> action_names("MountainCar-v0", 3)[1], action_names("Other-v0", 2)
    ("don't accelerate", None)
    """
    names = ACTION_NAMES.get(_known_environment(env_id))
    return list(names) if names is not None and len(names) == n_actions else None


def robustness_figure(
    axes_values: Sequence[tuple[str, np.ndarray]],
    means: np.ndarray,
    trained: Sequence[float],
    threshold: float | None,
    title: str,
) -> Figure:
    """The greedy policy's mean return as one physics value (a curve) or two (a heatmap) vary.

    Args:
        axes_values: ``(key, values)`` per varied key (one or two).
        means: shape ``(seeds, *grid)``: each seed's mean return at each grid point; the
            median across seeds is drawn, with the interquartile range as a band (curve).
        trained: the value of each key the policy was trained with (marked).
        threshold: the solve threshold (a dashed line on a curve), if any.
        title: the figure's title.
    """
    figure = Figure(figsize=CURVE_SIZE, dpi=DPI, layout="constrained")
    axes = figure.add_subplot()
    median = np.median(means, axis=0)
    if len(axes_values) == 1:
        key, values = axes_values[0]
        if means.shape[0] > 1:
            low, high = np.percentile(means, [25, 75], axis=0)
            axes.fill_between(
                values, low, high, alpha=0.25, label=f"interquartile range, {means.shape[0]} seeds"
            )
            axes.plot(values, median, marker="o", label="median across seeds")
        else:
            axes.plot(values, median, marker="o", label="greedy mean return")
        axes.axvline(
            trained[0], color="black", linestyle=":", label=f"trained with {key} = {trained[0]:g}"
        )
        if threshold is not None:
            axes.axhline(threshold, color="grey", linestyle="--", label=f"threshold {threshold:g}")
        axes.set_xlabel(key)
        axes.set_ylabel("greedy mean return")
        axes.legend(loc="best", fontsize="small")
        axes.grid(alpha=0.3)
    else:
        (key_x, x), (key_y, y) = axes_values
        image = axes.pcolormesh(_edges(x), _edges(y), median.T, shading="flat", cmap="viridis")
        figure.colorbar(
            image,
            ax=axes,
            label="greedy mean return" + (" (median of seeds)" if means.shape[0] > 1 else ""),
        )
        axes.plot([trained[0]], [trained[1]], marker="*", markersize=14, color="red",
                  markeredgecolor="white", label="trained with")  # fmt: skip
        axes.set_xlabel(key_x)
        axes.set_ylabel(key_y)
        axes.legend(loc="upper right", fontsize="small")
    axes.set_title(title)
    return figure


def _edges(values: np.ndarray) -> np.ndarray:
    """Cell edges around grid values (midpoints; the outer ones mirrored)."""
    if len(values) == 1:
        return np.array([values[0] - 0.5, values[0] + 0.5])
    middle = (values[:-1] + values[1:]) / 2
    return np.concatenate([[2 * values[0] - middle[0]], middle, [2 * values[-1] - middle[-1]]])
