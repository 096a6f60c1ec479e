"""Maps of a policy.

Binned and tiled tables, grid worlds (with paths), Blackjack's policies and values
(Sutton & Barto Figures 5.1, 5.2).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.colors import BoundaryNorm, ListedColormap, LogNorm

from cartpole_q.families import profile_for
from cartpole_q.figures.base import (
    DPI,
    POLICY_SIZE,
    DataFigure,
    PanelData,
    cell_square,
    colour_cycle,
)
from cartpole_q.figures.curves import (
    Curve,
    SeedBand,
    draw_reward_curves,
    moving_average,
)


@dataclass(frozen=True)
class MapDimensions:
    """The two dimensions a policy map draws, and every dimension's range and name."""

    dims: tuple[int, int]
    """the dimension on the y axis (rows; upwards unless ``rows_down``) and the one on the x axis"""
    low: Sequence[float]
    """each dimension's lowest value (a bin grid's ``low``)"""
    high: Sequence[float]
    """each dimension's highest value"""
    names: Sequence[str]
    """each dimension's name, on the axes"""


def policy_figure(
    q_table: np.ndarray,
    visits: np.ndarray | None,
    dimensions: MapDimensions,
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
    dims, low, high, names = dimensions.dims, dimensions.low, dimensions.high, dimensions.names
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
            axes.add_patch(cell_square(row, column, _CELL_COLOURS[cell]))
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


def grid_arrows_figure(
    panels: Sequence[tuple[str, np.ndarray, np.ndarray | None]], grid: GridMap, title: str
) -> DataFigure:
    """Figures 7.4 and 8.3: per run, an arrow where the greedy action is set.

    A cell gets its greedy action's arrow (the lowest among the largest ``Q``) where its
    values are not all equal, and none where they are (nothing learned there yet); cells
    the run visited are shaded (the path it took) where its visits are known (a run
    directory's, or a sweep's whose figure is ``metric: policy``). The data: per panel, ``greedy action`` (empty: all
    equal) and ``visits`` (the steps taken from the cell) per cell.
    """
    across = len(panels)
    width = min(18.0, across * (0.6 * grid.columns + 1.0) + 0.5)
    figure = DataFigure(figsize=(width, 0.6 * grid.rows + 1.6), dpi=DPI, layout="constrained")
    for index, (name, q_table, visits) in enumerate(panels):
        axes = figure.add_subplot(1, across, index + 1)
        record = figure.data.panel(name)
        q = q_table.reshape(grid.rows * grid.columns, -1)
        counts = (
            np.zeros(len(q)) if visits is None else visits.reshape(len(q), -1).sum(axis=1)
        ).astype(np.int64)
        _draw_grid(axes, grid)
        for state in range(len(q)):
            if counts[state] > 0 and grid.cells[state] not in _CELL_COLOURS:
                row, column = divmod(state, grid.columns)
                axes.add_patch(cell_square(row, column, "#f2d98c"))
        arrows = np.ma.masked_array(np.zeros((grid.rows, grid.columns), dtype=np.int64), mask=True)
        for state in range(len(q)):
            if grid.cells[state] in _CELL_COLOURS or q[state].max() == q[state].min():
                continue
            row, column = divmod(state, grid.columns)
            action = int(np.argmax(q[state]))
            arrows[row, column] = action
            d_row, d_col = grid.moves[action]
            axes.annotate("", xy=(column + 0.32 * d_col, row + 0.32 * d_row),
                          xytext=(column - 0.32 * d_col, row - 0.32 * d_row),
                          arrowprops={"arrowstyle": "->", "color": "#1f4e79", "linewidth": 1.8},
                          zorder=3)  # fmt: skip
        record.cells("greedy action (empty: all values equal)", range(grid.columns),
                     range(grid.rows), arrows)  # fmt: skip
        if visits is not None:
            record.cells("visits", range(grid.columns), range(grid.rows),
                         counts.reshape(grid.rows, grid.columns))  # fmt: skip
        shown = int(arrows.count())
        told = f"{shown} arrow{'s' if shown != 1 else ''}"
        if visits is not None:
            told += f", {int((counts > 0).sum())} cells visited"
        axes.set_title(f"{name}\n{told}", fontsize=9)
    figure.suptitle(title)
    return figure


_TRACK_COLOURS = {"#": "#4a4a4a", ".": "#f4f1e8", "S": "#f2d98c", "F": "#3c9a4a"}


def racetrack_figure(
    panels: Sequence[
        tuple[str, Sequence[str], Sequence[tuple[str, Sequence[tuple[int, int]], str]]]
    ],
    title: str,
) -> DataFigure:
    """Exercise 5.12 (Figure 5.5): a policy's trajectories from start cells, drawn on its track.

    ``panels``: per panel its name, its track's rows and paths ``(label, cells, how)``,
    ``cells`` the ``(row, column)`` the car passes, ``how`` ``finish``, ``crash`` or
    ``stuck`` (a crash or a stall is dashed and ends in a cross). The data: each path's
    cells, per panel.
    """
    from matplotlib.colors import ListedColormap

    kinds = "#.SF"
    cmap = ListedColormap([_TRACK_COLOURS[kind] for kind in kinds])
    across = len(panels)
    widest = max(len(track[0]) for _, track, _ in panels)
    tallest = max(len(track) for _, track, _ in panels)
    figure = DataFigure(
        figsize=(min(20.0, 1.0 + across * (0.2 * widest + 1.4)), 0.2 * tallest + 2.6),
        dpi=DPI, layout="constrained",
    )  # fmt: skip
    for index, (name, track, paths) in enumerate(panels):
        axes = figure.add_subplot(1, across, index + 1)
        record = figure.data.panel(name.replace("\n", " "))
        codes = np.array([[kinds.index(char) for char in line] for line in track])
        axes.imshow(codes, cmap=cmap, vmin=-0.5, vmax=3.5, interpolation="nearest")
        colours = colour_cycle(len(paths))
        for (label, cells, how), colour in zip(paths, colours, strict=True):
            ys = [row for row, _ in cells]
            xs = [column for _, column in cells]
            record.line(f"{label} ({how})", xs, ys)
            dashed = how != "finish"
            axes.plot(xs, ys, color=colour, linewidth=1.6, linestyle="--" if dashed else "-",
                      marker="o", markersize=3, label=f"{label}: {how}")  # fmt: skip
            if dashed:
                axes.plot(xs[-1], ys[-1], color=colour, marker="x", markersize=8)
        axes.set_xlim(-0.5, len(track[0]) - 0.5)
        axes.set_ylim(len(track) - 0.5, -0.5)
        axes.set_xticks(range(0, len(track[0]), 5))
        axes.set_yticks(range(0, len(track), 5))
        axes.set_title(name, fontsize=8)
        axes.legend(fontsize="xx-small", loc="lower right")
    figure.suptitle(title)
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
    colours = colour_cycle(len(paths))
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
    draw_reward_curves(top, figure.data.panel("training reward"), curves, threshold, title)
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
