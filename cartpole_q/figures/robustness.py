"""The robustness figure: a greedy policy's mean return as CartPole's physics vary."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from cartpole_q.figures.base import CURVE_SIZE, DPI, DataFigure


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
