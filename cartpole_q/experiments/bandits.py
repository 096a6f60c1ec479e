"""Bandit studies (``cartpole-q bandit``): a study file, its curves, its figure.

A study file names the testbed (``cartpole_q/Bandit-v0``'s ``k``, ``mean``, ``spread``,
``walk``), the runs (``seeds``: one run per seed) and their ``steps``, the learners to
compare (``curves``: a method and its parameters; a parameter study varies one parameter
over ``values``), the figure and the book's numbers to print beside ours. :func:`run_study`
plays every curve (:mod:`cartpole_q.engines.bandit`); :func:`write_study` draws the figure
with its data beside it (``<figure>.csv``).

Figure kinds: ``curves`` (Figures 2.2-2.5: each step's average reward and/or % optimal
action, averaged over the runs) and ``parameter_study`` (Figure 2.6: the average reward over
all the steps against each method's parameter, on a log2 axis).
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from cartpole_q.config import ConfigError, parse_seeds, read_yaml_mapping, shown_value
from cartpole_q.config.bounds import check_count, check_memory
from cartpole_q.errors import RunError
from cartpole_q.experiments.study import Finished, RunHandle, RunsKind, StudyFile, register_kind
from cartpole_q.experiments.sweep_spec import (
    check_top_keys,
    checked_figure_section,
    checked_list,
    checked_study,
)
from cartpole_q.progress import Units
from cartpole_q.rl.bandits import RULES, BanditAgent
from cartpole_q.store.studydir import Cell, RunRecord

STUDY_KEYS = ("name", "testbed", "seeds", "steps", "engine", "curves", "figure", "book")
"""the keys a study file may have"""
TESTBED_KEYS = ("k", "mean", "spread", "walk")
CURVE_KEYS = (
    "label", "method", "epsilon", "c", "alpha", "q_init", "baseline", "vary", "values",
)  # fmt: skip
PARAMETERS = ("epsilon", "c", "alpha", "q_init")
"""the parameters a curve sets (and a parameter study varies)"""
METHOD_PARAMETERS = {
    "epsilon_greedy": ("epsilon", "alpha", "q_init"),
    "ucb": ("c", "alpha", "q_init"),
    "gradient": ("alpha", "baseline"),
}
"""the keys each method takes (``alpha`` of a value method: a number or ``sample_average``)"""
FIGURE_KINDS = ("curves", "parameter_study")
FIGURE_KEYS = ("kind", "file", "title", "metrics")
METRICS = {"average_reward": "Average reward", "optimal_percent": "% Optimal action"}
"""a curve's per-step metrics and their axis labels (the book's)"""
BOOK_KEYS = ("label", "value", "curve", "above", "of", "step", "steps")
BOOK_OF = ("average_reward", "optimal_percent", "peak")
"""what a ``book`` entry compares: a metric at a step (or averaged over steps), or a
parameter study line's best point; with ``above``, the book's claim that one curve lies above
another over some steps (no value: ours is counted)"""
ENGINES = ("numba", "gymnasium")
MAX_STEPS = 10_000_000
"""the most steps a run may have"""
MAX_TESTBED_SCALE = 1e6
"""the largest ``|mean|``, ``spread`` and ``walk`` of a testbed"""


@dataclass(frozen=True)
class Curve:
    """One learner of a study (a parameter study: one line, one learner per value)."""

    label: str
    method: str
    settings: Mapping[str, float | bool]
    """its fixed parameters (``alpha`` 0.0: sample averages)"""
    vary: str | None
    """the parameter a parameter study varies, or ``None``"""
    values: tuple[float, ...]
    """the values it takes"""

    def agents(self) -> list[BanditAgent]:
        """The learners this curve plays: one, or one per value of the varied parameter."""
        settings = [dict(self.settings)]
        if self.vary is not None:
            settings = [{**self.settings, self.vary: value} for value in self.values]
        return [
            BanditAgent(
                RULES[self.method],
                float(given.get("epsilon", 0.0)),
                float(given.get("c", 0.0)),
                float(given.get("alpha", 0.0)),
                float(given.get("q_init", 0.0)),
                bool(given.get("baseline", False)),
            )
            for given in settings
        ]


@dataclass(frozen=True)
class BookNumber:
    """A number the book shows (read off its figure), compared with ours."""

    label: str
    value: float | None
    """``None``: a claim that ``curve`` lies above ``above``"""
    curve: int
    of: str
    steps: tuple[int, int]
    """the steps (1-based, inclusive) the metric is averaged over"""
    decimals: int
    """the decimals the book's value is given with (ours is printed with one more)"""
    above: int | None = None
    """the curve the book shows ``curve`` above (over ``steps``), or ``None``"""


@dataclass(frozen=True)
class Study:
    """A checked study file."""

    name: str
    testbed: tuple[int, float, float, float]
    """``(k, mean, spread, walk)``"""
    seeds: tuple[int, ...]
    steps: int
    curves: tuple[Curve, ...]
    kind: str
    file: str
    title: str
    metrics: tuple[str, ...]
    book: tuple[BookNumber, ...]
    where: str
    engine: str = "numba"
    """``numba`` (the compiled testbed) or ``gymnasium`` (``gymnasium.make``): the same numbers"""


@dataclass(frozen=True)
class Outcome:
    """What a study measured: per curve, per learner, each step's two metrics."""

    average_reward: list[np.ndarray]
    """per curve: ``(learners, steps)``"""
    optimal_percent: list[np.ndarray]
    """per curve: ``(learners, steps)``"""
    engine: str
    seconds: float = 0.0


def _number(value: Any, where: str) -> float:
    """A number, also as YAML strings such as ``1e-3`` or the book's axis labels ``1/128``."""
    if isinstance(value, str):
        text = value.strip()
        with contextlib.suppress(ValueError):
            value = float(text)
        fraction = re.fullmatch(r"(\d+(?:\.\d+)?)\s*/\s*(\d+(?:\.\d+)?)", text)
        if fraction and float(fraction[2]) != 0:
            value = float(fraction[1]) / float(fraction[2])
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ConfigError(
            f"{where}: must be a number (such as 0.1 or 1/128), got {shown_value(value)}."
        )
    return float(value)


def _whole(raw: Mapping[str, Any], key: str, default: int, where: str, least: int = 1) -> int:
    value = raw.get(key, default)
    if isinstance(value, bool) or not isinstance(value, int) or value < least:
        raise ConfigError(
            f"{where}: {key}: must be a whole number >= {least}, got {shown_value(value)}."
        )
    return value


def load_study(path: Path) -> Study:
    """Read and check a bandit study file.

    Raises:
        ConfigError: naming the file and the key, with what is wrong.
    """
    raw = read_yaml_mapping(path, "study file")
    return read_study(StudyFile(raw, "bandit", str(path), path.stem, path.parent))


def read_study(study: StudyFile) -> Study:
    """Check a bandit study file.

    Raises:
        ConfigError: naming the file and the key, with what is wrong.
    """
    raw, where, name = checked_study(
        study,
        STUDY_KEYS,
        "`seeds`, `steps`, `curves` and `figure`",
        "examples/book/fig2_2_epsilon_greedy.yaml",
    )
    testbed_raw = raw.get("testbed", {})
    if not isinstance(testbed_raw, Mapping):
        raise ConfigError(
            f"{where}: testbed: must be a mapping such as {{k: 10, mean: 0}}, got "
            f"{shown_value(testbed_raw)}."
        )
    check_top_keys(testbed_raw, TESTBED_KEYS, f"{where}: testbed")
    k = _whole(testbed_raw, "k", 10, f"{where}: testbed")
    mean, spread, walk = (
        _number(testbed_raw.get(key, default), f"{where}: testbed.{key}")
        for key, default in (("mean", 0.0), ("spread", 1.0), ("walk", 0.0))
    )
    if spread < 0 or walk < 0:
        raise ConfigError(f"{where}: testbed.spread and testbed.walk must not be negative.")
    for key, value in (("mean", mean), ("spread", spread), ("walk", walk)):
        if abs(value) > MAX_TESTBED_SCALE:
            raise ConfigError(
                f"{where}: testbed.{key}: must be within ±{MAX_TESTBED_SCALE:g} (rewards beyond "
                f"it overflow the averages), got {value:g}."
            )
    if "seeds" not in raw:
        raise ConfigError(f"{where}: seeds: is missing; one run per seed, such as 0-1999.")
    try:
        seeds = parse_seeds(raw["seeds"])
    except ValueError as error:
        raise ConfigError(f"{where}: seeds: {error}") from None
    steps = _whole(raw, "steps", 1000, where)
    check_count(where, "steps", steps, MAX_STEPS, "the book's runs are 1,000 and 10,000 steps")
    curves_raw = raw.get("curves")
    if not isinstance(curves_raw, list) or not curves_raw:
        raise ConfigError(
            f"{where}: curves: must be a list of learners such as {{method: epsilon_greedy, "
            f"epsilon: 0.1}}, got {shown_value(curves_raw)}."
        )
    curves = tuple(_curve(entry, index, where) for index, entry in enumerate(curves_raw))
    learners = sum(max(1, len(curve.values)) for curve in curves)
    # per learner two averaged curves (float64), and one run's rewards and flags at a time
    check_memory(
        where,
        "steps",
        steps * (16 * learners + 25),
        f"{learners} learners' curves of {steps:,} steps",
    )
    kind, file, title, metrics = _figure(raw.get("figure"), name, where)
    varied = [curve.vary is not None for curve in curves]
    if kind == "parameter_study" and not all(varied):
        index = varied.index(False)
        raise ConfigError(
            f"{where}: curves[{index}]: a parameter study's curve varies a parameter: give "
            "`vary` (epsilon, c, alpha or q_init) and its `values`."
        )
    if kind == "curves" and any(varied):
        index = varied.index(True)
        raise ConfigError(
            f"{where}: curves[{index}].vary: only a parameter study varies a parameter "
            "(figure.kind: parameter_study)."
        )
    book = tuple(
        _book(entry, index, len(curves), steps, kind, where)
        for index, entry in enumerate(checked_list(raw, "book", where))
    )
    engine = raw.get("engine", "numba")
    if engine not in ENGINES:
        raise ConfigError(
            f"{where}: engine: must be one of {', '.join(ENGINES)}, got {shown_value(engine)}."
        )
    return Study(
        name, (k, mean, spread, walk), seeds, steps, curves, kind, file, title, metrics, book,
        where, str(engine),
    )  # fmt: skip


def _curve(raw: Any, index: int, where: str) -> Curve:
    here = f"{where}: curves[{index}]"
    if not isinstance(raw, Mapping):
        raise ConfigError(f"{here}: must be a mapping {{method, ...}}, got {shown_value(raw)}.")
    check_top_keys(raw, CURVE_KEYS, here)
    method = raw.get("method")
    if method not in METHOD_PARAMETERS:
        raise ConfigError(
            f"{here}.method: must be one of {', '.join(METHOD_PARAMETERS)}, got {shown_value(method)}."
        )
    allowed = METHOD_PARAMETERS[str(method)]
    for key in (*PARAMETERS, "baseline"):
        if key in raw and key not in allowed:
            raise ConfigError(
                f"{here}.{key}: {method} takes no {key} (it takes {', '.join(allowed)})."
            )
    settings: dict[str, float | bool] = {}
    for key in ("epsilon", "c", "q_init"):
        if key in raw:
            settings[key] = _number(raw[key], f"{here}.{key}")
    if "alpha" in raw:
        if raw["alpha"] == "sample_average" and method != "gradient":
            settings["alpha"] = 0.0
        else:
            settings["alpha"] = _number(raw["alpha"], f"{here}.alpha")
            if settings["alpha"] <= 0:
                raise ConfigError(
                    f"{here}.alpha: must be positive (a constant step size)"
                    + ("" if method == "gradient" else ", or sample_average")
                    + f", got {settings['alpha']:g}."
                )
    if "baseline" in raw:
        if not isinstance(raw["baseline"], bool):
            raise ConfigError(f"{here}.baseline: must be true or false.")
        settings["baseline"] = raw["baseline"]
    vary, values = raw.get("vary"), raw.get("values")
    if vary is not None:
        if vary not in allowed or vary == "baseline":
            raise ConfigError(
                f"{here}.vary: {method} can vary {', '.join(p for p in allowed if p != 'baseline')}, "
                f"got {shown_value(vary)}."
            )
        if vary in raw:
            raise ConfigError(f"{here}: {vary} is both set and varied; give it only in `values`.")
        if not isinstance(values, list) or not values:
            raise ConfigError(
                f"{here}.values: the values of {vary}, a list, got {shown_value(values)}."
            )
        numbers = tuple(_number(v, f"{here}.values[{i}]") for i, v in enumerate(values))
        if any(v <= 0 for v in numbers):
            raise ConfigError(f"{here}.values: must be positive (the axis is log2).")
        for number in numbers:
            _check_range(str(vary), number, f"{here}.values")
    elif values is not None:
        raise ConfigError(f"{here}.values: give `vary` too (the parameter the values are of).")
    else:
        numbers = ()
    if method == "gradient" and "alpha" not in settings and vary != "alpha":
        raise ConfigError(f"{here}.alpha: the gradient bandit needs a step size.")
    for key, number in settings.items():
        if key in PARAMETERS and isinstance(number, float):
            _check_range(key, number, f"{here}.{key}")
    label = raw.get("label", _default_label(str(method), settings))
    if not isinstance(label, str) or not label:
        raise ConfigError(f"{here}.label: must be text, got {shown_value(label)}.")
    return Curve(label, str(method), settings, None if vary is None else str(vary), numbers)


def _check_range(key: str, value: float, where: str) -> None:
    """Refuse a parameter outside its range (epsilon in [0, 1], c and alpha not negative)."""
    if key == "epsilon" and not 0.0 <= value <= 1.0:
        raise ConfigError(f"{where}: epsilon must be in [0, 1], got {value:g}.")
    if key == "c" and value < 0.0:
        raise ConfigError(f"{where}: c must not be negative, got {value:g}.")
    if key == "alpha" and value < 0.0:
        raise ConfigError(f"{where}: alpha must be positive, got {value:g}.")
    if abs(value) > MAX_TESTBED_SCALE:
        raise ConfigError(f"{where}: {key} must be within ±{MAX_TESTBED_SCALE:g}, got {value:g}.")


def _default_label(method: str, settings: Mapping[str, float | bool]) -> str:
    shown = ", ".join(
        f"{key} {value:g}" for key, value in settings.items() if not isinstance(value, bool)
    )
    if settings.get("baseline"):
        shown += ", with baseline"
    return f"{method} ({shown})" if shown else method


def _figure(raw: Any, name: str, where: str) -> tuple[str, str, str, tuple[str, ...]]:
    kind, file, title = checked_figure_section(raw, name, where, FIGURE_KEYS, FIGURE_KINDS)
    metrics = raw.get("metrics", list(METRICS) if kind == "curves" else ["average_reward"])
    if (
        not isinstance(metrics, list)
        or not metrics
        or any(metric not in METRICS for metric in metrics)
        or len(set(metrics)) != len(metrics)
    ):
        raise ConfigError(
            f"{where}: figure.metrics: a list of {', '.join(METRICS)}, got {shown_value(metrics)}."
        )
    if kind == "parameter_study" and metrics != ["average_reward"]:
        raise ConfigError(
            f"{where}: figure.metrics: a parameter study draws the average reward (Figure 2.6)."
        )
    return kind, file, title, tuple(metrics)


def _book(raw: Any, index: int, curves: int, steps: int, kind: str, where: str) -> BookNumber:
    here = f"{where}: book[{index}]"
    if not isinstance(raw, Mapping):
        raise ConfigError(
            f"{here}: must be a mapping {{label, value, curve, ...}}, got {shown_value(raw)}."
        )
    check_top_keys(raw, BOOK_KEYS, here)
    label, value, above = raw.get("label"), raw.get("value"), raw.get("above")
    if not isinstance(label, str):
        raise ConfigError(f"{here}.label: must be text, got {shown_value(label)}.")
    if above is None and (isinstance(value, bool) or not isinstance(value, (int, float))):
        raise ConfigError(f"{here}.value: the book's value, a number, got {shown_value(value)}.")
    if above is not None and value is not None:
        raise ConfigError(f"{here}: give the book's `value` or the curve it is `above`, not both.")
    for key, given in (("curve", raw.get("curve")), ("above", above)):
        if key == "above" and given is None:
            continue
        if isinstance(given, bool) or not isinstance(given, int) or not 0 <= given < curves:
            raise ConfigError(
                f"{here}.{key}: a curve's index in `curves` (0 to {curves - 1}), got "
                f"{shown_value(given)}."
            )
    curve = raw["curve"]
    if above is not None and kind == "parameter_study":
        raise ConfigError(f"{here}.above: compares the curves of a curves figure.")
    of = raw.get("of", "average_reward")
    if of not in BOOK_OF or (of == "peak") != (kind == "parameter_study"):
        allowed = "peak" if kind == "parameter_study" else "average_reward, optimal_percent"
        raise ConfigError(f"{here}.of: must be {allowed} for this figure, got {shown_value(of)}.")
    if "step" in raw and "steps" in raw:
        raise ConfigError(f"{here}: give `step` or `steps` ([first, last]), not both.")
    if "steps" in raw:
        span = raw["steps"]
        if (
            not isinstance(span, list)
            or len(span) != 2
            or not all(isinstance(s, int) and not isinstance(s, bool) for s in span)
            or not 1 <= span[0] <= span[1] <= steps
        ):
            raise ConfigError(
                f"{here}.steps: [first, last], 1 <= first <= last <= {steps}, got {shown_value(span)}."
            )
        first, last = span
    else:
        first = last = _whole(raw, "step", steps, here)
        if last > steps:
            raise ConfigError(f"{here}.step: {last}, but the runs have {steps} steps.")
    if value is None:
        return BookNumber(label, None, curve, str(of), (first, last), 0, above)
    text = repr(float(value))
    decimals = 0 if isinstance(value, int) or "e" in text else len(text.partition(".")[2])
    return BookNumber(label, float(value), curve, str(of), (first, last), decimals)


def run_study(
    study: Study, engine: str | None = None, stop: Callable[[], bool] | None = None
) -> Outcome | None:
    """Play every curve's learners in this process, one run per seed each.

    ``engine`` overrides the study's. ``stop`` is asked before every run; when it says so
    the study ends, returning ``None``.
    """
    import time

    start = time.perf_counter()
    if engine is not None:
        study = dataclasses.replace(study, engine=engine)
    keys = BANDIT.runs(study)
    records = []
    for key in keys:
        record = play_learner(study, key, stop)
        if record is None:
            return None
        records.append(record)
    outcome = study_outcome(study, keys, records)
    return dataclasses.replace(outcome, seconds=time.perf_counter() - start)


def play_learner(
    study: Study,
    key: Mapping[str, Cell],
    stop: Callable[[], bool] | None = None,
    progress: Callable[[int], None] | None = None,
) -> RunRecord | None:
    """One learner (``key``: its curve and its index there) on every seed, in order.

    Returns ``None`` when ``stop`` ended it early.
    """
    from cartpole_q.engines.bandit import play_curve
    from cartpole_q.families.bandit.twin import ArmedTestbed

    curve = study.curves[int(key["curve"] or 0)]
    agent = curve.agents()[int(key["learner"] or 0)]
    result = play_curve(
        agent, ArmedTestbed(*study.testbed), list(study.seeds), study.steps, study.engine,
        stop=stop, progress=progress,
    )  # fmt: skip
    if result is None:
        return None
    # an overflow is refused before the run is saved
    average = np.zeros((len(curve.agents()), study.steps))
    average[int(key["learner"] or 0)] = result.average_reward
    _check_finite(curve, average, study.where)
    return RunRecord(
        {"mean_reward": mean_over_steps(result.average_reward)},
        {"average_reward": result.average_reward, "optimal_percent": result.optimal_percent},
    )


def study_outcome(
    study: Study, keys: Sequence[Mapping[str, Cell]], records: Sequence[RunRecord]
) -> Outcome:
    """Every curve's learners' averages, from their records (in run order).

    Raises:
        RunError: a curve overflowed (:func:`_check_finite`).
    """
    rewards: list[list[np.ndarray]] = [[] for _ in study.curves]
    optimal: list[list[np.ndarray]] = [[] for _ in study.curves]
    for key, record in zip(keys, records, strict=True):
        rewards[int(key["curve"] or 0)].append(record.arrays["average_reward"])
        optimal[int(key["curve"] or 0)].append(record.arrays["optimal_percent"])
    outcome = Outcome(
        [np.array(rows) for rows in rewards], [np.array(rows) for rows in optimal], study.engine
    )
    for curve, average in zip(study.curves, outcome.average_reward, strict=True):
        _check_finite(curve, average, study.where)
    return outcome


def _check_finite(curve: Curve, average_reward: np.ndarray, where: str) -> None:
    """Refuse a curve whose averages overflowed: no figure is drawn of infinities.

    Raises:
        RunError: naming the curve and the first step that is not a finite number.
    """
    bad = np.flatnonzero(~np.isfinite(average_reward))
    if bad.size:
        learner, step = divmod(int(bad[0]), average_reward.shape[-1])
        value = f" ({curve.vary} {curve.values[learner]:g})" if curve.vary is not None else ""
        raise RunError(
            f"{where}: the curve {curve.label!r}{value} overflowed: its average reward at step "
            f"{step + 1} is {average_reward.flat[bad[0]]}. Its rewards or parameters are too "
            "large for float64; scale them down."
        )


def mean_over_steps(curve: np.ndarray, first: int = 1, last: int | None = None) -> float:
    """A curve's mean over steps ``first`` to ``last`` (1-based): summed in step order from 0.0."""
    last = curve.shape[0] if last is None else last
    total = 0.0
    for value in curve[first - 1 : last].tolist():
        total += value
    return total / (last - first + 1)


def study_points(study: Study, outcome: Outcome) -> list[np.ndarray]:
    """A parameter study's points: per curve, each value's mean reward over all the steps."""
    return [
        np.array([mean_over_steps(row) for row in rewards]) for rewards in outcome.average_reward
    ]


@dataclass(frozen=True)
class BookRow:
    """One line of the comparison: the book's number (read off its figure) and ours."""

    label: str
    book: float
    ours: float
    where: str
    """the step(s), or the parameter value, ours is taken at"""
    decimals: int
    """the book's value's decimals; ours is printed with one more"""

    def text(self) -> str:
        """``epsilon 0.1, average reward at step 1000: book ~1.35, ours 1.353 (step 1000)``."""
        book, ours = f"{self.book:.{self.decimals}f}", f"{self.ours:.{self.decimals + 1}f}"
        return f"{self.label}: book ~{book}, ours {ours} ({self.where})"


@dataclass(frozen=True)
class AboveRow:
    """The book's claim that one curve lies above another, and how often ours does."""

    label: str
    steps: tuple[int, int]
    above_count: int
    """the steps where ours is strictly above"""
    means: tuple[float, float]
    """each curve's mean over the steps"""
    from_step: int | None
    """the step from which ours stays above to the last step (``None``: not above at the last)"""

    def text(self) -> str:
        """``UCB above epsilon-greedy: book above; ours above at 985 of 990 steps (...)``."""
        first, last = self.steps
        since = "" if self.from_step is None else f", and at every step from {self.from_step} on"
        return (
            f"{self.label}: book above; ours above at {self.above_count} of {last - first + 1} "
            f"steps {first}-{last} (means {self.means[0]:.3f} and {self.means[1]:.3f}){since}"
        )


def book_rows(study: Study, outcome: Outcome) -> list[BookRow | AboveRow]:
    """The book's numbers beside ours."""
    rows: list[BookRow | AboveRow] = []
    points = study_points(study, outcome) if study.kind == "parameter_study" else []
    for number in study.book:
        curve = study.curves[number.curve]
        if number.of == "peak" and number.value is not None:
            best = int(np.argmax(points[number.curve]))
            rows.append(BookRow(
                number.label, number.value, float(points[number.curve][best]),
                f"its best, at {curve.vary} = {_fraction(curve.values[best])}", number.decimals,
            ))  # fmt: skip
            continue
        metric = (
            outcome.average_reward if number.of == "average_reward" else outcome.optimal_percent
        )
        first, last = number.steps
        ours = mean_over_steps(metric[number.curve][0], first, last)
        if number.above is not None or number.value is None:
            below = metric[number.above or 0][0]
            count = int(np.sum(metric[number.curve][0][first - 1 : last] > below[first - 1 : last]))
            means = (ours, mean_over_steps(below, first, last))
            not_above = np.flatnonzero(~(metric[number.curve][0] > below))
            since = int(not_above[-1]) + 2 if not_above.size else 1
            from_step = None if since > study.steps else since
            rows.append(AboveRow(number.label, number.steps, count, means, from_step))
            continue
        span = f"step {first}" if first == last else f"mean over steps {first}-{last}"
        rows.append(BookRow(number.label, number.value, ours, span, number.decimals))
    return rows


def _fraction(value: float) -> str:
    """``0.0078125`` as ``1/128``, ``4.0`` as ``4``: the book's axis labels."""
    if value >= 1 and float(value).is_integer():
        return str(int(value))
    inverse = 1.0 / value
    if float(inverse).is_integer():
        return f"1/{int(inverse)}"
    return f"{value:g}"


def summary(study: Study, outcome: Outcome) -> list[str]:
    """Lines saying what ran and what each curve ended at."""
    k, mean, spread, walk = study.testbed
    testbed = f"{k}-armed testbed, q*(a) ~ N({mean:g}, {spread:g}^2)"
    if walk > 0:
        testbed += f", walking by N(0, {walk:g}^2) per step"
    lines = [
        f"{study.name}: {len(study.seeds)} runs x {study.steps} steps on the {testbed}, "
        f"{outcome.engine} engine"
    ]
    last = study.steps
    first = max(1, last - 99)
    if study.kind == "parameter_study":
        for curve, points in zip(study.curves, study_points(study, outcome), strict=True):
            shown = ", ".join(
                f"{_fraction(v)}: {p:.3f}" for v, p in zip(curve.values, points, strict=True)
            )
            lines.append(f"  {curve.label} ({curve.vary}): {shown}")
        return lines
    for index, curve in enumerate(study.curves):
        reward = outcome.average_reward[index][0]
        optimal = outcome.optimal_percent[index][0]
        lines.append(
            f"  {curve.label}: step {last}: average reward {reward[-1]:.3f}, "
            f"{optimal[-1]:.1f}% optimal; steps {first}-{last}: "
            f"{mean_over_steps(reward, first, last):.3f}, "
            f"{mean_over_steps(optimal, first, last):.1f}%"
        )
    return lines


def study_figure(study: Study, outcome: Outcome) -> Any:
    """The study's figure (a :class:`~cartpole_q.figures.DataFigure`)."""
    from cartpole_q import figures

    labels = [curve.label for curve in study.curves]
    if study.kind == "parameter_study":
        lines = [
            figures.ParameterLine(curve.label, curve.vary or "", np.array(curve.values), points)
            for curve, points in zip(study.curves, study_points(study, outcome), strict=True)
        ]
        return figures.parameter_study_figure(
            lines, f"Average reward over first {study.steps:,} steps", study.title
        )
    panels = []
    for metric in study.metrics:
        values = outcome.average_reward if metric == "average_reward" else outcome.optimal_percent
        panels.append(
            (METRICS[metric], [(label, v[0]) for label, v in zip(labels, values, strict=True)])
        )
    return figures.step_curves_figure(panels, study.title)


def write_study(study: Study, outcome: Outcome, out: Path) -> Path:
    """Write the figure with its data (``<figure>.csv``) beside it."""
    from cartpole_q.store.figure_file import write_figure

    return write_figure(out, study_figure(study, outcome))


def check_outputs(out: Path, force: bool) -> None:
    """Refuse, before any work, outputs that exist (without ``force``) or cannot be written."""
    from cartpole_q.store.figure_file import check_figure_file

    check_figure_file(out, "--out", force)


def default_out(study: Study) -> Path:
    """The figure file when ``--out`` is not given: the study's ``figure.file`` here."""
    return Path(study.file)


class BanditKind(RunsKind):
    """``kind: bandit``: one run per learner, the figure and the book's numbers from all.

    A learner is a curve, or one value of a parameter study's curve; its run plays every
    seed in order (the averages are summed in seed order).
    """

    name = "bandit"
    figure_kinds = FIGURE_KINDS
    units = Units("bandit", "runs", "learners")
    runs_per_task = 1  # a learner plays every seed: each is a job of its own

    def read(self, study: StudyFile) -> Study:
        """Check the file (:func:`read_study`)."""
        return read_study(study)

    def runs(self, spec: Study) -> list[dict[str, Cell]]:
        """Each curve's learners, in order: ``curve``, ``learner``."""
        return [
            {"curve": index, "learner": learner}
            for index, curve in enumerate(spec.curves)
            for learner in range(len(curve.agents()))
        ]

    def describe(self, spec: Study) -> tuple[int, str]:
        """Learners x seeds."""
        learners = len(self.runs(spec))
        return learners, (
            f"a bandit study: {_count(learners, 'learner')} x {_count(len(spec.seeds), 'seed')} "
            f"({spec.steps:,} steps each, the {spec.engine} engine)"
        )

    def result_columns(self, spec: Study) -> tuple[str, ...]:
        """The learner's average reward over all its steps (Figure 2.6's measure)."""
        return ("mean_reward",)

    def run_size(self, spec: Study, key: Mapping[str, Cell]) -> int:
        """A learner plays one run per seed."""
        return len(spec.seeds)

    def before_runs(self, spec: Study) -> str | None:
        """The compile notice of the study's engine."""
        from cartpole_q.engines.bandit import compile_notice

        return compile_notice(spec.engine)

    def run_one(self, spec: Study, key: Mapping[str, Cell], handle: RunHandle) -> RunRecord | None:
        """Play one learner on every seed (:func:`play_learner`)."""
        return play_learner(spec, key, handle.should_stop, handle.report)

    def finish(
        self, spec: Study, keys: Sequence[Mapping[str, Cell]], records: Sequence[RunRecord]
    ) -> Finished:
        """The figure, the summary and the book's numbers beside ours."""
        outcome = study_outcome(spec, keys, records)
        lines = summary(spec, outcome)
        rows = book_rows(spec, outcome)
        if rows:
            lines.append("the book's numbers (read off its figure) and ours:")
            lines.extend(f"  {row.text()}" for row in rows)
        return Finished([(spec.file, study_figure(spec, outcome))], (), lines)


BANDIT = register_kind(BanditKind())
"""the bandit kind (registered)"""


def _count(n: int, noun: str) -> str:
    """``1 seed``, ``2,000 seeds``."""
    return f"{n:,} {noun}{'' if n == 1 else 's'}"
