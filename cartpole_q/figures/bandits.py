"""The bandit testbed's figures (Sutton & Barto Figures 2.2-2.6)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from cartpole_q.figures.base import DPI, DRAWN_POINTS, DataFigure, colour_cycle, drawn_points


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
        for (label, every), colour in zip(curves, colour_cycle(len(curves)), strict=True):
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
    for line, colour in zip(lines, colour_cycle(len(lines)), strict=True):
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
