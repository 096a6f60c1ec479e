"""Learning curves.

Reward curves of runs and of seeds' bands, any metric's curves, and one summary per point
against an axis (Sutton & Barto Figure 12.10).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from matplotlib.axes import Axes

from cartpole_q.figures.base import (
    BOOTSTRAP_RESAMPLES,
    CURVE_SIZE,
    DPI,
    DRAWN_POINTS,
    DataFigure,
    PanelData,
    colour_cycle,
    drawn_points,
)
from cartpole_q.learning_curves import AGGREGATE_NAMES, aggregate_band, smooth
from cartpole_q.rl.solve import SOLVE_WINDOW


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
    seeds: Sequence[int] = ()
    """the seeds, in the order of ``returns`` (they name the data's series; default: none,
    the series are numbered ``run 1``, ``run 2``, ...)"""


CURVE_POINTS = 20_000
"""the most episodes a run's reward curve draws: a longer run's every ``stride``-th
(``ceil(episodes / CURVE_POINTS)``), its data likewise"""


def moving_average(values: np.ndarray, window: int = SOLVE_WINDOW) -> np.ndarray:
    """Trailing mean over the last ``window`` values (fewer at the start).

    >>> moving_average(np.array([1.0, 3.0, 5.0, 7.0]), window=2).tolist()
    [1.0, 2.0, 4.0, 6.0]
    """
    return smooth(values, window)


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
    return aggregate_band(curves, "mean", rng, resamples)


def reward_curve_figure(
    curves: Sequence[Curve | SeedBand], threshold: float | None, title: str = "Training reward"
) -> DataFigure:
    """Training returns: per run, the returns (faint) and their 100-episode moving average.

    A :class:`SeedBand` is drawn as its seeds' moving averages (faint), their mean, and a
    95% bootstrap confidence band, with the median solve episode marked. One dashed
    threshold line when the runs share their threshold (``threshold`` stands for a run
    without its own); otherwise each run's in its colour. An interrupted run says so in
    its legend entry.
    """
    figure = DataFigure(figsize=CURVE_SIZE, dpi=DPI, layout="constrained")
    draw_reward_curves(figure.add_subplot(), figure.data.panel(""), curves, threshold, title)
    return figure


def draw_reward_curves(
    axes: Axes,
    record: PanelData,
    curves: Sequence[Curve | SeedBand],
    threshold: float | None,
    title: str,
) -> None:
    """Draw runs' reward curves and seeds' bands on ``axes``, recording them."""
    colours = colour_cycle(len(curves))
    for item, colour in zip(curves, colours, strict=True):
        if isinstance(item, SeedBand):
            _draw_band(axes, record, item, colour)
            continue
        # A long run's curve is drawn at every stride-th episode (at most CURVE_POINTS
        # points): a million points are no clearer on a page and took seconds to draw and
        # write. The moving average is of every episode all the same.
        stride = max(1, math.ceil(len(item.returns) / CURVE_POINTS))
        episodes = np.arange(1, len(item.returns) + 1)[::stride]
        axes.plot(episodes, item.returns[::stride], color=colour, alpha=0.25, linewidth=0.8)
        record.line(f"{item.label}: return", episodes, item.returns[::stride])
        suffix = f" (solved at {item.solved_episode})" if item.solved_episode else ""
        if item.interrupted:
            suffix += f" (interrupted at episode {len(item.returns)})"
        average = moving_average(item.returns)[::stride]
        axes.plot(episodes, average, color=colour, linewidth=2.0,
                  label=f"{item.label}{suffix}")  # fmt: skip
        record.line(f"{item.label}: {SOLVE_WINDOW}-episode average", episodes, average)
        if item.solved_episode:
            axes.axvline(item.solved_episode, color=colour, linestyle=":", linewidth=1.0)
            record.mark(f"{item.label}: solved", item.solved_episode)
    thresholds = [threshold if item.threshold is None else item.threshold for item in curves]
    if len(set(thresholds)) == 1:
        shared = thresholds[0]
        if shared is not None:
            axes.axhline(shared, color="black", linestyle="--", linewidth=1.0,
                         label=f"reward threshold {shared:g}")  # fmt: skip
            record.level("reward threshold", shared)
    else:
        for item, colour, own in zip(curves, colours, thresholds, strict=True):
            if own is not None:
                axes.axhline(own, color=colour, linestyle="--", linewidth=1.0,
                             label=f"{item.label}: reward threshold {own:g}")  # fmt: skip
                record.level(f"{item.label}: reward threshold", own)
    axes.set_xlabel("training episode")
    # A short axis label: a long one (what bold and faint mean) would be cut at the figure's
    # edge, so that goes under the title instead.
    axes.set_ylabel("return")
    axes.set_title(f"{title}\n{_return_label(curves)}", fontsize="medium")
    axes.grid(alpha=0.3)
    axes.legend(loc="best", fontsize="small")


@dataclass(frozen=True)
class MetricBand:
    """One run set's learning curve of a metric: per seed, and aggregated with a band."""

    label: str
    x: np.ndarray
    per_seed: np.ndarray
    """``(seeds, len(x))``, NaN where a seed has no value"""
    centre: np.ndarray
    low: np.ndarray
    high: np.ndarray
    aggregate: str
    """``mean`` or ``iqm``"""
    seeds: Sequence[int] = ()
    """the seeds of ``per_seed``'s rows (they name the data's series; default: none, the
    series are numbered ``run 1``, ``run 2``, ...)"""


def metric_curve_figure(
    bands: Sequence[MetricBand],
    x_label: str,
    y_label: str,
    title: str,
    log_y: bool = False,
    reference: tuple[float, str] | None = None,
    y_limits: tuple[float | None, float | None] = (None, None),
    log_x: bool = False,
    most: int | None = DRAWN_POINTS,
) -> DataFigure:
    """Learning curves of any metric: each seed faint, the aggregate bold, a 95% band.

    One run (a single seed) is drawn as its line alone. ``reference`` is a dashed
    horizontal line and its legend label (an optimum, the book's figure); ``y_limits`` the
    y axis's ends (``None``: automatic). A band of more than ``most`` points is drawn at
    ``most`` of them (:func:`drawn_points`, log-spaced on a log x axis).
    """
    figure = DataFigure(figsize=CURVE_SIZE, dpi=DPI, layout="constrained")
    axes = figure.add_subplot()
    record = figure.data.panel("")
    for whole, colour in zip(bands, colour_cycle(len(bands)), strict=True):
        kept = drawn_points(len(whole.x), log_x, most)
        band = dataclasses.replace(
            whole, x=whole.x[kept], per_seed=whole.per_seed[:, kept], centre=whole.centre[kept],
            low=whole.low[kept], high=whole.high[kept],
        )  # fmt: skip
        seeds = band.per_seed.shape[0]
        if seeds == 1:
            axes.plot(band.x, band.centre, color=colour, linewidth=1.6, label=band.label)
            record.line(band.label, band.x, band.centre)
            continue
        if seeds <= 50:  # more faint lines only grey the figure
            for name, row in zip(_run_names(band.seeds, seeds), band.per_seed, strict=True):
                axes.plot(band.x, row, color=colour, alpha=0.12, linewidth=0.6)
                record.line(f"{band.label}: {name}", band.x, row)
        axes.fill_between(band.x, band.low, band.high, color=colour, alpha=0.3, linewidth=0)
        name = AGGREGATE_NAMES[band.aggregate]
        axes.plot(band.x, band.centre, color=colour, linewidth=2.0,
                  label=f"{band.label}: {name} of {seeds} seeds, 95% CI")  # fmt: skip
        record.line(f"{band.label}: {name}", band.x, band.centre, band.low, band.high)
    if reference is not None:
        axes.axhline(reference[0], color="black", linestyle="--", linewidth=1.0,
                     label=reference[1])  # fmt: skip
        record.level(reference[1], reference[0])
    if log_y:
        axes.set_yscale("log")
    if log_x:
        axes.set_xscale("log")
    if y_limits != (None, None):
        axes.set_ylim(*y_limits)
    axes.set_xlabel(x_label)
    axes.set_ylabel(y_label)
    axes.set_title(title, fontsize="medium")
    axes.grid(alpha=0.3, which="both" if log_y or log_x else "major")
    axes.legend(loc="best", fontsize="small")
    return figure


def summary_line_figure(
    lines: Sequence[tuple[str, Sequence[float], np.ndarray, np.ndarray, np.ndarray]],
    x_label: str,
    y_label: str,
    title: str,
    log_y: bool = False,
    y_limits: tuple[float | None, float | None] = (None, None),
    second: tuple[str, Sequence[float], np.ndarray] | None = None,
    line_styles: Sequence[tuple[int, bool]] | None = None,
    x_names: Mapping[float, str] | None = None,
) -> DataFigure:
    """One summary per point against an axis: a line per group, a 95% band (S&B Fig. 12.10).

    Each line is ``(label, xs, centre, low, high)``; ``y_limits`` fixes either end of the y
    axis (the book's range: Figure 7.2's 0.25 to 0.55 leaves the large errors off the top).
    Lines of more than 100 points are drawn without markers. ``second`` is ``(label, xs,
    ys)``, drawn shaded on a second y axis at the right (Figure 9.1's on-policy distribution).
    ``line_styles`` gives each line ``(colour index, dashed)`` (Figure 6.3: a colour per
    algorithm, interim dashed); by default each line has its own colour, solid.
    ``x_names`` names the x ticks (Example 6.2's states A-E): a tick at each named x.
    """
    figure = DataFigure(figsize=CURVE_SIZE, dpi=DPI, layout="constrained")
    axes = figure.add_subplot()
    record = figure.data.panel("")
    if x_names:
        axes.set_xticks(list(x_names), list(x_names.values()))
    if second is not None:
        label, xs, ys = second
        right = axes.twinx()
        right.fill_between(xs, 0.0, ys, color="0.6", alpha=0.35, linewidth=0, step="mid")
        right.set_ylim(0.0, float(np.max(ys)) * 1.05)
        right.set_ylabel(label)
        axes.set_zorder(right.get_zorder() + 1)  # the lines above the shading
        axes.patch.set_visible(False)
        record.line(label, xs, ys)
    if line_styles is None:
        line_styles = [(index, False) for index in range(len(lines))]
    palette = colour_cycle(max((index for index, _ in line_styles), default=-1) + 1)
    for (label, xs, centre, low, high), (index, dashed) in zip(lines, line_styles, strict=True):
        colour = palette[index]
        axes.fill_between(xs, low, high, color=colour, alpha=0.25, linewidth=0)
        marker = {"marker": "o", "markersize": 3} if len(xs) <= 100 else {}
        axes.plot(xs, centre, color=colour, linewidth=1.8, label=label,
                  linestyle="--" if dashed else "-", **marker)  # type: ignore[arg-type]  # fmt: skip
        record.line(label, xs, centre, low, high)
    if log_y:
        axes.set_yscale("log")
    if y_limits != (None, None):
        axes.set_ylim(*y_limits)
    axes.set_xlabel(x_label)
    axes.set_ylabel(y_label)
    axes.set_title(title, fontsize="medium")
    axes.grid(alpha=0.3)
    axes.legend(loc="best", fontsize="small")
    return figure


@dataclass(frozen=True)
class ValueChanges:
    """One panel of :func:`value_changes_figure`: a run's values before and after, by state."""

    label: str
    """the point's label (its algorithm, say)"""
    before: np.ndarray
    """``V`` before the run, one value per state drawn"""
    after: np.ndarray
    """``V`` after the run (the mean over seeds), one value per state drawn"""


def value_changes_figure(
    panels: Sequence[ValueChanges],
    states: Sequence[float],
    truth: np.ndarray,
    names: Mapping[float, str] | None,
    y_label: str,
    title: str,
) -> DataFigure:
    """The change each run makes to each state's value, as arrows (Sutton & Barto Figure 6.1).

    One panel per point, side by side: the values before the run joined by a line, an
    arrow from each to its value after the run (none where it did not move), and the true
    values dashed (driving home's actual times to go).
    """
    figure = DataFigure(figsize=(CURVE_SIZE[0] * 0.75 * len(panels), CURVE_SIZE[1]), dpi=DPI,
                        layout="constrained")  # fmt: skip
    grid = figure.subplots(1, len(panels), sharey=True, squeeze=False)[0]
    for axes, panel in zip(grid, panels, strict=True):
        record = figure.data.panel(panel.label)
        axes.plot(states, panel.before, color="0.25", marker="o", markersize=4, linewidth=1.5,
                  label="before the run")  # fmt: skip
        axes.plot(states, truth, color="0.5", linestyle="--", linewidth=1.2, label="true values")
        for x, start, end in zip(states, panel.before, panel.after, strict=True):
            if end != start:
                axes.annotate("", xy=(x, end), xytext=(x, start),
                              arrowprops={"arrowstyle": "-|>", "color": "tab:red", "lw": 1.8})  # fmt: skip
        axes.plot(states, panel.after, linestyle="none", marker="_", markersize=12,
                  color="tab:red", label="after the run")  # fmt: skip
        record.line("before the run", states, panel.before)
        record.line("after the run", states, panel.after)
        record.line("true values", states, truth)
        if names:
            axes.set_xticks(list(names), list(names.values()), rotation=30, ha="right")
        axes.set_title(panel.label, fontsize="medium")
        axes.set_xlabel("state")
        axes.grid(alpha=0.3)
    grid[0].set_ylabel(y_label)
    grid[0].legend(loc="best", fontsize="small")
    figure.suptitle(title, fontsize="medium")
    return figure


def _return_label(curves: Sequence[Curve | SeedBand]) -> str:
    bands = sum(isinstance(item, SeedBand) for item in curves)
    average = f"{SOLVE_WINDOW}-episode average"
    if bands == 0:
        return f"return (faint: each episode; bold: {average})"
    if bands == len(curves):
        return f"return, {average} (faint: each seed; bold: mean of seeds)"
    return f"return (bold: {average}, of a run or mean of seeds; faint: episodes or seeds)"


def _draw_band(axes: Axes, record: PanelData, band: SeedBand, colour: tuple[float, ...]) -> None:
    length = max(len(r) for r in band.returns)
    curves = np.full((len(band.returns), length), np.nan)
    for i, returns in enumerate(band.returns):
        curves[i, : len(returns)] = moving_average(returns)
        # A run that stopped when solved keeps its last average for the rest of the plot.
        if len(returns):
            curves[i, len(returns) :] = curves[i, len(returns) - 1]
    episodes = np.arange(1, length + 1)
    for name, row in zip(_run_names(band.seeds, len(curves)), curves, strict=True):
        axes.plot(episodes, row, color=colour, alpha=0.12, linewidth=0.6)
        record.line(f"{band.label}: {name}", episodes, row)
    mean, low, high = bootstrap_band(curves, np.random.default_rng(0))
    solved = [s for s in band.solved_episodes if s is not None]
    note = f", median solve {np.median(solved):g}" if solved else ""
    if band.interrupted:
        note += f", {band.interrupted} interrupted"
    axes.fill_between(episodes, low, high, color=colour, alpha=0.3, linewidth=0)
    axes.plot(episodes, mean, color=colour, linewidth=2.0,
              label=f"{band.label}: mean of {len(curves)} seeds, 95% CI{note}")  # fmt: skip
    record.line(f"{band.label}: mean", episodes, mean, low, high)
    if solved:
        median = float(np.median(solved))
        axes.axvline(median, color=colour, linestyle=":", linewidth=1.2)
        record.mark(f"{band.label}: median solve episode", median)


def _run_names(seeds: Sequence[int], count: int) -> list[str]:
    """Each seed's series name: ``seed 3`` when the seeds are known, else ``run 1``, ...

    >>> _run_names([3, 7], 2), _run_names([], 2)
    (['seed 3', 'seed 7'], ['run 1', 'run 2'])
    """
    if len(seeds) == count:
        return [f"seed {seed}" for seed in seeds]
    return [f"run {number}" for number in range(1, count + 1)]
