"""Linear function approximation studies (``kind: linear``): Figures 9.5, 9.10, 11.2, 11.5, 11.6.

A study file names a world with a transition table, a target and a behaviour policy, and
curves: each an algorithm (:mod:`cartpole_q.rl.linear`) on a feature layer
(:mod:`cartpole_q.rl.features`) with its step sizes. Each curve runs once per seed (an
expected algorithm once: it draws nothing) for ``episodes`` (an episodic world) or
``steps`` (a continuing one, or sweeps), recording the weights, ``√VE`` and ``√PBE`` every
``record_every``. The figure is either the errors of every curve against the episodes
(``figure.kind: errors``, Figures 9.5, 9.10) or one panel per curve with its weights and
errors (``weights``, Figures 11.2, 11.5, 11.6), averaged over the runs; the fixed points
(least ``VE``, the TD fixed point) are printed, and drawn as levels on an errors figure.
"""

from __future__ import annotations

import contextlib
import functools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from cartpole_q.config import ConfigError, parse_seeds, shown_value
from cartpole_q.config.bounds import check_count, check_memory
from cartpole_q.experiments.study import (
    CurveFunctions,
    CurvesKind,
    Finished,
    RunHandle,
    StudyFile,
    register_kind,
)
from cartpole_q.experiments.sweep_spec import check_top_keys, checked_figure_section, checked_study
from cartpole_q.progress import Units
from cartpole_q.rl import features as layers
from cartpole_q.rl import linear as methods
from cartpole_q.rl.solvers import one_thread
from cartpole_q.store.studydir import Cell, RunRecord

STUDY_KEYS = (
    "name", "world", "gamma", "seeds", "episodes", "steps", "record_every", "engine", "target",
    "behaviour", "errors", "curves", "figure", "book",
)  # fmt: skip
"""the keys a linear study file may have"""
WORLD_KEYS = ("id", "kwargs")
CURVE_KEYS = ("label", "algorithm", "features", "alpha", "beta", "epsilon", "w0")
FEATURE_KEYS = {
    "table": ("kind",),
    "tiles": ("kind", "bins", "low", "high", "tilings"),
    "polynomial": ("kind", "order"),
    "fourier": ("kind", "order"),
    "declared": ("kind",),
}
"""each feature layer's keys"""
FIGURE_KINDS = ("errors", "weights")
FIGURE_KEYS = ("kind", "file", "title", "y_min", "y_max", "log_y", "fixed_points", "show_errors")
MEASURES = ("ve", "pbe")
"""the errors a study may record: ``√VE`` and ``√PBE``"""
BOOK_KEYS = ("label", "curve", "at", "of", "value", "below", "text")
ENGINES = ("numba", "gymnasium")
ERROR_NAMES = {"ve": "√VE", "pbe": "√PBE"}
EXAMPLE = "examples/book/fig11_2_baird.yaml"


@dataclass(frozen=True)
class FeatureSpec:
    """A curve's feature layer, as its ``features`` mapping gives it."""

    kind: str
    order: int = 0
    bins: tuple[int, ...] = ()
    low: tuple[float, ...] = ()
    high: tuple[float, ...] = ()
    tilings: int = 1

    def text(self) -> str:
        """``Fourier order 5``, ``50 tilings of 5 tiles``, ``the table``, ``declared features``."""
        if self.kind in ("polynomial", "fourier"):
            return f"{'Fourier' if self.kind == 'fourier' else 'polynomial'} order {self.order}"
        if self.kind == "tiles":
            tiles = " x ".join(str(b) for b in self.bins)
            return f"{self.tilings} tiling{'s' if self.tilings != 1 else ''} of {tiles} tiles"
        return "the table" if self.kind == "table" else "declared features"


@dataclass(frozen=True)
class CurveSpec:
    """One curve: an algorithm on a layer, its step sizes and its starting weights."""

    label: str
    algorithm: str
    features: FeatureSpec
    alpha: float
    beta: float
    epsilon: float
    w0: tuple[float, ...]
    """one number (every weight) or one per weight"""

    @property
    def expected(self) -> bool:
        """Whether it sweeps the model (one run) rather than stepping the world."""
        return self.algorithm in methods.EXPECTED


@dataclass(frozen=True)
class BookNumber:
    """What the book shows at one point of one curve: a number read off the figure, or a claim."""

    label: str
    curve: int
    at: int
    of: str
    """``ve``, ``pbe`` or ``w<i>`` (a weight, 1-based as the book numbers them)"""
    value: float | None
    below: int | None
    """the curve the book shows this one below (at ``at``), or ``None``"""
    text: str
    decimals: int


@dataclass(frozen=True)
class Study:
    """A checked linear study file."""

    name: str
    world_id: str
    world_kwargs: tuple[tuple[str, Any], ...]
    gamma: float
    seeds: tuple[int, ...]
    count: int
    """episodes (episodic world) or steps (continuing)"""
    continuing: bool
    record_every: int
    engine: str
    target: tuple[float, ...]
    behaviour: tuple[float, ...]
    uniform_behaviour: bool
    errors: tuple[str, ...]
    curves: tuple[CurveSpec, ...]
    figure_kind: str
    file: str
    title: str
    y_limits: tuple[float | None, float | None]
    log_y: bool
    fixed_points: bool
    book: tuple[BookNumber, ...]
    where: str
    show_errors: bool = True
    """a weights figure draws the errors beside the weights"""

    @property
    def unit(self) -> str:
        """What the count counts: ``episodes`` or ``steps``."""
        return "steps" if self.continuing else "episodes"


# -- reading --------------------------------------------------------------------------------


def read_study(study: StudyFile) -> Study:
    """Check a linear study file (and its world: it is made once, to read its table).

    Raises:
        ConfigError: naming the file and the key, with what is wrong.
    """
    raw, where, name = checked_study(
        study, STUDY_KEYS, "a `world`, `curves` and `episodes` or `steps`", EXAMPLE
    )
    world_id, world_kwargs = world_key(raw.get("world"), where)
    facts = world_facts(world_id, world_kwargs, where)
    gamma = number_of(raw, "gamma", 1.0, where)
    if not 0.0 <= gamma <= 1.0:
        raise ConfigError(f"{where}: gamma: must be in [0, 1], got {gamma:g}.")
    if facts.continuing and gamma >= 1.0:
        raise ConfigError(
            f"{where}: gamma: {world_id} is continuing (nothing ends), so its values need "
            f"gamma < 1, got {gamma:g}."
        )
    count = _count_of(raw, facts.continuing, world_id, where)
    seeds = seeds_of(raw, where)
    record_every = whole_of(raw, "record_every", 1, where, 1)
    check_count(where, "record_every", record_every)
    engine = raw.get("engine", "numba")
    if engine not in ENGINES:
        raise ConfigError(
            f"{where}: engine: must be one of {', '.join(ENGINES)}, got {shown_value(engine)}."
        )
    n = facts.n_actions
    target, _ = _policy(raw.get("target", "random"), "target", n, where)
    behaviour, uniform = _policy(
        raw.get("behaviour", raw.get("target", "random")), "behaviour", n, where
    )
    for a in range(n):
        if target[a] > 0.0 and behaviour[a] == 0.0:
            raise ConfigError(
                f"{where}: behaviour: never takes action {a}, which the target takes: the "
                "behaviour must cover the target (b(a) > 0 wherever π(a) > 0)."
            )
    errors = _errors(raw.get("errors", ["ve"]), where)
    curves_raw = raw.get("curves")
    if not isinstance(curves_raw, list) or not curves_raw:
        raise ConfigError(
            f"{where}: curves: must be a list such as [{{label: TD, algorithm: "
            f"semi_gradient_td, features: {{kind: fourier, order: 5}}, alpha: 0.0001}}], got "
            f"{shown_value(curves_raw)}."
        )
    on_policy = behaviour == target
    curves = tuple(
        _curve(entry, index, facts, on_policy, where) for index, entry in enumerate(curves_raw)
    )
    records = count // record_every + 2
    for index, curve in enumerate(curves):
        rows, width, weights = _layer_size(curve.features, facts)
        runs = 1 if curve.expected else len(seeds)
        needed = rows * width * 16 + runs * records * (weights + len(errors)) * 8
        if curve.algorithm == "lstd" or "pbe" in errors:
            needed += weights * weights * 8 * 3
        check_memory(where, f"curves[{index}].features", needed,
                     f"{curve.features.text()} on {rows:,} states, {runs:,} run{'s' if runs != 1 else ''} "
                     f"of {records:,} records")  # fmt: skip
    kind, file, title = checked_figure_section(
        raw.get("figure", {"kind": "errors"}), name, where, FIGURE_KEYS, FIGURE_KINDS
    )
    figure = raw.get("figure", {})
    y_limits = (
        optional_number_of(figure, "y_min", where),
        optional_number_of(figure, "y_max", where),
    )
    log_y = flag_of(figure, "log_y", False, where)
    fixed_points = flag_of(figure, "fixed_points", kind == "errors", where)
    show_errors = flag_of(figure, "show_errors", True, where)
    book_raw = raw.get("book", [])
    if not isinstance(book_raw, list):
        raise ConfigError(f"{where}: book: must be a list, got {shown_value(book_raw)}.")
    book = tuple(
        _book(entry, index, curves, count, errors, facts, where)
        for index, entry in enumerate(book_raw)
    )
    return Study(
        name, world_id, world_kwargs, gamma, seeds, count, facts.continuing, record_every,
        str(engine), target, behaviour, uniform, errors, curves, kind, file, title, y_limits,
        log_y, fixed_points, book, where, show_errors,
    )  # fmt: skip


def world_key(raw: Any, where: str) -> tuple[str, tuple[tuple[str, Any], ...]]:
    """The ``world`` mapping's id and its kwargs (sorted pairs), checked."""
    if not isinstance(raw, Mapping) or not isinstance(raw.get("id"), str):
        raise ConfigError(
            f"{where}: world: must be a mapping with the world's id, such as {{id: "
            f"cartpole_q/Baird-v0}} or {{id: cartpole_q/RandomWalk1000-v0, kwargs: {{position: "
            f"true}}}}, got {shown_value(raw)}."
        )
    check_top_keys(raw, WORLD_KEYS, f"{where}: world")
    kwargs = raw.get("kwargs", {}) or {}
    if not isinstance(kwargs, Mapping):
        raise ConfigError(f"{where}: world.kwargs: must be a mapping, got {shown_value(kwargs)}.")
    return str(raw["id"]), tuple(sorted((str(k), v) for k, v in kwargs.items()))


def _count_of(raw: Mapping[str, Any], continuing: bool, world_id: str, where: str) -> int:
    """``steps`` on a continuing world, ``episodes`` on an episodic one (the other refused)."""
    given, other = ("steps", "episodes") if continuing else ("episodes", "steps")
    if other in raw:
        nature = "continuing: nothing ever ends" if continuing else "episodic"
        raise ConfigError(f"{where}: {other}: {world_id} is {nature}; give `{given}` instead.")
    if given not in raw:
        raise ConfigError(f"{where}: {given}: is missing; how many {given} each run lasts.")
    count = whole_of(raw, given, None, where, 1)
    check_count(where, given, count)
    return count


def seeds_of(raw: Mapping[str, Any], where: str) -> tuple[int, ...]:
    """The ``seeds`` key as run seeds (``0-29``, a list, a number)."""
    try:
        return parse_seeds(raw.get("seeds", 0))
    except ValueError as error:
        raise ConfigError(f"{where}: seeds: {error}") from None


def _policy(raw: Any, key: str, n: int, where: str) -> tuple[tuple[float, ...], bool]:
    """``random`` (uniform, drawn by ``rng.integers``) or ``n`` probabilities (``"6/7"`` allowed)."""
    if raw == "random":
        return tuple(1.0 / n for _ in range(n)), True
    values: list[float] = []
    for item in raw if isinstance(raw, list) else []:
        number = fraction_of(item)
        if number is None or number < 0.0:
            values = []
            break
        values.append(number)
    if len(values) != n or abs(math.fsum(values) - 1.0) > 1e-9:
        raise ConfigError(
            f"{where}: {key}: must be `random` or a list of {n} probabilities, one per action, "
            f'summing to 1 (numbers or fractions such as "6/7"), got {shown_value(raw)}.'
        )
    return tuple(values), False


def fraction_of(item: Any) -> float | None:
    """A number, or text ``a/b`` read as ``a / b`` (float64), else ``None``."""
    if isinstance(item, bool):
        return None
    if isinstance(item, (int, float)):
        return float(item) if math.isfinite(item) else None
    if isinstance(item, str):
        top, slash, bottom = item.partition("/")
        with contextlib.suppress(ValueError, ZeroDivisionError):
            return float(top) / float(bottom) if slash else float(top)
    return None


def _errors(raw: Any, where: str) -> tuple[str, ...]:
    if (
        not isinstance(raw, list)
        or not raw
        or not all(item in MEASURES for item in raw)
        or len(set(raw)) != len(raw)
    ):
        raise ConfigError(
            f"{where}: errors: must be a list of distinct errors among {', '.join(MEASURES)} "
            f"(√VE, √PBE), got {shown_value(raw)}."
        )
    return tuple(raw)


def _curve(raw: Any, index: int, facts: WorldFacts, on_policy: bool, where: str) -> CurveSpec:
    here = f"{where}: curves[{index}]"
    if not isinstance(raw, Mapping):
        raise ConfigError(
            f"{here}: must be a mapping {{label, algorithm, features, alpha}}, got {shown_value(raw)}."
        )
    check_top_keys(raw, CURVE_KEYS, here)
    algorithm = raw.get("algorithm")
    if algorithm not in methods.ALGORITHMS:
        raise ConfigError(
            f"{here}.algorithm: must be one of {', '.join(methods.ALGORITHMS)}, got "
            f"{shown_value(algorithm)}."
        )
    if facts.continuing and algorithm in methods.EPISODIC_ONLY:
        raise ConfigError(
            f"{here}.algorithm: {algorithm} learns from whole episodes; {facts.world_id} is continuing (nothing ends)."
        )
    if not facts.continuing and algorithm in methods.CONTINUING_ONLY:
        raise ConfigError(
            f"{here}.algorithm: {algorithm} is for continuing worlds; {facts.world_id} is episodic."
        )
    if not on_policy and (algorithm in methods.ON_POLICY or not facts.continuing):
        raise ConfigError(
            f"{where}: behaviour: {algorithm} learns on-policy here; its behaviour must be its "
            "target (or choose off_policy_td, tdc, gtd2, emphatic_td or an expected algorithm on "
            "a continuing world)."
        )
    label = raw.get("label", algorithm)
    if not isinstance(label, str):
        raise ConfigError(f"{here}.label: must be text, got {shown_value(label)}.")
    features = _features(raw.get("features"), facts, f"{here}.features")
    if algorithm == "lstd" and "alpha" in raw:
        raise ConfigError(
            f"{here}.alpha: lstd has no step size (its weights solve M c); remove it."
        )
    alpha = number_of(raw, "alpha", 0.0 if algorithm == "lstd" else None, here, dotted=True)
    if algorithm != "lstd" and not alpha > 0.0:
        raise ConfigError(f"{here}.alpha: must be positive, got {alpha:g}.")
    beta = number_of(
        raw, "beta", 0.0 if algorithm not in methods.WITH_BETA else None, here, dotted=True
    )
    if algorithm in methods.WITH_BETA and not beta > 0.0:
        raise ConfigError(f"{here}.beta: must be positive (the step size of v), got {beta:g}.")
    if algorithm not in methods.WITH_BETA and "beta" in raw:
        raise ConfigError(
            f"{here}.beta: {algorithm} has no second step size (tdc, gtd2 and expected_tdc have)."
        )
    epsilon = number_of(raw, "epsilon", 1.0, here, dotted=True)
    if "epsilon" in raw and algorithm != "lstd":
        raise ConfigError(f"{here}.epsilon: only lstd takes it (its M starts at I / epsilon).")
    if not epsilon > 0.0:
        raise ConfigError(f"{here}.epsilon: must be positive, got {epsilon:g}.")
    _, _, weights = _layer_size(features, facts)
    w0 = weights_of(raw.get("w0", 0.0), weights, f"{here}.w0")
    return CurveSpec(label, str(algorithm), features, alpha, beta, epsilon, w0)


def _features(raw: Any, facts: WorldFacts, here: str) -> FeatureSpec:
    kind = raw.get("kind") if isinstance(raw, Mapping) else None
    if kind not in layers.KINDS:
        raise ConfigError(
            f"{here}: must be a mapping whose kind is one of {', '.join(layers.KINDS)} (such as "
            f"{{kind: fourier, order: 5}}), got {shown_value(raw)}."
        )
    assert isinstance(raw, Mapping)
    check_top_keys(raw, FEATURE_KEYS[kind], here)
    if kind in ("tiles", "polynomial", "fourier") and facts.points is None:
        raise ConfigError(
            f"{here}: {kind} features need the world's states as points (point_of_state); "
            f"{facts.world_id} has none"
            + (
                " here: give it world.kwargs {position: true}"
                if "RandomWalk1000" in facts.world_id
                else ""
            )
            + "."
        )
    if kind == "declared" and facts.declared is None:
        raise ConfigError(
            f"{here}: {facts.world_id} declares no feature matrix (features_of_state); choose "
            "table, tiles, polynomial or fourier."
        )
    if kind in ("polynomial", "fourier"):
        order = raw.get("order")
        if (
            isinstance(order, bool)
            or not isinstance(order, int)
            or not 1 <= order <= layers.MAX_ORDER
        ):
            raise ConfigError(
                f"{here}.order: must be a whole number from 1 to {layers.MAX_ORDER}, got "
                f"{shown_value(order)}."
            )
        assert facts.points is not None
        count = layers.feature_count(order, facts.points.shape[1])
        check_memory(here.partition(": ")[0], here.partition(": ")[2] + ".order",
                     facts.n_states * count * 16, f"{count:,} features on {facts.n_states:,} states")  # fmt: skip
        return FeatureSpec(kind, order=order)
    if kind == "tiles":
        assert facts.points is not None
        return _tiles(raw, facts.points.shape[1], here)
    return FeatureSpec(kind)


def _tiles(raw: Mapping[str, Any], dimensions: int, here: str) -> FeatureSpec:
    bins = raw.get("bins")
    if (
        not isinstance(bins, list)
        or len(bins) != dimensions
        or not all(
            isinstance(b, int) and not isinstance(b, bool) and 1 <= b <= 10_000 for b in bins
        )
    ):
        raise ConfigError(
            f"{here}.bins: must be a list of {dimensions} whole numbers from 1 to 10,000 (one per "
            f"dimension of the world's points), got {shown_value(bins)}."
        )
    bounds = []
    for key in ("low", "high"):
        value = raw.get(key)
        numbers = [fraction_of(item) for item in value] if isinstance(value, list) else []
        if len(numbers) != dimensions or any(v is None for v in numbers):
            raise ConfigError(
                f"{here}.{key}: must be a list of {dimensions} numbers, got {shown_value(value)}."
            )
        bounds.append(tuple(float(v) for v in numbers if v is not None))
    if not all(low < high for low, high in zip(bounds[0], bounds[1], strict=True)):
        raise ConfigError(f"{here}: low must be below high in every dimension.")
    tilings = raw.get("tilings", 1)
    if isinstance(tilings, bool) or not isinstance(tilings, int) or not 1 <= tilings <= 1024:
        raise ConfigError(
            f"{here}.tilings: must be a whole number from 1 to 1,024, got {shown_value(tilings)}."
        )
    return FeatureSpec("tiles", bins=tuple(bins), low=bounds[0], high=bounds[1], tilings=tilings)


def weights_of(raw: Any, weights: int, here: str) -> tuple[float, ...]:
    """Starting weights: one number for every weight, or a list of ``weights``."""
    if isinstance(raw, list):
        numbers = [fraction_of(item) for item in raw]
        if len(numbers) == weights and all(v is not None for v in numbers):
            return tuple(float(v) for v in numbers if v is not None)
    else:
        number = fraction_of(raw)
        if number is not None and not isinstance(raw, str):
            return (number,)
    raise ConfigError(
        f"{here}: must be a number (every weight) or a list of {weights} numbers (one per "
        f"weight), got {shown_value(raw)}."
    )


def _book(
    raw: Any, index: int, curves: Sequence[CurveSpec], count: int, errors: Sequence[str],
    facts: WorldFacts, where: str,
) -> BookNumber:  # fmt: skip
    here = f"{where}: book[{index}]"
    if not isinstance(raw, Mapping):
        raise ConfigError(
            f"{here}: must be a mapping {{label, curve, at, of, value}}, got {shown_value(raw)}."
        )
    check_top_keys(raw, BOOK_KEYS, here)
    label, text = raw.get("label"), raw.get("text", "")
    if not isinstance(label, str) or not isinstance(text, str):
        raise ConfigError(
            f"{here}.label: the row's label (and `text`, the book's words) must be text."
        )
    curve = raw.get("curve")
    for key, given in (("curve", curve), ("below", raw.get("below"))):
        if key == "below" and given is None:
            continue
        if isinstance(given, bool) or not isinstance(given, int) or not 0 <= given < len(curves):
            raise ConfigError(
                f"{here}.{key}: a curve's index (0 to {len(curves) - 1}), got {shown_value(given)}."
            )
    at = raw.get("at", count)
    if isinstance(at, bool) or not isinstance(at, int) or not 0 <= at <= count:
        raise ConfigError(f"{here}.at: a point from 0 to {count:,}, got {shown_value(at)}.")
    of = raw.get("of", errors[0])
    assert isinstance(curve, int)
    weights = _layer_size(curves[curve].features, facts)[2]
    valid = [*errors, *(f"w{i + 1}" for i in range(weights))]
    if of not in valid:
        raise ConfigError(
            f"{here}.of: one of the recorded errors ({', '.join(errors)}) or a weight w1 to "
            f"w{weights}, got {shown_value(of)}."
        )
    value = raw.get("value")
    if value is not None and (isinstance(value, bool) or not isinstance(value, (int, float))):
        raise ConfigError(f"{here}.value: the book's number, got {shown_value(value)}.")
    text_value = repr(float(value)) if value is not None else ""
    decimals = (
        0 if isinstance(value, int) or "e" in text_value else len(text_value.partition(".")[2])
    )
    below = raw.get("below")
    return BookNumber(
        label, curve, at, str(of), None if value is None else float(value), below, text, decimals
    )


def number_of(
    raw: Mapping[str, Any], key: str, default: float | None, where: str, dotted: bool = False
) -> float:
    """A finite number at ``key`` (text such as ``1e-3`` read as a number)."""
    value = raw.get(key, default)
    if isinstance(value, str):
        with contextlib.suppress(ValueError):
            value = float(value)
    name = f".{key}" if dotted else f": {key}"
    if value is None and default is None:
        raise ConfigError(f"{where}{name}: is missing; give a number.")
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ConfigError(f"{where}{name}: must be a number, got {shown_value(value)}.")
    return float(value)


def optional_number_of(raw: Any, key: str, where: str) -> float | None:
    """``figure.<key>`` as a number, or ``None`` when absent."""
    if not isinstance(raw, Mapping) or raw.get(key) is None:
        return None
    return number_of(raw, key, None, f"{where}: figure", dotted=True)


def flag_of(raw: Any, key: str, default: bool, where: str) -> bool:
    """``figure.<key>`` as true or false."""
    value = raw.get(key, default) if isinstance(raw, Mapping) else default
    if not isinstance(value, bool):
        raise ConfigError(
            f"{where}: figure.{key}: must be true or false, got {shown_value(value)}."
        )
    return value


def whole_of(raw: Mapping[str, Any], key: str, default: int | None, where: str, least: int) -> int:
    """A whole number at ``key``, at least ``least``."""
    value = raw.get(key, default)
    if isinstance(value, bool) or not isinstance(value, int) or value < least:
        raise ConfigError(
            f"{where}: {key}: must be a whole number >= {least}, got {shown_value(value)}."
        )
    return value


# -- the world ------------------------------------------------------------------------------


@dataclass(frozen=True)
class WorldFacts:
    """A world as a linear study needs it: its table, points, groups and declared features."""

    world_id: str
    n_states: int
    n_actions: int
    continuing: bool
    time_limit: int | None
    points: np.ndarray | None
    """float32 ``(N, k)`` (``point_of_state``), or ``None``"""
    low: np.ndarray | None
    high: np.ndarray | None
    groups: np.ndarray | None
    """int64 ``(N,)`` (``observation_of_state``), or ``None``"""
    observations: int
    declared: np.ndarray | None
    transitions: Mapping[int, Mapping[int, Sequence[tuple[float, int, float, bool]]]]
    initial: np.ndarray
    declared_actions: np.ndarray | None = None
    """float64 ``(N, n, d)`` (``features_of_action``: a policy's features), or ``None``"""


@functools.lru_cache(maxsize=8)
def world_facts(world_id: str, kwargs: tuple[tuple[str, Any], ...], where: str) -> WorldFacts:
    """Make the world once and read what a study needs (kept for the process).

    Raises:
        ConfigError: the world cannot be made, or has no transition table.
    """
    import gymnasium

    try:
        env = gymnasium.make(world_id, **dict(kwargs))
    except Exception as error:  # an unknown id, a refused argument: the world's own message
        raise ConfigError(f"{where}: world: {world_id} cannot be made: {error}") from None
    world = env.unwrapped
    transitions = getattr(world, "P", None)
    initial = getattr(world, "initial_state_distrib", None)
    if not isinstance(transitions, Mapping) or initial is None:
        raise ConfigError(
            f"{where}: world: {world_id} has no transition table (P): a linear study needs a "
            "world whose model is known, such as cartpole_q/RandomWalk1000-v0 or cartpole_q/Baird-v0."
        )
    from cartpole_q.families.tables.twin import table_params

    playable = table_params(world, aggregated=True)
    if isinstance(playable, str):
        raise ConfigError(
            f"{where}: world: {world_id} cannot be played from its table: {playable}."
        )
    continuing = not any(
        outcome[3]
        for actions in transitions.values()
        for outcomes in actions.values()
        for outcome in outcomes
    )
    points = getattr(world, "point_of_state", None)
    space: Any = world.observation_space  # a Box where the world has points
    low = np.asarray(space.low, dtype=np.float64) if points is not None else None
    high = np.asarray(space.high, dtype=np.float64) if points is not None else None
    groups = getattr(world, "observation_of_state", None)
    n_states = len(transitions)
    observations = int(getattr(space, "n", n_states)) if groups is not None else n_states
    spec = env.spec
    env.close()
    return WorldFacts(
        world_id, n_states, int(getattr(world.action_space, "n", 0)), continuing,
        None if spec is None else spec.max_episode_steps,
        None if points is None else np.asarray(points), low, high,
        None if groups is None else np.asarray(groups, dtype=np.int64), observations,
        getattr(world, "features_of_state", None), transitions, np.asarray(initial, dtype=np.float64),
        getattr(world, "features_of_action", None),
    )  # fmt: skip


def _layer_size(features: FeatureSpec, facts: WorldFacts) -> tuple[int, int, int]:
    """``(N, K, d)`` of a layer on the world, without building it."""
    n = facts.n_states
    if features.kind == "table":
        return n, 1, facts.observations
    if features.kind == "declared":
        assert facts.declared is not None
        return n, int(np.count_nonzero(facts.declared, axis=1).max()), int(facts.declared.shape[1])
    if features.kind == "tiles":
        from cartpole_q.rl.tiles import tile_shape

        return n, features.tilings, int(np.prod(tile_shape(list(features.bins), features.tilings)))
    assert facts.points is not None
    count = layers.feature_count(features.order, facts.points.shape[1])
    return n, count, count


def feature_rows(features: FeatureSpec, facts: WorldFacts) -> layers.FeatureRows:
    """The layer's rows for every state of the world."""
    if features.kind == "table":
        groups = facts.groups if facts.groups is not None else np.arange(facts.n_states)
        return layers.table_rows(groups, facts.observations)
    if features.kind == "declared":
        assert facts.declared is not None
        return layers.declared_rows(facts.declared)
    assert facts.points is not None and facts.low is not None and facts.high is not None
    if features.kind == "tiles":
        return layers.tile_rows(
            facts.points, features.bins, features.low, features.high, features.tilings
        )
    scaled = layers.scaled_points(facts.points, facts.low, facts.high)
    make = layers.fourier_rows if features.kind == "fourier" else layers.polynomial_rows
    return make(scaled, features.order)


@dataclass(frozen=True)
class Problem:
    """A study's world as its runs use it: the model, the measured states, ``μ`` and ``v_π``."""

    model: Any
    """the :class:`~cartpole_q.rl.mdp.FiniteMDP`"""
    first: np.ndarray
    measured: np.ndarray
    mu: np.ndarray
    """on the measured states"""
    truth: np.ndarray
    """``v_π`` on the measured states"""
    expected_reward: np.ndarray
    """``r̄(s)`` on the measured states (the TD fixed point)"""


@functools.lru_cache(maxsize=8)
def problem(study: Study) -> Problem:
    """The study's model, measured states, ``μ`` and ``v_π`` (once per process)."""
    from cartpole_q.rl.mdp import FiniteMDP
    from cartpole_q.rl.solvers import evaluate_policy, reachable_states

    facts = world_facts(study.world_id, study.world_kwargs, study.where)
    model = FiniteMDP.from_transitions(facts.transitions, facts.initial, facts.n_actions)
    target = np.tile(np.asarray(study.target), (facts.n_states, 1))
    behaviour = np.tile(np.asarray(study.behaviour), (facts.n_states, 1))
    first = np.searchsorted(model.state, np.arange(facts.n_states + 1)).astype(np.int64)
    if study.continuing:
        measured = np.arange(facts.n_states)
        mu = stationary_distribution(model, behaviour)
    else:
        reachable = reachable_states(model, behaviour)
        measured = np.flatnonzero(reachable & ~_terminal_states(model))
        mu = episodic_distribution(model, behaviour, np.flatnonzero(reachable), measured)
    if study.continuing:
        truth = evaluate_policy(model, target, study.gamma)[measured]
    else:  # solved where an episode of the target can be, as a prediction run's truth
        reach = np.flatnonzero(reachable_states(model, target))
        values = np.zeros(facts.n_states)
        values[reach] = evaluate_policy(model, target, study.gamma, reach)
        truth = values[measured]
    expected_reward, _ = model.stochastic_policy_matrix(target)
    return Problem(model, first, measured, mu, truth, expected_reward[measured])


def episodic_distribution(
    model: Any, behaviour: np.ndarray, reach: np.ndarray, measured: np.ndarray
) -> np.ndarray:
    """``μ`` of an episodic world: ``eta = h + eta P_b`` on ``reach``, normalised on ``measured``.

    Raises:
        ConfigError: the behaviour may never end an episode (the system is singular).
    """
    _, matrix = model.stochastic_policy_matrix(behaviour)
    system = np.eye(len(reach)) - matrix[np.ix_(reach, reach)]
    try:
        with one_thread():
            visits = np.linalg.solve(system.T, model.initial[reach])
    except np.linalg.LinAlgError:
        raise ConfigError("behaviour: may never end an episode of this world") from None
    kept = visits[np.searchsorted(reach, measured)]
    mu: np.ndarray = kept / kept.sum()
    return mu


def stationary_distribution(model: Any, behaviour: np.ndarray) -> np.ndarray:
    """``μ = μ P_b``, ``sum μ = 1``: ``solve(A, e)`` with ``A = P_bᵀ - I``, its last row ones."""
    _, matrix = model.stochastic_policy_matrix(behaviour)
    system = matrix.T - np.eye(model.n_states)
    system[-1, :] = 1.0
    unit = np.zeros(model.n_states)
    unit[-1] = 1.0
    with one_thread():
        mu: np.ndarray = np.linalg.solve(system, unit)
    return mu


def _terminal_states(model: Any) -> np.ndarray:
    """States every outcome of which stays, pays 0 and terminates (a walk's ends)."""
    stays = (model.next_state == model.state) & (model.reward == 0.0) & model.terminated
    ends = np.ones(model.n_states, dtype=bool)
    np.logical_and.at(ends, model.state, stays)
    return ends


@dataclass(frozen=True)
class CurveSetup:
    """A curve's layer with what its errors and fixed point need."""

    rows: layers.FeatureRows
    pseudo_inverse: np.ndarray
    fixed_point: np.ndarray | None
    """the curve's fixed point (least VE, or the TD fixed point), or ``None``"""


@functools.lru_cache(maxsize=32)
def curve_setup(study: Study, index: int) -> CurveSetup:
    """The curve's rows, ``C⁺`` (when ``√PBE`` is recorded) and fixed point (once per process)."""
    curve = study.curves[index]
    facts = world_facts(study.world_id, study.world_kwargs, study.where)
    found = problem(study)
    rows = feature_rows(curve.features, facts)
    dense = rows.dense(found.measured)
    pseudo = np.zeros((0, 0))
    if "pbe" in study.errors:
        with one_thread():
            pseudo = np.linalg.pinv(_covariance(rows, found))
    fixed: np.ndarray | None = None
    if curve.algorithm == "gradient_mc":
        fixed = methods.least_ve_weights(dense, found.mu, found.truth)
    elif curve.algorithm not in ("emphatic_td", "expected_emphatic_td"):
        following = _expected_next_rows(study, rows, found)
        fixed = methods.td_fixed_point(
            dense, following, found.mu, found.expected_reward, study.gamma
        )
    return CurveSetup(rows, pseudo, fixed)


def _covariance(rows: layers.FeatureRows, found: Problem) -> np.ndarray:
    """``C = sum_s μ(s) x(s) x(s)ᵀ`` over the measured states in order, row pairs only."""
    c = np.zeros((rows.weights, rows.weights))
    for k, state in enumerate(found.measured):
        index, value = rows.index[state], rows.value[state]
        c[np.ix_(index, index)] += np.outer(found.mu[k] * value, value)
    return c


def _expected_next_rows(study: Study, rows: layers.FeatureRows, found: Problem) -> np.ndarray:
    """``x̄'(s)`` of each measured state: the target's expected next features."""
    model = found.model
    dense = rows.dense()
    target = np.asarray(study.target)
    following = np.zeros((len(found.measured), rows.weights))
    for k, state in enumerate(found.measured):
        for o in range(found.first[state], found.first[state + 1]):
            chance = target[model.action[o]]
            if chance > 0.0 and not model.terminated[o]:
                following[k] += (chance * model.probability[o]) * dense[model.next_state[o]]
    return following


# -- a run ----------------------------------------------------------------------------------


def runs_of(study: Study) -> list[dict[str, Cell]]:
    """Every run's key: each curve on each seed (an expected curve on the first seed only)."""
    return [
        {"curve": index, "seed": seed}
        for index, curve in enumerate(study.curves)
        for seed in (study.seeds[:1] if curve.expected else study.seeds)
    ]


def run_one(study: Study, key: Mapping[str, Cell], handle: RunHandle) -> RunRecord | None:
    """One curve on one seed: its records (``None`` when stopped)."""
    from cartpole_q.engines import linear as engine

    index, seed = int(key["curve"]), int(key["seed"])  # type: ignore[arg-type]
    curve = study.curves[index]
    setup = curve_setup(study, index)
    found = problem(study)
    facts = world_facts(study.world_id, study.world_kwargs, study.where)
    rows = setup.rows
    w0 = np.full(rows.weights, curve.w0[0]) if len(curve.w0) == 1 else np.asarray(curve.w0)
    learner = methods.new_learner(
        curve.algorithm, curve.alpha, curve.beta, study.gamma, curve.epsilon, rows.index,
        rows.value, w0,
    )  # fmt: skip
    target, behaviour = np.asarray(study.target), np.asarray(study.behaviour)
    mu_all = np.zeros(facts.n_states)
    mu_all[found.measured] = found.mu
    model = methods.Model(
        found.first, found.model.action, found.model.probability, found.model.next_state,
        found.model.reward, found.model.terminated, target, mu_all, mu_all * 1.0,
        np.zeros(facts.n_states),
    )  # fmt: skip
    errors = methods.Errors(
        found.measured.astype(np.int64), found.mu, found.truth, setup.pseudo_inverse,
        np.zeros(facts.n_states),
    )  # fmt: skip
    world = engine.World(
        world_table(study.world_id, study.world_kwargs, study.where), study.continuing,
        facts.time_limit if facts.time_limit else engine.EPISODE_CAP,
        functools.partial(make_world, study.world_id, study.world_kwargs),
    )  # fmt: skip
    records = engine.run(
        learner, engine.make_behaviour(target, behaviour, study.uniform_behaviour), world, model,
        errors, engine.Schedule(seed, study.count, study.record_every, study.errors, study.engine),
        handle.should_stop, handle.report,
    )  # fmt: skip
    if records is None:
        return None
    arrays = records.arrays()
    row: dict[str, Cell] = {name: float(arrays[name][-1]) for name in study.errors}
    return RunRecord(row, arrays)


@functools.lru_cache(maxsize=8)
def world_table(
    world_id: str, world_kwargs: tuple[tuple[str, Any], ...], where: str
) -> tuple[np.ndarray, ...]:
    """The world's table as the compiled loops step it (once per process)."""
    from cartpole_q.families.tables.twin import table_params

    env = make_world(world_id, world_kwargs)
    params = table_params(env.unwrapped, aggregated=True)
    env.close()
    if isinstance(params, str):  # (world_facts has read the same table)
        raise ConfigError(f"{where}: world: {world_id}: {params}.")
    return params


def make_world(world_id: str, kwargs: tuple[tuple[str, Any], ...]) -> Any:
    """``gymnasium.make`` of the world with its kwargs."""
    import gymnasium

    return gymnasium.make(world_id, **dict(kwargs))


# -- averages, figure, summary ---------------------------------------------------------------


@dataclass(frozen=True)
class CurveOutcome:
    """A curve averaged over its runs."""

    at: np.ndarray
    weights: np.ndarray
    """mean over runs, ``(records, d)``"""
    errors: dict[str, np.ndarray]
    """mean over runs, per error"""
    runs: int
    fixed_error: float | None
    """``√VE`` at the curve's fixed point"""


def outcomes(
    study: Study, keys: Sequence[Mapping[str, Cell]], records: Sequence[RunRecord]
) -> list[CurveOutcome]:
    """Each curve's runs averaged point by point (summed in seed order from 0.0, divided)."""
    from cartpole_q.engines import linear as engine

    result = []
    for index, _ in enumerate(study.curves):
        mine = [r for k, r in zip(keys, records, strict=True) if int(k["curve"]) == index]  # type: ignore[arg-type]
        at = np.asarray(mine[0].arrays["at"])
        weights = _mean([np.asarray(r.arrays["weights"]) for r in mine])
        errors = {name: _mean([np.asarray(r.arrays[name]) for r in mine]) for name in study.errors}
        setup = curve_setup(study, index)
        fixed_error = None
        if setup.fixed_point is not None and "ve" in study.errors:
            found = problem(study)
            learner = methods.new_learner(
                "semi_gradient_td", 1.0, 0.0, study.gamma, 1.0, setup.rows.index, setup.rows.value,
                setup.fixed_point,
            )  # fmt: skip
            measured = methods.Errors(
                found.measured.astype(np.int64),
                found.mu,
                found.truth,
                np.zeros((0, 0)),
                np.zeros(1),
            )
            fixed_error = float(engine.compiled("linear_root_ve")(learner, measured))
        result.append(CurveOutcome(at, weights, errors, len(mine), fixed_error))
    return result


def _mean(arrays: Sequence[np.ndarray]) -> np.ndarray:
    total = np.zeros_like(arrays[0], dtype=np.float64)
    for array in arrays:
        total = total + array
    return total / len(arrays)


def _x_label(study: Study, curve: CurveSpec) -> str:
    if curve.expected:
        return "Sweeps"
    return "Steps" if study.continuing else "Episodes"


def study_figure(study: Study, found: Sequence[CurveOutcome]) -> Any:
    """The study's figure (a :class:`~cartpole_q.figures.DataFigure`)."""
    from cartpole_q.figures.linear import (
        ErrorCurve,
        WeightsPanel,
        error_curves_figure,
        weights_figure,
    )

    if study.figure_kind == "errors":
        measure = study.errors[0]
        curves = [
            ErrorCurve(
                curve.label,
                outcome.at,
                outcome.errors[measure],
                outcome.fixed_error if study.fixed_points and measure == "ve" else None,
            )
            for curve, outcome in zip(study.curves, found, strict=True)
        ]
        runs = ", ".join(sorted({f"{o.runs}" for o in found}))
        y_label = f"{ERROR_NAMES[measure]}, averaged over {runs} run{'s' if runs != '1' else ''}"
        return error_curves_figure(
            curves,
            study.title,
            _x_label(study, study.curves[0]),
            y_label,
            study.y_limits,
            study.log_y,
        )
    panels = [
        WeightsPanel(
            curve.label,
            _x_label(study, curve),
            outcome.at,
            outcome.weights,
            [
                (ERROR_NAMES[name], outcome.errors[name])
                for name in study.errors
                if study.show_errors
            ],
            outcome.runs,
        )
        for curve, outcome in zip(study.curves, found, strict=True)
    ]
    return weights_figure(panels, study.title, study.y_limits)


def _value_at(study: Study, outcome: CurveOutcome, of: str, at: int) -> float:
    """The curve's mean ``of`` at the record ``at`` (the last record at or before it)."""
    where = int(np.searchsorted(outcome.at, at, side="right")) - 1
    if of.startswith("w"):
        return float(outcome.weights[where, int(of[1:]) - 1])
    return float(outcome.errors[of][where])


def summary(study: Study, found: Sequence[CurveOutcome]) -> list[str]:
    """What ran, each curve's last errors and fixed point, and the book beside ours."""
    policy = "random" if study.uniform_behaviour else ", ".join(f"{p:.4g}" for p in study.behaviour)
    lines = [
        f"{study.name}: {study.world_id}, gamma {study.gamma:g}, behaviour {policy}, "
        f"{study.count:,} {study.unit} per run, {study.engine} engine"
    ]
    for curve, outcome in zip(study.curves, found, strict=True):
        unit = _x_label(study, curve).lower()
        measured = ", ".join(
            f"{ERROR_NAMES[name]} {outcome.errors[name][-1]:.4f}" for name in study.errors
        )
        runs = f"mean of {outcome.runs} runs" if outcome.runs > 1 else "one run"
        weights = outcome.weights[-1]
        largest = float(np.max(np.abs(weights))) if weights.size else 0.0
        fixed = (
            f"; its fixed point's √VE {outcome.fixed_error:.4f}"
            if outcome.fixed_error is not None
            else ""
        )
        lines.append(
            f"  {curve.label} ({curve.algorithm}, {curve.features.text()}, alpha {curve.alpha:g}): "
            f"after {int(outcome.at[-1]):,} {unit}: {measured} ({runs}); largest |w| "
            f"{largest:.4g}{fixed}"
        )
    for number in study.book:
        lines.append("  " + _book_line(study, found, number))
    return lines


def _book_line(study: Study, found: Sequence[CurveOutcome], number: BookNumber) -> str:
    outcome = found[number.curve]
    ours = _value_at(study, outcome, number.of, number.at)
    name = ERROR_NAMES.get(number.of, number.of)
    unit = _x_label(study, study.curves[number.curve]).lower()
    where = f"{name} at {number.at:,} {unit}"
    book = f"book: {number.text}" if number.text else "book"
    if number.below is not None:
        other = _value_at(study, found[number.below], number.of, number.at)
        verdict = "below" if ours < other else "NOT below"
        return (
            f"{number.label}: {book}; ours {ours:.4f} against {other:.4f} "
            f"({study.curves[number.below].label}), {verdict} ({where})"
        )
    if number.value is not None:
        return f"{number.label}: {book} ~{number.value:.{number.decimals}f}, ours {ours:.{number.decimals + 1}f} ({where})"
    return f"{number.label}: {book}; ours {ours:.4g} ({where})"


def finish(
    study: Study, keys: Sequence[Mapping[str, Cell]], records: Sequence[RunRecord]
) -> Finished:
    """The figure and the summary."""
    found = outcomes(study, keys, records)
    return Finished([(study.file, study_figure(study, found))], (), summary(study, found))


def _columns(study: Study) -> tuple[str, ...]:
    return study.errors


def _count(study: Study) -> int:
    return study.count


def _unit(study: Study) -> str:
    return study.unit


def _compile_notice() -> str | None:
    from cartpole_q.engines.linear import compile_notice

    return compile_notice()


class LinearKind(CurvesKind):
    """``kind: linear``: linear methods on feature layers (Figures 9.5, 9.10, 11.2, 11.5, 11.6)."""

    name = "linear"
    units = Units("linear", "episodes or steps", "runs")
    runs_per_task = 4


LINEAR = register_kind(
    LinearKind(
        CurveFunctions(
            read_study, runs_of, run_one, finish, _columns, _count, _unit, _compile_notice,
        )
    )
)  # fmt: skip
"""the linear-methods kind (registered)"""
