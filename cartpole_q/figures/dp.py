"""Dynamic programming's figures (Sutton & Barto Figures 3.2, 3.5, 4.1, 4.2, 4.3)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from matplotlib.axes import Axes
from matplotlib.colors import BoundaryNorm, ListedColormap

from cartpole_q.figures.base import DPI, DataFigure, cell_square, colour_cycle


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
            axes.add_patch(cell_square(*divmod(int(end), cols), "#c8c8c8"))
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
    for (label, values), colour in zip(sweeps, colour_cycle(len(sweeps)), strict=True):
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
