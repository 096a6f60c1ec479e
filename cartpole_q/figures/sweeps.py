"""A sweep's own figures and ``compare``'s.

``sweep.png``: the statistics against the axes, the performance profiles.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from matplotlib.axes import Axes

from cartpole_q.figures.base import DPI, DataFigure, PanelData, colour_cycle, text_outline

SWEEP_PANEL_SIZE = (5.0, 4.2)
"""inches per panel of ``sweep.png``"""


PROFILE_MAX_POINTS = 10
"""the performance profile draws at most this many points (the best by IQM)"""


@dataclass(frozen=True)
class SweepAxis:
    """One axis of a sweep as drawn: its name and its values as ``results.csv`` cells."""

    name: str
    values: list[str]


def sweep_figure(
    title: str,
    axes: Sequence[SweepAxis],
    point_ids: Sequence[str],
    statistics: Sequence[dict[str, float | int | None]],
    eval_means: Sequence[np.ndarray],
    threshold: float | None,
) -> DataFigure:
    """``sweep.png``: success rate and median solve episode against the axes, and profiles.

    One axis: both statistics against it, with their 95% intervals as error bars. Two
    axes: a heatmap of each. More: both against the point id. A last panel draws the
    performance profiles (fraction of seeds whose greedy eval mean reaches each return) of
    up to :data:`PROFILE_MAX_POINTS` points, the best by IQM.

    Args:
        title: the sweep's name.
        axes: the axes, in point order (last fastest); the zip group counts as one.
        point_ids: the points' ids.
        statistics: each point's ``points.csv`` statistics (``None`` = missing).
        eval_means: each point's seeds' eval means.
        threshold: the reward threshold (marked on the profile), if any.
    """
    figure = DataFigure(figsize=(SWEEP_PANEL_SIZE[0] * 3, SWEEP_PANEL_SIZE[1]), dpi=DPI,
                        layout="constrained")  # fmt: skip
    rate_axes, solve_axes, profile_axes = figure.subplots(1, 3)
    rate = _column(statistics, "success_rate")
    solve = _column(statistics, "median_solved_episode")
    if len(axes) == 2:
        shape = (len(axes[0].values), len(axes[1].values))
        _sweep_heatmap(figure, rate_axes, axes, rate.reshape(shape), "success rate", (0.0, 1.0))
        _sweep_heatmap(figure, solve_axes, axes, solve.reshape(shape), "median solve episode", None)
    else:
        if len(axes) == 1:
            labels, name = axes[0].values, axes[0].name
        else:
            labels, name = list(point_ids), "point"
        # Along one axis neighbouring points are neighbours; along the point ids of three or
        # more axes they are not, so no line joins them.
        joined = len(axes) == 1
        _sweep_errorbars(rate_axes, figure.data.panel("success rate"), labels, name,
                         statistics, "success_rate", "success rate", joined)  # fmt: skip
        rate_axes.set_ylim(-0.02, 1.02)
        _sweep_errorbars(solve_axes, figure.data.panel("median solve episode"), labels, name,
                         statistics, "median_solved_episode",
                         "median solve episode (solved seeds)", joined)  # fmt: skip
    iqm = _column(statistics, "iqm_eval_return")
    order = [i for i in np.argsort(-np.nan_to_num(iqm, nan=-np.inf), kind="stable")
             if eval_means[i].size][:PROFILE_MAX_POINTS]  # fmt: skip
    draw_profiles(
        profile_axes,
        figure.data.panel("performance profiles"),
        [eval_means[i] for i in order],
        [f"point {point_ids[i]}" for i in order],
        threshold,
        "greedy eval mean return τ",
    )
    profile_axes.set_title(
        "performance profiles" + (" (best by IQM)" if len(point_ids) > len(order) else "")
    )
    figure.suptitle(f"Sweep {title}: 95% intervals (Wilson; bootstrap over seeds)")
    return figure


def prediction_sweep_figure(
    title: str,
    axes: Sequence[SweepAxis],
    point_ids: Sequence[str],
    statistics: Sequence[dict[str, float | int | None]],
) -> DataFigure:
    """``sweep.png`` of a prediction sweep: each point's final RMS error against the axes.

    The mean over seeds of the RMS error after the last episode, with its 95% bootstrap
    interval as error bars; two axes: a heatmap. More: against the point id.

    Args:
        title: the sweep's name.
        axes: the axes, in point order (last fastest); the zip group counts as one.
        point_ids: the points' ids.
        statistics: each point's ``points.csv`` statistics (``None`` = missing).
    """
    figure = DataFigure(figsize=(SWEEP_PANEL_SIZE[0] * 1.5, SWEEP_PANEL_SIZE[1]), dpi=DPI,
                        layout="constrained")  # fmt: skip
    panel = figure.subplots(1, 1)
    label = "RMS error after the last episode"
    if len(axes) == 2:
        shape = (len(axes[0].values), len(axes[1].values))
        values = _column(statistics, "mean_rms_error").reshape(shape)
        _sweep_heatmap(figure, panel, axes, values, label, None, digits=3)
    else:
        labels, name = (
            (axes[0].values, axes[0].name) if len(axes) == 1 else (list(point_ids), "point")
        )
        # points joined by a line only along one numeric axis (not categories, not ids)
        joined = len(axes) == 1 and _numeric(labels) is not None
        _sweep_errorbars(panel, figure.data.panel(label), labels, name, statistics,
                         "mean_rms_error", label, joined)  # fmt: skip
        panel.set_ylim(bottom=0.0)
    figure.suptitle(f"Sweep {title}: mean over seeds, 95% bootstrap intervals")
    return figure


def profile_thresholds(
    scores: Sequence[np.ndarray], threshold: float | None = None, count: int = 200
) -> np.ndarray:
    """The thresholds ``τ`` a performance profile is drawn over.

    From below the lowest score to above the highest (the threshold included), with a
    margin, so that every step is visible, also when every seed has the same score.

    >>> taus = profile_thresholds([np.array([500.0, 500.0])])
    >>> bool(taus[0] < 500.0 < taus[-1])
    True
    """
    every = np.concatenate([np.asarray(s, dtype=np.float64) for s in scores] or [np.zeros(0)])
    points = [*every.tolist(), *([] if threshold is None else [threshold])]
    if not points:
        return np.linspace(0.0, 1.0, count)
    low, high = min(points), max(points)
    margin = 0.05 * (high - low) or max(1.0, 0.05 * abs(high))
    return np.linspace(low - margin, high + margin, count)


def draw_profiles(
    axes: Axes,
    record: PanelData,
    scores: Sequence[np.ndarray],
    labels: Sequence[str],
    threshold: float | None,
    xlabel: str,
) -> None:
    """Performance profiles: the fraction of seeds scoring at least ``τ``, per run or point.

    Drawn as steps (each value holds until the next ``τ``); ``record`` gets the points.
    """
    taus = profile_thresholds(scores, threshold)
    for colour, values, label in zip(colour_cycle(len(scores)), scores, labels, strict=True):
        fraction = (np.asarray(values)[:, None] >= taus[None, :]).mean(axis=0)
        axes.step(taus, fraction, where="post", color=colour, label=label)
        record.line(label, taus, fraction)
    if threshold is not None:
        axes.axvline(threshold, color="grey", linestyle="--", label=f"threshold {threshold:g}")
        record.mark("threshold", threshold)
    axes.set_ylim(-0.02, 1.02)
    axes.set_xlabel(xlabel)
    axes.set_ylabel("fraction of seeds ≥ τ")
    if labels or threshold is not None:  # (a prediction sweep's points have no scores)
        axes.legend(loc="lower left", fontsize="x-small")
    axes.grid(alpha=0.3)


def compare_figure(data: dict[str, Any], title: str) -> DataFigure:
    """The aggregate picture of several runs, as rliable draws it.

    IQM and optimality gap with 95% stratified-bootstrap intervals, and performance
    profiles.

    Args:
        data: from :func:`cartpole_q.experiments.compare.compare_figure_data`.
        title: the figure's title.
    """
    gaps = [gap for gap in data["gap"] if gap is not None]
    panels = 3 if gaps else 2
    height = max(SWEEP_PANEL_SIZE[1], 1.0 + 0.45 * len(data["labels"]))
    figure = DataFigure(figsize=(SWEEP_PANEL_SIZE[0] * panels, height), dpi=DPI,
                        layout="constrained")  # fmt: skip
    axes = figure.subplots(1, panels)
    rows = np.arange(len(data["labels"]))[::-1]
    colours = colour_cycle(len(data["labels"]))
    iqm_title = "IQM (higher is better)" if data["higher_is_better"] else "IQM (lower is better)"
    _interval_rows(axes[0], figure.data.panel(iqm_title), rows, data["iqm"], colours,
                   data["labels"])  # fmt: skip
    axes[0].set_title(iqm_title)
    axes[0].set_xlabel(data["metric"])
    if gaps:
        gap_title = f"optimality gap below {data['target']:g} (lower is better)"
        _interval_rows(axes[1], figure.data.panel(gap_title), rows, data["gap"], colours,
                       data["labels"])  # fmt: skip
        axes[1].set_title(gap_title)
        axes[1].set_xlabel("mean shortfall per seed")
    draw_profiles(axes[-1], figure.data.panel("performance profiles"), data["values"],
                  data["labels"], data["target"], data["metric"] + " τ")  # fmt: skip
    axes[-1].set_title("performance profiles")
    figure.suptitle(f"{title}: 95% stratified-bootstrap intervals over seeds")
    return figure


def _interval_rows(
    axes: Axes,
    record: PanelData,
    rows: np.ndarray,
    figures: Sequence[tuple[float, float, float] | None],
    colours: Sequence[tuple[float, ...]],
    labels: Sequence[str],
) -> None:
    """One horizontal interval per run, its point estimate marked.

    Drawn sideways: ``record`` gets, per run, a row whose ``x`` is the run's label and whose
    ``y``, ``y_low`` and ``y_high`` are its estimate and interval.
    """
    for row, item, colour, label in zip(rows, figures, colours, labels, strict=True):
        if item is None or not np.isfinite(item[0]):
            continue
        value, low, high = item
        record.line(label, [label], [value], [low], [high])
        axes.plot([low, high], [row, row], color=colour, linewidth=6, alpha=0.45,
                  solid_capstyle="butt")  # fmt: skip
        axes.plot([value], [row], marker="|", color="black", markersize=14)
    axes.set_yticks(rows, labels, fontsize="small")
    axes.set_ylim(-0.7, len(rows) - 0.3)
    axes.grid(axis="x", alpha=0.3)


def _column(statistics: Sequence[dict[str, float | int | None]], name: str) -> np.ndarray:
    values = [row[name] for row in statistics]
    return np.array([np.nan if value is None else float(value) for value in values])


def _numeric(labels: Sequence[str]) -> np.ndarray | None:
    """The labels as numbers, when every one is a number."""
    try:
        return np.array([float(label) for label in labels])
    except ValueError:
        return None


def _sweep_errorbars(
    axes: Axes,
    record: PanelData,
    labels: Sequence[str],
    name: str,
    statistics: Sequence[dict[str, float | int | None]],
    column: str,
    ylabel: str,
    joined: bool = True,
) -> None:
    values = _column(statistics, column)
    low = _column(statistics, f"{column}_low")
    high = _column(statistics, f"{column}_high")
    numbers = _numeric(labels)
    positions = numbers if numbers is not None else np.arange(len(labels), dtype=float)
    errors = np.vstack([np.clip(values - low, 0, None), np.clip(high - values, 0, None)])
    axes.errorbar(positions, values, yerr=np.nan_to_num(errors), marker="o", capsize=4,
                  linestyle="-" if joined else "none")  # fmt: skip
    # x as the axis's values are written in points.csv (a number, or a category's name)
    record.line(ylabel, labels, values, low, high)
    if numbers is None:
        axes.set_xticks(positions, labels, rotation=30, ha="right", fontsize="small")
    elif np.all(numbers > 0) and numbers.max() / numbers.min() >= 100:
        axes.set_xscale("log")
    axes.set_xlabel(name)
    axes.set_ylabel(ylabel)
    axes.grid(alpha=0.3)


def _sweep_heatmap(
    figure: DataFigure,
    axes: Axes,
    sweep_axes: Sequence[SweepAxis],
    values: np.ndarray,
    label: str,
    limits: tuple[float, float] | None,
    digits: int | None = None,
) -> None:
    """A heatmap of one statistic: first axis down, second across, each cell annotated.

    Each cell's text has ``digits`` decimals (default: 2 for a statistic with ``limits``,
    else 0).
    """
    digits = digits if digits is not None else 2 if limits else 0
    masked = np.ma.masked_invalid(values)
    cmap = "viridis" if limits is not None else "viridis_r"
    vmin, vmax = limits if limits is not None else (None, None)
    image = axes.imshow(masked, cmap=cmap, vmin=vmin, vmax=vmax, aspect="auto")
    figure.colorbar(image, ax=axes, label=label)
    figure.data.panel(label).cells(label, sweep_axes[1].values, sweep_axes[0].values, masked)
    rows, columns = values.shape
    for i in range(rows):
        for j in range(columns):
            text = "—" if np.isnan(values[i, j]) else f"{values[i, j]:.{digits}f}"
            axes.text(j, i, text, ha="center", va="center", fontsize="small", color="white",
                      path_effects=text_outline())  # fmt: skip
    axes.set_xticks(range(columns), sweep_axes[1].values, rotation=30, ha="right", fontsize="small")
    axes.set_yticks(range(rows), sweep_axes[0].values, fontsize="small")
    axes.set_xlabel(sweep_axes[1].name)
    axes.set_ylabel(sweep_axes[0].name)
    axes.set_title(label)
