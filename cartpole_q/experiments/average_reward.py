"""Average-reward studies (``kind: average_reward``): Figure 10.5, access control.

A study file names a continuing world with a transition table and curves: each an
algorithm (:mod:`cartpole_q.rl.average_reward`: differential semi-gradient SARSA) with its
step sizes ``alpha`` and ``beta``, its exploration and its action-value layer. Each curve
runs once per seed for ``steps`` steps, recording ``R̄`` and the reward per step every
``record_every`` steps. Two figures: ``policy`` (Figure 10.5: the learned greedy policy and
the value of its best action in each state, beside the exact optimal policy and
differential values of relative value iteration, and ``R̄`` over the steps against the
optimal gain) and ``average_reward`` (each curve's ``R̄`` over the steps, averaged over its
runs).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from cartpole_q.config import ConfigError, shown_value
from cartpole_q.config.bounds import check_count, check_memory
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
from cartpole_q.rl import average_reward as methods
from cartpole_q.rl.mdp import FiniteMDP
from cartpole_q.rl.solvers import GainSolution, policy_gain, relative_value_iteration
from cartpole_q.store.studydir import Cell, RunRecord

STUDY_KEYS = ("name", "world", "seeds", "steps", "record_every", "engine", "curves", "figure")
"""the keys an average-reward study file may have"""
CURVE_KEYS = ("label", "algorithm", "alpha", "beta", "epsilon", "features", "w0", "r_bar0")
FIGURE_KINDS = ("policy", "average_reward")
FIGURE_KEYS = ("kind", "file", "title", "optimum", "y_min", "y_max")
ENGINES = ("numba", "gymnasium")
EXAMPLE = "examples/book/fig10_5_access_control.yaml"
LAST_SHARE = 10
"""the summary's final performance: the mean over the last tenth of the records"""


@dataclass(frozen=True)
class CurveSpec:
    """One curve: an algorithm, its step sizes, exploration, layer and start."""

    label: str
    algorithm: str
    alpha: float
    beta: float
    epsilon: float
    features: str
    w0: tuple[float, ...]
    r_bar0: float


@dataclass(frozen=True)
class Study:
    """A checked average-reward study file."""

    name: str
    world_id: str
    world_kwargs: tuple[tuple[str, Any], ...]
    seeds: tuple[int, ...]
    steps: int
    record_every: int
    engine: str
    curves: tuple[CurveSpec, ...]
    figure_kind: str
    file: str
    title: str
    y_limits: tuple[float | None, float | None]
    optimum: bool
    where: str


# -- reading --------------------------------------------------------------------------------


def read_study(study: StudyFile) -> Study:
    """Check an average-reward study file (its world is made once, to read its table).

    Raises:
        ConfigError: naming the file and the key, with what is wrong.
    """
    raw, where, name = checked_study(study, STUDY_KEYS, "a `world`, `curves` and `steps`", EXAMPLE)
    world_id, world_kwargs = world_key(raw.get("world"), where)
    facts = world_facts(world_id, world_kwargs, where)
    if not facts.continuing:
        raise ConfigError(
            f"{where}: world: {world_id} is episodic (some outcome ends): an average-reward "
            "study learns the reward per step of a continuing world, such as "
            "cartpole_q/AccessControl-v0."
        )
    if "steps" not in raw:
        raise ConfigError(f"{where}: steps: is missing; how many steps each run lasts.")
    steps = whole_of(raw, "steps", None, where, 1)
    check_count(where, "steps", steps)
    record_every = whole_of(raw, "record_every", max(1, steps // 100), where, 1)
    if record_every > steps:
        raise ConfigError(
            f"{where}: record_every: at most steps ({steps:,}), got {record_every:,}."
        )
    seeds = seeds_of(raw, where)
    engine = raw.get("engine", "numba")
    if engine not in ENGINES:
        raise ConfigError(
            f"{where}: engine: must be one of {', '.join(ENGINES)}, got {shown_value(engine)}."
        )
    curves_raw = raw.get("curves")
    if not isinstance(curves_raw, list) or not curves_raw:
        raise ConfigError(
            f"{where}: curves: must be a list such as [{{label: SARSA, algorithm: "
            f"differential_sarsa, alpha: 0.01, beta: 0.01}}], got {shown_value(curves_raw)}."
        )
    curves = tuple(_curve(entry, index, facts, where) for index, entry in enumerate(curves_raw))
    points = -(-steps // record_every)
    for index, curve in enumerate(curves):
        d = _weights(curve, facts)
        pairs = facts.n_states * facts.n_actions
        needed = pairs * 16 + d * 8 + len(seeds) * points * 24
        check_memory(where, f"curves[{index}]", needed,
                     f"{d:,} weights, {len(seeds):,} runs of {points:,} records")  # fmt: skip
    figure = raw.get("figure", {"kind": "average_reward"})
    kind, file, title = checked_figure_section(figure, name, where, FIGURE_KEYS, FIGURE_KINDS)
    y_limits = (
        optional_number_of(figure, "y_min", where),
        optional_number_of(figure, "y_max", where),
    )
    optimum = flag_of(figure, "optimum", kind == "policy", where)
    if kind == "policy":
        _check_policy_figure(curves, facts, world_id, where)
    study_spec = Study(
        name, world_id, world_kwargs, seeds, steps, record_every, str(engine), curves, kind,
        file, title, y_limits, optimum, where,
    )  # fmt: skip
    if optimum:
        optimal_gain(study_spec)  # refused now, not after the runs, if the world has no gain
    return study_spec


def _curve(raw: Any, index: int, facts: WorldFacts, where: str) -> CurveSpec:
    here = f"{where}: curves[{index}]"
    if not isinstance(raw, Mapping):
        raise ConfigError(
            f"{here}: must be a mapping {{label, algorithm, alpha, beta, ...}}, got "
            f"{shown_value(raw)}."
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
    beta = _step_size(raw, "beta", here)
    epsilon = number_of(raw, "epsilon", 0.1, here, dotted=True)
    if not 0.0 <= epsilon <= 1.0:
        raise ConfigError(f"{here}.epsilon: must be in [0, 1], got {epsilon:g}.")
    features = raw.get("features", "table")
    if features not in methods.LAYERS:
        raise ConfigError(
            f"{here}.features: must be one of {', '.join(methods.LAYERS)}, got "
            f"{shown_value(features)}."
        )
    if features == "declared" and facts.declared_actions is None:
        raise ConfigError(
            f"{here}.features: {facts.world_id} declares no features of its actions "
            "(features_of_action); use `table`."
        )
    r_bar0 = number_of(raw, "r_bar0", 0.0, here, dotted=True)
    spec = CurveSpec(label, str(algorithm), alpha, beta, epsilon, str(features), (), r_bar0)
    w0 = weights_of(raw.get("w0", 0.0), _weights(spec, facts), f"{here}.w0")
    return CurveSpec(label, str(algorithm), alpha, beta, epsilon, str(features), w0, r_bar0)


def _step_size(raw: Mapping[str, Any], key: str, here: str) -> float:
    if key not in raw:
        raise ConfigError(f"{here}.{key}: is missing; a step size above 0.")
    value = number_of(raw, key, None, here, dotted=True)
    if value <= 0.0:
        raise ConfigError(f"{here}.{key}: a step size must be above 0, got {value:g}.")
    return value


def _weights(curve: CurveSpec, facts: WorldFacts) -> int:
    """The layer's weights ``d``."""
    if curve.features == "declared":
        assert facts.declared_actions is not None
        return int(facts.declared_actions.shape[2])
    return facts.observations * facts.n_actions


def _check_policy_figure(
    curves: Sequence[CurveSpec], facts: WorldFacts, world_id: str, where: str
) -> None:
    """``figure.kind: policy`` draws one curve's table on a world of two state components."""
    from cartpole_q.families import profile_for

    if len(curves) != 1:
        raise ConfigError(
            f"{where}: figure.kind: policy draws one curve's policy; this study has "
            f"{len(curves)} curves (use `average_reward` to compare them)."
        )
    profile = profile_for(world_id)
    shape = profile.state_components
    if len(shape) != 2 or math.prod(shape) != facts.n_states or facts.groups is not None:
        raise ConfigError(
            f"{where}: figure.kind: policy draws a world whose states are two components "
            f"(access control: priority and free servers); {world_id} has none declared."
        )


# -- a run ----------------------------------------------------------------------------------


def runs_of(study: Study) -> list[dict[str, Cell]]:
    """Every run's key: each curve on each seed."""
    return [
        {"curve": index, "seed": seed} for index in range(len(study.curves)) for seed in study.seeds
    ]


def action_rows(features: str, facts: WorldFacts) -> tuple[np.ndarray, np.ndarray]:
    """The action-value layer's rows, row ``s * n + a``: ``(index, value)``, padded with zero values."""
    n_states, n = facts.n_states, facts.n_actions
    if features == "table":
        groups = facts.groups if facts.groups is not None else np.arange(n_states)
        index = (np.repeat(groups, n) * n + np.tile(np.arange(n), n_states)).astype(np.int64)
        return index.reshape(-1, 1), np.ones((n_states * n, 1))
    assert facts.declared_actions is not None
    flat = np.asarray(facts.declared_actions, dtype=np.float64).reshape(n_states * n, -1)
    width = max(1, int(np.count_nonzero(flat, axis=1).max()))
    index = np.zeros((flat.shape[0], width), dtype=np.int64)
    value = np.zeros((flat.shape[0], width))
    for row in range(flat.shape[0]):
        nonzero = np.flatnonzero(flat[row])
        index[row, : nonzero.size] = nonzero
        value[row, : nonzero.size] = flat[row, nonzero]
    return index, value


def new_agent(study: Study, curve: CurveSpec) -> methods.Agent:
    """A curve's agent at its start."""
    facts = world_facts(study.world_id, study.world_kwargs, study.where)
    d = _weights(curve, facts)
    w0 = np.full(d, curve.w0[0]) if len(curve.w0) == 1 else np.asarray(curve.w0)
    return methods.new_agent(
        curve.algorithm, curve.alpha, curve.beta, curve.epsilon, facts.n_actions,
        action_rows(curve.features, facts), w0, curve.r_bar0, facts.n_states,
    )  # fmt: skip


def run_one(study: Study, key: Mapping[str, Cell], handle: RunHandle) -> RunRecord | None:
    """One curve on one seed: ``R̄`` and the reward rate at every record, ``w``, the visits."""
    from cartpole_q.engines import average_reward as engine
    from cartpole_q.engines import linear as tables
    from cartpole_q.experiments.linear import world_table

    index, seed = int(key["curve"]), int(key["seed"])  # type: ignore[arg-type]
    agent = new_agent(study, study.curves[index])
    world = tables.World(
        world_table(study.world_id, study.world_kwargs, study.where),
        True,
        0,
        functools.partial(make_world, study.world_id, study.world_kwargs),
    )
    records = engine.run(
        agent, world, seed, study.steps, study.record_every, study.engine, handle.should_stop,
        handle.report,
    )  # fmt: skip
    if records is None:
        return None
    tail = max(1, records.at.shape[0] // LAST_SHARE)
    row: dict[str, Cell] = {
        "r_bar": float(agent.r_bar[0]),
        "final_r_bar": float(np.mean(records.r_bar[-tail:])),
        "final_rate": float(np.mean(records.rate[-tail:])),
    }
    arrays = {
        "at": records.at, "r_bar": records.r_bar, "rate": records.rate, "w": agent.w.copy(),
        "visits": agent.visits.copy(),
    }  # fmt: skip
    return RunRecord(row, arrays)


# -- the exact optimum ----------------------------------------------------------------------


def world_model(study: Study) -> FiniteMDP:
    """The world's finite MDP (its table and start)."""
    facts = world_facts(study.world_id, study.world_kwargs, study.where)
    return FiniteMDP.from_transitions(facts.transitions, facts.initial, facts.n_actions)


@functools.lru_cache(maxsize=8)
def optimal_gain(study: Study) -> GainSolution:
    """The optimal gain, differential values and policy (relative value iteration).

    Raises:
        ConfigError: the world has no single optimal gain that the iteration reaches.
    """
    try:
        return relative_value_iteration(world_model(study), max_iterations=100_000)
    except ValueError as error:
        raise ConfigError(
            f"{study.where}: figure.optimum: relative value iteration on {study.world_id} "
            f"failed ({error}); set `optimum: false`."
        ) from None


def learned_q(study: Study, curve: CurveSpec, w: np.ndarray) -> np.ndarray:
    """``q̂(s, a)`` of every state and action from the weights ``w``, ``(N, n)``."""
    facts = world_facts(study.world_id, study.world_kwargs, study.where)
    index, value = action_rows(curve.features, facts)
    q = np.zeros(index.shape[0])
    for j in range(index.shape[1]):
        q = q + w[index[:, j]] * value[:, j]
    return q.reshape(facts.n_states, facts.n_actions)


def greedy_policy(q: np.ndarray) -> np.ndarray:
    """The lowest action with the largest value, per state (int64)."""
    found: np.ndarray = np.argmax(q, axis=1).astype(np.int64)
    return found


def greedy_gain(study: Study, policy: np.ndarray) -> float | None:
    """The exact gain of a deterministic policy (``None``: it has no single gain)."""
    try:
        return policy_gain(world_model(study), policy)[0]
    except ValueError:
        return None


@dataclass(frozen=True)
class GainOptimum:
    """``cartpole-q optimum`` on an average-reward world: the optimal gain and policy."""

    env_id: str
    kwargs: dict[str, Any]
    solution: GainSolution
    component_names: tuple[str, ...]
    component_values: tuple[tuple[str, ...], ...]
    action_names: tuple[str, ...]

    def to_json(self) -> dict[str, Any]:
        """The gain, the sweeps and the policy (one action per state), for ``--json``."""
        return {
            "env_id": self.env_id, "kwargs": self.kwargs, "gain": self.solution.gain,
            "iterations": self.solution.iterations,
            "policy": [int(a) for a in self.solution.policy],
        }  # fmt: skip

    def lines(self) -> list[str]:
        """The gain, then the policy as rows of the first state component (if declared)."""
        found = self.solution
        lines = [
            f"optimal gain (reward per step, relative value iteration, {found.iterations:,} "
            f"sweeps): {found.gain:.6f}"
        ]
        shape = tuple(len(values) for values in self.component_values)
        if len(shape) != 2 or math.prod(shape) != found.policy.shape[0]:
            names = [self.action_names[int(a)] for a in found.policy]
            return [*lines, "optimal policy, by state: " + " ".join(names)]
        width = max(len(name) for name in self.action_names)
        columns = " ".join(f"{value:>{width}}" for value in self.component_values[1])
        label = max(len(value) for value in self.component_values[0])
        lines.append(
            f"optimal policy ({self.component_names[0]} by row, {self.component_names[1]} "
            "by column; with no choice to make, the lowest action):"
        )
        lines.append(f"  {'':>{label}}  {columns}")
        policy = found.policy.reshape(shape)
        for row in reversed(range(shape[0])):
            cells = " ".join(f"{self.action_names[int(a)]:>{width}}" for a in policy[row])
            lines.append(f"  {self.component_values[0][row]:>{label}}  {cells}")
        return lines


def gain_optimum(env_id: str, assignments: Sequence[tuple[str, Any]]) -> GainOptimum:
    """The optimal gain of an average-reward world (``cartpole-q optimum``).

    Raises:
        UserError: a key other than the world's (``env.kwargs.KEY``).
        ConfigError: the world cannot be made, or relative value iteration fails.
    """
    import gymnasium

    from cartpole_q.config import COMMAND_LINE, load_config
    from cartpole_q.errors import UserError
    from cartpole_q.families import profile_for

    overrides: dict[str, Any] = {"env.id": env_id}
    for key, value in assignments:
        if key != "env" and not key.startswith("env."):
            raise UserError(f"--set {key}: optimum takes env keys (env.kwargs.KEY=VALUE).")
        overrides[key] = value
    kwargs = dict(load_config(overrides=overrides, override_source=COMMAND_LINE).env.kwargs)
    try:
        env = gymnasium.make(env_id, **kwargs)
    except Exception as error:  # a refused argument: the world's own message
        raise ConfigError(f"--set env.kwargs: {env_id} cannot be made: {error}") from None
    world: Any = env.unwrapped
    model = FiniteMDP.from_transitions(
        world.P, world.initial_state_distrib, int(world.action_space.n)
    )
    env.close()
    try:
        solution = relative_value_iteration(model, max_iterations=100_000)
    except ValueError as error:
        raise ConfigError(f"{env_id}: relative value iteration failed: {error}.") from None
    profile = profile_for(env_id)
    values = profile.component_values
    if kwargs:  # another size: the components' values are counted afresh
        values = ()
    return GainOptimum(
        env_id, kwargs, solution, profile.component_names, values,
        profile.action_names or tuple(str(a) for a in range(model.n_actions)),
    )  # fmt: skip


# -- averages, figures, summary --------------------------------------------------------------


def _records_of(
    study: Study, keys: Sequence[Mapping[str, Cell]], records: Sequence[RunRecord], index: int
) -> list[RunRecord]:
    return [
        record
        for key, record in zip(keys, records, strict=True)
        if int(key["curve"]) == index  # type: ignore[arg-type]
    ]


def study_figure(
    study: Study, keys: Sequence[Mapping[str, Cell]], records: Sequence[RunRecord]
) -> Any:
    """The study's figure: Figure 10.5's panels, or each curve's ``R̄`` over the steps."""
    from cartpole_q.figures.linear import ErrorCurve, error_curves_figure

    levels: list[tuple[str, float]] = []
    if study.optimum:
        levels.append(
            (f"optimal gain r* = {optimal_gain(study).gain:.4f}", optimal_gain(study).gain)
        )
    if study.figure_kind == "policy":
        return _policy_figure(study, records[0], levels)
    curves = []
    for index, curve in enumerate(study.curves):
        mine = _records_of(study, keys, records, index)
        at = np.asarray(mine[0].arrays["at"])
        mean = np.mean(np.stack([np.asarray(r.arrays["r_bar"]) for r in mine]), axis=0)
        curves.append(ErrorCurve(curve.label, at, mean, None))
    runs = len(study.seeds)
    return error_curves_figure(
        curves, study.title, "Steps",
        f"R̄ (the learned reward per step), averaged over {runs:,} run{'s' if runs != 1 else ''}",
        study.y_limits, levels=levels,
    )  # fmt: skip


def _policy_figure(study: Study, record: RunRecord, levels: list[tuple[str, float]]) -> Any:
    """Figure 10.5 from the first run (the first curve on the first seed)."""
    from cartpole_q.families import profile_for
    from cartpole_q.figures.average_reward import PolicyPanels, policy_values_figure

    profile = profile_for(study.world_id)
    shape = profile.state_components
    curve = study.curves[0]
    q = learned_q(study, curve, np.asarray(record.arrays["w"]))
    visits = np.asarray(record.arrays["visits"])
    learned = greedy_policy(q)
    optimum = optimal_gain(study) if study.optimum else None
    gain = greedy_gain(study, learned)
    if gain is not None:
        levels = [*levels, (f"gain of the learned greedy policy = {gain:.4f}", gain)]
    best = q.max(axis=1)
    optimal_best = None
    if optimum is not None:
        # differential values are defined up to a constant: the optimum's is shifted to the
        # learned one's mean over the steps taken (the visits), so that the two can be compared
        exact = optimum.q.max(axis=1)
        weights = visits / max(1, int(visits.sum()))
        optimal_best = exact + float(np.sum(weights * (best - exact)))
    names = profile.component_values
    panels = PolicyPanels(
        shape=(int(shape[0]), int(shape[1])),
        component_names=(profile.component_names[0], profile.component_names[1]),
        component_values=(
            names[0] if names else tuple(str(i) for i in range(shape[0])),
            names[1] if len(names) > 1 else tuple(str(i) for i in range(shape[1])),
        ),
        action_names=profile.action_names or tuple(str(a) for a in range(q.shape[1])),
        learned=learned,
        visited=visits > 0,
        optimal=None if optimum is None else optimum.policy,
        learned_best=best,
        optimal_best=optimal_best,
        at=np.asarray(record.arrays["at"]),
        r_bar=np.asarray(record.arrays["r_bar"]),
        rate=np.asarray(record.arrays["rate"]),
        levels=tuple(levels),
        label=f"{curve.label}, seed {study.seeds[0]}, {study.steps:,} steps",
    )
    return policy_values_figure(panels, study.title)


def summary(
    study: Study, keys: Sequence[Mapping[str, Cell]], records: Sequence[RunRecord]
) -> list[str]:
    """What ran, each curve's learned ``R̄``, reward rate and greedy policy's gain; the optimum."""
    runs = len(study.seeds)
    lines = [
        f"{study.name}: {study.world_id}, {runs:,} run{'s' if runs != 1 else ''} of "
        f"{study.steps:,} steps, {study.engine} engine"
    ]
    for index, curve in enumerate(study.curves):
        mine = _records_of(study, keys, records, index)
        r_bars = [float(r.row["r_bar"]) for r in mine]  # type: ignore[arg-type]
        tails = [float(r.row["final_r_bar"]) for r in mine]  # type: ignore[arg-type]
        rates = [float(r.row["final_rate"]) for r in mine]  # type: ignore[arg-type]
        gains = [
            greedy_gain(study, greedy_policy(learned_q(study, curve, np.asarray(r.arrays["w"]))))
            for r in mine
        ]
        known = [g for g in gains if g is not None]
        gain_text = f"{float(np.mean(known)):.4f}" if known else "none (not one recurrent class)"
        lines.append(
            f"  {curve.label} ({curve.algorithm}, alpha {curve.alpha:g}, beta {curve.beta:g}, "
            f"epsilon {curve.epsilon:g}): R̄ at the end {float(np.mean(r_bars)):.4f} (runs "
            f"{min(r_bars):.4f} to {max(r_bars):.4f}); over the last tenth of the records, "
            f"R̄ {float(np.mean(tails)):.4f} and the reward per step "
            f"{float(np.mean(rates)):.4f}; the exact gain of the learned greedy policy "
            f"{gain_text}"
        )
    if study.optimum:
        found = optimal_gain(study)
        lines.append(
            f"  optimal gain (relative value iteration, {found.iterations:,} sweeps): "
            f"{found.gain:.6f}"
        )
    return lines


def finish(
    study: Study, keys: Sequence[Mapping[str, Cell]], records: Sequence[RunRecord]
) -> Finished:
    """The figure and the summary."""
    return Finished(
        [(study.file, study_figure(study, keys, records))], (), summary(study, keys, records)
    )


def _columns(study: Study) -> tuple[str, ...]:
    return ("r_bar", "final_r_bar", "final_rate")


def _steps(study: Study) -> int:
    return study.steps


def _unit(study: Study) -> str:
    return "steps"


def _compile_notice() -> str | None:
    from cartpole_q.engines.average_reward import compile_notice

    return compile_notice()


class AverageRewardKind(CurvesKind):
    """``kind: average_reward``: differential semi-gradient SARSA (Figure 10.5)."""

    name = "average_reward"
    units = Units("average reward", "steps", "runs")
    runs_per_task = 1


AVERAGE_REWARD = register_kind(
    AverageRewardKind(
        CurveFunctions(
            read_study, runs_of, run_one, finish, _columns, _steps, _unit, _compile_notice,
        )
    )
)  # fmt: skip
"""the average-reward kind (registered)"""
