"""The gymnasium engine: real ``gymnasium.make`` environments, stepped from Python."""

from __future__ import annotations

from typing import Any

import numpy as np
from numba import njit

from cartpole_q.agent import (
    begin_episode,
    learn_step,
    reaches_threshold,
    record_episode,
    schedule_value,
)
from cartpole_q.config import Config
from cartpole_q.engines.base import AgentParams, TrainingState
from cartpole_q.engines.rng_handle import GeneratorHandle, wrap_generator
from cartpole_q.environment import make_env
from cartpole_q.evaluation import play_greedy
from cartpole_q.numba_cache import configure as configure_numba_cache

configure_numba_cache()  # before any cache=True function is defined


@njit(cache=True, nogil=True)
def _begin(handle, q, observation, low, high, bins, epsilon):
    return begin_episode(q, observation, low, high, bins, epsilon, handle.rng)


@njit(cache=True, nogil=True)
def _learn(
    handle, q, visits, state, action, reward, observation, terminated, truncated,
    low, high, bins, alpha, gamma, epsilon,
):  # fmt: skip
    return learn_step(
        q, visits, state, action, reward, observation, terminated, truncated,
        low, high, bins, alpha, gamma, epsilon, handle.rng,
    )  # fmt: skip


class GymnasiumEngine:
    """Trains in ``gymnasium.make(env.id, **env.kwargs)``; works for any Box/Discrete env.

    The environment is seeded once, at its first reset, with ``env_seed``; a resumed run
    instead restores the environment generator's saved state.
    """

    name = "gymnasium"
    chunk_episodes = 1

    def __init__(
        self,
        config: Config,
        params: AgentParams,
        env_seed: int,
        env_rng_state: dict[str, Any] | None = None,
    ) -> None:
        self._config = config
        self._params = params
        self._env = make_env(config.env)
        self._first_reset_seed: int | None = env_seed
        if env_rng_state is not None:
            generator = np.random.Generator(np.random.PCG64())
            generator.bit_generator.state = env_rng_state
            self._env.unwrapped.np_random = generator
            self._first_reset_seed = None
        self._handle: GeneratorHandle | None = None
        self._handle_rng: np.random.Generator | None = None

    def _rng_handle(self, rng: np.random.Generator) -> GeneratorHandle:
        if self._handle_rng is not rng:
            self._handle, self._handle_rng = wrap_generator(rng), rng
        assert self._handle is not None
        return self._handle

    def run(self, state: TrainingState, stop: int, check_solved: bool) -> int | None:
        """Train episodes up to ``stop`` (see :class:`~cartpole_q.engines.base.Engine`)."""
        p, env, q, visits = self._params, self._env, state.q, state.visits
        low, high, bins, gamma = p.low, p.high, p.bins, p.gamma
        handle = self._rng_handle(state.agent_rng)
        for episode in range(state.episode, stop):
            epsilon = schedule_value(*p.epsilon, episode)
            alpha = schedule_value(*p.alpha, episode)
            observation, _ = env.reset(seed=self._first_reset_seed)
            self._first_reset_seed = None
            s, a = _begin(handle, q, observation, low, high, bins, epsilon)
            episode_return, length = 0.0, 0
            while True:
                observation, reward, terminated, truncated, _ = env.step(a)
                length += 1
                episode_return += reward
                s, a = _learn(
                    handle, q, visits, s, a, float(reward), observation, terminated, truncated,
                    low, high, bins, alpha, gamma, epsilon,
                )  # fmt: skip
                if terminated or truncated:
                    break
            record_episode(
                state.returns, state.lengths, state.epsilons, state.alphas,
                episode, episode_return, length, epsilon, alpha,
            )  # fmt: skip
            state.episode = episode + 1
            state.env_steps += length
            if check_solved and reaches_threshold(state.returns, episode, p.threshold):
                return episode
        return None

    def warm_up(self, state: TrainingState) -> None:
        """Compile the per-step functions on a one-row scratch table.

        The observation sits on every lower grid edge, so it maps to row 0; epsilon 0 and a
        terminated step draw nothing from the agent's generator.
        """
        p = self._params
        space = self._env.observation_space
        observation = p.low.astype(space.dtype)
        q = np.zeros((1, state.q.shape[1]))
        visits = np.zeros((1, state.q.shape[1]), dtype=np.int64)
        handle = self._rng_handle(state.agent_rng)
        _begin(handle, q, observation, p.low, p.high, p.bins, 0.0)
        _learn(handle, q, visits, 0, 0, 0.0, observation, True, False,
               p.low, p.high, p.bins, 0.0, p.gamma, 0.0)  # fmt: skip

    def evaluate(self, q: np.ndarray, episodes: int, seed: int) -> np.ndarray:
        """Play the greedy policy in a fresh ``gymnasium.make`` environment."""
        env = make_env(self._config.env)
        try:
            return play_greedy(env, q, self._params, episodes, seed)
        finally:
            env.close()

    def env_rng_state(self) -> dict[str, Any]:
        """Return the training environment's generator state."""
        return dict(self._env.unwrapped.np_random.bit_generator.state)

    def close(self) -> None:
        """Close the training environment."""
        self._env.close()
