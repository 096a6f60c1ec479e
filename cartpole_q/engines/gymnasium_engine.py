"""The gymnasium engine: real ``gymnasium.make`` environments, stepped from Python.

Each step calls compiled code built on the same
:func:`~cartpole_q.rl.algorithms.learn_step` as the numba engine's loop.
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np
from gymnasium import spaces

from cartpole_q.config import Config
from cartpole_q.engines.base import AgentParams, Tables, TrainingState
from cartpole_q.engines.kernel import (
    compiled,
    episode_rates,
    reaches_threshold,
    record_episode,
)
from cartpole_q.engines.play import play_greedy
from cartpole_q.engines.rng_handle import GeneratorHandle, wrap_generator
from cartpole_q.envs.gym import make_env, set_physics
from cartpole_q.numba_cache import configure as configure_numba_cache
from cartpole_q.rl.algorithms import ENDED, first_action, learn_step
from cartpole_q.rl.policy import observation_row

configure_numba_cache()  # before any cache=True function is defined


@functools.cache
def step_functions(algorithm: int) -> tuple[Any, Any]:
    """The compiled first and next step of one algorithm, for a Python loop.

    They take the agent's generator wrapped in a handle (see :mod:`rng_handle`) and call
    :func:`~cartpole_q.rl.algorithms.first_action` and
    :func:`~cartpole_q.rl.algorithms.learn_step` with the algorithm as a constant, as the
    numba engine's loop does.
    """

    def first(handle, tables, grid, observation, epsilon):
        state = observation_row(observation, grid)
        return state, first_action(algorithm, tables.q, tables.q_b, state, epsilon, handle.rng)

    def following(handle, tables, grid, gamma, state, action, reward, observation,
                  terminated, truncated, alpha, epsilon):  # fmt: skip
        next_state = observation_row(observation, grid)
        next_action = learn_step(
            algorithm, tables.q, tables.q_b, tables.visits, state, action, reward, next_state,
            terminated, truncated, alpha, gamma, epsilon, handle.rng,
        )  # fmt: skip
        return next_state, next_action

    return compiled(first, f"first_step_{algorithm}"), compiled(following, f"next_step_{algorithm}")


class GymnasiumEngine:
    """Trains in ``gymnasium.make(env.id, **env.kwargs)``; works for any env ``inspect_env`` accepts.

    The environment is seeded once, at its first reset, with ``env_seed``; a resumed run
    instead restores the environment generator's saved state. Observations go to compiled
    code as they come: an array (Box), an integer (Discrete) or a tuple of integers.
    """

    name = "gymnasium"
    chunk_episodes = 1

    def __init__(
        self,
        config: Config,
        params: AgentParams,
        env_seed: int,
        env_rng_state: dict[str, Any] | None = None,
        step_cap: int | None = None,
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
        self._first, self._next = step_functions(params.agent.algorithm)
        # Tuple observations as plain integers: one compiled specialisation for any env.
        self._as_ints = isinstance(self._env.observation_space, spaces.Tuple)
        self._step_cap = step_cap
        self._handle: GeneratorHandle | None = None
        self._handle_rng: np.random.Generator | None = None

    def _rng_handle(self, rng: np.random.Generator) -> GeneratorHandle:
        # A numba call that takes a Generator costs ~6 microseconds; a handle ~0.5.
        if self._handle_rng is not rng:
            self._handle, self._handle_rng = wrap_generator(rng), rng
        assert self._handle is not None
        return self._handle

    def run(self, state: TrainingState, stop: int, check_solved: bool) -> int | None:
        """Train episodes up to ``stop`` (see :class:`~cartpole_q.engines.base.Engine`)."""
        grid, agent = self._params.grid, self._params.agent
        env, tables, metrics = self._env, state.tables, state.metrics
        handle = self._rng_handle(state.agent_rng)
        randomize = self._config.env.randomize
        for episode in range(state.episode, stop):
            epsilon, alpha = episode_rates(agent, episode)
            if randomize:  # one draw per key, in the config's (canonical) order
                drawn = {
                    key: state.physics_rng.uniform(low, high)
                    for key, (low, high) in randomize.items()
                }
                set_physics(env, drawn)
            observation, _ = env.reset(seed=self._first_reset_seed)
            self._first_reset_seed = None
            if self._as_ints:
                observation = tuple(map(int, observation))
            s, a = self._first(handle, tables, grid, observation, epsilon)
            episode_return, length = 0.0, 0
            while a != ENDED:
                observation, reward, terminated, truncated, _ = env.step(a)
                if self._as_ints:
                    observation = tuple(map(int, observation))
                length += 1
                episode_return += reward
                s, a = self._next(handle, tables, grid, agent.gamma, s, a, float(reward),
                                  observation, terminated, truncated, alpha, epsilon)  # fmt: skip
            record_episode(metrics, episode, episode_return, length, epsilon, alpha)
            state.episode = episode + 1
            state.env_steps += length
            if check_solved and reaches_threshold(metrics.returns, episode, agent.threshold):
                return episode
        return None

    def warm_up(self, state: TrainingState) -> None:
        """Compile the per-step functions on a one-row scratch table.

        The observation sits on every lower grid edge (or is every component's ``start``),
        so it maps to row 0; epsilon 0 and a terminated step draw nothing from the agent's
        generator, except Double Q-learning's coin, which is drawn from a scratch generator
        here.
        """
        grid, agent = self._params.grid, self._params.agent
        space = self._env.observation_space
        observation: Any = grid.low.astype(space.dtype)
        if grid.indexed:
            starts = tuple(int(start) for start in grid.starts)
            observation = starts if isinstance(space, spaces.Tuple) else starts[0]
        n_actions = state.tables.q.shape[1]
        scratch = Tables(
            np.zeros((1, n_actions)),
            np.zeros((1 if state.tables.q_b.size else 0, n_actions)),
            np.zeros((1, n_actions), dtype=np.int64),
        )
        handle = wrap_generator(np.random.default_rng(0))
        self._first(handle, scratch, grid, observation, 0.0)
        self._next(handle, scratch, grid, agent.gamma, 0, 0, 0.0, observation, True, False,
                   0.0, 0.0)  # fmt: skip

    def evaluate(self, q: np.ndarray, episodes: int, seed: int) -> np.ndarray:
        """Play the greedy policy in a fresh ``gymnasium.make`` environment."""
        env = make_env(self._config.env)
        try:
            return play_greedy(env, q, self._params.grid, episodes, seed, step_cap=self._step_cap)
        finally:
            env.close()

    def env_rng_state(self) -> dict[str, Any]:
        """Return the training environment's generator state."""
        return dict(self._env.unwrapped.np_random.bit_generator.state)

    def close(self) -> None:
        """Close the training environment."""
        self._env.close()
