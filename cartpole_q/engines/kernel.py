"""The compiled training loop, written once for every algorithm and every twin.

Both engines run the same per-step code: the numba engine's loop (:func:`training_kernel`)
runs whole episodes on a twin; the gymnasium engine steps a real environment from Python and
calls compiled functions once per step (:mod:`cartpole_q.engines.gymnasium_engine`). Either
way an episode is: epsilon and alpha of the episode; reset; the algorithm's ``start`` on the
reset state; then per step the environment's step, the observation's row,
the visit counted, and the algorithm's ``step``; at the end, the algorithm's ``end``.
The row rule is the gymnasium engine's (:mod:`cartpole_q.engines.rows`), for the twin's
kind of observation.

The functions below are templates: their upper-case globals (``ALGORITHM_STEP``,
``TWIN_STEP``, ...) are placeholders that :func:`~cartpole_q.engines.compile.specialise`
binds to one algorithm's hooks and one twin's functions. Each (algorithm, twin) pair is
compiled on its own, with no branch on either left in the loop, and cached on disk.

A pair has two training loops, each calling its own episode loop: the *exploring* one
plays the episodes whose epsilon is positive, the *greedy* one, compiled with epsilon the
constant 0 (without the generator calls greedy steps skip anyway: a third faster), those
whose epsilon is 0. Each returns at the first episode that is the other's, and the engine goes on with
the other; epsilon schedules never rise, so a run switches at most once. The exploring
loop can also play the greedy episodes itself (``plays_greedy``), with epsilon 0: the same
draws (none), so the same results, without the greedy loop's third less time per step; a
run that explores first compiles the greedy loop only where its greedy episodes are long
enough for that to pay (:func:`~cartpole_q.engines.base.greedy_loop_pays`), or finds it
cached. A run compiles only the loops it plays (a constant positive epsilon: the
exploring one alone); on a cold cache, the first loop in a forked process and the other
(if any) and the greedy play here, side by side.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np

from cartpole_q.engines.base import (
    NO_STEP_LIMIT,
    AgentRecord,
    EpisodeMetrics,
    Grid,
    Tables,
    Truth,
    kernel_name,
    pair_name,
)
from cartpole_q.engines.compile import specialise
from cartpole_q.engines.rows import ARRAY_STATE_RULES
from cartpole_q.envs.registry import Twin
from cartpole_q.rl.algorithm import Algorithm
from cartpole_q.rl.prediction import value_error
from cartpole_q.rl.schedules import schedule_value
from cartpole_q.rl.solve import SOLVE_WINDOW
from cartpole_q.rl.tabular import ENDED, Rates, Transition, best_action, compilable, visit

# Placeholders, bound per (algorithm, twin) by specialise(); never called as they are.
ALGORITHM_START: Any = None
ALGORITHM_STEP: Any = None
ALGORITHM_END: Any = None
TWIN_RESET: Any = None
TWIN_STEP: Any = None
TWIN_RANDOMIZE: Any = None
OBSERVATION_STATE: Any = None
STEP_SIZE: Any = None
"""bound to :func:`scheduled_step_size`, or :func:`update_counts` under sample averages"""
EPISODE: Any = None
GREEDY: bool = False
"""bound to True in the copies of :func:`twin_episode` and :func:`train_episodes` compiled
for epsilon 0"""
RANDOMIZED: bool = False
"""bound to True in the outer loop of a run whose ``env.randomize`` draws physics"""


@compilable
def episode_rates(agent: AgentRecord, episode: int) -> tuple[float, float]:
    """Epsilon and alpha of a 0-based episode."""
    e, a = agent.epsilon, agent.alpha
    epsilon = schedule_value(e.kind, e.start, e.end, e.rate, episode)
    return epsilon, schedule_value(a.kind, a.start, a.end, a.rate, episode)


@compilable
def scheduled_step_size(alpha: float, memory: Any) -> float:
    """What the hooks get as ``alpha``: the episode's value of ``agent.alpha``'s schedule."""
    return alpha


@compilable
def update_counts(alpha: float, memory: Any) -> np.ndarray:
    """What the hooks get as ``alpha`` under ``agent.alpha: sample_average``: the counts.

    The table of update counts is the last memory array (after the algorithm's own); the
    hooks' :func:`~cartpole_q.rl.tabular.update` is then compiled as
    :func:`~cartpole_q.rl.tabular.averaged_update`, which reads and counts it.
    """
    counts: np.ndarray = memory[-1]
    return counts


@compilable
def reaches_threshold(returns: np.ndarray, episode: int, threshold: float) -> bool:
    """Whether the moving average of the last ``SOLVE_WINDOW`` returns reaches the threshold.

    Needs a full window: no episode before the 100th can solve a run. Summed left to
    right from 0.0.
    """
    if episode + 1 < SOLVE_WINDOW:
        return False
    total = 0.0
    for i in range(episode + 1 - SOLVE_WINDOW, episode + 1):
        total += returns[i]
    return total / SOLVE_WINDOW >= threshold


@compilable
def record_episode(
    metrics: EpisodeMetrics, episode: int, episode_return: float, length: int,
    epsilon: float, alpha: float,
) -> None:  # fmt: skip
    """Store one finished episode's metrics at its 0-based index."""
    metrics.returns[episode] = episode_return
    metrics.lengths[episode] = length
    metrics.epsilons[episode] = epsilon
    metrics.alphas[episode] = alpha


class Generators(NamedTuple):
    """A run's three random generators, as the training loop takes them."""

    agent: np.random.Generator
    """exploration, and the algorithm's own draws"""
    env: np.random.Generator
    """the twin's resets, and the steps of a world that draws"""
    physics: np.random.Generator
    """the draws of ``env.randomize``"""


class TwinEnv(NamedTuple):
    """The twin as the loops take it: its time limit, scratch arrays and parameters.

    ``state`` and ``observation`` are the twin's scratch arrays, which every reset
    overwrites: made by the caller, so that no compiled loop compiles numba's array
    allocation.
    """

    max_steps: int
    """the episode's time limit (no time limit: the largest int64)"""
    state: np.ndarray
    observation: np.ndarray
    params: Any
    """the twin's parameters (its physics)"""
    randomize: tuple[np.ndarray, np.ndarray, np.ndarray]
    """``(keys, lows, highs)`` of ``env.randomize`` (empty arrays: none)"""


class Turn(NamedTuple):
    """One loop's turn: the episodes it may play, and what ends it early."""

    start: int
    """the first episode (0-based) to train"""
    stop: int
    """train up to this episode, excluded"""
    check_solved: bool
    """stop right after the first solving episode"""
    plays_greedy: bool
    """the exploring copy plays the greedy episodes too (the greedy copy ignores it)"""


class Measure(NamedTuple):
    """A prediction run's true values, and where each episode's RMS error of ``V`` goes."""

    truth: Truth
    """when it measures any state, each episode's error goes to ``errors``"""
    errors: np.ndarray
    """per-episode errors, at the episode's index (empty when nothing is measured)"""


def twin_episode(
    tables: Tables, params: Any, grid: Grid, rates: Rates, generators: Generators,
    env: TwinEnv,
) -> tuple[float, int]:  # fmt: skip
    """Reset the twin, then play and learn one episode; return its return and length.

    ``rates.alpha`` is the episode's value of the schedule (the hooks get the step size
    :data:`STEP_SIZE` makes of it) and ``env.max_steps`` the episode's time limit. The
    records are unpacked before the loop: reading a record's array inside it would cost two
    atomic reference-count updates per step. In the copy compiled with ``GREEDY`` bound to
    True, epsilon is the constant 0: the compiler removes the generator calls that greedy
    steps would skip anyway (a third faster).
    """
    q, visits, memory = tables.q, tables.visits, tables.memory
    low, high, bins, starts = grid.low, grid.high, grid.bins, grid.starts
    rng, env_rng = generators.agent, generators.env
    env_state, observation, env_params = env.state, env.observation, env.params
    max_steps, epsilon = env.max_steps, rates.epsilon
    if GREEDY:
        epsilon = 0.0
    TWIN_RESET(env_state, observation, env_rng, env_params)
    state = OBSERVATION_STATE(q, observation, low, high, bins, starts, -1)
    action = ALGORITHM_START(q, memory, params, state, epsilon, rng)
    step_rates = Rates(STEP_SIZE(rates.alpha, memory), rates.gamma, epsilon)
    episode_return, length = 0.0, 0
    while action != ENDED:
        reward, terminated = TWIN_STEP(env_state, action, observation, env_rng, env_params)
        length += 1
        episode_return += reward
        next_state = OBSERVATION_STATE(q, observation, low, high, bins, starts, state)
        visit(visits, q, state, action)
        transition = Transition(state, action, reward, next_state, terminated, length >= max_steps)
        action = ALGORITHM_STEP(q, memory, params, transition, step_rates, rng)
        state = next_state
    ALGORITHM_END(q, memory, params, step_rates, rng)
    return episode_return, length


def train_episodes(
    tables: Tables, params: Any, grid: Grid, agent: AgentRecord, metrics: EpisodeMetrics,
    generators: Generators, env: TwinEnv, turn: Turn, measure: Measure,
) -> tuple[int, int, int]:  # fmt: skip
    """Train episodes ``turn.start .. turn.stop - 1`` on the twin, up to the first that is the other loop's.

    The exploring copy (``GREEDY`` False) plays the episodes whose epsilon is positive and
    returns at the first whose epsilon is not, unless ``turn.plays_greedy``: then it plays
    those too, with epsilon 0. The greedy copy plays the episodes whose epsilon is not
    positive and returns at the first that is (see the module docstring). An episode handed
    back is untouched: nothing of it is drawn.

    Args:
        tables: the learned table as ``(n_states, n_actions)``, updated in place (on tiles
            the pair ``(weights, features)``: see :mod:`cartpole_q.rl.tiles`); how often
            each (state, action) was taken, and the algorithm's memory (a tuple of arrays),
            both updated in place.
        params: the algorithm's parameters (a tuple of floats).
        grid: the binning grid.
        agent: the hyperparameters and the solve threshold.
        metrics: per-episode metrics, written at each episode's index.
        generators: the agent's, the twin's and ``env.randomize``'s generators.
        env: the twin (see :class:`TwinEnv`).
        turn: the episodes this turn may play (see :class:`Turn`).
        measure: a prediction run's true values and its errors (see :class:`Measure`).

    Returns:
        ``(episodes finished, env steps taken, 0-based solve episode or -1)``; stops
        right after the solve episode when ``turn.check_solved``, right after the episode
        that reaches ``agent.max_env_steps`` (cut there: its time limit is the steps left),
        and before an episode that is the other loop's (then ``episodes finished <
        turn.stop`` and no solve).
    """
    keys, lows, highs = env.randomize
    truth, errors = measure.truth, measure.errors
    start, stop, plays_greedy = turn.start, turn.stop, turn.plays_greedy
    env_steps = 0
    steps_left = agent.max_env_steps  # (the steps of episodes before start: their lengths)
    if steps_left < NO_STEP_LIMIT:
        for earlier in range(start):
            steps_left -= metrics.lengths[earlier]
    for episode in range(start, stop):
        epsilon, alpha = episode_rates(agent, episode)
        explores = epsilon > 0.0  # (NaN: a greedy episode)
        if explores == GREEDY and (GREEDY or not plays_greedy):  # the other loop's episode
            return episode, env_steps, -1
        env_params = env.params
        if RANDOMIZED:  # compiled in only where env.randomize draws physics
            env_params = TWIN_RANDOMIZE(env.params, generators.physics, keys, lows, highs)
        limit = min(env.max_steps, steps_left - env_steps)
        episode_return, length = EPISODE(
            tables, params, grid, Rates(alpha, agent.gamma, epsilon if explores else 0.0),
            generators, TwinEnv(limit, env.state, env.observation, env_params, env.randomize),
        )  # fmt: skip
        record_episode(metrics, episode, episode_return, length, epsilon, alpha)
        if truth.rows.shape[0] > 0:
            errors[episode] = value_error(tables.q, truth.rows, truth.values)
        env_steps += length
        if turn.check_solved and reaches_threshold(metrics.returns, episode, agent.threshold):
            return episode + 1, env_steps, episode
        if env_steps >= steps_left:
            return episode + 1, env_steps, -1
    return stop, env_steps, -1


def greedy_returns(
    q: Any, grid: Grid, env_rng: np.random.Generator, env: TwinEnv, returns: np.ndarray
) -> np.ndarray:
    """The greedy policy's return in each of ``len(returns)`` twin episodes, into ``returns``.

    ``returns`` comes in zeroed; ``env`` as :func:`train_episodes` takes it, with the greedy
    step cap as the time limit of an environment that has none.
    """
    max_steps, env_state, observation, params = (
        env.max_steps,
        env.state,
        env.observation,
        env.params,
    )
    low, high, bins, starts = grid.low, grid.high, grid.bins, grid.starts
    for episode in range(returns.shape[0]):
        TWIN_RESET(env_state, observation, env_rng, params)
        for length in range(1, max_steps + 1):
            state = OBSERVATION_STATE(q, observation, low, high, bins, starts, -1)
            action = best_action(q, state)
            reward, terminated = TWIN_STEP(env_state, action, observation, env_rng, params)
            returns[episode] += reward
            if terminated or length >= max_steps:
                break
    return returns


@dataclass(frozen=True)
class TrainingKernel:
    """One (algorithm, twin) pair's two training loops (see the module docstring).

    Each is compiled at its first call (or loaded from numba's cache): a run that never
    plays a greedy episode never compiles the greedy loop.
    """

    exploring_name: str
    """the exploring loop's name (its cache entry)"""
    exploring: Any
    """:func:`train_episodes` for the episodes whose epsilon is positive"""
    greedy_name: str
    """the greedy loop's name (its cache entry)"""
    greedy: Any
    """:func:`train_episodes` compiled for the episodes whose epsilon is 0"""

    def loop(self, greedy: bool) -> tuple[str, Any]:
        """The name and the loop for greedy (epsilon 0) or exploring episodes."""
        return (self.greedy_name, self.greedy) if greedy else (self.exploring_name, self.exploring)


def training_kernel(
    algorithm: Algorithm,
    twin: Twin,
    randomized: bool = False,
    tiled: bool = False,
    averaged: bool = False,
) -> TrainingKernel:
    """The compiled training loop of one algorithm on one twin.

    Compiled for the pair, with the algorithm's hooks and the twin's functions inlined and no
    branch on either left in the loop; cached on disk under the pair's keys (which carry
    digests of their sources), so a run compiles (or loads) only the machine code it runs.
    ``randomized`` compiles the draws of ``env.randomize`` in (a run without them does not
    compile them at all); ``tiled`` compiles for tile-coded tables (``q`` is then the pair
    ``(weights, features)``, see :mod:`cartpole_q.rl.tiles`); ``averaged`` for
    ``agent.alpha: sample_average`` (the hooks get the update counts as ``alpha``, and
    their ``update`` is :func:`~cartpole_q.rl.tabular.averaged_update`).
    """
    return _training_kernel(algorithm.key, twin.key, randomized, tiled, averaged, algorithm, twin)


@functools.cache
def _training_kernel(
    algorithm_key: str,
    twin_key: str,
    randomized: bool,
    tiled: bool,
    averaged: bool,
    algorithm: Algorithm,
    twin: Twin,
) -> TrainingKernel:
    pair = pair_name(algorithm_key, twin_key, tiled, averaged)
    hooks = {
        "ALGORITHM_START": algorithm.start,
        "ALGORITHM_STEP": algorithm.step,
        "ALGORITHM_END": algorithm.end,
        "STEP_SIZE": update_counts if averaged else scheduled_step_size,
        **twin_bindings(twin, tiled),
    }
    loops: list[Any] = []  # name, loop, name, loop
    for greedy in (False, True):
        # The episode loop is compiled (and cached) on its own and called, not inlined:
        # numba's inlining of a whole episode loop costs more than the call saves.
        episode = specialise(
            twin_episode,
            f"{'greedy' if greedy else 'exploring'}_episode__{pair}",
            {**hooks, "GREEDY": greedy},
            callee=True,
            tiled=tiled,
            averaged=averaged,
        )
        name = kernel_name(algorithm_key, twin_key, randomized, tiled, greedy, averaged)
        bindings = {
            "EPISODE": episode,
            "GREEDY": greedy,
            "TWIN_RANDOMIZE": twin.randomize,
            "RANDOMIZED": randomized,
        }
        loops += [
            name,
            specialise(train_episodes, name, bindings, tiled=tiled, averaged=averaged),
        ]
    return TrainingKernel(*loops)


@functools.cache
def greedy_kernel(twin: Twin, tiled: bool = False) -> Any:
    """The compiled greedy play of one twin (see :func:`training_kernel`)."""
    name = f"greedy_returns__{twin.key}" + ("__tiles" if tiled else "")
    return specialise(greedy_returns, name, twin_bindings(twin, tiled), tiled=tiled)


def twin_bindings(twin: Twin, tiled: bool = False) -> dict[str, Any]:
    """What a loop template's ``TWIN_...`` placeholders and its state rule are for ``twin``."""
    return {
        "TWIN_RESET": twin.reset,
        "TWIN_STEP": twin.step,
        "OBSERVATION_STATE": ARRAY_STATE_RULES["tiles" if tiled else twin.observation_kind],
    }
