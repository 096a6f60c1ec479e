"""Greedy evaluation of finished runs: one run (with video or a window), or many seeds at once.

``cartpole-q eval`` calls one function here and prints what it returns. Every evaluation
plays in ``gymnasium.make`` (or, with ``--engine numba``, on the environment's compiled twin:
the same returns, every seed in this process); where the environment has an exact model,
the greedy policy's exact return is given beside the optimum. ``cartpole-q optimum`` is here too: the model's
optimum without a run.
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from cartpole_q.config import COMMAND_LINE, Config, load_config
from cartpole_q.envs.models import GridLayout, grid_layout
from cartpole_q.errors import UserError
from cartpole_q.evaluation import (
    PLAY_ENGINES,
    EvalReport,
    ExactReport,
    evaluate,
    evaluate_tables,
    exact_report,
    under_conditions,
)
from cartpole_q.experiments.workers import JobHandle, default_workers, map_jobs
from cartpole_q.results import is_success
from cartpole_q.store.rundir import Run
from cartpole_q.store.runsets import RunSet

if TYPE_CHECKING:
    from cartpole_q.engines.base import EvaluatedPolicy
    from cartpole_q.engines.plan import Plan


@dataclass(frozen=True)
class RunEvaluation:
    """One run's greedy evaluation: its returns, the threshold, the exact figures."""

    report: EvalReport
    threshold: float | None
    """the threshold under the conditions played (a changed time limit scales CartPole's)"""
    exact: ExactReport | None
    """the greedy policy's exact return beside the optimum (``None`` without a model)"""
    conditions: dict[str, Any]
    """the changed physics and time limit played under (empty when unchanged)"""

    def to_json(self) -> dict[str, Any]:
        """What ``eval --json`` prints: the report, and the exact figures and conditions."""
        data = self.report.to_dict()
        if self.exact is not None:
            data["exact"] = self.exact.to_dict()
        if self.conditions:
            data["conditions"] = self.conditions
        return data


@dataclass(frozen=True)
class Recording:
    """Where ``eval --video`` records, and how much: a GIF or MP4 of the first episodes."""

    path: Path
    """the ``.gif`` or ``.mp4`` file"""
    episodes: int = 1
    """how many of the played episodes it records"""
    force: bool = False
    """replace an existing file"""


def evaluate_run(
    run: Run,
    *,
    episodes: int | None = None,
    seed: int | None = None,
    physics: Mapping[str, Any] | None = None,
    max_steps: int | None = None,
    recording: Recording | None = None,
    render: bool = False,
    engine: str = "gymnasium",
) -> RunEvaluation:
    """Play one run's greedy policy in ``gymnasium.make``, maybe recording or showing it.

    Args:
        run: the run.
        episodes: greedy episodes (default: the run's ``eval.episodes``).
        seed: the first reset's seed (default: the run's ``eval.seed``).
        physics: play under these ``env.physics`` values instead.
        max_steps: play with this time limit instead.
        recording: record the first episodes as a GIF or MP4.
        render: show the episodes in Gymnasium's window.
        engine: ``gymnasium``, or ``numba`` to play on the compiled twin (no video, no window).

    Raises:
        UserError: ``render`` and ``recording`` together, ``render`` without a display, or
            a ``recording`` path that cannot be written (checked before any episode is
            played); ``recording`` or ``render`` with ``numba``.
        ConfigError: ``physics`` or ``max_steps`` do not fit the environment, or the
            environment has no twin under them (``numba``).
    """
    from cartpole_q.envs.gym import config_threshold, display_problem

    if engine != "gymnasium" and (render or recording is not None):
        raise UserError(
            f"--{'render' if render else 'video'} shows gymnasium.make's own drawing: it "
            f"cannot be combined with --engine {engine} (the compiled twin draws nothing)."
        )
    threshold = run.result.reward_threshold
    if physics or max_steps is not None:
        run = dataclasses.replace(run, config=under_conditions(run.config, physics, max_steps))
        threshold = config_threshold(run.config)
    if render and recording is not None:
        raise UserError("--render and --video cannot be combined: choose one.")
    if render and (problem := display_problem()) is not None:
        raise UserError(
            f"--render needs a display, but {problem}; "
            "record the episodes with --video FILE.gif instead."
        )
    if recording is None:
        report = evaluate(
            run.q_table, run.config, episodes=episodes, seed=seed,
            render_mode="human" if render else None, engine=engine,
        )  # fmt: skip
    else:
        from cartpole_q.store.video import VideoRecorder, offscreen_rendering

        # The recorder checks the file (extension, directory, an existing file) before playing.
        with VideoRecorder(
            recording.path, episodes=recording.episodes, force=recording.force
        ) as recorder:
            with offscreen_rendering():
                report = evaluate(
                    run.q_table, run.config, episodes=episodes, seed=seed,
                    render_mode="rgb_array", on_frame=recorder.on_frame,
                )  # fmt: skip
            recorder.save()
    exact = exact_report(run.config, run.q_table)  # a sentence when there is no model
    return RunEvaluation(
        report,
        threshold,
        None if isinstance(exact, str) else exact,
        conditions_of(physics, max_steps),
    )


def _evaluate_one(
    handle: JobHandle | None,
    name: str,
    config_mapping: dict[str, Any],
    q_table: np.ndarray,
    episodes: int | None,
    seed: int | None,
    physics: dict[str, Any] | None = None,
    max_steps: int | None = None,
) -> dict[str, Any]:
    """Job: one seed's greedy evaluation in ``gymnasium.make`` (and its exact figures)."""
    trained = load_config(config_mapping)
    config = under_conditions(trained, physics, max_steps)
    report = evaluate(q_table, config, episodes=episodes, seed=seed)
    result = {"run_seed": trained.seed, "path": name, **report.to_dict()}
    exact = exact_report(config, q_table)
    if not isinstance(exact, str):
        result["exact"] = exact.to_dict()
    return result


def exact_summary(results: list[dict[str, Any]]) -> dict[str, Any] | None:
    """The seeds' exact greedy returns against the optimum (``None`` without a model).

    ``within_0.01`` counts the seeds whose gap is at most 0.01, ``within_1%`` those within
    1% of the optimum's magnitude (both as the issue's acceptance states them).
    """
    exact = [result["exact"] for result in results if "exact" in result]
    if not exact:
        return None
    optimum = exact[0]["optimum"]["return"]
    greedy = np.array([item["greedy"]["return"] for item in exact])
    gaps = optimum - greedy
    tolerance = 1e-9 * max(1.0, abs(optimum))  # the same value, up to rounding
    return {
        "note": exact[0]["note"],
        "optimum": optimum,
        "greedy_median": float(np.median(greedy)),
        "greedy_min": float(np.min(greedy)),
        "gap_max": float(np.max(gaps)),
        "within_0.01": int(np.sum(gaps <= 0.01 + tolerance)),
        "within_1%": int(np.sum(gaps <= 0.01 * abs(optimum) + tolerance)),
        "optimal": int(np.sum(gaps <= tolerance)),
        "seeds": len(exact),
    }


def evaluate_seeds(
    run_set: RunSet,
    *,
    episodes: int | None = None,
    seed: int | None = None,
    workers: int | None = None,
    physics: dict[str, Any] | None = None,
    max_steps: int | None = None,
    engine: str = "gymnasium",
) -> dict[str, Any]:
    """Evaluate every finished seed of a multi-seed run or sweep point.

    ``physics`` and ``max_steps`` play under other conditions (see ``under_conditions``).
    In ``gymnasium.make`` the seeds play in parallel on ``workers`` processes; on the
    compiled twin (``engine="numba"``) they play here, one after another, with the compiled
    play loaded once (faster than starting workers: 100 seeds x 100 episodes in a fraction
    of a second).

    Returns:
        ``runs`` (one ``eval --json`` object per finished seed, with ``run_seed`` and
        ``path``), ``successes`` (means at or above the threshold), ``reward_threshold``,
        ``episodes``, the ``mean`` and ``min`` of the seeds' means, ``seeds`` (how many
        the run has), ``missing`` and ``unfinished`` (seeds left out), ``conditions`` (the physics and time limit played under, when changed),
        ``notes`` (what was left out or is unfinished) and ``note`` (them as one line, or
        None), ``played_in`` (``gymnasium`` or ``twin``).
    """
    from cartpole_q.envs.gym import config_threshold

    runs = run_set.runs
    if engine == "gymnasium":
        workers = workers or default_workers(len(runs))
        jobs = [
            (run.path.name, run.config.to_dict(), run.q_table, episodes, seed, physics, max_steps)
            for run in runs
        ]
        results = map_jobs(_evaluate_one, jobs, workers)
    else:
        results = _evaluate_here(run_set, episodes, seed, physics, max_steps, engine)
    reward_threshold = run_set.reward_threshold
    if physics or max_steps is not None:  # the horizon may scale CartPole's threshold
        conditions = under_conditions(run_set.config, physics, max_steps)
        reward_threshold = config_threshold(conditions)
    means = [result["mean"] for result in results]
    exact = exact_summary(results)
    return {
        **({"exact": exact} if exact else {}),
        "runs": results,
        "successes": sum(is_success(m, reward_threshold) is True for m in means),
        "reward_threshold": reward_threshold,
        "episodes": results[0]["episodes"],
        "mean": float(np.mean(means)),
        "min": float(np.min(means)),
        "seeds": run_set.seeds,
        "missing": list(run_set.missing),
        "unfinished": list(run_set.unfinished),
        "conditions": conditions_of(physics, max_steps),
        "notes": list(run_set.notes),
        "note": " ".join(run_set.notes) or None,
        "played_in": PLAY_ENGINES[engine],
    }


def _evaluate_here(
    run_set: RunSet,
    episodes: int | None,
    seed: int | None,
    physics: dict[str, Any] | None,
    max_steps: int | None,
    engine: str,
) -> list[dict[str, Any]]:
    """Every seed's evaluation in this process, as :func:`_evaluate_one` gives them.

    The seeds of a multi-seed run or sweep point share their config but for ``seed``: the
    set's config gives the environment, the grid and the evaluation's defaults.
    """
    config = under_conditions(run_set.config, physics, max_steps)
    reports = evaluate_tables(
        [run.q_table for run in run_set.runs], config, episodes=episodes, seed=seed,
        engine=engine,
    )  # fmt: skip
    results = []
    for run, report in zip(run_set.runs, reports, strict=True):
        result = {"run_seed": run.config.seed, "path": run.path.name, **report.to_dict()}
        exact = exact_report(config, run.q_table)
        if not isinstance(exact, str):
            result["exact"] = exact.to_dict()
        results.append(result)
    return results


def conditions_of(physics: Mapping[str, Any] | None, max_steps: int | None) -> dict[str, Any]:
    """The changed conditions an evaluation played under, as ``eval --json`` echoes them.

    >>> conditions_of({"length": 0.75}, None), conditions_of(None, None)
    ({'physics': {'length': 0.75}}, {})
    """
    conditions: dict[str, Any] = {}
    if physics:
        conditions["physics"] = dict(physics)
    if max_steps is not None:
        conditions["max_steps"] = max_steps
    return conditions


@dataclass(frozen=True)
class Optimum:
    """An environment's exact optimum (``cartpole-q optimum``)."""

    env_id: str
    kwargs: dict[str, Any]
    exact: ExactReport
    layout: GridLayout | None
    """the grid world's map, ``None`` for other environments"""

    def to_json(self) -> dict[str, Any]:
        """What ``optimum --json`` prints."""
        return {
            "env_id": self.env_id,
            "kwargs": self.kwargs,
            **self.exact.to_dict(),
            "policy": list(self.exact.optimal_policy),
        }


def optimum(env_id: str, assignments: list[tuple[str, Any]], gamma: float | None) -> Optimum:
    """The best expected return from the start, by value iteration on the environment's model.

    Args:
        env_id: a Gymnasium id with a transition table, or Blackjack.
        assignments: ``(key, value)`` of env keys (``env.kwargs.map_name``).
        gamma: also the optimal discounted return with this discount, below 1.

    Raises:
        UserError: ``gamma`` is 1, a key is not an env key, or the environment has no model.
        ConfigError: the id or an argument is unknown.
    """
    if gamma is not None and gamma >= 1.0:
        raise UserError(
            "--gamma 1: the discounted optimum needs a discount below 1 (with no time limit, "
            "undiscounted returns may not converge); the undiscounted optimum within the "
            "time limit is printed without --gamma."
        )
    plan, policy_keys = _world(env_id, assignments)
    if policy_keys:
        raise UserError(
            f"--set {next(iter(policy_keys))}: a run's policy is evaluated with --policy greedy "
            "or epsilon_greedy; without --policy, optimum takes env keys alone."
        )
    config = plan.config
    exact = exact_report(config, gamma=1.0 if gamma is None else gamma)
    if isinstance(exact, str):
        continuing = _continuing_optimum(config, gamma)
        if continuing is None:
            raise UserError(
                f"{env_id}: no exact optimum: {exact}. It needs a transition table "
                "(env.unwrapped.P: FrozenLake, Taxi, CliffWalking), a dense model (Jack's car "
                "rental) or Blackjack's rules."
            )
        exact = continuing
    return Optimum(env_id, dict(config.env.kwargs), exact, grid_layout(config.env))


def _continuing_optimum(config: Config, gamma: float | None) -> ExactReport | None:
    """A world with a dense model and no end (Jack's car rental): its discounted optimum.

    Value iteration on the model (:func:`~cartpole_q.rl.dynamic_programming.value_iteration_sweeps`,
    to 1e-10), the optimum the mean of ``v*`` over the states, an episode's start being
    drawn uniformly; ``None`` for a world without a dense model.

    Raises:
        UserError: no ``gamma`` (a continuing task's undiscounted return is not finite).
    """
    from cartpole_q.envs.models import planning_model
    from cartpole_q.rl import solvers as dp

    world = planning_model(config.env)
    if isinstance(world, str) or not world.source.endswith("dense_model()"):
        return None
    if gamma is None:
        raise UserError(
            f"{config.env.id}: a continuing task (no end, no time limit): its undiscounted "
            "return is not finite; give --gamma below 1, such as --gamma 0.9 (the book's)."
        )
    found = dp.value_iteration_sweeps(world.model, gamma)
    values = found.values[-1]
    greedy = dp.greedy(world.model.backup(values, gamma), world.model.allowed, 1e-9)
    start = float(np.mean(values))
    note = f"expected discounted return (gamma {gamma:g}), a continuing task from a uniformly drawn state"
    return ExactReport(note, 0, gamma, start, None, None, None, tuple(int(a) for a in greedy))


@dataclass(frozen=True)
class PolicyValues:
    """A fixed policy's exact state values on a world with a model (``optimum --policy``)."""

    env_id: str
    kwargs: dict[str, Any]
    policy: str
    gamma: float
    values: dict[int, float]
    """the non-terminal states' values, by state (a terminal state's value is 0)"""

    def to_json(self) -> dict[str, Any]:
        """The JSON object ``optimum --policy --json`` prints (states as string keys)."""
        return {
            "env_id": self.env_id, "kwargs": self.kwargs, "policy": self.policy,
            "gamma": self.gamma, "values": {str(state): v for state, v in self.values.items()},
        }  # fmt: skip


RUN_POLICY_KEYS = ("agent.policy_run", "agent.policy_epsilon")
"""the agent keys ``optimum --policy`` takes: a run's policy's"""


def _world(env_id: str, assignments: list[tuple[str, Any]]) -> tuple[Plan, dict[str, Any]]:
    """The plan of the world ``optimum`` is asked about, and the policy keys given with it.

    Raises:
        UserError: a key is neither an env key nor one of :data:`RUN_POLICY_KEYS`.
        ConfigError: the id or an argument is unknown (naming it).
    """
    from cartpole_q.engines.plan import planned

    overrides: dict[str, Any] = {"env.id": env_id}
    policy_keys: dict[str, Any] = {}
    for key, value in assignments:
        if key in RUN_POLICY_KEYS:
            policy_keys[key] = value
        elif key == "env" or key.startswith("env."):
            overrides[key] = value
        else:
            raise UserError(
                f"--set {key}: optimum takes env keys (env.kwargs.KEY=VALUE) and, for --policy "
                "greedy or epsilon_greedy, agent.policy_run=RUN_DIR and agent.policy_epsilon=E."
            )
    return planned(load_config(overrides=overrides, override_source=COMMAND_LINE)), policy_keys


def _evaluated_policy(name: str, keys: Mapping[str, Any], env_id: str) -> EvaluatedPolicy:
    """``optimum --policy``'s policy, checked as a prediction config's ``agent.policy`` is.

    Raises:
        UserError: an unknown policy, an epsilon outside [0, 1], or what
            :func:`~cartpole_q.config.validation.named_policy_problem` finds (naming the
            option or ``--set`` key).
    """
    from cartpole_q.config.validation import named_policy_problem
    from cartpole_q.engines.base import EvaluatedPolicy
    from cartpole_q.rl.prediction import POLICIES, POLICY_EPSILON

    if name not in POLICIES:
        raise UserError(f"--policy {name}: not a policy; give one of {', '.join(POLICIES)}.")
    epsilon = keys.get("agent.policy_epsilon", POLICY_EPSILON.default)
    number = isinstance(epsilon, int | float) and not isinstance(epsilon, bool)
    if not number or not POLICY_EPSILON.low <= epsilon <= POLICY_EPSILON.high:
        raise UserError(
            f"--set agent.policy_epsilon={epsilon}: give a number in {POLICY_EPSILON.interval}."
        )
    run = str(keys.get("agent.policy_run", ""))
    problem = named_policy_problem(name, run, env_id, tiled=False)
    if run:  # as a config's agent.policy_run is read: from here, ~ expanded
        run = os.path.abspath(os.path.expanduser(run))
    if problem is not None:
        key, why = problem
        option = "--policy" if key == "agent.policy" else f"--set {key}"
        raise UserError(f"{option}: {why}")
    return EvaluatedPolicy(name, run, float(epsilon))


def policy_values(
    env_id: str, assignments: list[tuple[str, Any]], policy: str, gamma: float
) -> PolicyValues:
    """The exact values ``v_pi`` of ``agent.policy`` (what a prediction run is measured against).

    Raises:
        UserError: a key is not an env key, the world has no model, or the policy's values
            are not defined (it never ends an episode and ``gamma`` is 1).
        ConfigError: the id, an argument or the policy is unknown.
    """
    from cartpole_q.engines.base import UndefinedValuesError, exact_values

    plan, policy_keys = _world(env_id, assignments)
    evaluated = _evaluated_policy(policy, policy_keys, plan.config.env.id)
    config = plan.config
    try:
        truth = exact_values(config.env, plan.env_info, evaluated, gamma)
    except UndefinedValuesError as error:
        raise UserError(
            f"{env_id}: the {policy} policy's values are not defined at --gamma {gamma:g} "
            f"({error.reason}); give --gamma below 1, such as --gamma 0.99."
        ) from None
    except ValueError as error:
        raise UserError(f"{env_id}: the {policy} policy's values: {error}.") from None
    if not truth.measured:
        raise UserError(
            f"{env_id}: no exact values: it needs a model (a transition table, "
            "env.unwrapped.P: FrozenLake, Taxi, CliffWalking, the book's worlds; or "
            "Blackjack's rules)."
        )
    values = {
        int(state): float(value) for state, value in zip(truth.states, truth.values, strict=True)
    }
    return PolicyValues(env_id, dict(config.env.kwargs), policy, gamma, values)
