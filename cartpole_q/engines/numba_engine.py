"""The numba engine: the compiled CartPole twin and the agent in one compiled loop.

Same agent functions, same random draws in the same order as the gymnasium engine, so
the Q-table and metrics are byte-identical to it; about two hundred times faster.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium.utils import seeding
from numba import njit

from cartpole_q.agent import (
    begin_episode,
    best_action,
    epsilon_greedy,
    greedy_action,
    reaches_threshold,
    record_episode,
    schedule_value,
    state_index,
    td_update,
)
from cartpole_q.engines import cartpole_twin
from cartpole_q.engines.base import AgentParams, TrainingState
from cartpole_q.engines.cartpole_twin import TwinSettings
from cartpole_q.numba_cache import configure as configure_numba_cache

configure_numba_cache()  # before any cache=True function is defined


@njit(cache=True, nogil=True, inline="always")
def training_episode(
    q, visits, low, high, bins, gamma, alpha, epsilon, agent_rng,
    state, observation, max_episode_steps, sutton_barto_reward, may_explore,
):  # fmt: skip
    """Play and learn one episode on the twin (already reset); return its return and length.

    ``may_explore`` is a literal at both call sites: with ``False`` (epsilon is 0 for the
    whole episode) the compiled loop holds no generator call, which makes a step a third
    faster; the choices are the same, since at epsilon 0 ``epsilon_greedy`` draws nothing.
    """
    s, a = begin_episode(q, observation, low, high, bins, epsilon, agent_rng)
    episode_return, length = 0.0, 0
    while True:
        reward, terminated = cartpole_twin.step(state, a, observation, sutton_barto_reward)
        length += 1
        truncated = length >= max_episode_steps
        episode_return += reward
        # agent.learn_step, spelled out: numba keeps reference-count updates for every
        # array argument of an inlined call, which would double the cost of a step.
        visits[s, a] += 1
        next_state = state_index(observation, low, high, bins)
        td_update(q, s, a, reward, next_state, terminated, alpha, gamma)
        if terminated or truncated:
            return episode_return, length
        s = next_state
        a = epsilon_greedy(q, s, epsilon, agent_rng) if may_explore else best_action(q, s)


@njit(cache=True, nogil=True)
def train_episodes(
    q, visits, low, high, bins, gamma,
    alpha_kind, alpha_start, alpha_end, alpha_rate,
    epsilon_kind, epsilon_start, epsilon_end, epsilon_rate,
    agent_rng, env_rng, max_episode_steps, sutton_barto_reward,
    returns, lengths, epsilons, alphas,
    start, stop, threshold, check_solved,
):  # fmt: skip
    """Train episodes ``start .. stop - 1`` on the twin.

    Returns:
        ``(episodes finished, env steps taken, 0-based solve episode or -1)``; stops right
        after the solve episode when ``check_solved``.
    """
    state = np.empty(4, dtype=np.float64)
    observation = np.empty(4, dtype=np.float32)
    env_steps = 0
    for episode in range(start, stop):
        epsilon = schedule_value(epsilon_kind, epsilon_start, epsilon_end, epsilon_rate, episode)
        alpha = schedule_value(alpha_kind, alpha_start, alpha_end, alpha_rate, episode)
        cartpole_twin.reset(state, observation, env_rng)
        if epsilon > 0.0:
            episode_return, length = training_episode(
                q, visits, low, high, bins, gamma, alpha, epsilon, agent_rng,
                state, observation, max_episode_steps, sutton_barto_reward, True,
            )  # fmt: skip
        else:
            episode_return, length = training_episode(
                q, visits, low, high, bins, gamma, alpha, epsilon, agent_rng,
                state, observation, max_episode_steps, sutton_barto_reward, False,
            )  # fmt: skip
        record_episode(
            returns, lengths, epsilons, alphas, episode, episode_return, length, epsilon, alpha
        )
        env_steps += length
        if check_solved and reaches_threshold(returns, episode, threshold):
            return episode + 1, env_steps, episode
    return stop, env_steps, -1


@njit(cache=True, nogil=True)
def greedy_returns(q, low, high, bins, env_rng, episodes, max_episode_steps, sutton_barto_reward):
    """Return the greedy policy's return in each of ``episodes`` twin episodes."""
    state = np.empty(4, dtype=np.float64)
    observation = np.empty(4, dtype=np.float32)
    returns = np.zeros(episodes, dtype=np.float64)
    for episode in range(episodes):
        cartpole_twin.reset(state, observation, env_rng)
        for length in range(1, max_episode_steps + 1):
            action = greedy_action(q, observation, low, high, bins)
            reward, terminated = cartpole_twin.step(state, action, observation, sutton_barto_reward)
            returns[episode] += reward
            if terminated or length >= max_episode_steps:
                break
    return returns


class NumbaEngine:
    """Trains on the compiled CartPole twin (CartPole-v0/v1 only)."""

    name = "numba"
    chunk_episodes = 1000

    def __init__(
        self,
        settings: TwinSettings,
        params: AgentParams,
        env_seed: int,
        env_rng_state: dict[str, Any] | None = None,
    ) -> None:
        self._settings = settings
        self._params = params
        # Seeded exactly as Gymnasium seeds env.np_random at reset(seed=env_seed).
        self._env_rng: np.random.Generator = seeding.np_random(env_seed)[0]
        if env_rng_state is not None:
            self._env_rng.bit_generator.state = env_rng_state

    def run(self, state: TrainingState, stop: int, check_solved: bool) -> int | None:
        """Train episodes up to ``stop`` (see :class:`~cartpole_q.engines.base.Engine`)."""
        p, s = self._params, self._settings
        finished, env_steps, solved = train_episodes(
            state.q, state.visits, p.low, p.high, p.bins, p.gamma,
            *p.alpha, *p.epsilon,
            state.agent_rng, self._env_rng, s.max_episode_steps, s.sutton_barto_reward,
            state.returns, state.lengths, state.epsilons, state.alphas,
            state.episode, stop, p.threshold, check_solved,
        )  # fmt: skip
        state.episode = finished
        state.env_steps += env_steps
        return None if solved < 0 else solved

    def warm_up(self, state: TrainingState) -> None:
        """Compile the kernels with an empty range of episodes (nothing runs, nothing drawn)."""
        self.run(state, state.episode, check_solved=False)
        self.evaluate(state.q, 0, 0)

    def evaluate(self, q: np.ndarray, episodes: int, seed: int) -> np.ndarray:
        """Play the greedy policy on the twin, seeded like ``reset(seed=seed)``."""
        p, s = self._params, self._settings
        env_rng = seeding.np_random(seed)[0]
        returns: np.ndarray = greedy_returns(
            q, p.low, p.high, p.bins, env_rng, episodes, s.max_episode_steps, s.sutton_barto_reward
        )
        return returns

    def env_rng_state(self) -> dict[str, Any]:
        """Return the twin environment's generator state."""
        return dict(self._env_rng.bit_generator.state)

    def close(self) -> None:
        """Nothing to release."""
