"""The compiled training loop, written once for every algorithm and every twin.

Both engines run the same per-step code: the numba engine's loop (:func:`training_kernel`)
runs whole episodes on a twin; the gymnasium engine steps a real environment from Python and
calls compiled functions once per step (:mod:`cartpole_q.engines.gymnasium_engine`). Both
call :func:`~cartpole_q.rl.algorithms.first_action` and
:func:`~cartpole_q.rl.algorithms.learn_step` on the row given by the binning rule. Either way an
episode is: epsilon and alpha of the episode; reset; the first action epsilon-greedy on the
reset state; then per step the environment's step, the observation's row, and the
algorithm's :func:`~cartpole_q.rl.algorithms.learn_step`.

The algorithm and the twin are integer codes (see :mod:`cartpole_q.rl.algorithms` and
:mod:`cartpole_q.envs.registry`): numba compiles one loop, caches it on disk, and the
branches on the codes are the same for a whole run.
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np
from numba import njit

from cartpole_q.engines.base import AgentRecord, EpisodeMetrics, Grid, Tables
from cartpole_q.envs.registry import twin_randomize, twin_reset, twin_step
from cartpole_q.numba_cache import configure as configure_numba_cache
from cartpole_q.rl.algorithms import ENDED, first_action, learn_step
from cartpole_q.rl.policy import best_action, state_index
from cartpole_q.rl.schedules import schedule_value
from cartpole_q.rl.solve import SOLVE_WINDOW

configure_numba_cache()  # before any cache=True function is defined


@njit(cache=True, nogil=True, inline="always")
def episode_rates(agent: AgentRecord, episode: int) -> tuple[float, float]:
    """Epsilon and alpha of a 0-based episode."""
    e, a = agent.epsilon, agent.alpha
    epsilon = schedule_value(e.kind, e.start, e.end, e.rate, episode)
    return epsilon, schedule_value(a.kind, a.start, a.end, a.rate, episode)


@njit(cache=True, nogil=True, inline="always")
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


@njit(cache=True, nogil=True, inline="always")
def record_episode(
    metrics: EpisodeMetrics, episode: int, episode_return: float, length: int,
    epsilon: float, alpha: float,
) -> None:  # fmt: skip
    """Store one finished episode's metrics at its 0-based index."""
    metrics.returns[episode] = episode_return
    metrics.lengths[episode] = length
    metrics.epsilons[episode] = epsilon
    metrics.alphas[episode] = alpha


@njit(cache=True, nogil=True, inline="always")
def _twin_episode(
    tables: Tables, grid: Grid, algorithm: int, gamma: float, alpha: float, epsilon: float,
    rng: np.random.Generator, twin: int, params: tuple[float, ...], max_steps: int,
    env_state: np.ndarray, observation: np.ndarray,
) -> tuple[float, int]:  # fmt: skip
    """Play and learn one episode on a twin (already reset); return its return and length.

    The arrays are taken out of their records once: reading a record's array inside the
    loop would cost two atomic reference-count updates per step.
    """
    q, q_b, visits = tables
    low, high, bins, _ = grid  # twins have Box observations: binned, never indexed
    state = state_index(observation, low, high, bins)
    action = first_action(algorithm, q, q_b, state, epsilon, rng)
    episode_return, length = 0.0, 0
    while action != ENDED:
        reward, terminated = twin_step(twin, env_state, action, observation, params)
        length += 1
        episode_return += reward
        next_state = state_index(observation, low, high, bins)
        action = learn_step(
            algorithm, q, q_b, visits, state, action, reward, next_state, terminated,
            length >= max_steps, alpha, gamma, epsilon, rng,
        )  # fmt: skip
        state = next_state
    return episode_return, length


@functools.cache
def training_kernel(algorithm: int, twin: int) -> Any:
    """The compiled training loop of one algorithm on one twin (both given by their codes).

    A factory, so that each (algorithm, twin) pair is compiled on its own, with the codes as
    constants: no branch on them is left in the loop, and a run compiles (or loads from
    numba's disk cache, keyed by the codes) only the machine code it runs.
    """

    def train_episodes(
        tables: Tables, grid: Grid, agent: AgentRecord, metrics: EpisodeMetrics,
        agent_rng: np.random.Generator, env_rng: np.random.Generator,
        env: tuple[int, int, int, tuple[float, ...]], start: int, stop: int, check_solved: bool,
        physics_rng: np.random.Generator, randomize: tuple[np.ndarray, np.ndarray, np.ndarray],
    ) -> tuple[int, int, int]:  # fmt: skip
        """Train episodes ``start .. stop - 1`` on the twin.

        Args:
            tables: the learned tables, updated in place.
            grid: the binning grid.
            agent: the hyperparameters and the solve threshold.
            metrics: per-episode metrics, written at each episode's index.
            agent_rng: the agent's generator (exploration, Double Q-learning's coin).
            env_rng: the twin's generator (resets).
            env: ``(max_episode_steps, state_size, observation_size, params)`` of the twin.
            start: the first episode (0-based) to train.
            stop: train up to this episode, excluded.
            check_solved: stop right after the first solving episode.
            physics_rng: the generator of ``env.randomize``'s draws.
            randomize: ``(keys, lows, highs)`` of ``env.randomize`` (empty arrays: none).

        Returns:
            ``(episodes finished, env steps taken, 0-based solve episode or -1)``; stops
            right after the solve episode when ``check_solved``.
        """
        max_steps, state_size, observation_size, base_params = env
        keys, lows, highs = randomize
        env_state = np.empty(state_size, dtype=np.float64)
        observation = np.empty(observation_size, dtype=np.float32)
        gamma = agent.gamma
        env_steps = 0
        for episode in range(start, stop):
            epsilon, alpha = episode_rates(agent, episode)
            params = base_params
            if keys.size:
                params = twin_randomize(twin, base_params, physics_rng, keys, lows, highs)
            twin_reset(twin, env_state, observation, env_rng, params)
            # Greedy episodes (epsilon 0) run a copy of the loop compiled with a constant
            # epsilon, without the generator calls they would skip anyway: a third faster.
            if epsilon > 0.0:
                episode_return, length = _twin_episode(
                    tables, grid, algorithm, gamma, alpha, epsilon, agent_rng, twin, params,
                    max_steps, env_state, observation,
                )  # fmt: skip
            else:
                episode_return, length = _twin_episode(
                    tables, grid, algorithm, gamma, alpha, 0.0, agent_rng, twin, params,
                    max_steps, env_state, observation,
                )  # fmt: skip
            record_episode(metrics, episode, episode_return, length, epsilon, alpha)
            env_steps += length
            if check_solved and reaches_threshold(metrics.returns, episode, agent.threshold):
                return episode + 1, env_steps, episode
        return stop, env_steps, -1

    return compiled(train_episodes, f"train_episodes_{algorithm}_{twin}")


@functools.cache
def greedy_kernel(twin: int) -> Any:
    """The compiled greedy play of one twin (see :func:`training_kernel`)."""

    def greedy_returns(
        q: np.ndarray, grid: Grid, env_rng: np.random.Generator,
        env: tuple[int, int, int, tuple[float, ...]], episodes: int,
    ) -> np.ndarray:  # fmt: skip
        """The greedy policy's return in each of ``episodes`` twin episodes."""
        max_steps, state_size, observation_size, params = env
        env_state = np.empty(state_size, dtype=np.float64)
        observation = np.empty(observation_size, dtype=np.float32)
        returns = np.zeros(episodes, dtype=np.float64)
        for episode in range(episodes):
            twin_reset(twin, env_state, observation, env_rng, params)
            for length in range(1, max_steps + 1):
                state = state_index(observation, grid.low, grid.high, grid.bins)
                action = best_action(q, state)
                reward, terminated = twin_step(twin, env_state, action, observation, params)
                returns[episode] += reward
                if terminated or length >= max_steps:
                    break
        return returns

    return compiled(greedy_returns, f"greedy_returns_{twin}")


def compiled(function: Any, name: str) -> Any:
    """``function`` compiled and cached under its own name.

    The closures of one factory share a name; numba would give every (algorithm, twin)
    pair the same symbols and cache file, and a process that loads two of them from the
    cache would link one to the other's code.
    """
    function.__name__ = function.__qualname__ = name
    return njit(cache=True, nogil=True)(function)
