"""The gymnasium engine: real ``gymnasium.make`` environments, stepped from Python.

Each step calls compiled code built from the same algorithm hooks as the numba engine's
loop (see :mod:`cartpole_q.engines.kernel`).
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import Any

import numpy as np
from gymnasium import spaces

from cartpole_q.config import Config
from cartpole_q.engines.base import AgentParams, TrainingState, step_function_name
from cartpole_q.engines.compile import jit, specialise
from cartpole_q.engines.context import StepContext, step_context
from cartpole_q.engines.kernel import (
    episode_rates,
    reaches_threshold,
    record_episode,
    scheduled_step_size,
    update_counts,
)
from cartpole_q.engines.play import play_greedy
from cartpole_q.engines.rows import STATE_RULES
from cartpole_q.envs.gym import info_value, make_env, set_physics
from cartpole_q.numba_cache import configure as configure_numba_cache
from cartpole_q.rl.algorithm import Algorithm
from cartpole_q.rl.prediction import value_error
from cartpole_q.rl.tabular import ENDED, Rates, Transition, no_episode_end, visit

configure_numba_cache()  # before any cache=True function is defined

# Placeholders, bound per algorithm (and for tiles or every other observation) by
# specialise(); never called as they are.
ALGORITHM_START: Any = None
ALGORITHM_STEP: Any = None
ALGORITHM_END: Any = None
OBSERVATION_STATE: Any = None
STEP_SIZE: Any = None


def first_step(context: Any, observation: Any, epsilon: float) -> tuple[int, int]:
    """An episode's first row and action, for the reset observation."""
    state = OBSERVATION_STATE(context.q, observation, context.grid, -1)
    action = ALGORITHM_START(context.q, context.memory, context.params, state, epsilon, context.rng)
    return state, action


def next_step(
    context: Any, state: int, action: int, reward: float, observation: Any, terminated: bool,
    truncated: bool, alpha: float, epsilon: float,
) -> tuple[int, int]:  # fmt: skip
    """Learn from one step; the next row and the next action (or ``ENDED``)."""
    row = OBSERVATION_STATE(context.q, observation, context.grid, state)
    visit(context.visits, context.q, state, action)
    transition = Transition(state, action, reward, row, terminated, truncated)
    rates = Rates(STEP_SIZE(alpha, context.memory), context.gamma, epsilon)
    chosen = ALGORITHM_STEP(
        context.q, context.memory, context.params, transition, rates, context.rng
    )
    return row, chosen


def end_episode(context: Any, alpha: float, epsilon: float) -> None:
    """Finish an episode (the algorithm's ``end``)."""
    rates = Rates(STEP_SIZE(alpha, context.memory), context.gamma, epsilon)
    ALGORITHM_END(context.q, context.memory, context.params, rates, context.rng)


@functools.cache
def step_functions(algorithm: Algorithm, kind: str, averaged: bool = False) -> tuple[Any, Any, Any]:
    """The compiled first step, next step and episode end of one algorithm, for a Python loop.

    Args:
        algorithm: the algorithm whose hooks they call.
        kind: how observations come (``values``: any observation's values as a float64
            array; ``tiles``: a Box observation on tiles; see
            :data:`~cartpole_q.engines.rows.STATE_RULES`).
        averaged: compiled for ``agent.alpha: sample_average`` (the hooks get the update
            counts, the context's last memory array, as ``alpha``).

    They take the run's step context (see :mod:`~cartpole_q.engines.context`) and call the
    algorithm's hooks as the numba engine's loop does; cached on disk under the algorithm's
    key and the kind.
    """
    bindings = {
        "ALGORITHM_START": algorithm.start,
        "ALGORITHM_STEP": algorithm.step,
        "ALGORITHM_END": algorithm.end,
        "OBSERVATION_STATE": STATE_RULES[kind],
        "STEP_SIZE": update_counts if averaged else scheduled_step_size,
    }
    tiled = kind == "tiles"

    def compiled(template: Any) -> Any:
        name = step_function_name(template.__name__, algorithm.key, kind, averaged)
        return specialise(template, name, bindings, tiled=tiled, averaged=averaged)

    return compiled(first_step), compiled(next_step), compiled(end_episode)


class GymnasiumEngine:
    """Trains in ``gymnasium.make(env.id, **env.kwargs)``; works for any env ``inspect_env`` accepts.

    The environment is seeded once, at its first reset, with ``env_seed``; a resumed run
    instead restores the environment generator's saved state. Observations go to compiled
    code as a float64 array of its values: a Box observation's float32 values widened (as the
    binning rule widens them), a Discrete or Tuple one's integer components. So one
    compilation per algorithm serves every world (tiles apart).
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
        kind = "tiles" if params.tiled else "values"
        self._first, self._next, self._end = step_functions(params.algorithm, kind, params.averaged)
        self._has_end = params.algorithm.end is not no_episode_end
        # Every observation but tiles' is copied into this array (float64 values), which the
        # step functions read at once: the same compiled code for every world.
        self._values: np.ndarray | None = None
        if kind == "values":
            size = len(params.grid.starts) if params.grid.indexed else len(params.grid.bins)
            self._values = np.zeros(size, dtype=np.float64)
        self._step_cap = step_cap
        self._info_key = config.train.info_metric
        self._value_error: Any = jit(value_error) if params.truth.measured else None
        self._context: StepContext | None = None
        self._context_of: tuple[Any, ...] = ()

    def _step_context(self, state: TrainingState) -> StepContext:
        """The run's step context (made again only if the state's arrays were replaced)."""
        q, visits, memory = state.tables
        of = (state.agent_rng, q, visits, *memory)
        if (
            self._context is None
            or len(of) != len(self._context_of)
            or any(a is not b for a, b in zip(of, self._context_of, strict=True))
        ):
            p = self._params
            self._context = step_context(
                state.agent_rng, p.hook_table(q), visits, memory, p.params, p.grid, p.agent.gamma
            )
            self._context_of = of
        return self._context

    def run(self, state: TrainingState, stop: int, check_solved: bool) -> int | None:
        """Train episodes up to ``stop`` (see :class:`~cartpole_q.engines.base.Engine`)."""
        agent = self._params.agent
        env, metrics = self._env, state.metrics
        context = self._step_context(state)
        randomize = self._config.env.randomize
        first, following, values = self._first, self._next, self._values
        # A Discrete observation is one integer: item assignment is several times cheaper
        # than a slice's (which a Box or Tuple needs).
        scalar = values is not None and isinstance(self._env.observation_space, spaces.Discrete)
        info_key, info_sums, env_id = self._info_key, state.info, self._config.env.id
        truth, errors, measure = self._params.truth, state.errors, self._value_error
        steps_left = agent.max_env_steps - state.env_steps  # (NO_STEP_LIMIT: never reached)
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
            if values is not None:
                if scalar:
                    values[0] = observation
                else:
                    values[:] = observation
                observation = values
            s, a = first(context, observation, epsilon)
            episode_return, length, info_sum = 0.0, 0, 0.0
            while a != ENDED:
                observation, reward, terminated, truncated, info = env.step(a)
                if values is not None:
                    if scalar:
                        values[0] = observation
                    else:
                        values[:] = observation
                    observation = values
                length += 1
                truncated = truncated or length >= steps_left  # train.max_env_steps cuts it
                episode_return += reward
                if info_key is not None:
                    info_sum += info_value(info, info_key, env_id)
                s, a = following(context, s, a, float(reward), observation, terminated,
                                 truncated, alpha, epsilon)  # fmt: skip
            if self._has_end:
                self._end(context, alpha, epsilon)
            record_episode(metrics, episode, episode_return, length, epsilon, alpha)
            if info_sums is not None:
                info_sums[episode] = info_sum
            if errors is not None and measure is not None:  # q: the table, or tiles' weights
                errors[episode] = measure(state.tables.q, truth.rows, truth.values)
            state.episode = episode + 1
            state.env_steps += length
            steps_left -= length
            if check_solved and reaches_threshold(metrics.returns, episode, agent.threshold):
                return episode
            if steps_left <= 0:
                return None
        return None

    def warm_up(self, state: TrainingState) -> None:
        """Compile the per-step functions on scratch copies of the run's arrays.

        The observation sits on every lower grid edge (or is every component's ``start``),
        so it maps to row 0; everything the calls change is a copy, and the generator a
        scratch one.
        """
        p = self._params
        grid = p.grid
        if self._values is not None:
            observation: Any = (grid.starts if grid.indexed else grid.low).astype(np.float64)
        else:  # tiles: a Box observation as it comes
            observation = grid.low.astype(self._env.observation_space.dtype)
        q, visits, memory = state.tables
        scratch = step_context(
            np.random.default_rng(0), p.hook_table(q.copy()), visits.copy(),
            tuple(array.copy() for array in memory), p.params, grid, p.agent.gamma,
        )  # fmt: skip
        self._first(scratch, observation, 0.0)
        self._next(scratch, 0, 0, 0.0, observation, True, False, 0.0, 0.0)
        if self._has_end:
            self._end(scratch, 0.0, 0.0)

    def evaluate(
        self,
        q: np.ndarray,
        episodes: int,
        seed: int,
        should_stop: Callable[[], bool] | None = None,
    ) -> np.ndarray:
        """Play the greedy policy in a fresh ``gymnasium.make`` environment."""
        env = make_env(self._config.env)
        try:
            p = self._params
            return play_greedy(
                env, q, p.grid, episodes, seed, step_cap=self._step_cap, tilings=p.tilings,
                should_stop=should_stop,
            )  # fmt: skip
        finally:
            env.close()

    def env_rng_state(self) -> dict[str, Any]:
        """Return the training environment's generator state."""
        return dict(self._env.unwrapped.np_random.bit_generator.state)

    def close(self) -> None:
        """Close the training environment."""
        self._env.close()
