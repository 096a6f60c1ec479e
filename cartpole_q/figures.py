"""Figures, drawn with matplotlib's object API (no pyplot state) on the Agg canvas.

The ``*_figure`` functions take arrays and return a :class:`DataFigure`: a matplotlib figure
that carries the numbers it draws (:class:`FigureData`), recorded by the same code that
draws them, so that every figure file goes out with its data beside it (``<figure>.csv``,
see :mod:`cartpole_q.store.figure_file`). ``cartpole-q plot`` and the studies load run
directories, draw with these functions, and write both.
"""

from __future__ import annotations

import csv
import dataclasses
import io
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import BoundaryNorm, ListedColormap, LogNorm
from matplotlib.figure import Figure

from cartpole_q.families import profile_for
from cartpole_q.learning_curves import AGGREGATE_NAMES, aggregate_band, smooth
from cartpole_q.rl.solve import SOLVE_WINDOW

DPI = 100
CURVE_SIZE = (8.0, 4.5)
DRAWN_POINTS = 1_000
"""the most points a long line keeps along its x axis, drawn and in its data: a figure 8
inches wide at 100 dpi has 800 pixel columns, so more points draw nothing more (the full
record stays in the run or study directory; ``plot --all-points`` draws every point)"""
"""inches; at 100 dpi a reward curve is 800 x 450 pixels"""
POLICY_SIZE = (13.5, 4.2)
"""inches; at 100 dpi a policy map is 1350 x 420 pixels"""
BOOTSTRAP_RESAMPLES = 1000
FIGURE_FORMATS = {".png": "png", ".svg": "svg", ".pdf": "pdf"}
"""the extensions ``plot --out`` writes, and matplotlib's format for each"""


# -- the numbers a figure draws ------------------------------------------------------------

DATA_COLUMNS = ("panel", "series", "x", "y", "y_low", "y_high", "value")
"""the columns of a figure's data, ``<figure>.csv``"""

Cell = float | int | str | None
"""one value of a figure's data: a number, a category (a sweep axis's value), or nothing"""


class FigureData:
    """The numbers a figure draws, in the tidy long format of ``<figure>.csv``.

    One row per plotted point, columns :data:`DATA_COLUMNS`: the ``panel`` (its title; empty
    on a one-panel figure), the ``series`` (a curve, a band, a line or a map, named as its
    legend names it), the point's ``x`` and ``y``, the interval drawn around it (``y_low``,
    ``y_high``, empty where none is drawn); a coloured cell (a heatmap, a policy map) is a
    row with ``x``, ``y`` and its ``value``. A horizontal reference line is one row with an
    empty ``x``, a vertical one a row with an empty ``y``. Numbers are written with
    ``repr``, so they read back as the very floats drawn; a value not drawn (NaN, a masked
    cell) is an empty cell. Rows keep the order the figure draws them in.

    >>> data = FigureData()
    >>> data.panel("").line("mean", [1, 2], [0.5, float("nan")], low=[0.25, None], high=[1.0, None])
    >>> data.panel("").level("threshold", 475.0)
    >>> print(data.csv_text(), end="")
    panel,series,x,y,y_low,y_high,value
    ,mean,1,0.5,0.25,1.0,
    ,mean,2,,,,
    ,threshold,,475.0,,,
    """

    def __init__(self) -> None:
        self.rows: list[tuple[str, str, Cell, Cell, Cell, Cell, Cell]] = []

    def panel(self, name: str) -> PanelData:
        """A recorder for the panel titled ``name`` (``""``: the figure's only panel)."""
        return PanelData(self, name)

    def csv_text(self) -> str:
        """The rows as CSV text (Unix line ends), the header first."""
        buffer = io.StringIO()
        writer = csv.writer(buffer, lineterminator="\n")
        writer.writerow(DATA_COLUMNS)
        labels: dict[str, str] = {}

        def cell(value: Cell) -> str:
            # The common cells first, without _data_cell's checks: a long run's curve has
            # millions (a float64 is a float: its repr is the float's).
            kind = type(value)
            if kind is float or kind is np.float64:
                return float.__repr__(value) if value == value else ""
            if isinstance(value, str):
                if value not in labels:
                    labels[value] = _data_cell(value)
                return labels[value]
            return _data_cell(value)

        writer.writerows([cell(value) for value in row] for row in self.rows)
        return buffer.getvalue()


@dataclass(frozen=True)
class PanelData:
    """What one panel of a figure draws, recorded into its :class:`FigureData`."""

    data: FigureData
    name: str

    def line(
        self,
        series: str,
        x: Iterable[Cell],
        y: Iterable[Cell],
        low: Iterable[Cell] | None = None,
        high: Iterable[Cell] | None = None,
    ) -> None:
        """Points of a curve (a band's centre with its ``low`` and ``high`` edges), in order."""
        xs, ys = list(x), list(y)
        lows = [None] * len(xs) if low is None else list(low)
        highs = [None] * len(xs) if high is None else list(high)
        rows = zip(xs, ys, lows, highs, strict=True)
        self.data.rows.extend((self.name, series, a, b, c, d, None) for a, b, c, d in rows)

    def level(self, series: str, y: float) -> None:
        """A horizontal line at ``y`` (a threshold, a reference): ``x`` stays empty."""
        self.data.rows.append((self.name, series, None, y, None, None, None))

    def mark(self, series: str, x: float) -> None:
        """A vertical line at ``x`` (a solve episode, a trained value): ``y`` stays empty."""
        self.data.rows.append((self.name, series, x, None, None, None, None))

    def cells(self, series: str, x: Sequence[Cell], y: Sequence[Cell], values: np.ndarray) -> None:
        """A map: ``values[i, j]`` coloured at ``(x[j], y[i])``, row by row; masked: empty.

        Integer values (actions, counts) stay integers.
        """
        shown = np.ma.asarray(values)
        if shown.dtype.kind == "f":
            shown = np.ma.masked_invalid(shown)
        if shown.shape != (len(y), len(x)):
            raise ValueError(f"cells: values of shape {shown.shape} for {len(y)} x {len(x)}")
        mask = np.ma.getmaskarray(shown)
        for i, row_y in enumerate(y):
            for j, column_x in enumerate(x):
                value = None if mask[i, j] else shown.data[i, j].item()
                self.data.rows.append((self.name, series, column_x, row_y, None, None, value))


def _data_cell(value: Cell) -> str:
    """A value as a CSV cell: floats round-trip (``repr``), NaN and ``None`` are empty.

    Text is written as the figure draws it (:func:`drawable`: an undecodable file name's
    bytes become U+FFFD), so the data is UTF-8 whatever the directory's name.

    >>> _data_cell(0.1), _data_cell(np.float64(2.5)), _data_cell(np.int64(3)), _data_cell(None)
    ('0.1', '2.5', '3', '')
    >>> _data_cell(float("nan")), _data_cell("0.5")
    ('', '0.5')
    """
    if value is None:
        return ""
    if isinstance(value, str):  # a label naming a directory: as the figure draws it
        return drawable(value)
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    number = float(value)
    return "" if np.isnan(number) else repr(number)


class DataFigure(Figure):
    """A matplotlib figure that carries the numbers it draws (``data``), for its ``.csv``."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.data = FigureData()


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


def drawn_points(count: int, log: bool = False, most: int | None = DRAWN_POINTS) -> np.ndarray:
    """The indices of a line's ``count`` points that are drawn, and written as its data.

    Every point when there are at most ``most`` (or ``most`` is ``None``); else ``most``
    evenly spaced along the axis, log-spaced on a log axis (whose x are 1, 2, ..., as
    episodes are), the first and the last always kept.

    >>> drawn_points(5).tolist(), drawn_points(10, most=4).tolist()
    ([0, 1, 2, 3, 4], [0, 3, 6, 9])
    >>> drawn_points(100_000, log=True)[:12].tolist(), int(drawn_points(100_000, log=True)[-1])
    ([0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11], 99999)
    """
    if most is None or count <= most:
        return np.arange(count)
    spaced = np.geomspace(1.0, count, most) if log else np.linspace(1.0, count, most)
    return np.unique(np.rint(spaced).astype(np.int64)) - 1


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
    _draw_reward_curves(figure.add_subplot(), figure.data.panel(""), curves, threshold, title)
    return figure


def _draw_reward_curves(
    axes: Axes,
    record: PanelData,
    curves: Sequence[Curve | SeedBand],
    threshold: float | None,
    title: str,
) -> None:
    colours = _colours(len(curves))
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
    for whole, colour in zip(bands, _colours(len(bands)), strict=True):
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
    palette = _colours(max((index for index, _ in line_styles), default=-1) + 1)
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


def policy_figure(
    q_table: np.ndarray,
    visits: np.ndarray | None,
    dims: tuple[int, int],
    low: Sequence[float],
    high: Sequence[float],
    names: Sequence[str],
    title: str,
    action_names: Sequence[str] | None = None,
    value_name: str = "state value max_a Q",
    rows_down: bool = False,
) -> DataFigure:
    """Greedy action, state value ``max_a Q`` and visit counts over two binned dimensions.

    The other dimensions are averaged out, weighted by how often training visited each
    state (uniformly where it never did); with one bin there, the maps are exact.
    States training never visited are shown blank. The greedy action has one colour per
    action, labelled ``"0: push left"`` and so on when ``action_names`` are given.
    ``rows_down`` draws the first dimension downwards (a grid world's rows, as Taxi).
    """
    q_map, value_map, visit_map = project_policy(q_table, visits, dims)
    actions = np.argmax(q_map, axis=-1)
    action_map = actions.astype(float)
    unvisited = visit_map == 0 if visits is not None else np.zeros_like(value_map, dtype=bool)
    figure = DataFigure(figsize=POLICY_SIZE, dpi=DPI, layout="constrained")
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
        (value_name, np.ma.masked_where(unvisited, value_map), "viridis", None),
        ("training visits (log scale)", np.ma.masked_where(visit_map == 0, visit_map), "magma", visit_norm),
    )  # fmt: skip
    # The data: each cell at its centre; actions and visits as the integers they are.
    columns = _centres(extent[0], extent[1], action_map.shape[1])
    rows = _centres(extent[2], extent[3], action_map.shape[0])
    recorded = (
        ("action", np.ma.masked_where(unvisited, actions)),
        ("value", layers[1][1]),
        ("visits", np.ma.masked_where(visit_map == 0, visit_map.astype(np.int64))),
    )
    for axes, (name, data, cmap, norm), (series, values) in zip(
        panels, layers, recorded, strict=True
    ):
        image = axes.imshow(data, origin="lower", aspect="auto", extent=extent, cmap=cmap,
                            norm=norm, interpolation="nearest")  # fmt: skip
        if series != "visits" or visits is not None:  # no visits: the panel stays blank
            figure.data.panel(name).cells(series, columns, rows, values)
        axes.set_title(name)
        axes.set_xlabel(names[d_col])
        axes.set_ylabel(names[d_row])
        if rows_down:  # a grid world's row 0 is its top row, as the world is drawn
            axes.invert_yaxis()
        bar = figure.colorbar(image, ax=axes)
        if name == "greedy action":
            bar.set_ticks(list(range(n_actions)))
            if action_names is not None and len(action_names) == n_actions:
                bar.set_ticklabels([f"{a}: {text}" for a, text in enumerate(action_names)])
            bar.minorticks_off()
    figure.suptitle(title)
    return figure


def _centres(low: float, high: float, count: int) -> list[float]:
    """The centres of ``count`` equal cells from ``low`` to ``high`` (an image's extent).

    >>> _centres(-0.5, 2.5, 3), _centres(0.0, 1.0, 2)
    ([0.0, 1.0, 2.0], [0.25, 0.75])
    """
    width = (high - low) / count
    return [low + (index + 0.5) * width for index in range(count)]


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


def drawable(text: str) -> str:
    r"""``text`` as a font can draw it: undecodable file-name bytes become U+FFFD.

    A directory name that is not UTF-8 (``--out $'bad\xffname'``) reaches Python as a
    string with surrogate escapes, which matplotlib cannot lay out; titles and labels
    name run directories, so every text of a figure goes through this before rendering.

    >>> drawable("bad\udcffname") == "bad\ufffdname", drawable("seed 3")
    (True, 'seed 3')
    """
    try:
        return text.encode("utf-8", "surrogateescape").decode("utf-8", "replace")
    except UnicodeEncodeError:  # a surrogate that no undecodable byte made
        return text.encode("utf-8", "replace").decode("utf-8")


def _make_drawable(figure: Figure) -> None:
    """Make every text of ``figure`` drawable (see :func:`drawable`)."""
    from matplotlib.text import Text

    for artist in figure.findobj(Text):
        assert isinstance(artist, Text)
        text = artist.get_text()
        if text != drawable(text):
            artist.set_text(drawable(text))


def figure_png(figure: Figure) -> bytes:
    """Render a figure to PNG bytes."""
    _make_drawable(figure)
    canvas = FigureCanvasAgg(figure)
    buffer = io.BytesIO()
    canvas.print_png(buffer)  # type: ignore[no-untyped-call]
    return buffer.getvalue()


def figure_bytes(figure: Figure, file_format: str) -> bytes:
    """Render a figure as ``png``, ``svg`` or ``pdf`` bytes."""
    if file_format == "png":
        return figure_png(figure)
    _make_drawable(figure)
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


def dimension_names(env_id: str, n_dims: int) -> list[str]:
    """Axis names of the observation dimensions (the profile's); ``observation N`` otherwise.

    >>> dimension_names("CartPole-v1", 4)[2], dimension_names("Other-v0", 2)
    ('pole angle (rad)', ['observation 0', 'observation 1'])
    """
    return profile_for(env_id).names_observations(n_dims)


def action_names(env_id: str, n_actions: int) -> list[str] | None:
    """What each action does, as the environment's profile says.

    >>> action_names("MountainCar-v0", 3)[1], action_names("Other-v0", 2)
    ("don't accelerate", None)
    """
    return profile_for(env_id).names_actions(n_actions)


@dataclass(frozen=True)
class GridMap:
    """A grid world's map, as the figures take it (see ``cartpole_q.envs.models.GridLayout``)."""

    rows: int
    columns: int
    cells: Sequence[str]
    """per state ``row * columns + column``: ``S`` start, ``F`` free, ``H`` hole, ``C`` cliff,
    ``G`` goal, ``#`` wall, ``E`` an end that is not the goal"""
    moves: Sequence[tuple[int, int]]
    """per action: ``(row step, column step)``; ``(0, 0)`` stays"""


_CELL_COLOURS = {"H": "#30405a", "C": "#3a3a3a", "G": "#3c9a4a", "#": "#6b6b6b", "E": "#9a3c3c"}
_CELL_NAMES = {"H": "hole", "C": "cliff", "G": "goal", "S": "start", "#": "wall", "E": "end"}


def _draw_grid(
    axes: Axes, grid: GridMap, values: np.ndarray | None = None, record: PanelData | None = None
) -> None:
    """Cells (holes, cliff and goal coloured and named; others by ``values`` if given).

    ``values`` drawn are recorded into ``record`` as the series ``state value max_a Q``.
    """
    shape = (grid.rows, grid.columns)
    special = np.array([cell in _CELL_COLOURS for cell in grid.cells]).reshape(shape)
    if values is not None:
        shown = np.ma.masked_where(special | np.isnan(values.reshape(shape)), values.reshape(shape))
        image = axes.imshow(shown, cmap="viridis", origin="upper", interpolation="nearest")
        if record is not None:
            record.cells("state value max_a Q", range(grid.columns), range(grid.rows), shown)
        figure: Any = axes.figure
        figure.colorbar(image, ax=axes, shrink=0.8, label="state value max_a Q")
    for state, cell in enumerate(grid.cells):
        row, column = divmod(state, grid.columns)
        if cell in _CELL_COLOURS:
            axes.add_patch(_square(row, column, _CELL_COLOURS[cell]))
        if cell in _CELL_NAMES:
            colour = "white" if cell in _CELL_COLOURS else "black"
            axes.text(column, row + 0.3, _CELL_NAMES[cell], ha="center", va="center",
                      fontsize=7, color=colour)  # fmt: skip
    axes.set_xlim(-0.5, grid.columns - 0.5)
    axes.set_ylim(grid.rows - 0.5, -0.5)
    axes.set_xticks(np.arange(-0.5, grid.columns, 1.0), minor=True)
    axes.set_yticks(np.arange(-0.5, grid.rows, 1.0), minor=True)
    axes.grid(which="minor", color="white", linewidth=1.0)
    axes.tick_params(which="both", length=0)
    axes.set_xticks(range(grid.columns))
    axes.set_yticks(range(grid.rows))
    axes.set_aspect("equal")


def _square(row: int, column: int, colour: str) -> Any:
    from matplotlib.patches import Rectangle

    return Rectangle((column - 0.5, row - 0.5), 1.0, 1.0, color=colour, zorder=2)


def grid_policy_figure(
    q_table: np.ndarray, visits: np.ndarray | None, grid: GridMap, title: str
) -> DataFigure:
    """A grid world's greedy policy: an arrow per cell over the state value ``max_a Q``.

    Holes, cliff and goal are coloured and named; cells training never visited get no
    arrow and no colour.
    """
    q = q_table.reshape(grid.rows * grid.columns, -1)
    visited = (
        np.ones(len(q), dtype=bool) if visits is None else visits.reshape(len(q), -1).sum(1) > 0
    )
    values = np.where(visited, q.max(axis=1), np.nan)
    width = min(14.0, 1.0 + 0.75 * grid.columns + 1.5)
    figure = DataFigure(figsize=(width, 1.0 + 0.75 * grid.rows), dpi=DPI, layout="constrained")
    axes = figure.add_subplot()
    record = figure.data.panel("")
    _draw_grid(axes, grid, values, record)
    arrows = np.ma.masked_array(np.zeros((grid.rows, grid.columns), dtype=np.int64), mask=True)
    for state in range(len(q)):
        if not visited[state] or grid.cells[state] in _CELL_COLOURS:
            continue
        row, column = divmod(state, grid.columns)
        arrows[row, column] = int(np.argmax(q[state]))
        d_row, d_col = grid.moves[int(np.argmax(q[state]))]
        if (d_row, d_col) == (0, 0):  # an arrow of no length would not show: a dot stays
            axes.plot(column, row, marker="o", color="white", markersize=5, zorder=3)
            continue
        axes.annotate("", xy=(column + 0.32 * d_col, row + 0.32 * d_row),
                      xytext=(column - 0.32 * d_col, row - 0.32 * d_row),
                      arrowprops={"arrowstyle": "->", "color": "white", "linewidth": 1.8},
                      zorder=3)  # fmt: skip
    record.cells("greedy action", range(grid.columns), range(grid.rows), arrows)
    axes.set_xlabel("column")
    axes.set_ylabel("row")
    axes.set_title(f"{title}\ngreedy action per cell (blank: never visited in training)")
    return figure


def draw_paths(
    axes: Axes,
    record: PanelData,
    grid: GridMap,
    paths: Sequence[tuple[str, Sequence[int], bool]],
) -> None:
    """Draw greedy paths (lists of states) on a grid; a path that never ends is dashed.

    Paths are drawn a little apart, so that paths over the same cells all show; ``record``
    gets each path's cells themselves (``x`` its columns, ``y`` its rows).
    """
    _draw_grid(axes, grid)
    colours = _colours(len(paths))
    for index, ((label, states, ends), colour) in enumerate(zip(paths, colours, strict=True)):
        record.line(label, [state % grid.columns for state in states],
                    [state // grid.columns for state in states])  # fmt: skip
        offset = 0.12 * (index - (len(paths) - 1) / 2)
        rows = [divmod(state, grid.columns)[0] + offset for state in states]
        columns = [divmod(state, grid.columns)[1] + offset for state in states]
        steps = len(states) - 1
        text = f"{label}: {steps} steps" if ends else f"{label}: never reaches the goal"
        axes.plot(columns, rows, color=colour, linewidth=2.5, linestyle="-" if ends else "--",
                  marker="o", markersize=3, label=text, zorder=4)  # fmt: skip
    axes.legend(loc="upper center", bbox_to_anchor=(0.5, -0.12), fontsize="small", ncol=2)


def reward_and_paths_figure(
    curves: Sequence[Curve | SeedBand],
    threshold: float | None,
    title: str,
    grid: GridMap,
    paths: Sequence[tuple[str, Sequence[int], bool]],
) -> DataFigure:
    """Reward curves (as :func:`reward_curve_figure`) above each run's greedy path on the grid."""
    figure = DataFigure(figsize=(9.0, 8.0), dpi=DPI, layout="constrained")
    top, bottom = figure.subplots(2, 1, height_ratios=[1.4, 1.0])
    _draw_reward_curves(top, figure.data.panel("training reward"), curves, threshold, title)
    # The first episodes of a grid world can cost thousands; show the learning after them.
    settled = []
    for item in curves:
        runs = item.returns if isinstance(item, SeedBand) else [item.returns]
        for returns in runs:
            averages = moving_average(np.asarray(returns, dtype=float))
            settled.append(averages[len(averages) // 10 :])
    values = np.concatenate(settled) if settled else np.zeros(1)
    if values.size:
        low, high = float(np.percentile(values, 1)), float(np.max(values))
        top.set_ylim(low - 0.1 * (high - low + 1.0), high + 0.1 * (high - low + 1.0))
    draw_paths(bottom, figure.data.panel("greedy path"), grid, paths)
    bottom.set_title("greedy path from the start (a multi-seed run's first seed)")
    return figure


def blackjack_policy_figure(
    q_table: np.ndarray, visits: np.ndarray | None, title: str
) -> DataFigure:
    """Blackjack's greedy policy as Sutton & Barto draw it: usable ace or not, hit or stick.

    ``q_table`` has shape ``(32, 11, 2, 2)``: player sum, dealer's card, usable ace,
    action (0 stick, 1 hit). Player sums 12-21 (below 12 a hit cannot bust); cells never
    visited in training are blank.
    """
    sums, dealer = np.arange(12, 22), np.arange(1, 11)
    figure = DataFigure(figsize=(10.0, 4.6), dpi=DPI, layout="constrained")
    panels = figure.subplots(1, 2)
    colours = ListedColormap(["#d9e6f2", "#c0392b"])
    for axes, usable in zip(panels, (1, 0), strict=True):
        chosen = np.ma.asarray(np.argmax(q_table[12:22, 1:11, usable], axis=-1))
        if visits is not None:
            chosen = np.ma.masked_where(visits[12:22, 1:11, usable].sum(-1) == 0, chosen)
        actions = chosen.astype(float)
        axes.imshow(actions, origin="lower", cmap=colours, vmin=0, vmax=1, aspect="auto",
                    extent=(0.5, 10.5, 11.5, 21.5), interpolation="nearest")  # fmt: skip
        panel = figure.data.panel("usable ace" if usable else "no usable ace")
        panel.cells("action (0 stick / 1 hit)", dealer.tolist(), sums.tolist(), chosen)
        axes.set_xticks(dealer, ["A", *map(str, range(2, 11))])
        axes.set_yticks(sums)
        axes.set_xlabel("dealer showing")
        axes.set_ylabel("player sum")
        axes.set_title("usable ace" if usable else "no usable ace")
    from matplotlib.patches import Patch

    figure.legend(handles=[Patch(color="#c0392b", label="hit"), Patch(color="#d9e6f2", label="stick")],
                  loc="outside right center")  # fmt: skip
    figure.suptitle(title)
    return figure


def blackjack_values_figure(maps: Sequence[tuple[str, np.ndarray]], title: str) -> DataFigure:
    """Blackjack's state values as Sutton & Barto's Figure 5.1: usable ace above, none below.

    Each map is ``(label, V)`` with ``V`` of shape ``(32, 11, 2)`` (player sum, dealer's
    card, usable ace), drawn as one column: player sums 12-21 against the dealer's card, on
    one colour scale from -1 to 1.
    """
    sums, dealer = np.arange(12, 22), np.arange(1, 11)
    figure = DataFigure(figsize=(3.6 * len(maps) + 1.2, 6.4), dpi=DPI, layout="constrained")
    panels = np.asarray(figure.subplots(2, len(maps), squeeze=False))
    image = None
    for column, (label, values) in enumerate(maps):
        for row, usable in enumerate((1, 0)):
            axes = panels[row, column]
            shown = values[12:22, 1:11, usable]
            image = axes.imshow(shown, origin="lower", cmap="RdYlGn", vmin=-1.0, vmax=1.0,
                                aspect="auto", extent=(0.5, 10.5, 11.5, 21.5),
                                interpolation="nearest")  # fmt: skip
            name = f"{label}, {'usable ace' if usable else 'no usable ace'}"
            figure.data.panel(name).cells("value", dealer.tolist(), sums.tolist(), shown)
            axes.set_xticks(dealer, ["A", *map(str, range(2, 11))])
            axes.set_yticks(sums)
            axes.set_xlabel("dealer showing")
            axes.set_ylabel("player sum")
            axes.set_title(name, fontsize="small")
    if image is not None:
        figure.colorbar(image, ax=panels, label="estimated value", shrink=0.8)
    figure.suptitle(title)
    return figure


def blackjack_optimal_figure(
    maps: Sequence[tuple[str, np.ndarray, np.ndarray]], title: str
) -> DataFigure:
    """Blackjack's policy and its values as Sutton & Barto's Figure 5.2, one pair per map.

    Each map is ``(label, policy, values)``, both of shape ``(32, 11, 2)`` (player sum,
    dealer's card, usable ace): the action in each state (0 stick, 1 hit) and its value.
    Drawn for player sums 12-21: a policy panel and a value panel (from -1 to 1) per map,
    usable ace above, none below. Every other map's policy cells that differ from the last map's (the exact optimum, when it is last)
    are marked with a cross.
    """
    from matplotlib.patches import Patch

    sums, dealer = np.arange(12, 22), np.arange(1, 11)
    figure = DataFigure(figsize=(3.3 * 2 * len(maps) + 1.4, 6.6), dpi=DPI, layout="constrained")
    panels = np.asarray(figure.subplots(2, 2 * len(maps), squeeze=False))
    colours = ListedColormap(["#d9e6f2", "#c0392b"])
    image = None
    for column, (label, policy, values) in enumerate(maps):
        for row, usable in enumerate((1, 0)):
            ace = "usable ace" if usable else "no usable ace"
            chosen = policy[12:22, 1:11, usable]
            axes = panels[row, 2 * column]
            axes.imshow(chosen.astype(float), origin="lower", cmap=colours, vmin=0, vmax=1,
                        aspect="auto", extent=(0.5, 10.5, 11.5, 21.5), interpolation="nearest")  # fmt: skip
            figure.data.panel(f"{label}, policy, {ace}").cells(
                "action (0 stick / 1 hit)", dealer.tolist(), sums.tolist(), chosen
            )
            if column < len(maps) - 1:
                other = maps[-1][1][12:22, 1:11, usable]
                for i, j in zip(*np.nonzero(chosen != other), strict=True):
                    axes.plot(dealer[j], sums[i], marker="x", color="black", markersize=8)
            axes.set_title(f"{label}\npolicy, {ace}", fontsize="small")
            shown = values[12:22, 1:11, usable]
            axes_v = panels[row, 2 * column + 1]
            image = axes_v.imshow(shown, origin="lower", cmap="RdYlGn", vmin=-1.0, vmax=1.0,
                                  aspect="auto", extent=(0.5, 10.5, 11.5, 21.5),
                                  interpolation="nearest")  # fmt: skip
            figure.data.panel(f"{label}, values, {ace}").cells(
                "value", dealer.tolist(), sums.tolist(), shown
            )
            axes_v.set_title(f"{label}\nvalues, {ace}", fontsize="small")
            for each in (axes, axes_v):
                each.set_xticks(dealer, ["A", *map(str, range(2, 11))])
                each.set_yticks(sums)
                each.set_xlabel("dealer showing")
                each.set_ylabel("player sum")
    if image is not None:
        figure.colorbar(image, ax=panels, label="value", shrink=0.8)
    handles = [Patch(color="#c0392b", label="hit"), Patch(color="#d9e6f2", label="stick")]
    figure.legend(handles=handles, loc="outside lower center", ncol=2)
    figure.suptitle(title)
    return figure


def robustness_figure(
    axes_values: Sequence[tuple[str, np.ndarray]],
    means: np.ndarray,
    trained: Sequence[float],
    threshold: float | None,
    title: str,
) -> DataFigure:
    """The greedy policy's mean return as one physics value (a curve) or two (a heatmap) vary.

    Args:
        axes_values: ``(key, values)`` per varied key (one or two).
        means: shape ``(seeds, *grid)``: each seed's mean return at each grid point; the
            median across seeds is drawn, with the interquartile range as a band (curve).
        trained: the value of each key the policy was trained with (marked).
        threshold: the solve threshold (a dashed line on a curve), if any.
        title: the figure's title.
    """
    figure = DataFigure(figsize=CURVE_SIZE, dpi=DPI, layout="constrained")
    axes = figure.add_subplot()
    record = figure.data.panel("")
    median = np.median(means, axis=0)
    if len(axes_values) == 1:
        key, values = axes_values[0]
        if means.shape[0] > 1:
            low, high = np.percentile(means, [25, 75], axis=0)
            axes.fill_between(
                values, low, high, alpha=0.25, label=f"interquartile range, {means.shape[0]} seeds"
            )
            axes.plot(values, median, marker="o", label="median across seeds")
            record.line("median across seeds", values, median, low, high)
        else:
            axes.plot(values, median, marker="o", label="greedy mean return")
            record.line("greedy mean return", values, median)
        axes.axvline(
            trained[0], color="black", linestyle=":", label=f"trained with {key} = {trained[0]:g}"
        )
        record.mark(f"trained with {key}", trained[0])
        if threshold is not None:
            axes.axhline(threshold, color="grey", linestyle="--", label=f"threshold {threshold:g}")
            record.level("threshold", threshold)
        axes.set_xlabel(key)
        axes.set_ylabel("greedy mean return")
        axes.legend(loc="best", fontsize="small")
        axes.grid(alpha=0.3)
    else:
        (key_x, x), (key_y, y) = axes_values
        image = axes.pcolormesh(_edges(x), _edges(y), median.T, shading="flat", cmap="viridis")
        name = "greedy mean return" + (" (median of seeds)" if means.shape[0] > 1 else "")
        figure.colorbar(image, ax=axes, label=name)
        record.cells(name, x.tolist(), y.tolist(), median.T)
        axes.plot([trained[0]], [trained[1]], marker="*", markersize=14, color="red",
                  markeredgecolor="white", label="trained with")  # fmt: skip
        record.line("trained with", [trained[0]], [trained[1]])
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


# -- sweeps ------------------------------------------------------------------------------

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
    for colour, values, label in zip(_colours(len(scores)), scores, labels, strict=True):
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
    colours = _colours(len(data["labels"]))
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
                      path_effects=_outline())  # fmt: skip
    axes.set_xticks(range(columns), sweep_axes[1].values, rotation=30, ha="right", fontsize="small")
    axes.set_yticks(range(rows), sweep_axes[0].values, fontsize="small")
    axes.set_xlabel(sweep_axes[1].name)
    axes.set_ylabel(sweep_axes[0].name)
    axes.set_title(label)


def _outline() -> list[object]:
    from matplotlib import patheffects

    return [patheffects.withStroke(linewidth=2, foreground="black")]


# -- tune studies --------------------------------------------------------------------------


def tune_history_figure(
    trials: Sequence[int], objectives: Sequence[float], title: str
) -> DataFigure:
    """``history.png``: each finished trial's objective, and the best so far (maximised).

    Args:
        trials: the finished trials' numbers, in order.
        objectives: their objectives.
        title: the figure's title.
    """
    figure = DataFigure(figsize=CURVE_SIZE, dpi=DPI, layout="constrained")
    axes = figure.add_subplot()
    record = figure.data.panel("")
    best = np.maximum.accumulate(np.asarray(objectives, dtype=np.float64))
    axes.scatter(trials, objectives, s=16, color="tab:blue", label="objective")
    record.line("objective", trials, objectives)
    axes.step(trials, best, where="post", color="tab:red", label="best so far")
    record.line("best so far", trials, best)
    axes.set_xlabel("trial")
    axes.set_ylabel("objective")
    axes.set_title(title, fontsize="medium")
    axes.grid(alpha=0.3)
    axes.legend(loc="lower right", fontsize="small")
    return figure


def importance_figure(importances: Sequence[tuple[str, float]], title: str) -> DataFigure:
    """``importance.png``: each searched parameter's importance, the largest on top.

    Drawn sideways: the data's ``x`` is the parameter, ``y`` its importance.

    Args:
        importances: ``(parameter, importance)`` pairs, the most important first.
        title: the figure's title.
    """
    height = max(2.5, 1.2 + 0.4 * len(importances))
    figure = DataFigure(figsize=(CURVE_SIZE[0], height), dpi=DPI, layout="constrained")
    axes = figure.add_subplot()
    names = [name for name, _ in importances]
    values = [value for _, value in importances]
    rows = np.arange(len(importances))[::-1]
    axes.barh(rows, values, color="tab:blue", alpha=0.8)
    figure.data.panel("").line("importance", names, values)
    for row, value in zip(rows, values, strict=True):
        axes.text(value, row, f" {value:.2f}" if value >= 0.01 else " <0.01", va="center",
                  fontsize="small")  # fmt: skip
    axes.set_yticks(rows, names, fontsize="small")
    axes.set_xlabel("importance (they sum to 1)")
    axes.set_title(title, fontsize="medium")
    axes.grid(axis="x", alpha=0.3)
    return figure


# -- dynamic programming (Sutton & Barto, chapters 3-4) ------------------------------------


@dataclass(frozen=True)
class GridPanel:
    """One panel of a gridworld's dynamic programming figure: values, or greedy arrows."""

    title: str
    shape: tuple[int, int]
    """the grid's ``(rows, columns)``"""
    values: np.ndarray | None = None
    """float, ``(rows, columns)``: written in the cells"""
    tied: np.ndarray | None = None
    """bool, ``(rows * columns, actions)``: the tied best actions, an arrow each"""
    ends: np.ndarray | None = None
    """bool, ``(rows * columns,)``: terminal cells (shaded, no arrow)"""
    labels: Mapping[int, str] = field(default_factory=dict)
    """names written small in the corner of some cells (Example 3.5's A, A', B, B')"""


def book_round(value: float, decimals: int) -> float:
    """``value`` rounded to ``decimals``, halves upwards, as the book prints (-1.75 -> -1.7).

    >>> book_round(-1.75, 1), book_round(8.7893, 1), book_round(-13.99999999, 0)
    (-1.7, 8.8, -14.0)
    """
    scale = 10.0**decimals
    return float(np.floor(value * scale + 0.5) / scale)


def dp_grid_figure(
    panels: Sequence[GridPanel],
    moves: Sequence[tuple[int, int]],
    names: Sequence[str],
    title: str,
    decimals: int = 1,
    columns: int | None = None,
) -> DataFigure:
    """Gridworld values written in their cells, and greedy arrows (every tied best action).

    Panels are laid out ``columns`` to a row (default: all in one row); the values drawn
    are rounded as the book prints them (:func:`book_round`); the data keeps them exact,
    and a policy cell's value names its arrows (``up left``).
    """
    across = columns or len(panels)
    down = -(-len(panels) // across)
    width = max(2.9 * across, 5.0)
    figure = DataFigure(figsize=(width, 3.1 * down + 0.7), dpi=DPI, layout="constrained")
    grid_axes = np.atleast_1d(figure.subplots(down, across, squeeze=False)).ravel()
    for axes, panel in zip(grid_axes, panels, strict=False):
        record = figure.data.panel(panel.title)
        rows, cols = panel.shape
        ends = np.zeros(rows * cols, bool) if panel.ends is None else panel.ends
        for end in np.flatnonzero(ends):
            axes.add_patch(_square(*divmod(int(end), cols), "#c8c8c8"))
        for state, name in panel.labels.items():
            label_row, label_column = divmod(state, cols)
            axes.text(label_column - 0.42, label_row - 0.42, name, ha="left", va="top",
                      fontsize=7, color="#9a3c3c")  # fmt: skip
        if panel.values is not None:
            record.cells("value", range(cols), range(rows), panel.values)
            if panel.tied is None:
                for (row, column), value in np.ndenumerate(panel.values):
                    axes.text(column, row, f"{book_round(float(value), decimals) + 0.0:.{decimals}f}",
                              ha="center", va="center", fontsize=9 if cols > 4 else 10)  # fmt: skip
        if panel.tied is not None:
            for state in range(rows * cols):
                here_row, here_column = divmod(state, cols)
                best = [] if ends[state] else [int(a) for a in np.flatnonzero(panel.tied[state])]
                label = " ".join(names[a] for a in best) if best else None
                record.data.rows.append(
                    (record.name, "greedy actions", here_column, here_row, None, None, label)
                )
                for action in best:
                    d_row, d_col = moves[action]
                    axes.annotate("", xy=(here_column + 0.38 * d_col, here_row + 0.38 * d_row),
                                  xytext=(here_column, here_row),
                                  arrowprops={"arrowstyle": "->", "color": "#1f4e79", "linewidth": 1.4})  # fmt: skip
        axes.set_xlim(-0.5, cols - 0.5)
        axes.set_ylim(rows - 0.5, -0.5)
        axes.set_xticks(np.arange(-0.5, cols, 1.0), minor=True)
        axes.set_yticks(np.arange(-0.5, rows, 1.0), minor=True)
        axes.grid(which="minor", color="#555555", linewidth=0.8)
        axes.tick_params(which="both", length=0, labelbottom=False, labelleft=False)
        axes.set_aspect("equal")
        axes.set_title(panel.title, fontsize=10)
    for axes in grid_axes[len(panels) :]:
        axes.set_axis_off()
    import textwrap

    figure.suptitle(textwrap.fill(title, int(width * 9)))
    return figure


def gambler_figure(
    sweeps: Sequence[tuple[str, np.ndarray]], stakes: np.ndarray, title: str
) -> DataFigure:
    """Figure 4.3: value estimates against capital for some sweeps, then the final policy.

    ``sweeps`` are ``(label, values)`` over the capitals ``1 .. len(values)``; ``stakes`` the
    final policy's stake per capital.
    """
    figure = DataFigure(figsize=(7.5, 8.0), dpi=DPI, layout="constrained")
    top, bottom = figure.subplots(2, 1)
    record = figure.data.panel("value estimates")
    for (label, values), colour in zip(sweeps, _colours(len(sweeps)), strict=True):
        capital = np.arange(1, len(values) + 1)
        top.plot(capital, values, label=label, color=colour, linewidth=1.2)
        record.line(label, capital.tolist(), values.tolist())
    top.set_xlabel("capital")
    top.set_ylabel("value estimates")
    top.set_ylim(0.0, 1.0)
    top.legend(loc="upper left", fontsize="small")
    top.set_title("value estimates")
    capital = np.arange(1, len(stakes) + 1)
    bottom.step(capital, stakes, where="mid", color="#1f4e79")
    bottom.plot(capital, stakes, linestyle="none", marker=".", color="#1f4e79", markersize=3)
    figure.data.panel("final policy (stake)").line("stake", capital.tolist(), stakes.tolist())
    bottom.set_xlabel("capital")
    bottom.set_ylabel("final policy (stake)")
    bottom.set_title("final policy (stake)")
    figure.suptitle(title)
    return figure


def car_rental_figure(
    policies: Sequence[np.ndarray], values: np.ndarray, title: str, value_title: str
) -> DataFigure:
    """Figure 4.2: each policy as a contour map of the cars moved, then the last one's values.

    Each array is ``(cars at the first location, cars at the second)``: the first location
    upwards, the second across, as the book draws them.
    """
    count = len(policies) + 1
    across = 3
    down = -(-count // across)
    figure = DataFigure(figsize=(4.2 * across, 3.8 * down + 0.4), dpi=DPI, layout="constrained")
    panels = figure.subplots(down, across, squeeze=False).ravel()
    size = values.shape[0]
    cars = np.arange(size)
    low = min(int(policy.min()) for policy in policies)
    high = max(int(policy.max()) for policy in policies)
    levels = np.arange(low - 0.5, high + 1.5)
    colours = ListedColormap([_moves_colour(move) for move in range(low, high + 1)])
    norm = BoundaryNorm(levels, colours.N)
    for index, (axes, policy) in enumerate(zip(panels, policies, strict=False)):
        name = f"pi_{index}"
        axes.pcolormesh(cars, cars, policy, cmap=colours, norm=norm, shading="nearest")
        if policy.min() != policy.max():
            axes.contour(cars, cars, policy, levels=levels[1:-1], colors="black", linewidths=0.8)
        for move in np.unique(policy):  # each move's number on its region, as the book writes
            cells = np.argwhere(policy == move)
            row, column = cells[np.argmin(((cells - cells.mean(axis=0)) ** 2).sum(axis=1))]
            axes.text(column, row, str(int(move)), ha="center", va="center", fontsize=9,
                      fontweight="bold")  # fmt: skip
        figure.data.panel(name).cells("cars moved", cars.tolist(), cars.tolist(), policy)
        axes.set_title(f"{name}: cars moved from the first location (negative: to it)", fontsize=8)
        _car_axes(axes, size)
    axes = panels[len(policies)]
    image = axes.pcolormesh(cars, cars, values, cmap="viridis", shading="nearest")
    figure.colorbar(image, ax=axes, shrink=0.85)
    figure.data.panel(value_title).cells("value", cars.tolist(), cars.tolist(), values)
    axes.set_title(f"{value_title}: {values.min():.1f} to {values.max():.1f}", fontsize=9)
    _car_axes(axes, size)
    for axes in panels[count:]:
        axes.set_axis_off()
    figure.suptitle(title)
    return figure


def _car_axes(axes: Axes, size: int) -> None:
    """Cars at the second location across, at the first upwards, ticks every 5."""
    axes.set_xticks(range(0, size, 5))
    axes.set_yticks(range(0, size, 5))
    axes.set_xlabel("cars at the second location")
    axes.set_ylabel("cars at the first location")
    axes.set_aspect("equal")


def _moves_colour(move: int) -> tuple[float, ...]:
    """A colour per number of cars moved: blues one way, reds the other, white for none."""
    from matplotlib import colormaps

    return tuple(colormaps["RdBu_r"](0.5 + 0.09 * max(-5, min(5, move))))


# -- bandits (chapter 2) -------------------------------------------------------------------


def step_curves_figure(
    panels: Sequence[tuple[str, Sequence[tuple[str, np.ndarray]]]],
    title: str,
    most: int | None = DRAWN_POINTS,
) -> DataFigure:
    """Figures 2.2-2.5: per-step curves (one value per step, steps from 1), panels stacked.

    Each panel is ``(y label, [(curve label, values), ...])``; its data panel is named by
    its y label, the x of each point is the step. A curve of more than ``most`` steps is
    drawn at ``most`` of them (:func:`drawn_points`).
    """
    figure = DataFigure(figsize=(8.0, 3.2 * len(panels) + 0.6), dpi=DPI, layout="constrained")
    axes_list = figure.subplots(len(panels), 1, sharex=True, squeeze=False)[:, 0]
    for axes, (y_label, curves) in zip(axes_list, panels, strict=True):
        record = figure.data.panel(y_label)
        for (label, every), colour in zip(curves, _colours(len(curves)), strict=True):
            kept = drawn_points(len(every), most=most)
            steps, values = kept + 1, every[kept]
            axes.plot(steps, values, color=colour, linewidth=1.0, label=label)
            record.line(label, steps.tolist(), values.tolist())
        axes.set_ylabel(y_label)
        if y_label.startswith("%"):
            axes.set_ylim(0.0, 100.0)
        axes.legend(loc="lower right", fontsize="small")
        axes.grid(alpha=0.3)
    axes_list[-1].set_xlabel("Steps")
    figure.suptitle(title, fontsize="medium")
    return figure


ALPHA = "\N{GREEK SMALL LETTER ALPHA}"


@dataclass(frozen=True)
class ParameterLine:
    """One method's line of a parameter study (Figure 2.6)."""

    label: str
    parameter: str
    """the varied parameter's name, drawn beside the line (epsilon, alpha, c, q_init)"""
    values: np.ndarray
    """the parameter's values (positive: the axis is log2)"""
    points: np.ndarray
    """the measure at each value"""


def _power_label(value: float) -> str:
    """A power of two as the book's axis writes it: ``1/128``, ``1/2``, ``1``, ``4``."""
    exponent = round(float(np.log2(value)))
    return str(2**exponent) if exponent >= 0 else f"1/{2**-exponent}"


def parameter_study_figure(lines: Sequence[ParameterLine], y_label: str, title: str) -> DataFigure:
    """Figure 2.6: each method's measure against its parameter, the x axis in powers of 2."""
    figure = DataFigure(figsize=(8.0, 5.2), dpi=DPI, layout="constrained")
    axes = figure.add_subplot()
    record = figure.data.panel("")
    names = {"epsilon": "ε", "alpha": ALPHA, "c": "c", "q_init": "Q₀"}
    for line, colour in zip(lines, _colours(len(lines)), strict=True):
        label = f"{line.label} ({names.get(line.parameter, line.parameter)})"
        axes.plot(line.values, line.points, color=colour, marker="o", markersize=3, label=label)
        record.line(label, line.values.tolist(), line.points.tolist())
    axes.set_xscale("log", base=2)
    every = sorted({float(v) for line in lines for v in line.values})
    low, high = int(np.floor(np.log2(every[0]))), int(np.ceil(np.log2(every[-1])))
    ticks = [2.0**e for e in range(low, high + 1)]
    axes.set_xticks(ticks, [_power_label(t) for t in ticks])
    axes.set_xlabel(f"ε   {ALPHA}   c   Q₀")
    axes.set_ylabel(y_label)
    axes.legend(loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2, fontsize="small")
    axes.grid(alpha=0.3)
    axes.set_title(title)
    return figure


def expected_vs_sample_figure(
    curves: Sequence[tuple[int, np.ndarray]], initial_error: float, title: str
) -> DataFigure:
    """Figure 8.7: RMS error against ``max Q`` computations, in units of ``b`` (0 to 2b).

    ``curves`` are ``(b, rms)`` with ``rms[t]`` after ``t`` sample updates; the expected
    update is one line: ``initial_error`` until ``b`` computations, 0 from there. A curve of
    more than :data:`DRAWN_POINTS` points is drawn at that many, evenly spaced in ``t``.
    """
    figure = DataFigure(figsize=(8.0, 5.0), dpi=DPI, layout="constrained")
    axes = figure.add_subplot()
    record = figure.data.panel("")
    for (branching, every), colour in zip(curves, _colours(len(curves)), strict=True):
        kept = drawn_points(every.shape[0])
        x, rms = (kept / branching).tolist(), every[kept]
        label = f"sample updates, b = {branching:,}"
        axes.plot(x, rms, color=colour, linewidth=1.2, label=label)
        record.line(label, x, rms.tolist())
    x, y = [0.0, 1.0, 1.0, 2.0], [initial_error, initial_error, 0.0, 0.0]
    axes.plot(x, y, color="black", linewidth=1.6, linestyle="--", label="expected updates")
    record.line("expected updates", x, y)
    axes.set_xticks([0.0, 1.0, 2.0], ["0", "1b", "2b"])
    axes.set_xlabel("Number of max_a' Q(s', a') computations")
    axes.set_ylabel("RMS error in value estimate")
    axes.set_xlim(0.0, 2.0)
    axes.set_ylim(0.0, max(initial_error, 1.0) * 1.05)
    axes.legend(loc="upper right", fontsize="small")
    axes.grid(alpha=0.3)
    axes.set_title(title)
    return figure


@dataclass(frozen=True)
class TrajectoryCurve:
    """One line of Figure 8.8: the start state's greedy value, averaged over tasks."""

    label: str
    updates: np.ndarray
    """the computation time (expected updates) of each point"""
    mean: np.ndarray
    low: np.ndarray | None
    high: np.ndarray | None
    on_policy: bool


def trajectory_sampling_figure(
    panels: Sequence[tuple[str, Sequence[TrajectoryCurve]]], title: str
) -> DataFigure:
    """Figure 8.8: value of the start state under the greedy policy against updates, panels stacked.

    Curves of the same branching share a colour: uniform dashed, on-policy solid; the
    interval (when given) is shaded.
    """
    figure = DataFigure(figsize=(8.0, 4.0 * len(panels) + 0.6), dpi=DPI, layout="constrained")
    axes_list = figure.subplots(len(panels), 1, squeeze=False)[:, 0]
    for axes, (name, curves) in zip(axes_list, panels, strict=True):
        record = figure.data.panel(name)
        colours = _colours(max(1, len(curves) // 2))
        for index, curve in enumerate(curves):
            colour = colours[(index // 2) % len(colours)]
            style = "-" if curve.on_policy else "--"
            x = curve.updates.tolist()
            axes.plot(x, curve.mean, color=colour, linestyle=style, linewidth=1.3,
                      label=curve.label)  # fmt: skip
            if curve.low is not None and curve.high is not None:
                axes.fill_between(x, curve.low, curve.high, color=colour, alpha=0.12, linewidth=0)
                record.line(curve.label, x, curve.mean.tolist(), curve.low.tolist(),
                            curve.high.tolist())  # fmt: skip
            else:
                record.line(curve.label, x, curve.mean.tolist())
        axes.set_title(name, fontsize="medium")
        axes.set_ylabel("Value of start state\nunder greedy policy")
        axes.legend(loc="lower right", fontsize="small")
        axes.grid(alpha=0.3)
    axes_list[-1].set_xlabel("Computation time, in expected updates")
    figure.suptitle(title, fontsize="medium")
    return figure


def until_optimal_figure(
    curves: Sequence[tuple[str, np.ndarray, np.ndarray, np.ndarray | None, np.ndarray | None]],
    title: str,
) -> DataFigure:
    """Example 8.4's figure: updates until the greedy path is optimal against maze size.

    ``curves`` are ``(label, states, mean, least, most)``; log y axis (as the book's), each
    point drawn with the range of its runs.
    """
    figure = DataFigure(figsize=(8.0, 5.0), dpi=DPI, layout="constrained")
    axes = figure.add_subplot()
    record = figure.data.panel("")
    for (label, x, mean, low, high), colour in zip(curves, _colours(len(curves)), strict=True):
        xs = x.tolist()
        axes.plot(xs, mean, color=colour, marker="o", linewidth=1.4, label=label)
        if low is not None and high is not None:
            axes.fill_between(xs, low, high, color=colour, alpha=0.15, linewidth=0)
            record.line(label, xs, mean.tolist(), low.tolist(), high.tolist())
        else:
            record.line(label, xs, mean.tolist())
    axes.set_yscale("log")
    axes.set_xlabel("Gridworld size (#states)")
    axes.set_ylabel("Updates until optimal solution")
    axes.legend(loc="upper left", fontsize="small")
    axes.grid(alpha=0.3, which="both")
    axes.set_title(title)
    return figure
