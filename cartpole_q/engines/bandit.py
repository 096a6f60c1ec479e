"""Playing the k-armed testbed: many independent runs, per-step metrics averaged over them.

A bandit has one state and no episodes: a run is ``steps`` plays of a fresh testbed by a
fresh learner, and what the book plots is each step's reward and whether the arm was
optimal, averaged over the runs. Two engines play a run, with the same compiled rules
(:mod:`cartpole_q.rl.bandits`) and the same draws:

- ``numba``: one compiled call per run plays the testbed's twin
  (:mod:`cartpole_q.families.bandit.twin`);
- ``gymnasium``: a Python loop over ``gymnasium.make("cartpole_q/Bandit-v0")``, the rules
  compiled, one call per step each.

They give the same floats, byte for byte (``tests/test_bandits.py``).

**Seeds.** Run ``seed``: ``agent_seq, env_seq = np.random.SeedSequence(seed).spawn(2)``; the
agent draws from ``Generator(PCG64(agent_seq))``; the testbed is reset with ``seed =
int(env_seq.generate_state(1, dtype=np.uint32)[0])`` (Gymnasium's ``np_random``:
``Generator(PCG64(SeedSequence(that seed)))``), as ``cartpole-q train`` seeds a run.

**Step t** (1, 2, ..., ``steps``): the agent's rule chooses an arm (:func:`~cartpole_q.rl.bandits.choose`);
the testbed pays its reward (and walks); the learner learns (:func:`~cartpole_q.rl.bandits.learn`).

**Averages.** Each step's rewards are summed over the runs in seed order, from 0.0, then
divided by the number of runs; % optimal is ``100.0 * count / runs``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from cartpole_q.engines.compile import specialise
from cartpole_q.families.bandit.twin import ArmedTestbed, reset_testbed, step_testbed
from cartpole_q.rl.bandits import BanditAgent, choose, learn, new_memory

BANDIT_ID = "cartpole_q/Bandit-v0"
ENGINES = ("numba", "gymnasium")


def run_generators(seed: int) -> tuple[np.random.Generator, int]:
    """A run's agent generator and the seed its testbed is reset with."""
    agent_seq, env_seq = np.random.SeedSequence(seed).spawn(2)
    return (
        np.random.Generator(np.random.PCG64(agent_seq)),
        int(env_seq.generate_state(1, dtype=np.uint32)[0]),
    )


def _play_run(
    agent: BanditAgent, testbed: ArmedTestbed, agent_rng: Any, env_rng: Any,
    rewards: np.ndarray, optimal: np.ndarray,
) -> None:  # fmt: skip
    """One run on the twin: ``rewards.shape[0]`` steps, each step's reward and optimality."""
    q_star = np.empty(testbed.k)
    reset_testbed(testbed, q_star, env_rng)
    memory = new_memory(agent, testbed.k)
    for index in range(rewards.shape[0]):
        t = index + 1
        arm = choose(agent, memory, t, agent_rng)
        reward, best = step_testbed(testbed, q_star, arm, env_rng)
        learn(agent, memory, arm, reward, t)
        rewards[index] = reward
        optimal[index] = best


_compiled: dict[str, Any] = {}

LOOP_NAMES = {"numba": ("bandit_play_run",), "gymnasium": ("bandit_choose", "bandit_learn")}
"""the compiled functions each engine runs, by their cache names"""


def compile_notice(engine: str) -> str | None:
    """A sentence when ``engine``'s functions are not compiled yet (the first run), else ``None``."""
    from cartpole_q.numba_cache import is_cached

    if all(is_cached(name) for name in LOOP_NAMES[engine]):
        return None
    return f"compiling the bandit loop ({engine} engine): once per machine and version, a few seconds..."


def _function(name: str, template: Any) -> Any:
    """``template`` compiled and cached on disk under ``name`` (once per process)."""
    if name not in _compiled:
        _compiled[name] = specialise(template, name, {})
    return _compiled[name]


def play_run_numba(
    agent: BanditAgent, testbed: ArmedTestbed, seed: int, steps: int
) -> tuple[np.ndarray, np.ndarray]:
    """One run on the compiled twin: its rewards (float64) and optimal flags (bool) per step."""
    agent_rng, env_seed = run_generators(seed)
    env_rng = np.random.Generator(np.random.PCG64(np.random.SeedSequence(env_seed)))
    rewards, optimal = np.empty(steps), np.empty(steps, dtype=np.bool_)
    _function("bandit_play_run", _play_run)(agent, testbed, agent_rng, env_rng, rewards, optimal)
    return rewards, optimal


def play_run_gymnasium(
    agent: BanditAgent, testbed: ArmedTestbed, seed: int, steps: int, env: Any = None
) -> tuple[np.ndarray, np.ndarray]:
    """One run on ``gymnasium.make(BANDIT_ID, ...)`` (or ``env``, made so): as :func:`play_run_numba`."""
    if env is None:
        env = make_env(testbed, steps)
    agent_rng, env_seed = run_generators(seed)
    choose_arm, learn_from = _function("bandit_choose", choose), _function("bandit_learn", learn)
    env.reset(seed=env_seed)
    memory = new_memory(agent, testbed.k)
    rewards, optimal = np.empty(steps), np.empty(steps, dtype=np.bool_)
    for index in range(steps):
        t = index + 1
        arm = choose_arm(agent, memory, t, agent_rng)
        _, reward, _, _, info = env.step(arm)
        learn_from(agent, memory, arm, float(reward), t)
        rewards[index] = reward
        optimal[index] = info["optimal"]
    return rewards, optimal


def warm_up(engine: str) -> None:
    """Compile (or load from the cache) ``engine``'s functions: one run of one step.

    The functions take every rule and testbed alike (their types do not change), so one
    run compiles what every bandit study plays (``cartpole-q compile --all``).
    """
    from cartpole_q.rl.bandits import RULES

    agent = BanditAgent(RULES["epsilon_greedy"], 0.1, 0.0, 0.0, 0.0, False)
    testbed = ArmedTestbed(2, 0.0, 1.0, 0.0)
    if engine == "gymnasium":
        play_run_gymnasium(agent, testbed, 0, 1)
    else:
        play_run_numba(agent, testbed, 0, 1)


def make_env(testbed: ArmedTestbed, steps: int | None = None) -> Any:
    """``gymnasium.make("cartpole_q/Bandit-v0")`` with the testbed's arguments.

    ``steps``: the run's length as its time limit (else the registered 1,000).
    """
    import gymnasium

    import cartpole_q.families.registration  # noqa: F401  (the ids are registered with the package)

    return gymnasium.make(
        BANDIT_ID, max_episode_steps=steps, k=testbed.k, mean=testbed.mean,
        spread=testbed.spread, walk=testbed.walk,
    )  # fmt: skip


@dataclass(frozen=True)
class CurveResult:
    """A learner's per-step metrics over many runs."""

    average_reward: np.ndarray
    """float64 ``(steps,)``: each step's reward averaged over the runs"""
    optimal_percent: np.ndarray
    """float64 ``(steps,)``: the % of runs that played an optimal arm at each step"""
    rewards: np.ndarray | None = None
    """float64 ``(runs, steps)``: every run's rewards (when asked to keep them)"""
    optimal: np.ndarray | None = None
    """bool ``(runs, steps)``: every run's optimal flags (when asked to keep them)"""


def play_curve(
    agent: BanditAgent,
    testbed: ArmedTestbed,
    seeds: list[int],
    steps: int,
    engine: str = "numba",
    keep_runs: bool = False,
    stop: Callable[[], bool] | None = None,
    progress: Callable[[int], None] | None = None,
) -> CurveResult | None:
    """Play one run per seed, in order, and average each step over the runs.

    ``stop`` is asked before each run; when it says so, nothing more is played and the
    result is ``None``. ``progress`` is told how many runs are done after each.
    """
    reward_total = np.zeros(steps)
    optimal_count = np.zeros(steps, dtype=np.int64)
    kept_rewards = np.empty((len(seeds), steps)) if keep_runs else None
    kept_optimal = np.empty((len(seeds), steps), dtype=np.bool_) if keep_runs else None
    env = make_env(testbed, steps) if engine == "gymnasium" else None
    for index, seed in enumerate(seeds):
        if stop is not None and stop():
            return None
        if engine == "gymnasium":
            rewards, optimal = play_run_gymnasium(agent, testbed, seed, steps, env)
        else:
            rewards, optimal = play_run_numba(agent, testbed, seed, steps)
        reward_total += rewards
        optimal_count += optimal
        if kept_rewards is not None and kept_optimal is not None:
            kept_rewards[index], kept_optimal[index] = rewards, optimal
        if progress is not None:
            progress(index + 1)
    runs = len(seeds)
    return CurveResult(
        reward_total / runs, 100.0 * optimal_count / runs, kept_rewards, kept_optimal
    )
