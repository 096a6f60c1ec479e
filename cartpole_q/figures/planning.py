"""Chapter 8's planning figures (Sutton & Barto Figures 8.7, 8.8 and Example 8.4's)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from cartpole_q.figures.base import DPI, DataFigure, colour_cycle, drawn_points


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
    for (branching, every), colour in zip(curves, colour_cycle(len(curves)), strict=True):
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
        colours = colour_cycle(max(1, len(curves) // 2))
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
    line_styles: Sequence[tuple[int, bool]] | None = None,
) -> DataFigure:
    """Example 8.4's figure: updates until the greedy path is optimal against maze size.

    ``curves`` are ``(label, states, mean, least, most)``; log axes (as the book's), the
    sizes ticked, each point drawn with the range of its runs. ``line_styles`` gives each
    curve ``(colour index, dashed)`` (a colour per method, another criterion dashed); by
    default each curve has its own colour, solid.
    """
    figure = DataFigure(figsize=(8.0, 5.0), dpi=DPI, layout="constrained")
    axes = figure.add_subplot()
    record = figure.data.panel("")
    styles = line_styles or [(index, False) for index in range(len(curves))]
    palette = colour_cycle(max(index for index, _ in styles) + 1 if styles else 0)
    for (label, x, mean, low, high), (index, dashed) in zip(curves, styles, strict=True):
        colour, xs = palette[index], x.tolist()
        axes.plot(xs, mean, color=colour, marker="o", linewidth=1.4, label=label,
                  linestyle="--" if dashed else "-")  # fmt: skip
        if low is not None and high is not None:
            axes.fill_between(xs, low, high, color=colour, alpha=0.15, linewidth=0)
            record.line(label, xs, mean.tolist(), low.tolist(), high.tolist())
        else:
            record.line(label, xs, mean.tolist())
    axes.set_yscale("log")
    # a log size axis, ticked at the sizes drawn (the book's doubling 47 ... 6,016)
    sizes = sorted({float(value) for _, x, _, _, _ in curves for value in x})
    axes.set_xscale("log", base=2)
    axes.set_xticks(sizes, [f"{size:,.0f}" for size in sizes])
    axes.minorticks_off()
    axes.set_xlabel("Gridworld size (#states)")
    axes.set_ylabel("Updates until optimal solution")
    axes.legend(loc="upper left", fontsize="small")
    axes.grid(alpha=0.3, which="both")
    axes.set_title(title)
    return figure
