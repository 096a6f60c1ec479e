"""Policy-gradient studies (``kind: policy_gradient``): Figures 13.1 and 13.2.

A study file names an episodic world with a transition table and curves: each an algorithm
(:mod:`cartpole_q.rl.policy_gradient`: REINFORCE, REINFORCE with a baseline, one-step
actor-critic) with its step sizes, its feature layers and its starting weights. Each curve
runs once per seed for ``episodes`` episodes, recording every episode's total reward; the
figure draws each curve's total reward per episode averaged over its runs, with the best
value of the start state a policy that cannot tell the states apart can reach (the short
corridor's, Example 13.1) as a dashed level.
"""

from __future__ import annotations

import functools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from cartpole_q.config import ConfigError, shown_value
from cartpole_q.config.bounds import check_count, check_memory
from cartpole_q.experiments.average_reward import action_rows
from cartpole_q.experiments.linear import (
    WorldFacts,
    flag_of,
    make_world,
    number_of,
    optional_number_of,
    seeds_of,
    weights_of,
    whole_of,
    world_facts,
    world_key,
)
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
from cartpole_q.rl import policy_gradient as methods
from cartpole_q.rl.solvers import one_thread
from cartpole_q.store.studydir import Cell, RunRecord

STUDY_KEYS = ("name", "world", "gamma", "seeds", "episodes", "engine", "curves", "figure")
"""the keys a policy-gradient study file may have"""
CURVE_KEYS = (
    "label", "algorithm", "alpha", "alpha_w", "policy_features", "value_features", "theta0",
    "w0", "min_probability", "lambda_theta", "lambda_w",
)  # fmt: skip
FIGURE_KINDS = ("rewards",)
FIGURE_KEYS = ("kind", "file", "title", "y_min", "y_max", "optimum")
ENGINES = ("numba", "gymnasium")
EXAMPLE = "examples/book/fig13_1_reinforce.yaml"
GRID = 10_000
"""the optimum's grid: ``P(action 1) = k / GRID``, ``k = 1 .. GRID - 1``"""
LAST_SHARE = 10
"""the summary's final performance: the mean over the last tenth of the episodes"""


@dataclass(frozen=True)
class CurveSpec:
    """One curve: an algorithm, its step sizes, its layers and starting weights."""

    label: str
    algorithm: str
    alpha: float
    alpha_w: float
    policy_features: str
    value_features: str
    theta0: tuple[float, ...]
    w0: tuple[float, ...]
    floor: float = 0.0
    """``min_probability`` (two actions): the least probability either action may have"""
    lambdas: tuple[float, float] = (0.0, 0.0)
    """``(lambda_theta, lambda_w)``: actor-critic with traces"""


@dataclass(frozen=True)
class Study:
    """A checked policy-gradient study file."""

    name: str
    world_id: str
    world_kwargs: tuple[tuple[str, Any], ...]
    gamma: float
    seeds: tuple[int, ...]
    episodes: int
    engine: str
    curves: tuple[CurveSpec, ...]
    file: str
    title: str
    y_limits: tuple[float | None, float | None]
    optimum: bool
    where: str


# -- reading --------------------------------------------------------------------------------


def read_study(study: StudyFile) -> Study:
    """Check a policy-gradient study file (its world is made once, to read its table).

    Raises:
        ConfigError: naming the file and the key, with what is wrong.
    """
    raw, where, name = checked_study(
        study, STUDY_KEYS, "a `world`, `curves` and `episodes`", EXAMPLE
    )
    world_id, world_kwargs = world_key(raw.get("world"), where)
    facts = world_facts(world_id, world_kwargs, where)
    if facts.continuing:
        raise ConfigError(
            f"{where}: world: {world_id} is continuing (nothing ends): a policy-gradient study "
            "learns from episodes; give an episodic world such as cartpole_q/ShortCorridor-v0."
        )
    gamma = number_of(raw, "gamma", 1.0, where)
    if not 0.0 <= gamma <= 1.0:
        raise ConfigError(f"{where}: gamma: must be in [0, 1], got {gamma:g}.")
    if "episodes" not in raw:
        raise ConfigError(f"{where}: episodes: is missing; how many episodes each run lasts.")
    episodes = whole_of(raw, "episodes", None, where, 1)
    check_count(where, "episodes", episodes)
    seeds = seeds_of(raw, where)
    engine = raw.get("engine", "numba")
    if engine not in ENGINES:
        raise ConfigError(
            f"{where}: engine: must be one of {', '.join(ENGINES)}, got {shown_value(engine)}."
        )
    curves_raw = raw.get("curves")
    if not isinstance(curves_raw, list) or not curves_raw:
        raise ConfigError(
            f"{where}: curves: must be a list such as [{{label: REINFORCE, algorithm: "
            f"reinforce, alpha: 0.0002}}], got {shown_value(curves_raw)}."
        )
    curves = tuple(_curve(entry, index, facts, where) for index, entry in enumerate(curves_raw))
    for index, curve in enumerate(curves):
        d, d_w = _weights(curve, facts)
        pairs = facts.n_states * facts.n_actions * _policy_width(curve, facts)
        needed = pairs * 16 + (d + d_w) * 8 + len(seeds) * episodes * 16
        check_memory(where, f"curves[{index}]", needed,
                     f"{d:,} policy weights, {len(seeds):,} runs of {episodes:,} episodes")  # fmt: skip
    figure = raw.get("figure", {"kind": "rewards"})
    _, file, title = checked_figure_section(figure, name, where, FIGURE_KEYS, FIGURE_KINDS)
    y_limits = (
        optional_number_of(figure, "y_min", where),
        optional_number_of(figure, "y_max", where),
    )
    optimum = flag_of(figure, "optimum", False, where)
    if optimum:
        _check_state_blind(curves, facts, where)
    return Study(
        name, world_id, world_kwargs, gamma, seeds, episodes, str(engine), curves, file, title,
        y_limits, optimum, where,
    )  # fmt: skip


def _curve(raw: Any, index: int, facts: WorldFacts, where: str) -> CurveSpec:
    here = f"{where}: curves[{index}]"
    if not isinstance(raw, Mapping):
        raise ConfigError(
            f"{here}: must be a mapping {{label, algorithm, alpha, ...}}, got {shown_value(raw)}."
        )
    check_top_keys(raw, CURVE_KEYS, here)
    algorithm = raw.get("algorithm")
    if algorithm not in methods.ALGORITHMS:
        raise ConfigError(
            f"{here}.algorithm: must be one of {', '.join(methods.ALGORITHMS)}, got "
            f"{shown_value(algorithm)}."
        )
    label = raw.get("label", algorithm)
    if not isinstance(label, str):
        raise ConfigError(f"{here}.label: must be text, got {shown_value(label)}.")
    alpha = _step_size(raw, "alpha", here)
    with_value = algorithm in methods.WITH_VALUE
    if with_value:
        alpha_w = _step_size(raw, "alpha_w", here)
    elif "alpha_w" in raw:
        raise ConfigError(
            f"{here}.alpha_w: {algorithm} learns no value; only "
            f"{' and '.join(methods.WITH_VALUE)} take it."
        )
    else:
        alpha_w = 0.0
    default_policy = "declared" if facts.declared_actions is not None else "table"
    policy_features = raw.get("policy_features", default_policy)
    if policy_features not in methods.POLICY_LAYERS:
        raise ConfigError(
            f"{here}.policy_features: must be one of {', '.join(methods.POLICY_LAYERS)}, got "
            f"{shown_value(policy_features)}."
        )
    if policy_features == "declared" and facts.declared_actions is None:
        raise ConfigError(
            f"{here}.policy_features: {facts.world_id} declares no features of its actions "
            "(features_of_action); use `table`."
        )
    value_features = raw.get("value_features", "constant")
    if value_features not in methods.VALUE_LAYERS:
        raise ConfigError(
            f"{here}.value_features: must be one of {', '.join(methods.VALUE_LAYERS)}, got "
            f"{shown_value(value_features)}."
        )
    if not with_value and "value_features" in raw:
        raise ConfigError(f"{here}.value_features: {algorithm} learns no value.")
    floor = number_of(raw, "min_probability", 0.0, here, dotted=True)
    if floor != 0.0 and (facts.n_actions != 2 or not 0.0 < floor < 0.5):
        raise ConfigError(
            f"{here}.min_probability: the least probability of either of two actions, in (0, "
            f"0.5), on a world of two actions ({facts.world_id} has {facts.n_actions}), got "
            f"{floor:g}."
        )
    lambdas = (0.0, 0.0)
    if algorithm in methods.WITH_TRACES:
        lambdas = (_decay(raw, "lambda_theta", here), _decay(raw, "lambda_w", here))
    else:
        for key in ("lambda_theta", "lambda_w"):
            if key in raw:
                raise ConfigError(
                    f"{here}.{key}: {algorithm} keeps no traces; only "
                    f"{', '.join(methods.WITH_TRACES)} takes it."
                )
    spec = CurveSpec(label, str(algorithm), alpha, alpha_w, str(policy_features),
                     str(value_features), (), ())  # fmt: skip
    d, d_w = _weights(spec, facts)
    theta0 = weights_of(raw.get("theta0", 0.0), d, f"{here}.theta0")
    w0 = weights_of(raw.get("w0", 0.0), d_w, f"{here}.w0")
    return CurveSpec(label, str(algorithm), alpha, alpha_w, str(policy_features),
                     str(value_features), theta0, w0, floor, lambdas)  # fmt: skip


def _step_size(raw: Mapping[str, Any], key: str, here: str) -> float:
    value = number_of(raw, key, None, here, dotted=True)
    if value <= 0.0:
        raise ConfigError(f"{here}.{key}: a step size must be above 0, got {value:g}.")
    return value


def _decay(raw: Mapping[str, Any], key: str, here: str) -> float:
    value = number_of(raw, key, None, here, dotted=True)
    if not 0.0 <= value <= 1.0:
        raise ConfigError(f"{here}.{key}: a trace decay in [0, 1], got {value:g}.")
    return value


def _weights(curve: CurveSpec, facts: WorldFacts) -> tuple[int, int]:
    """``(d, d_w)``: the policy's and the value's weights."""
    if curve.policy_features == "declared":
        assert facts.declared_actions is not None
        d = int(facts.declared_actions.shape[2])
    else:
        d = facts.observations * facts.n_actions
    return d, (facts.observations if curve.value_features == "table" else 1)


def _policy_width(curve: CurveSpec, facts: WorldFacts) -> int:
    if curve.policy_features == "declared":
        assert facts.declared_actions is not None
        return max(1, int(np.count_nonzero(facts.declared_actions, axis=2).max()))
    return 1


def _check_state_blind(curves: Sequence[CurveSpec], facts: WorldFacts, where: str) -> None:
    """``figure.optimum`` needs two actions and a policy that is the same in every state."""
    blind = (
        facts.n_actions == 2
        and facts.declared_actions is not None
        and all(curve.policy_features == "declared" for curve in curves)
        and bool(np.all(facts.declared_actions == facts.declared_actions[:1]))
    )
    if not blind:
        raise ConfigError(
            f"{where}: figure.optimum: the best start value is computed over the policies "
            "that are the same in every state, which needs a world of two actions whose "
            "declared action features are the same in every state (the short corridor) and "
            "every curve on them (`policy_features: declared`)."
        )


# -- a run ----------------------------------------------------------------------------------


def runs_of(study: Study) -> list[dict[str, Cell]]:
    """Every run's key: each curve on each seed."""
    return [
        {"curve": index, "seed": seed} for index in range(len(study.curves)) for seed in study.seeds
    ]


def policy_rows(curve: CurveSpec, facts: WorldFacts) -> tuple[np.ndarray, np.ndarray]:
    """The policy layer's rows, row ``s * n + a``: ``(index, value)`` (:func:`~cartpole_q.experiments.average_reward.action_rows`)."""
    return action_rows(curve.policy_features, facts)


def value_rows(curve: CurveSpec, facts: WorldFacts) -> tuple[np.ndarray, np.ndarray]:
    """The value layer's rows, one per state: ``constant`` or ``table``."""
    if curve.value_features == "table":
        groups = facts.groups if facts.groups is not None else np.arange(facts.n_states)
        return groups.astype(np.int64).reshape(-1, 1), np.ones((facts.n_states, 1))
    return np.zeros((facts.n_states, 1), dtype=np.int64), np.ones((facts.n_states, 1))


def new_agent(study: Study, curve: CurveSpec) -> methods.Agent:
    """A curve's agent at its start."""
    facts = world_facts(study.world_id, study.world_kwargs, study.where)
    d, d_w = _weights(curve, facts)
    theta0 = np.full(d, curve.theta0[0]) if len(curve.theta0) == 1 else np.asarray(curve.theta0)
    w0 = np.full(d_w, curve.w0[0]) if len(curve.w0) == 1 else np.asarray(curve.w0)
    settings = methods.Settings(curve.alpha, curve.alpha_w, study.gamma, curve.floor, curve.lambdas)
    return methods.new_agent(
        curve.algorithm, settings, facts.n_actions,
        methods.Layer(*policy_rows(curve, facts), theta0),
        methods.Layer(*value_rows(curve, facts), w0),
    )  # fmt: skip


def run_one(study: Study, key: Mapping[str, Cell], handle: RunHandle) -> RunRecord | None:
    """One curve on one seed: its episodes' total rewards and lengths (``None`` when stopped)."""
    from cartpole_q.engines import linear as tables
    from cartpole_q.engines import policy_gradient as engine
    from cartpole_q.experiments.linear import world_table

    index, seed = int(key["curve"]), int(key["seed"])  # type: ignore[arg-type]
    agent = new_agent(study, study.curves[index])
    facts = world_facts(study.world_id, study.world_kwargs, study.where)
    world = tables.World(
        world_table(study.world_id, study.world_kwargs, study.where),
        False,
        facts.time_limit if facts.time_limit else tables.EPISODE_CAP,
        functools.partial(make_world, study.world_id, study.world_kwargs),
    )
    records = engine.run(
        agent, world, seed, study.episodes, study.engine, handle.should_stop, handle.report
    )
    if records is None:
        return None
    tail = max(1, study.episodes // LAST_SHARE)
    row: dict[str, Cell] = {
        "mean_reward": float(np.mean(records.totals)),
        "final_reward": float(np.mean(records.totals[-tail:])),
    }
    arrays = {
        "rewards": records.totals, "lengths": records.lengths, "theta": agent.theta.copy(),
        "w": agent.w.copy(),
    }  # fmt: skip
    return RunRecord(row, arrays)


# -- the exact optimum ----------------------------------------------------------------------


def start_value(facts: WorldFacts, p: float) -> float:
    """The start value of the policy that takes action 1 with probability ``p`` everywhere."""
    return float(start_values(facts, np.array([p]))[0])


def start_values(facts: WorldFacts, p: np.ndarray) -> np.ndarray:
    """The start value for each ``P(action 1)`` in ``p``: ``solve(I - P_p, r_p)``, weighted by ``d_0``."""
    n = facts.n_states
    values = np.zeros(p.shape[0])
    with one_thread():
        for k, chance in enumerate(p.tolist()):
            pi = (1.0 - chance, chance)
            matrix = np.zeros((n, n))
            reward = np.zeros(n)
            for state in range(n):
                for action in range(2):
                    for probability, following, r, terminated in facts.transitions[state][action]:
                        reward[state] = reward[state] + pi[action] * (probability * r)
                        if not terminated:
                            matrix[state, following] = (
                                matrix[state, following] + pi[action] * probability
                            )
            v = np.linalg.solve(np.eye(n) - matrix, reward)
            total = 0.0
            for state in range(n):
                total = total + facts.initial[state] * v[state]
            values[k] = total
    return values


@functools.lru_cache(maxsize=8)
def best_start(study: Study) -> tuple[float, float]:
    """``(p, value)``: the best start value over ``p = k / GRID`` (the lowest ``k`` on a tie)."""
    facts = world_facts(study.world_id, study.world_kwargs, study.where)
    grid = np.arange(1, GRID) / GRID
    values = start_values(facts, grid)
    best = int(np.argmax(values))  # the first of equal largest
    return float(grid[best]), float(values[best])


def starting_p(study: Study, curve: CurveSpec) -> float:
    """``P(action 1)`` of a curve's starting policy (a state-blind policy: any state's)."""
    agent = new_agent(study, curve)
    methods.policy(agent, 0)
    return float(agent.probabilities[1])


# -- averages, figure, summary ---------------------------------------------------------------


def mean_rewards(
    study: Study, keys: Sequence[Mapping[str, Cell]], records: Sequence[RunRecord]
) -> list[np.ndarray]:
    """Each curve's total reward per episode, the mean over its runs (NumPy's, per episode)."""
    result = []
    for index in range(len(study.curves)):
        mine = [
            np.asarray(r.arrays["rewards"])
            for k, r in zip(keys, records, strict=True)
            if int(k["curve"]) == index  # type: ignore[arg-type]
        ]
        result.append(np.mean(np.stack(mine), axis=0))
    return result


def study_figure(study: Study, means: Sequence[np.ndarray]) -> Any:
    """Each curve's mean total reward per episode; the best start value dashed."""
    from cartpole_q.figures.linear import ErrorCurve, error_curves_figure

    episodes = np.arange(1, study.episodes + 1)
    curves = [
        ErrorCurve(curve.label, episodes, mean, None)
        for curve, mean in zip(study.curves, means, strict=True)
    ]
    levels: list[tuple[str, float]] = []
    if study.optimum:
        p, value = best_start(study)
        levels.append(
            (f"v*(s₀) = {value:.2f}, the best policy blind to the state (p {p:.2f})", value)
        )
    runs = len(study.seeds)
    return error_curves_figure(
        curves, study.title, "Episode",
        f"Total reward on episode, averaged over {runs:,} run{'s' if runs != 1 else ''}",
        study.y_limits, levels=levels,
    )  # fmt: skip


def summary(study: Study, means: Sequence[np.ndarray]) -> list[str]:
    """What ran, each curve's early and final reward, and the exact optimum."""
    runs = len(study.seeds)
    lines = [
        f"{study.name}: {study.world_id}, gamma {study.gamma:g}, {runs:,} run"
        f"{'s' if runs != 1 else ''} of {study.episodes:,} episodes, {study.engine} engine"
    ]
    facts = world_facts(study.world_id, study.world_kwargs, study.where)
    tail = max(1, study.episodes // LAST_SHARE)
    head = min(10, study.episodes)
    for curve, mean in zip(study.curves, means, strict=True):
        steps = f"alpha {curve.alpha:g}" + (
            f", alpha_w {curve.alpha_w:g}" if curve.algorithm in methods.WITH_VALUE else ""
        )
        start = ""
        if study.optimum:
            p = starting_p(study, curve)
            start = f"; its starting policy (p {p:.4f}) has start value {start_value(facts, p):.2f}"
        lines.append(
            f"  {curve.label} ({curve.algorithm}, {steps}): total reward per episode, mean of "
            f"episodes 1-{head} {float(np.mean(mean[:head])):.2f}, of the last {tail:,} "
            f"{float(np.mean(mean[-tail:])):.2f}{start}"
        )
    if study.optimum:
        p, value = best_start(study)
        lines.append(
            f"  the best policy blind to the state: P(action 1) {p:.4f}, start value {value:.4f}"
        )
    return lines


def finish(
    study: Study, keys: Sequence[Mapping[str, Cell]], records: Sequence[RunRecord]
) -> Finished:
    """The figure and the summary."""
    means = mean_rewards(study, keys, records)
    return Finished([(study.file, study_figure(study, means))], (), summary(study, means))


def _columns(study: Study) -> tuple[str, ...]:
    return ("mean_reward", "final_reward")


def _episodes(study: Study) -> int:
    return study.episodes


def _unit(study: Study) -> str:
    return "episodes"


def _compile_notice() -> str | None:
    from cartpole_q.engines.policy_gradient import compile_notice

    return compile_notice()


class PolicyGradientKind(CurvesKind):
    """``kind: policy_gradient``: REINFORCE and actor-critic (Figures 13.1, 13.2)."""

    name = "policy_gradient"
    units = Units("policy gradient", "episodes", "runs")
    runs_per_task = 8


POLICY_GRADIENT = register_kind(
    PolicyGradientKind(
        CurveFunctions(
            read_study, runs_of, run_one, finish, _columns, _episodes, _unit, _compile_notice,
        )
    )
)  # fmt: skip
"""the policy-gradient kind (registered)"""
