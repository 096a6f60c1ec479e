"""The linear methods' figures (Sutton & Barto Figures 9.5, 9.10, 11.2, 11.5, 11.6)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from cartpole_q.figures.base import CURVE_SIZE, DPI, DataFigure, colour_cycle, drawn_points


@dataclass(frozen=True)
class ErrorCurve:
    """One curve of an errors figure: its error at each record, and its fixed point's."""

    label: str
    x: np.ndarray
    y: np.ndarray
    fixed: float | None
    """the error at the curve's fixed point, drawn as a dashed level (``None``: none)"""


def error_curves_figure(
    curves: Sequence[ErrorCurve], title: str, x_label: str, y_label: str,
    y_limits: tuple[float | None, float | None] = (None, None), log_y: bool = False,
    levels: Sequence[tuple[str, float]] = (),
) -> DataFigure:  # fmt: skip
    """Figures 9.5, 9.10, 13.1, 13.2: each curve against the episodes, its fixed point dashed.

    ``levels`` are further ``(name, value)`` levels, drawn dashed in black (the best start
    value of Figures 13.1 and 13.2).
    """
    figure = DataFigure(figsize=CURVE_SIZE, dpi=DPI, layout="constrained")
    axes = figure.add_subplot()
    record = figure.data.panel("")
    for curve, colour in zip(curves, colour_cycle(len(curves)), strict=True):
        kept = drawn_points(len(curve.x))
        axes.plot(curve.x[kept], curve.y[kept], color=colour, linewidth=1.2, label=curve.label)
        record.line(curve.label, curve.x[kept].tolist(), curve.y[kept].tolist())
        if curve.fixed is not None:
            name = f"{curve.label}: its fixed point"
            axes.axhline(curve.fixed, color=colour, linewidth=0.8, linestyle="--", label=name)
            record.level(name, curve.fixed)
    for name, value in levels:
        axes.axhline(value, color="black", linewidth=1.0, linestyle="--", label=name)
        record.level(name, value)
    if log_y:
        axes.set_yscale("log")
    axes.set_ylim(*y_limits)
    axes.set_xlabel(x_label)
    axes.set_ylabel(y_label)
    axes.legend(fontsize="small", ncol=2 if len(curves) > 3 else 1)
    axes.grid(alpha=0.3)
    axes.set_title(title, fontsize="medium")
    return figure


@dataclass(frozen=True)
class WeightsPanel:
    """One panel of a weights figure: a curve's weights and errors over its records."""

    title: str
    x_label: str
    x: np.ndarray
    weights: np.ndarray
    """``(records, d)``"""
    errors: Sequence[tuple[str, np.ndarray]]
    """``(name, values)``: ``√VE``, ``√PBE``"""
    runs: int


def weights_figure(
    panels: Sequence[WeightsPanel], title: str,
    y_limits: tuple[float | None, float | None] = (None, None),
) -> DataFigure:  # fmt: skip
    """Figures 11.2, 11.5, 11.6: each weight (``w1`` ...) and each error, a panel per curve."""
    figure = DataFigure(
        figsize=(8.0 * min(len(panels), 2), 4.6 * ((len(panels) + 1) // 2) + 0.4), dpi=DPI,
        layout="constrained",
    )  # fmt: skip
    columns = min(len(panels), 2)
    rows = (len(panels) + 1) // 2
    grid = figure.subplots(rows, columns, squeeze=False)
    for axes in grid.ravel()[len(panels) :]:
        axes.set_visible(False)
    for axes, panel in zip(grid.ravel(), panels, strict=False):
        record = figure.data.panel(panel.title)
        d = panel.weights.shape[1]
        kept = drawn_points(len(panel.x))
        x = panel.x[kept]
        for i, colour in zip(range(d), colour_cycle(d), strict=True):
            name = f"w{i + 1}"
            axes.plot(x, panel.weights[kept, i], color=colour, linewidth=1.0, label=name)
            record.line(name, x.tolist(), panel.weights[kept, i].tolist())
        for (name, values), style in zip(panel.errors, ("-", "--"), strict=False):
            axes.plot(x, values[kept], color="black", linewidth=1.8, linestyle=style, label=name)
            record.line(name, x.tolist(), values[kept].tolist())
        axes.set_ylim(*y_limits)
        axes.set_xlabel(panel.x_label)
        runs = "" if panel.runs == 1 else f" (mean of {panel.runs} runs)"
        axes.set_title(panel.title + runs, fontsize="medium")
        axes.legend(fontsize="x-small", ncol=2)
        axes.grid(alpha=0.3)
    figure.suptitle(title, fontsize="medium")
    return figure
