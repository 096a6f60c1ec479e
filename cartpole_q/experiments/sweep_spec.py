"""The sweep file: its axes over dotted config keys, its seeds, and the points they make.

A sweep file (design.md, "Sweep directory") names a base config, the seeds every point
runs, ``grid`` axes (their cartesian product, in file order, last axis fastest) and
``zip`` axes (moving together, one more axis after the grid's). Loading it checks
everything before any work starts: unknown keys (with the closest valid one), values
invalid for their key (naming the point and the key), empty axes, zip axes of different
lengths, and axes the sweep cannot vary (``seed``, ``train.seeds``).
"""

from __future__ import annotations

import difflib
import itertools
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from cartpole_q.config import (
    Config,
    ConfigError,
    format_seeds,
    load_config,
    parse_seeds,
    read_yaml_mapping,
    shown,
    shown_value,
)
from cartpole_q.experiments.study import StudyFile
from cartpole_q.store import sweepdir
from cartpole_q.store.sweepdir import axis_cell

SWEEP_KEYS = ("name", "base", "seeds", "grid", "zip", "curves", "figure")
"""the keys a sweep file may have"""
FORBIDDEN_AXES = ("seed", "train.seeds")
"""config keys a sweep cannot vary: its ``seeds`` say which seeds every point runs"""
DEFAULT_MAX_RUNS = 20_000
"""a sweep of more runs (points x seeds) needs ``--yes`` (or a larger ``--max-runs``)"""
_NAME = re.compile(r"[A-Za-z0-9_-]+")


@dataclass(frozen=True)
class Point:
    """One point of a sweep: its id, the axis values that define it, and its config."""

    index: int
    values: dict[str, Any]
    """axis key -> value, grid axes first (file order), then the zip axes"""
    config: Config
    """the point's resolved config (its ``seed`` is the base's; runs override it)"""


FIGURE_KEYS = (
    "metric", "x", "aggregate", "smooth", "log_y", "log_x", "title", "y_label", "offset", "scale",
    "reference", "reference_label", "x_max", "y_min", "y_max", "file", "against", "first",
    "distribution", "dashed", "arrows", "best", "total",
)  # fmt: skip
"""the keys of a sweep file's ``figure`` section"""


SWEEP_OWN_FILES = (
    sweepdir.SWEEP_FILE, sweepdir.RESULTS_FILE, sweepdir.POINTS_FILE, sweepdir.FIGURE_FILE,
)  # fmt: skip
"""the sweep directory's files a study figure (and its ``.csv``) must not replace"""


VALUES_FIGURE = "values"
"""``figure.metric: values``: each point's learned ``V`` against the state, beside the true
values (prediction; Sutton & Barto Example 6.2's left panel)"""

POLICY_FIGURE = "policy"
"""``figure.metric: policy``: each point's greedy policy and its values ``max_b Q``, beside
the exact optimal policy and ``v*`` from the world's model (control on a Blackjack world;
Sutton & Barto Figure 5.2); on a grid world, the first seed's table of each point as arrows
where its greedy action is set, blank where all its values are equal, over the cells its
training visited (Figures 7.4, 8.3)"""


@dataclass(frozen=True)
class FigureSpec:
    """The learning-curve figure a sweep draws of its points when it completes.

    The same curves as ``cartpole-q plot POINT ... --metric`` (one band per point, labelled
    with the point's axis values), with a textbook figure's own labels, a linear transform
    of the values (``(value + offset) * scale``) and an optional reference line.
    """

    metric: str
    """a learning-curve metric (``plot --metric``), or ``values``: each point's learned
    ``V`` per state (the mean over seeds, a 95% bootstrap interval), the policy's true
    values and the initial values beside them; or ``policy``: each point's greedy policy
    and ``max_b Q`` (of its seeds' mean ``Q``) beside the exact optimum (Blackjack)"""
    x: str = "episode"
    aggregate: str = "mean"
    smooth: int = 1
    log_y: bool = False
    log_x: bool = False
    """a logarithmic x axis (S&B Figures 5.3 and 5.4: episodes on a log scale)"""
    title: str | None = None
    y_label: str | None = None
    offset: float = 0.0
    scale: float = 1.0
    reference: float | None = None
    reference_label: str = "reference"
    x_max: float | None = None
    """where the x axis ends: the book's last step or episode (default: the longest seed's)"""
    y_min: float | None = None
    """where the y axis starts, as the book's figure (default: automatic)"""
    y_max: float | None = None
    """where the y axis ends (default: automatic)"""
    file: str = "figure.png"
    """written in the sweep directory: ``.png``, ``.svg`` or ``.pdf``"""
    against: str | None = None
    """an axis key: draw each point's mean of the metric per episode (over its ``first``
    episodes) against this axis's values, one line per value of the other axes, with a 95%
    bootstrap interval over seeds (S&B Fig. 12.10); ``None``: learning curves"""
    first: int | None = None
    """with ``against``: the episodes averaged (default: all)"""
    distribution: bool = False
    """with ``values``: also draw the evaluated policy's on-policy distribution ``mu`` (the
    fraction of time steps spent in each state, from the world's model) on a second y axis
    (Sutton & Barto Figure 9.1)"""
    best: dict[str, Any] | None = None
    """with ``against``: ``{AXIS: min}`` or ``{AXIS: max}``, another grid axis of numbers:
    at each value of ``against``, of the points that differ only in that axis the one whose
    mean over seeds is lowest (``min``) or highest (``max``) is drawn (the first in file
    order on a tie), its value of the axis kept in the figure's data (Sutton & Barto Figure
    12.14: each lambda at its best alpha)"""
    total: bool = False
    """with ``against``: a seed's value is the sum of the metric over its episodes (its
    ``first``), not the mean (failures in a run of so many steps: CartPole's
    ``sutton_barto_reward`` returns summed, Figure 12.14)"""
    arrows: bool = False
    """with ``values``: draw each point in a panel of its own, an arrow from each state's
    value before the run to its value after (the change the run makes: Sutton & Barto
    Figure 6.1)"""
    dashed: dict[str, Any] | None = None
    """with ``against``: ``{AXIS: VALUE}``, another axis and one of its values: the lines of
    the points at that value are dashed, and lines that differ only in that axis share a
    colour (Sutton & Barto Figure 6.3: interim dashed, asymptotic solid)"""

    def to_dict(self) -> dict[str, Any]:
        """The section as the resolved ``sweep.yaml`` holds it (every key)."""
        return {key: getattr(self, key) for key in FIGURE_KEYS}


@dataclass(frozen=True)
class SweepSpec:
    """A checked sweep: everything ``sweep.yaml`` holds, and the points it expands to."""

    name: str
    base: dict[str, Any]
    """the full resolved base config, as ``Config.to_dict`` gives it (``train.seeds`` null)"""
    seeds: tuple[int, ...]
    grid: dict[str, list[Any]]
    zip: dict[str, list[Any]]
    points: tuple[Point, ...]
    curves: bool = True
    """keep every run's per-episode returns and lengths in ``points/<p>/curves.npz``"""
    figure: FigureSpec | None = None
    """the learning-curve figure drawn when the sweep completes"""

    @property
    def axes(self) -> list[str]:
        """The axis keys, grid axes first, then the zip axes: one column each."""
        return [*self.grid, *self.zip]

    @property
    def runs(self) -> int:
        """Points times seeds."""
        return len(self.points) * len(self.seeds)

    def point_id(self, index: int) -> str:
        """The point's directory name: its index zero-padded to at least 3 digits."""
        return f"{index:0{max(3, len(str(len(self.points) - 1)))}d}"

    def seed_key(self, seed: int) -> str:
        """The key of a seed's table in ``q_tables.npz``, padded like ``train --seeds``."""
        return sweepdir.seed_key(seed, self.seeds)

    def to_dict(self) -> dict[str, Any]:
        """The resolved sweep, as ``sweep.yaml`` holds it (loading it gives this sweep back)."""
        resolved: dict[str, Any] = {
            "name": self.name,
            "base": self.base,
            "seeds": format_seeds(self.seeds),
            "grid": self.grid,
        }
        if self.zip:
            resolved["zip"] = self.zip
        if not self.curves:
            resolved["curves"] = False
        if self.figure is not None:
            resolved["figure"] = self.figure.to_dict()
        return resolved


def load_sweep(
    source: Path | Mapping[str, Any],
    *,
    label: str | None = None,
    base_dir: Path | None = None,
    default_name: str = "sweep",
) -> SweepSpec:
    """Read and check a sweep file (or a mapping laid out like one) and expand its points.

    Args:
        source: a sweep YAML file, or a mapping with the same keys.
        label: how errors name the sweep (default: the file's path, or "sweep mapping").
        base_dir: for a mapping, the directory a ``base`` path in it is relative to
            (default: the current directory).
        default_name: for a mapping, its name when it gives none.

    Returns:
        The checked sweep, every point's config resolved and validated.

    Raises:
        ConfigError: naming the file, the key (and the point) and what is wrong.
    """
    if isinstance(source, Mapping):
        raw: Mapping[str, Any] = source
        where = label or "sweep mapping"
        base_dir = base_dir or Path()
    else:
        raw = read_yaml_mapping(source, "sweep file")
        where = label or str(source)
        base_dir = source.parent
        default_name = safe_name(source.stem)
    if not raw:
        raise ConfigError(
            f"{where}: is empty; a sweep file gives `grid` (or `zip`) axes over config keys, "
            "and usually `base` and `seeds` (see docs/commands.md, `cartpole-q sweep`)."
        )
    kind = raw.get("kind", "sweep")
    if kind != "sweep":
        raise ConfigError(
            f"{where}: kind: is {shown_value(kind)}, not sweep; run it with `cartpole-q study "
            f"{where}`."
        )
    raw = {key: value for key, value in raw.items() if key != "kind"}
    check_top_keys(raw, SWEEP_KEYS, where)
    name = checked_name(raw, default_name, where)
    base = load_base(raw.get("base"), where, base_dir)
    curves = raw.get("curves", True)
    if not isinstance(curves, bool):
        raise ConfigError(
            f"{where}: curves: must be true (keep every run's learning curve) or false, got "
            f"{shown_value(curves)}."
        )
    try:
        seeds = parse_seeds(raw.get("seeds", base.seed))
    except ValueError as error:
        raise ConfigError(f"{where}: seeds: {error}") from None
    grid = _axes(raw.get("grid"), "grid", where)
    zipped = _axes(raw.get("zip"), "zip", where, each_distinct=False)
    lengths = {key: len(values) for key, values in zipped.items()}
    if len(set(lengths.values())) > 1:
        shown = ", ".join(f"{key} has {n}" for key, n in lengths.items())
        raise ConfigError(
            f"{where}: zip: its axes move together, so they need the same number of values "
            f"({shown})."
        )
    # The zip group is one axis: its tuples must differ (one key may repeat a value, as
    # TD's and MC's step sizes beside agent.algorithm: [td, td, mc_prediction, ...]).
    tuples = [
        tuple(axis_cell(values[i]) for values in zipped.values())
        for i in range(len(next(iter(zipped.values()), [])))
    ]
    twice = next((cells for cells in tuples if tuples.count(cells) > 1), None)
    if twice is not None:
        raise ConfigError(
            f"{where}: zip: gives the values {', '.join(twice)} twice; each point must differ."
        )
    for key in zipped:
        if key in grid:
            raise ConfigError(
                f"{where}: zip.{key}: is a grid axis too; a key can be one axis only."
            )
    check_overlaps([*grid, *zipped], where)
    base_mapping = base.to_dict()
    points = _expand(name, base_mapping, grid, zipped, where)
    figure = _figure(raw.get("figure"), curves, where)
    if figure is not None:
        _check_info_metric(figure.metric, points, where)
    if figure is not None and figure.against is not None:
        _check_against(figure.against, {**grid, **zipped}, where)
    if figure is not None and figure.dashed is not None:
        _check_dashed(figure, grid, where)
    if figure is not None and (figure.best is not None or figure.total):
        _check_best(figure, grid, curves, where)
    return SweepSpec(name, base_mapping, seeds, grid, zipped, points, curves, figure)


def _check_against(key: str, axes: Mapping[str, list[Any]], where: str) -> None:
    """``figure.against`` names an axis of numbers."""
    if key not in axes:
        raise ConfigError(
            f"{where}: figure.against: {shown(key)} is not an axis of this sweep "
            f"({', '.join(axes) or 'it has none'})."
        )
    if not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in axes[key]):
        raise ConfigError(
            f"{where}: figure.against: the axis {key} must hold numbers to be drawn against."
        )


def _check_dashed(figure: FigureSpec, grid: Mapping[str, list[Any]], where: str) -> None:
    """``figure.dashed`` names one grid axis (not ``against``) and one of its values."""
    dashed = figure.dashed or {}
    if figure.against is None:
        raise ConfigError(
            f"{where}: figure.dashed: styles the lines drawn against an axis; give "
            "figure.against too."
        )
    if len(dashed) != 1:
        raise ConfigError(
            f"{where}: figure.dashed: must be one grid axis and one of its values, such as "
            f"{{train.episodes: 100}}, got {shown_value(dashed)}."
        )
    key, value = next(iter(dashed.items()))
    others = [axis for axis in grid if axis != figure.against]
    if key not in others:
        raise ConfigError(
            f"{where}: figure.dashed: {shown(key)} is not a grid axis other than "
            f"figure.against ({', '.join(others) or 'there is none'})."
        )
    if axis_cell(value) not in [axis_cell(v) for v in grid[key]]:
        raise ConfigError(
            f"{where}: figure.dashed: {shown_value(value)} is not a value of the axis {key} "
            f"({', '.join(axis_cell(v) for v in grid[key])})."
        )


def _check_best(
    figure: FigureSpec, axes: Mapping[str, list[Any]], curves: bool, where: str
) -> None:
    """``figure.best`` names one axis (not ``against``) and ``min`` or ``max``.

    Both keys need ``against``, and ``total`` the curves.
    """
    key = "best" if figure.best is not None else "total"
    if figure.against is None:
        raise ConfigError(
            f"{where}: figure.{key}: works on the points drawn against an axis; give "
            "figure.against too."
        )
    if figure.total and not curves:
        raise ConfigError(
            f"{where}: figure.total: sums each run's curve, and curves: false keeps none; "
            "keep the curves (curves: true)."
        )
    if figure.best is None:
        return
    if len(figure.best) != 1:
        raise ConfigError(
            f"{where}: figure.best: must be one axis and min or max, such as "
            f"{{agent.alpha: min}}, got {shown_value(figure.best)}."
        )
    axis, rule = next(iter(figure.best.items()))
    others = [name for name in axes if name != figure.against]
    if axis not in others:
        raise ConfigError(
            f"{where}: figure.best: {shown(axis)} is not a grid axis other than "
            f"figure.against ({', '.join(others) or 'there is none'})."
        )
    if not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in axes[axis]):
        raise ConfigError(
            f"{where}: figure.best: the axis {axis} must hold numbers (the figure's data names "
            "the value chosen at each point)."
        )
    if rule not in ("min", "max"):
        raise ConfigError(
            f"{where}: figure.best: {axis}: must be min (the lowest mean is best: steps, "
            f"errors) or max (returns), got {shown_value(rule)}."
        )
    if figure.dashed is not None and axis in figure.dashed:
        raise ConfigError(
            f"{where}: figure.best: {axis} is figure.dashed's axis too; a line cannot both "
            "pick its best value of an axis and be styled by one."
        )


def _check_info_metric(metric: str, points: Sequence[Point], where: str) -> None:
    """Refuse a figure metric some point does not record.

    ``info:KEY`` needs every point to record KEY; ``rms_error`` needs every point to run a
    prediction algorithm.
    """
    from cartpole_q.learning_curves import ERROR_METRIC, info_key_of
    from cartpole_q.rl.algorithms import get as get_algorithm

    if metric == POLICY_FIGURE:
        from cartpole_q.families import profile_for

        for point in points:
            config = point.config
            if get_algorithm(config.agent.algorithm).predicts:
                raise ConfigError(
                    f"{where}: figure.metric: policy draws a control run's greedy policy, but "
                    f"point {point.index} runs agent.algorithm {config.agent.algorithm}, a "
                    "prediction algorithm; draw values of it instead."
                )
            profile = profile_for(config.env.id)
            if profile.grid is not None and config.discretization is None:
                continue  # a grid world: Figures 7.4 and 8.3, arrows where a greedy action is set
            if profile.policy_map == "racetrack":
                continue  # Figure 5.5: trajectories on the track
            if profile.policy_map != "blackjack":
                raise ConfigError(
                    f"{where}: figure.metric: policy draws Blackjack's policy as Sutton & "
                    f"Barto's Figure 5.2, or a grid world's arrows as Figures 7.4 and 8.3, but "
                    f"point {point.index} plays {config.env.id}; it needs a Blackjack world "
                    "(Blackjack-v1, cartpole_q/BlackjackES-v0) or a grid world "
                    "(cartpole_q/DynaMaze-v0, FrozenLake-v1, ...)."
                )
            if config.agent.gamma != 1.0:
                raise ConfigError(
                    f"{where}: figure.metric: policy compares with Blackjack's undiscounted "
                    f"optimum, but point {point.index} learns with agent.gamma "
                    f"{config.agent.gamma:g}; give agent.gamma: 1."
                )
        return
    if metric in (ERROR_METRIC, VALUES_FIGURE):
        for point in points:
            algorithm = point.config.agent.algorithm
            if not get_algorithm(algorithm).predicts:
                raise ConfigError(
                    f"{where}: figure.metric: {metric} is a prediction run's (V), but "
                    f"point {point.index} runs agent.algorithm {algorithm}, a control "
                    "algorithm; draw return, length, ... of it, or make every point predict."
                )
    key = info_key_of(metric)
    if key is None:
        return
    for point in points:
        if point.config.train.info_metric != key:
            recorded = point.config.train.info_metric
            raise ConfigError(
                f"{where}: figure.metric: info:{key} draws each episode's sum of info[{shown(key)}], "
                f"but point {point.index} sets train.info_metric: {recorded or 'null'}; put "
                f"train: {{info_metric: {key}}} in the base."
            )


def _figure(raw: Any, curves: bool, where: str) -> FigureSpec | None:
    """Check a sweep file's ``figure`` section (None when it has none)."""
    from cartpole_q.learning_curves import AGGREGATES, METRICS, X_AXES, check_metric

    if raw is None:
        return None
    if not isinstance(raw, Mapping):
        raise ConfigError(
            f"{where}: figure: must be a mapping such as {{metric: length, x: episode}}, got "
            f"{shown_value(raw)}."
        )
    check_top_keys(raw, FIGURE_KEYS, f"{where}: figure")
    values = dict(raw)
    from_results = values.get("metric") == "return" and values.get("first") is None
    if not curves and not (values.get("against") is not None and from_results):
        raise ConfigError(
            f"{where}: figure: is drawn from the learning curves, but the sweep says curves: "
            "false; keep the curves or leave the figure out (only the mean return over all "
            "episodes against an axis, metric: return with against and no first, is drawn "
            "from results.csv's mean_return)."
        )
    choices = {"x": X_AXES, "aggregate": AGGREGATES}
    if "metric" not in values:
        raise ConfigError(
            f"{where}: figure.metric: is missing; one of {', '.join(METRICS)}, or info:KEY."
        )
    metric = values["metric"]
    problem = check_metric(metric) if isinstance(metric, str) else "not a string"
    if metric in (VALUES_FIGURE, POLICY_FIGURE):
        problem = None
        if values.get("against") is not None:
            raise ConfigError(
                f"{where}: figure.against: draws a metric against an axis; metric: {metric} "
                "draws a table against the state, so leave one of them out."
            )
    if problem is not None:
        raise ConfigError(f"{where}: figure.metric: {shown_value(metric)} is {problem}.")
    if values.get("arrows") and metric != VALUES_FIGURE:
        raise ConfigError(
            f"{where}: figure.arrows: draws the change of each state's value as an arrow; it "
            "needs metric: values."
        )
    if values.get("distribution") and metric != VALUES_FIGURE:
        raise ConfigError(
            f"{where}: figure.distribution: draws the on-policy distribution beside the values "
            "of the states; it needs metric: values."
        )
    for key, allowed in choices.items():
        if key in values and values[key] not in allowed:
            raise ConfigError(
                f"{where}: figure.{key}: {shown_value(values[key])} is not one of "
                f"{', '.join(allowed)}."
            )
    kinds: dict[str, tuple[type, ...]] = {
        "smooth": (int,), "log_y": (bool,), "log_x": (bool,), "title": (str,), "y_label": (str,),
        "offset": (int, float), "scale": (int, float), "reference": (int, float),
        "reference_label": (str,), "x_max": (int, float), "file": (str,),
        "against": (str,), "first": (int,), "y_min": (int, float), "y_max": (int, float),
        "distribution": (bool,), "dashed": (Mapping,), "arrows": (bool,), "best": (Mapping,),
        "total": (bool,),
    }  # fmt: skip
    for key, kind in kinds.items():
        value = values.get(key)
        wrong_bool = isinstance(value, bool) and bool not in kind
        if value is not None and (not isinstance(value, kind) or wrong_bool):
            raise ConfigError(
                f"{where}: figure.{key}: {shown_value(value)} is not a "
                f"{' or '.join(k.__name__ for k in kind)}."
            )
    if values.get("smooth", 1) < 1:
        raise ConfigError(f"{where}: figure.smooth: must be at least 1, got {values['smooth']}.")
    file = values.get("file", "figure.png")
    if "/" in file or Path(file).suffix.lower() not in (".png", ".svg", ".pdf"):
        raise ConfigError(
            f"{where}: figure.file: {shown(file)} must be a file name in the sweep directory "
            "ending in .png, .svg or .pdf."
        )
    # The figure's data goes beside it as <stem>.csv: it must not replace the sweep's files.
    taken = {Path(name).stem.lower() for name in SWEEP_OWN_FILES}
    if Path(file).stem.lower() in taken:
        raise ConfigError(
            f"{where}: figure.file: {file!r} would write {Path(file).stem}.csv beside it, "
            f"which the sweep's own files ({', '.join(SWEEP_OWN_FILES)}) need; choose "
            "another name."
        )
    if values.get("first") is not None and values["first"] < 1:
        raise ConfigError(f"{where}: figure.first: must be at least 1, got {values['first']}.")
    if values.get("x_max") is not None and values["x_max"] <= 0:
        raise ConfigError(f"{where}: figure.x_max: must be positive, got {values['x_max']}.")
    low, high = values.get("y_min"), values.get("y_max")
    if low is not None and high is not None and not low < high:
        raise ConfigError(f"{where}: figure.y_min: must be below figure.y_max ({low} >= {high}).")
    for key in ("offset", "scale", "reference", "x_max", "y_min", "y_max"):
        if values.get(key) is not None:
            values[key] = float(values[key])
    for key in ("dashed", "best"):
        if values.get(key) is not None:
            values[key] = dict(values[key])
    return FigureSpec(**values)


def check_top_keys(raw: Mapping[str, Any], valid: tuple[str, ...], where: str) -> None:
    """Refuse a key a sweep or tune file does not know, suggesting the closest valid one.

    Raises:
        ConfigError: naming the file and the key.
    """
    for key in raw:
        if key not in valid:
            close = difflib.get_close_matches(str(key), valid, n=1)
            hint = (
                f"; did you mean {close[0]!r}?" if close else f"; valid keys: {', '.join(valid)}."
            )
            raise ConfigError(f"{where}: unknown key {shown(key)}{hint}")


def checked_name(raw: Mapping[str, Any], default: str, where: str) -> str:
    """The file's ``name`` (it names the directory): letters, digits, '-' and '_'.

    Raises:
        ConfigError: any other name.
    """
    name = raw.get("name", default)
    if not isinstance(name, str) or not _NAME.fullmatch(name):
        raise ConfigError(
            f"{where}: name: must be letters, digits, '-' or '_' (it names the directory), "
            f"got {shown_value(name)}."
        )
    return name


def check_overlaps(keys: list[str], where: str) -> None:
    """Refuse two keys where one holds the other (``agent`` and ``agent.alpha``).

    Both would set the inner key, and the row would name a value the run did not use.

    Raises:
        ConfigError: naming both keys.
    """
    for key in keys:
        for other in keys:
            if other != key and other.startswith(f"{key}."):
                raise ConfigError(
                    f"{where}: {key} and {other}: one key holds the other, so both would set "
                    f"{other}; vary it through one of them only."
                )


def safe_name(stem: str) -> str:
    """A file name's stem as a sweep or tune name: letters, digits, '-' and '_'."""
    cleaned = re.sub(r"[^A-Za-z0-9_-]+", "-", stem).strip("-")
    return cleaned or "sweep"


def load_base(base: Any, where: str, base_dir: Path) -> Config:
    """The base config: a file (relative to the sweep file), a shipped name, or a mapping."""
    if base is None:
        config = load_config()
    elif isinstance(base, Mapping):
        config = load_config(base, source=f"{where}: base")
    elif isinstance(base, str) and base.strip():
        looks_like_a_path = "/" in base or base.endswith((".yaml", ".yml"))
        if looks_like_a_path:  # relative to the sweep file, never to the current directory
            path = base_dir / base
            if not path.is_file():
                raise ConfigError(
                    f"{where}: base: {path} is not a file (a base path is relative to the "
                    "sweep file)."
                )
            config = load_config(path)
        else:
            config = load_config(base)  # a shipped config's name
    else:
        raise ConfigError(
            f"{where}: base: must be a config file (relative to the sweep file), the name of "
            f"a shipped config, or a mapping of config keys; got {shown_value(base)}."
        )
    # The sweep's own seeds say which seeds every point runs.
    return config.for_seed(config.seed)


def _axes(axes: Any, section: str, where: str, each_distinct: bool = True) -> dict[str, list[Any]]:
    """Check one axes section: dotted keys mapped to non-empty lists of values.

    With ``each_distinct`` (a grid) no axis may repeat a value; a zip group's axes may (its
    tuples are checked instead).
    """
    if axes is None:
        return {}
    if not isinstance(axes, Mapping):
        raise ConfigError(
            f"{where}: {section}: must map dotted config keys to lists of values, e.g. "
            f"{section}: {{agent.alpha: [0.1, 0.3]}}."
        )
    checked: dict[str, list[Any]] = {}
    for key, values in axes.items():
        if not isinstance(key, str) or not key:
            raise ConfigError(f"{where}: {section}: {shown(key)} is not a dotted config key.")
        if key in FORBIDDEN_AXES or key.startswith("train.seeds."):
            raise ConfigError(
                f"{where}: {section}.{key}: cannot be an axis; the sweep's `seeds` say which "
                "seeds every point runs (and each result row names its seed)."
            )
        if not isinstance(values, list):
            raise ConfigError(
                f"{where}: {section}.{key}: must be a list of the values to try, got "
                f"{shown_value(values)}."
            )
        if not values:
            raise ConfigError(
                f"{where}: {section}.{key}: is empty; an axis needs at least one value."
            )
        cells = [axis_cell(value) for value in values]
        twice = next((cell for cell in cells if cells.count(cell) > 1), None)
        if twice is not None and each_distinct:
            raise ConfigError(
                f"{where}: {section}.{key}: has the value {twice} twice; each point must differ."
            )
        checked[key] = values
    return checked


def _expand(
    name: str,
    base: dict[str, Any],
    grid: dict[str, list[Any]],
    zipped: dict[str, list[Any]],
    where: str,
) -> tuple[Point, ...]:
    """Every point: the grid's product (last axis fastest), then the zip group as one axis."""
    grid_values = list(itertools.product(*grid.values()))
    zip_values = list(zip(*zipped.values(), strict=True)) if zipped else [()]
    count = len(grid_values) * len(zip_values)
    width = max(3, len(str(count - 1)))
    points: list[Point] = []
    for combination in itertools.product(grid_values, zip_values):
        values = dict(zip([*grid, *zipped], [*combination[0], *combination[1]], strict=True))
        index = len(points)
        overrides = {"name": f"{name}-{index:0{width}d}", **values}
        shown = ", ".join(f"{key}={axis_cell(value)}" for key, value in values.items())
        label = f"{where}: point {index:0{width}d}" + (f" ({shown})" if shown else "")
        # The base was checked alone: whatever is wrong now comes with the point's values.
        config = load_config(base, overrides, source=label, override_source=label)
        points.append(Point(index, values, config))
    return tuple(points)


def checked_list(raw: Mapping[str, Any], key: str, where: str) -> list[Any]:
    """A study file's ``key``: a list (empty when left out).

    Raises:
        ConfigError: it is there and not a list.
    """
    value = raw.get(key, [])
    if not isinstance(value, list):
        raise ConfigError(f"{where}: {key}: must be a list, got {shown_value(value)}.")
    return value


def checked_figure_section(
    raw: Any, name: str, where: str, keys: Sequence[str], kinds: Sequence[str]
) -> tuple[str, str, str]:
    """A study file's ``figure`` section's common keys: its ``kind``, ``file`` and ``title``.

    Args:
        raw: the section as read.
        name: the study's name (the default file is ``<name>.png``, the default title it).
        where: the file, for messages.
        keys: every key the section may hold.
        kinds: the ``kind`` values it takes (the first is the example in messages).

    Raises:
        ConfigError: naming the key: not a mapping, an unknown key or kind, a file that is
            not a bare ``.png``, ``.svg`` or ``.pdf`` name, a title that is not text.
    """
    if not isinstance(raw, Mapping):
        raise ConfigError(
            f"{where}: figure: must be a mapping such as {{kind: {kinds[0]}, file: {name}.png}}, "
            f"got {shown_value(raw)}."
        )
    check_top_keys(raw, tuple(keys), f"{where}: figure")
    kind = raw.get("kind")
    if kind not in kinds:
        raise ConfigError(
            f"{where}: figure.kind: must be one of {', '.join(kinds)}, got {shown_value(kind)}."
        )
    file = raw.get("file", f"{name}.png")
    if (
        not isinstance(file, str)
        or "/" in file
        or Path(file).suffix.lower() not in (".png", ".svg", ".pdf")
    ):
        raise ConfigError(
            f"{where}: figure.file: must be a file name ending in .png, .svg or .pdf, got "
            f"{shown_value(file)}."
        )
    title = raw.get("title", name)
    if not isinstance(title, str):
        raise ConfigError(f"{where}: figure.title: must be text, got {shown_value(title)}.")
    return str(kind), file, title


def checked_study(
    study: StudyFile, keys: Sequence[str], gives: str, example: str
) -> tuple[Mapping[str, Any], str, str]:
    """A study file's mapping (``kind`` aside), its name for messages, and its study name.

    Args:
        study: the file as read.
        keys: its top-level keys (besides ``kind``).
        gives: what a study file gives, for the message of an empty one.
        example: a shipped study file to point to.

    Raises:
        ConfigError: an empty file, an unknown key, a bad name.
    """
    raw, where = study.body, study.where
    if not raw:
        raise ConfigError(f"{where}: is empty; a study file gives {gives} (see {example}).")
    check_top_keys(raw, tuple(keys), where)
    return raw, where, checked_name(raw, safe_name(study.stem), where)
