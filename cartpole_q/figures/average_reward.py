"""Figure 10.5: a policy learned for the reward per step, beside the optimum.

Four panels for a world whose states are two components (access control: the priority of
the customer at the head of the queue, and the free servers): the learned greedy policy,
the optimal policy of relative value iteration, the value of the best action in each state
(learned and optimal), and ``R̄`` over the steps against the optimal gain.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from matplotlib.colors import BoundaryNorm, ListedColormap

from cartpole_q.figures.base import DPI, DataFigure, colour_cycle, drawn_points

UNVISITED = "#dddddd"
"""the colour of a state the run never left"""


@dataclass(frozen=True)
class PolicyPanels:
    """What Figure 10.5 draws: both policies, both values, the run's ``R̄``."""

    shape: tuple[int, int]
    """the two components' sizes: a state is ``row * shape[1] + column``"""
    component_names: tuple[str, str]
    component_values: tuple[tuple[str, ...], tuple[str, ...]]
    action_names: tuple[str, ...]
    learned: np.ndarray
    """int64 ``(N,)``: the learned greedy action per state"""
    visited: np.ndarray
    """bool ``(N,)``: the states the run took a step from"""
    optimal: np.ndarray | None
    """int64 ``(N,)``: the optimal action (``None``: no optimum drawn)"""
    learned_best: np.ndarray
    """float64 ``(N,)``: ``max_a q̂(s, a)``"""
    optimal_best: np.ndarray | None
    """float64 ``(N,)``: ``max_a q*(s, a)``, shifted to the learned values' level"""
    at: np.ndarray
    r_bar: np.ndarray
    rate: np.ndarray
    levels: tuple[tuple[str, float], ...]
    """dashed levels on the ``R̄`` panel: ``(name, value)``"""
    label: str
    """the run drawn"""


def policy_values_figure(panels: PolicyPanels, title: str) -> DataFigure:
    """Figure 10.5: the learned and the optimal policy, the best action's value, ``R̄``."""
    figure = DataFigure(figsize=(13.0, 8.0), dpi=DPI, layout="constrained")
    grid = figure.subplots(2, 2)
    rows, columns = panels.shape
    from matplotlib.colors import to_hex

    colours = [to_hex((c[0], c[1], c[2])) for c in colour_cycle(max(2, len(panels.action_names)))]
    actions = ListedColormap([UNVISITED, *colours[: len(panels.action_names)]])
    norm = BoundaryNorm(np.arange(-1.5, len(panels.action_names)), actions.N)
    learned = np.where(panels.visited, panels.learned, -1).reshape(rows, columns)
    _policy_panel(figure, grid[0, 0], f"learned greedy policy ({panels.label})", learned,
                  panels, actions, norm)  # fmt: skip
    if panels.optimal is not None:
        optimal = panels.optimal.reshape(rows, columns)
        _policy_panel(figure, grid[0, 1], "optimal policy (relative value iteration)", optimal,
                      panels, actions, norm)  # fmt: skip
    else:
        grid[0, 1].set_axis_off()
    _values_panel(figure, grid[1, 0], panels)
    _rate_panel(figure, grid[1, 1], panels)
    figure.suptitle(title)
    return figure


def _policy_panel(
    figure: DataFigure, axes: object, name: str, actions: np.ndarray, panels: PolicyPanels,
    cmap: ListedColormap, norm: BoundaryNorm,
) -> None:  # fmt: skip
    from matplotlib.axes import Axes
    from matplotlib.patches import Patch

    assert isinstance(axes, Axes)
    rows, columns = panels.shape
    axes.pcolormesh(np.arange(columns), np.arange(rows), actions, cmap=cmap, norm=norm,
                    shading="nearest", edgecolors="white", linewidth=0.5)  # fmt: skip
    for row in range(rows):
        for column in range(columns):
            action = int(actions[row, column])
            if action >= 0:
                axes.text(column, row, panels.action_names[action][:3], ha="center",
                          va="center", fontsize=7)  # fmt: skip
    figure.data.panel(name).cells(
        "action (-1: never visited)",
        list(panels.component_values[1]),
        list(panels.component_values[0]),
        actions,
    )
    axes.set_xticks(range(columns), panels.component_values[1])
    axes.set_yticks(range(rows), panels.component_values[0])
    axes.set_xlabel(panels.component_names[1])
    axes.set_ylabel(panels.component_names[0])
    axes.set_title(name, fontsize=9)
    handles = [Patch(color=cmap(i + 1), label=n) for i, n in enumerate(panels.action_names)]
    handles.append(Patch(color=UNVISITED, label="never visited"))
    axes.legend(handles=handles, fontsize="x-small", loc="upper left", bbox_to_anchor=(1.0, 1.0))


def _values_panel(figure: DataFigure, axes: object, panels: PolicyPanels) -> None:
    from matplotlib.axes import Axes

    assert isinstance(axes, Axes)
    rows, columns = panels.shape
    x = np.arange(columns)
    name = "value of the best action"
    record = figure.data.panel(name)
    learned = np.where(panels.visited, panels.learned_best, np.nan).reshape(rows, columns)
    for row, colour in zip(range(rows), colour_cycle(rows), strict=True):
        series = f"{panels.component_names[0]} {panels.component_values[0][row]}"
        axes.plot(x, learned[row], color=colour, marker="o", markersize=3, label=series)
        record.line(series, x.tolist(), learned[row].tolist())
        if panels.optimal_best is not None:
            optimal = panels.optimal_best.reshape(rows, columns)[row]
            axes.plot(x, optimal, color=colour, linestyle="--", linewidth=0.9)
            record.line(f"{series}: optimal (shifted)", x.tolist(), optimal.tolist())
    axes.set_xticks(x, panels.component_values[1])
    axes.set_xlabel(panels.component_names[1])
    axes.set_ylabel("max_a q(s, a)")
    shifted = (
        "; dashed: the optimal differential values, shifted to the learned ones' mean over "
        "the visits"
        if panels.optimal_best is not None
        else ""
    )
    axes.set_title(f"{name}: learned (states visited){shifted}", fontsize=8, wrap=True)
    axes.legend(fontsize="x-small")
    axes.grid(alpha=0.3)


def _rate_panel(figure: DataFigure, axes: object, panels: PolicyPanels) -> None:
    from matplotlib.axes import Axes

    assert isinstance(axes, Axes)
    name = "reward per step"
    record = figure.data.panel(name)
    kept = drawn_points(panels.at.shape[0])
    at = panels.at[kept]
    for series, values, colour in (
        ("R̄ (learned)", panels.r_bar[kept], "C0"),
        ("reward per step since the last record", panels.rate[kept], "C1"),
    ):
        axes.plot(at, values, color=colour, linewidth=1.0, label=series)
        record.line(series, at.tolist(), values.tolist())
    for (series, value), colour in zip(panels.levels, ("black", "C2", "C3"), strict=False):
        axes.axhline(value, color=colour, linestyle="--", linewidth=1.0, label=series)
        record.level(series, value)
    axes.set_xlabel("steps")
    axes.set_ylabel("reward per step")
    axes.set_title(f"{name}: R̄ and the rewards received", fontsize=9)
    axes.legend(fontsize="x-small")
    axes.grid(alpha=0.3)
