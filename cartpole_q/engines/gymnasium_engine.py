"""The gymnasium engine: real ``gymnasium.make`` environments, stepped from Python.

Each step calls compiled code built from the same algorithm hooks as the numba engine's
loop (see :mod:`cartpole_q.engines.kernel`).
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np
from gymnasium import spaces

from cartpole_q.config import Config
from cartpole_q.engines.base import AgentParams, Tables, TrainingState
from cartpole_q.engines.compile import specialise
from cartpole_q.engines.kernel import episode_rates, reaches_threshold, record_episode
from cartpole_q.engines.play import play_greedy
from cartpole_q.engines.rng_handle import GeneratorHandle, wrap_generator
from cartpole_q.engines.rows import ROW_RULES
from cartpole_q.envs.gym import make_env, set_physics
from cartpole_q.numba_cache import configure as configure_numba_cache
from cartpole_q.rl.algorithm import Algorithm
from cartpole_q.rl.tabular import ENDED, no_episode_end

configure_numba_cache()  # before any cache=True function is defined

# Placeholders, bound per algorithm and observation kind by specialise(); never called as
# they are.
ALGORITHM_START: Any = None
ALGORITHM_STEP: Any = None
ALGORITHM_END: Any = None
OBSERVATION_ROW: Any = None


def first_step(
    handle: Any, q: np.ndarray, memory: Any, params: Any, grid: Any, observation: Any,
    epsilon: float,
) -> tuple[int, int]:  # fmt: skip
    """An episode's first row and action, for the reset observation."""
    state = OBSERVATION_ROW(observation, grid)
    return state, ALGORITHM_START(q, memory, params, state, epsilon, handle.rng)


def next_step(
    handle: Any, q: np.ndarray, visits: np.ndarray, memory: Any, params: Any, grid: Any,
    gamma: float, state: int, action: int, reward: float, observation: Any, terminated: bool,
    truncated: bool, alpha: float, epsilon: float,
) -> tuple[int, int]:  # fmt: skip
    """Learn from one step; the next row and the next action (or ``ENDED``)."""
    row = OBSERVATION_ROW(observation, grid)
    visits[state, action] += 1
    chosen = ALGORITHM_STEP(
        q, memory, params, state, action, reward, row, terminated, truncated, alpha, gamma,
        epsilon, handle.rng,
    )  # fmt: skip
    return row, chosen


def end_episode(
    handle: Any, q: np.ndarray, memory: Any, params: Any, alpha: float, gamma: float,
    epsilon: float,
) -> None:  # fmt: skip
    """Finish an episode (the algorithm's ``end``)."""
    ALGORITHM_END(q, memory, params, alpha, gamma, epsilon, handle.rng)


@functools.cache
def step_functions(algorithm: Algorithm, kind: str) -> tuple[Any, Any, Any]:
    """The compiled first step, next step and episode end of one algorithm, for a Python loop.

    Args:
        algorithm: the algorithm whose hooks they call.
        kind: the observation kind (``box``, ``discrete`` or ``tuple``; see
            :data:`~cartpole_q.engines.rows.ROW_RULES`).

    They take the agent's generator wrapped in a handle (see :mod:`rng_handle`) and call
    the algorithm's hooks as the numba engine's loop does; cached on disk under the
    algorithm's key and the kind.
    """
    bindings = {
        "ALGORITHM_START": algorithm.start,
        "ALGORITHM_STEP": algorithm.step,
        "ALGORITHM_END": algorithm.end,
        "OBSERVATION_ROW": ROW_RULES[kind],
    }
    suffix = f"{algorithm.key}__{kind}"
    return (
        specialise(first_step, f"first_step__{suffix}", bindings),
        specialise(next_step, f"next_step__{suffix}", bindings),
        specialise(end_episode, f"end_episode__{suffix}", bindings),
    )


def observation_kind(space: Any) -> str:
    """``box``, ``discrete`` or ``tuple``: how an observation of ``space`` becomes a row."""
    if isinstance(space, spaces.Tuple):
        return "tuple"
    if isinstance(space, spaces.Discrete):
        return "discrete"
    return "box"


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
        kind = observation_kind(self._env.observation_space)
        self._first, self._next, self._end = step_functions(params.algorithm, kind)
        self._has_end = params.algorithm.end is not no_episode_end
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
        grid, agent, params = self._params.grid, self._params.agent, self._params.params
        env, metrics = self._env, state.metrics
        q, visits, memory = state.tables
        gamma = agent.gamma
        handle = self._rng_handle(state.agent_rng)
        randomize = self._config.env.randomize
        first, following, as_ints = self._first, self._next, self._as_ints
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
            if as_ints:
                observation = tuple(map(int, observation))
            s, a = first(handle, q, memory, params, grid, observation, epsilon)
            episode_return, length = 0.0, 0
            while a != ENDED:
                observation, reward, terminated, truncated, _ = env.step(a)
                if as_ints:
                    observation = tuple(map(int, observation))
                length += 1
                episode_return += reward
                s, a = following(handle, q, visits, memory, params, grid, gamma, s, a,
                                 float(reward), observation, terminated, truncated, alpha,
                                 epsilon)  # fmt: skip
            if self._has_end:
                self._end(handle, q, memory, params, alpha, gamma, epsilon)
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
        generator (an algorithm's own draws, such as Double Q-learning's coin, come from a
        scratch generator here), and the scratch memory is a copy.
        """
        grid, agent, params = self._params.grid, self._params.agent, self._params.params
        space = self._env.observation_space
        observation: Any = grid.low.astype(space.dtype)
        if grid.indexed:
            starts = tuple(int(start) for start in grid.starts)
            observation = starts if isinstance(space, spaces.Tuple) else starts[0]
        q, visits, memory = state.tables
        scratch = Tables(q.copy(), visits.copy(), tuple(array.copy() for array in memory))
        handle = wrap_generator(np.random.default_rng(0))
        self._first(handle, scratch.q, scratch.memory, params, grid, observation, 0.0)
        self._next(handle, scratch.q, scratch.visits, scratch.memory, params, grid, agent.gamma,
                   0, 0, 0.0, observation, True, False, 0.0, 0.0)  # fmt: skip
        if self._has_end:
            self._end(handle, scratch.q, scratch.memory, params, 0.0, agent.gamma, 0.0)

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
