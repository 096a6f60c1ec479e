"""Figures, drawn with matplotlib's object API (no pyplot state) on the Agg canvas.

The ``*_figure`` functions take arrays and return a :class:`DataFigure`: a matplotlib figure
that carries the numbers it draws (:class:`FigureData`), recorded by the same code that
draws them, so that every figure file goes out with its data beside it (``<figure>.csv``,
see :mod:`cartpole_q.store.figure_file`). ``cartpole-q plot`` and the studies load run
directories, draw with these functions, and write both.

One module per kind of figure: :mod:`~cartpole_q.figures.base` (the data, sizes, colours,
formats), :mod:`~cartpole_q.figures.curves`, :mod:`~cartpole_q.figures.maps`,
:mod:`~cartpole_q.figures.robustness`, :mod:`~cartpole_q.figures.sweeps`,
:mod:`~cartpole_q.figures.tune`, :mod:`~cartpole_q.figures.dp`,
:mod:`~cartpole_q.figures.bandits`, :mod:`~cartpole_q.figures.planning` and
:mod:`~cartpole_q.figures.linear`; every public name is here too.
"""

from __future__ import annotations

from cartpole_q.figures.bandits import (
    ALPHA,
    ParameterLine,
    parameter_study_figure,
    step_curves_figure,
)
from cartpole_q.figures.base import (
    BOOTSTRAP_RESAMPLES,
    CURVE_SIZE,
    DATA_COLUMNS,
    DPI,
    DRAWN_POINTS,
    FIGURE_FORMATS,
    POLICY_SIZE,
    Cell,
    DataFigure,
    FigureData,
    PanelData,
    cell_square,
    colour_cycle,
    drawable,
    drawn_points,
    figure_bytes,
    figure_png,
    text_outline,
)
from cartpole_q.figures.curves import (
    CURVE_POINTS,
    Curve,
    MetricBand,
    SeedBand,
    ValueChanges,
    bootstrap_band,
    draw_reward_curves,
    metric_curve_figure,
    moving_average,
    reward_curve_figure,
    summary_line_figure,
    value_changes_figure,
)
from cartpole_q.figures.dp import (
    GridPanel,
    book_round,
    car_rental_figure,
    dp_grid_figure,
    gambler_figure,
)
from cartpole_q.figures.linear import ErrorCurve, WeightsPanel, error_curves_figure, weights_figure
from cartpole_q.figures.maps import (
    GridMap,
    MapDimensions,
    action_names,
    blackjack_optimal_figure,
    blackjack_policy_figure,
    blackjack_values_figure,
    default_dims,
    dimension_names,
    draw_paths,
    grid_policy_figure,
    policy_figure,
    project_policy,
    reward_and_paths_figure,
)
from cartpole_q.figures.planning import (
    TrajectoryCurve,
    expected_vs_sample_figure,
    trajectory_sampling_figure,
    until_optimal_figure,
)
from cartpole_q.figures.robustness import (
    robustness_figure,
)
from cartpole_q.figures.sweeps import (
    PROFILE_MAX_POINTS,
    SWEEP_PANEL_SIZE,
    SweepAxis,
    compare_figure,
    draw_profiles,
    prediction_sweep_figure,
    profile_thresholds,
    sweep_figure,
)
from cartpole_q.figures.tune import (
    importance_figure,
    tune_history_figure,
)

__all__ = [
    "ALPHA",
    "BOOTSTRAP_RESAMPLES",
    "CURVE_POINTS",
    "CURVE_SIZE",
    "DATA_COLUMNS",
    "DPI",
    "DRAWN_POINTS",
    "FIGURE_FORMATS",
    "POLICY_SIZE",
    "PROFILE_MAX_POINTS",
    "SWEEP_PANEL_SIZE",
    "Cell",
    "Curve",
    "DataFigure",
    "ErrorCurve",
    "FigureData",
    "GridMap",
    "GridPanel",
    "MapDimensions",
    "MetricBand",
    "PanelData",
    "ParameterLine",
    "SeedBand",
    "SweepAxis",
    "TrajectoryCurve",
    "ValueChanges",
    "WeightsPanel",
    "action_names",
    "blackjack_optimal_figure",
    "blackjack_policy_figure",
    "blackjack_values_figure",
    "book_round",
    "bootstrap_band",
    "car_rental_figure",
    "cell_square",
    "colour_cycle",
    "compare_figure",
    "default_dims",
    "dimension_names",
    "dp_grid_figure",
    "draw_paths",
    "draw_profiles",
    "draw_reward_curves",
    "drawable",
    "drawn_points",
    "error_curves_figure",
    "expected_vs_sample_figure",
    "figure_bytes",
    "figure_png",
    "gambler_figure",
    "grid_policy_figure",
    "importance_figure",
    "metric_curve_figure",
    "moving_average",
    "parameter_study_figure",
    "policy_figure",
    "prediction_sweep_figure",
    "profile_thresholds",
    "project_policy",
    "reward_and_paths_figure",
    "reward_curve_figure",
    "robustness_figure",
    "step_curves_figure",
    "summary_line_figure",
    "sweep_figure",
    "text_outline",
    "trajectory_sampling_figure",
    "tune_history_figure",
    "until_optimal_figure",
    "value_changes_figure",
    "weights_figure",
]
