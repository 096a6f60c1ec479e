"""The numba engine: a compiled twin and the algorithm in one compiled loop.

Same step functions, same random draws in the same order as the gymnasium engine, so the
Q-table and metrics are byte-identical to it; about two hundred times faster.
"""

from __future__ import annotations

import os
import signal
import threading
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np
from gymnasium.utils import seeding

from cartpole_q.engines.base import (
    AgentParams,
    Tables,
    TrainingState,
    exploring_plays_greedy,
    loops_played,
    played_until_stopped,
)
from cartpole_q.engines.kernel import (
    Generators,
    Measure,
    Turn,
    TwinEnv,
    greedy_kernel,
    training_kernel,
)
from cartpole_q.envs.models import GREEDY_STEP_CAP
from cartpole_q.envs.registry import TwinSettings
from cartpole_q.families import profile_for
from cartpole_q.numba_cache import is_cached
from cartpole_q.processes import leave_signals_to_parent

_NO_ERRORS = np.zeros(0, dtype=np.float64)
"""the per-episode errors of a run that measures none"""

NO_TIME_LIMIT = 2**63 - 1
"""the compiled loop's time limit for an environment without one: never reached"""


class NumbaEngine:
    """Trains on a compiled twin of the environment (see :mod:`cartpole_q.envs.registry`)."""

    name = "numba"
    chunk_episodes = 1000

    def __init__(
        self,
        settings: TwinSettings,
        params: AgentParams,
        env_seed: int,
        env_rng_state: dict[str, Any] | None = None,
        randomize: Mapping[str, tuple[float, float]] | None = None,
        greedy_loop: bool | None = None,
    ) -> None:
        """Build the engine of one run.

        Args:
            settings: the twin and its settings.
            params: the agent's parameters as the compiled code takes them.
            env_seed: seeds the twin's generator as ``reset(seed=env_seed)`` would.
            env_rng_state: a checkpointed state of that generator, restored instead.
            randomize: ``env.randomize``'s ranges.
            greedy_loop: whether greedy episodes that follow exploring ones play on the
                greedy loop; ``None``: where that is cached or pays (see :meth:`loops`).
        """
        self._greedy_loop = greedy_loop
        self._exploring_alone: bool | None = None  # decided by loops(), once
        self._time_limit = settings.max_episode_steps
        self._kernel = training_kernel(
            params.algorithm, settings.twin, bool(randomize), params.tiled, params.averaged
        )
        self._greedy_returns = greedy_kernel(settings.twin, params.tiled)
        limit = settings.max_episode_steps
        ranges = randomize or {}
        physics = profile_for(settings.twin.env_ids[0]).physics
        drawn = physics.randomizable if physics is not None else ()
        draws = (
            np.array([drawn.index(key) for key in ranges], dtype=np.int64),
            np.array([low for low, _ in ranges.values()], dtype=np.float64),
            np.array([high for _, high in ranges.values()], dtype=np.float64),
        )
        self._env = TwinEnv(
            NO_TIME_LIMIT if limit is None else limit, *_scratch(settings), settings.params, draws
        )
        # Greedy play stops at the step cap where the environment has no time limit, as
        # the gymnasium engine's evaluations do (a greedy policy may walk in circles). Its
        # own scratch arrays: an evaluation may come between two turns of training.
        self._greedy_env = TwinEnv(
            GREEDY_STEP_CAP if limit is None else limit, *_scratch(settings), settings.params,
            draws,
        )  # fmt: skip
        self._params = params
        self._hook_tables: tuple[Any, Any] = (None, None)  # (q, the hooks' view of it)
        # Seeded exactly as Gymnasium seeds env.np_random at reset(seed=env_seed).
        self._env_rng: np.random.Generator = seeding.np_random(env_seed)[0]
        if env_rng_state is not None:
            self._env_rng.bit_generator.state = env_rng_state

    def run(self, state: TrainingState, stop: int, check_solved: bool) -> int | None:
        """Train episodes up to ``stop`` (see :class:`~cartpole_q.engines.base.Engine`).

        The exploring and the greedy loop take turns (see :mod:`~cartpole_q.engines.kernel`):
        each plays episodes up to the first that is the other's. Where the exploring loop
        plays the greedy episodes too (see :meth:`loops`), it plays every episode.
        """
        self.loops(state)  # (decides, once)
        if self._exploring_alone:
            return self._run_loop(False, state, stop, check_solved)
        first = loops_played(self._params.agent.epsilon, state.episode, state.episode + 1)
        greedy = first == (True,)  # the loop of the first episode
        handed_back = False  # the last loop returned without playing an episode
        while state.episode < stop and not state.steps_spent(self._params.agent.max_env_steps):
            started = state.episode
            solved = self._run_loop(greedy, state, stop, check_solved)
            if solved is not None:
                return solved
            if state.episode == started:
                # Both loops handing back the same episode cannot happen (they read one
                # schedule value); a bug must not spin forever.
                if handed_back:
                    raise RuntimeError(f"no training loop takes episode {started}")
                handed_back = True
            else:
                handed_back = False
            greedy = not greedy
        return None

    def _run_loop(
        self, greedy: bool, state: TrainingState, stop: int, check_solved: bool
    ) -> int | None:
        """One loop's turn: episodes up to ``stop`` or the other loop's first one."""
        p = self._params
        q, visits, memory = state.tables
        _, loop = self._kernel.loop(greedy)
        errors = _NO_ERRORS if state.errors is None else state.errors
        finished, env_steps, solved = loop(
            Tables(self._hook_table(q), visits, memory), p.params, p.grid, p.agent,
            state.metrics, Generators(state.agent_rng, self._env_rng, state.physics_rng),
            self._env, Turn(state.episode, stop, check_solved, bool(self._exploring_alone)),
            Measure(p.truth, errors),
        )  # fmt: skip
        state.episode = finished
        state.env_steps += env_steps
        return None if solved < 0 else int(solved)

    def _hook_table(self, q: np.ndarray) -> Any:
        """``q`` as the hooks take it (made again only for another array)."""
        if self._hook_tables[0] is not q:
            self._hook_tables = (q, self._params.hook_table(q))
        return self._hook_tables[1]

    def loops(self, state: TrainingState) -> tuple[bool, ...]:
        """The loops the run plays from ``state`` on, as ``greedy`` flags (decided once).

        Those its epsilon plays over the episodes left (up to the configured episodes), but
        for a run that explores and then plays greedy: it plays the greedy loop only where
        that is cached or pays, else the exploring loop alone plays every episode (see
        :func:`~cartpole_q.engines.base.exploring_plays_greedy`, which
        :func:`~cartpole_q.engines.loop_names` asks too).
        """
        epsilon, start, stop = self._params.agent.epsilon, state.episode, len(state.metrics.returns)
        if self._exploring_alone is None:
            self._exploring_alone = exploring_plays_greedy(
                self._greedy_loop, self._kernel.greedy_name, epsilon, stop, self._time_limit
            )
        played = loops_played(epsilon, start, stop)
        return (False,) if played and self._exploring_alone else played

    def warm_up(self, state: TrainingState) -> None:
        """Compile the loops the run plays (or load them from the cache); nothing runs.

        The loops are those of the episodes left (``state.episode`` up to the configured
        episodes), and the greedy play. Compiling takes seconds, once per machine: then they
        are compiled side by side, in this process and a forked one, which leaves its code
        in numba's cache for this one to load (see :meth:`_compile_side_by_side`).
        """
        needed = self.loops(state)
        if not all(is_cached(self._kernel.loop(greedy)[0]) for greedy in needed):
            self._compile_side_by_side(state, needed)
        for greedy in needed:
            self._load(state, greedy)
        if not self._params.algorithm.predicts:  # (a prediction run plays no greedy policy)
            self.evaluate(state.tables.q, 0, 0)

    def _load(self, state: TrainingState, greedy: bool) -> None:
        """Compile one loop, or load it from the cache, by a call that plays no episode.

        A compiled function is compiled for the argument types of its first call; an empty
        range of episodes touches nothing and draws nothing.
        """
        self._run_loop(greedy, state, state.episode, check_solved=False)

    def _compile_side_by_side(self, state: TrainingState, needed: tuple[bool, ...]) -> None:
        """Compile the loops ``needed`` and the greedy play, in two processes at once.

        The first loop needed (the exploring one, the larger compilation, when both are) in
        a forked child, which writes numba's cache and exits; the other, if any, and the
        greedy play here, and then what writing the run will need is imported (see
        :func:`_import_for_outputs`) while the child finishes: the run loads the child's
        code from the cache. Where a process cannot fork (or has threads, where forking is
        unsafe), everything is compiled here, one after another.

        The child leaves signals to this process (a Ctrl-C to the terminal reaches both: the
        command answers it once) and dies with it; if this process stops (a second Ctrl-C,
        or a failure here), the child is killed, not waited for. Should the child fail, the
        run compiles that loop itself, where its error is raised.
        """
        plays = not self._params.algorithm.predicts  # the greedy play, compiled here
        if (
            not hasattr(os, "fork")
            or threading.active_count() > 1
            or (len(needed) < 2 and not plays)
        ):
            return
        parent = os.getpid()
        child = os.fork()
        if child == 0:  # the child: compile into the cache, then exit without clean-up
            code = 1
            try:
                leave_signals_to_parent(parent)
                self._load(state, needed[0])
                code = 0
            finally:
                os._exit(code)
        try:
            for greedy in needed[1:]:
                self._load(state, greedy)
            if plays:
                self.evaluate(state.tables.q.copy(), 0, 0)
            _import_for_outputs()
        except BaseException:
            os.kill(child, signal.SIGKILL)  # its half-compiled loop is worth nothing
            raise
        finally:
            os.waitpid(child, 0)

    def evaluate(
        self,
        q: np.ndarray,
        episodes: int,
        seed: int,
        should_stop: Callable[[], bool] | None = None,
    ) -> np.ndarray:
        """Play the greedy policy on the twin, seeded like ``reset(seed=seed)``."""
        env_rng = seeding.np_random(seed)[0]
        table, grid, env = self._params.hook_table(q), self._params.grid, self._greedy_env

        def play(count: int) -> np.ndarray:
            returns = np.zeros(count, dtype=np.float64)
            self._greedy_returns(table, grid, env_rng, env, returns)
            return returns

        if should_stop is None:
            return play(episodes)
        return played_until_stopped(play, episodes, should_stop)

    def env_rng_state(self) -> dict[str, Any]:
        """Return the twin environment's generator state."""
        return dict(self._env_rng.bit_generator.state)

    def close(self) -> None:
        """Nothing to release."""


def _scratch(settings: TwinSettings) -> tuple[np.ndarray, np.ndarray]:
    """A twin's state and observation arrays, as its reset and step fill them."""
    twin = settings.twin
    return (
        np.empty(settings.state_size, dtype=twin.state_dtype),
        np.empty(settings.observation_size, dtype=twin.observation_dtype),
    )


def _import_for_outputs() -> None:
    """Import matplotlib's figure and PNG writing, as a run's outputs will (about 0.4 s).

    Called while a forked child compiles the run's loop, when this process would otherwise
    wait: the import is then off a cold start's critical path. Nothing else changes; a
    missing module is left for the outputs to report.
    """
    import importlib

    for name in ("matplotlib.figure", "matplotlib.backends.backend_agg", "PIL.PngImagePlugin"):
        try:
            importlib.import_module(name)
        except ImportError:
            return
