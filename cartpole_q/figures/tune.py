"""A tune directory's figures: the objective's history and the parameters' importances."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from cartpole_q.figures.base import CURVE_SIZE, DPI, DataFigure


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
