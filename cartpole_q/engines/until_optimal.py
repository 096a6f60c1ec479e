"""Example 8.4's measure, compiled: updates until the greedy path from the start is shortest.

One run of a planning algorithm on a deterministic maze (a :class:`~cartpole_q.families.tables.world.
TableWorld` whose every ``P[s][a]`` has one outcome), played from its table as arrays: per
episode, from the start state, the algorithm's ``start``, then per step the maze's outcome
and the algorithm's ``step`` (truncated after ``limit`` steps), then its ``end``, exactly as
the engines' loop calls the hooks (:mod:`cartpole_q.engines.kernel`; no visit counts, no
metrics). After each episode the greedy path is checked: from the start, the greedy action
(:func:`~cartpole_q.rl.tabular.best_action`, the lowest on ties) of each state, at most
``shortest`` steps; the run stops at the first episode after which that path reaches the goal
in ``shortest`` steps (the BFS length, :func:`~cartpole_q.families.gridworlds.worlds.shortest_path`),
or once ``max_updates`` updates are made (then it did not get there).

**Updates** are every change of ``Q`` (every call of ``update``), real and planning alike:

- ``dyna_q``: ``1 + planning_steps`` per real step (its direct update and its planning
  updates, always all of them);
- ``prioritized_sweeping``: its count ``sweep_updates`` (memory 8): the pairs taken off its
  queue, at most ``planning_steps`` per real step, fewer when the queue empties (no direct
  update);
- ``q_learning``: one per real step.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from cartpole_q.engines.compile import specialise
from cartpole_q.rl.algorithm import Algorithm, MemoryContext
from cartpole_q.rl.algorithms.dyna_q import PLANNING_STEPS_AT
from cartpole_q.rl.tabular import ENDED, best_action, compilable

ALGORITHM_START: Any = None
ALGORITHM_STEP: Any = None
ALGORITHM_END: Any = None
UPDATES_MADE: Any = None
"""placeholders, bound per algorithm by :func:`_loop`"""


@compilable
def direct_and_planning(memory: Any, params: Any, steps: int) -> int:
    """``dyna_q``: its direct update and ``planning_steps`` planning updates per real step."""
    return steps * (int(params[PLANNING_STEPS_AT]) + 1)


@compilable
def swept(memory: Any, params: Any, steps: int) -> int:
    """``prioritized_sweeping``: its own count of updates (memory 8)."""
    return int(memory[8][0])


@compilable
def one_per_step(memory: Any, params: Any, steps: int) -> int:
    """``q_learning``: one update per real step."""
    return steps


COUNTERS = {
    "dyna_q": direct_and_planning,
    "prioritized_sweeping": swept,
    "q_learning": one_per_step,
}
"""the algorithms this measure counts, and how"""


@compilable
def greedy_path_length(q: Any, next_states: np.ndarray, terminals: np.ndarray, start: int,
                       most: int) -> int:  # fmt: skip
    """The steps of the greedy path from ``start`` to a terminal step, or -1 beyond ``most``."""
    n_actions = q.shape[1]
    state = start
    for length in range(1, most + 1):
        flat = state * n_actions + best_action(q, state)
        if terminals[flat]:
            return length
        state = next_states[flat]
    return -1


def run_until_optimal(
    q: Any, memory: Any, params: Any, next_states: np.ndarray, rewards: np.ndarray,
    terminals: np.ndarray, start: int, shortest: int, limit: int, max_updates: int,
    alpha: float, gamma: float, epsilon: float, rng: np.random.Generator,
) -> tuple[int, int, int, bool]:  # fmt: skip
    """Episodes until the greedy path is shortest; ``(updates, episodes, steps, reached)``."""
    n_actions = q.shape[1]
    steps, episodes = 0, 0
    while True:
        state = start
        action = ALGORITHM_START(q, memory, params, state, epsilon, rng)
        length = 0
        while action != ENDED:
            flat = state * n_actions + action
            next_state = next_states[flat]
            length += 1
            action = ALGORITHM_STEP(
                q, memory, params, state, action, rewards[flat], next_state,
                terminals[flat] != 0, length >= limit, alpha, gamma, epsilon, rng,
            )  # fmt: skip
            state = next_state
        ALGORITHM_END(q, memory, params, alpha, gamma, epsilon, rng)
        steps += length
        episodes += 1
        updates = UPDATES_MADE(memory, params, steps)
        if greedy_path_length(q, next_states, terminals, start, shortest) > 0:
            return updates, episodes, steps, True
        if updates >= max_updates:
            return updates, episodes, steps, False


_compiled: dict[str, Any] = {}


def loop_name(algorithm: Algorithm) -> str:
    """The compiled loop's name for ``algorithm`` (its numba cache entry)."""
    return f"until_optimal__{algorithm.key}"


def _loop(algorithm: Algorithm) -> Any:
    name = loop_name(algorithm)
    if name not in _compiled:
        bindings = {
            "ALGORITHM_START": algorithm.start,
            "ALGORITHM_STEP": algorithm.step,
            "ALGORITHM_END": algorithm.end,
            "UPDATES_MADE": COUNTERS[algorithm.name],
        }
        _compiled[name] = specialise(run_until_optimal, name, bindings)
    return _compiled[name]


@dataclass(frozen=True)
class Maze:
    """A deterministic maze as arrays: per pair ``state * n_actions + action`` its outcome."""

    n_states: int
    n_actions: int
    next_states: np.ndarray
    rewards: np.ndarray
    terminals: np.ndarray
    start: int
    shortest: int
    """the fewest steps from the start to the goal"""


def maze_arrays(world: Any) -> Maze:
    """The arrays of a deterministic :class:`~cartpole_q.families.tables.world.TableWorld`."""
    from cartpole_q.families.gridworlds.worlds import shortest_path

    n_states, n_actions = len(world.P), len(world.P[0])
    next_states = np.zeros(n_states * n_actions, dtype=np.int64)
    rewards = np.zeros(n_states * n_actions, dtype=np.float64)
    terminals = np.zeros(n_states * n_actions, dtype=np.int64)
    for state in range(n_states):
        for action in range(n_actions):
            ((_, following, reward, terminated),) = world.P[state][action]
            flat = state * n_actions + action
            next_states[flat], rewards[flat], terminals[flat] = following, reward, int(terminated)
    start = int(np.argmax(world.initial_state_distrib))
    return Maze(n_states, n_actions, next_states, rewards, terminals, start,
                shortest_path(world))  # fmt: skip


@dataclass(frozen=True)
class Settings:
    """One run's agent: the book's Example 8.4 uses alpha 0.5, gamma 0.95, 5 planning steps."""

    algorithm: str
    alpha: float
    gamma: float
    epsilon: float
    planning_steps: int
    theta: float
    tie_break: str
    limit: int
    """an episode is truncated after this many steps"""
    max_updates: int
    """give up after the episode in which this many updates are made"""


@dataclass(frozen=True)
class Result:
    """One run: updates until the greedy path was shortest, and what it took."""

    updates: int
    episodes: int
    steps: int
    reached: bool


def until_optimal(maze: Maze, settings: Settings, seed: int, compiled: bool = True) -> Result:
    """One run from an all-zero table, the agent's generator ``np.random.default_rng(seed)``.

    ``compiled=False`` runs the same Python (tests on tiny mazes).
    """
    from cartpole_q.rl.algorithms import get

    algorithm = get(settings.algorithm)
    values = {"planning_steps": settings.planning_steps, "theta": settings.theta}
    own = {param.key: values[param.key] for param in algorithm.params}
    params = algorithm.hook_params(own, settings.tie_break)
    context = MemoryContext(maze.n_states, maze.n_actions, 0.0, own, settings.limit)
    memory = algorithm.memory(context)
    q = np.zeros((maze.n_states, maze.n_actions), dtype=np.float64)
    rng = np.random.default_rng(seed)
    arguments = (
        q, memory, params, maze.next_states, maze.rewards, maze.terminals, maze.start,
        maze.shortest, settings.limit, settings.max_updates, settings.alpha, settings.gamma,
        settings.epsilon, rng,
    )  # fmt: skip
    if compiled:
        found = _loop(algorithm)(*arguments)
    else:
        globals()["ALGORITHM_START"] = algorithm.start
        globals()["ALGORITHM_STEP"] = algorithm.step
        globals()["ALGORITHM_END"] = algorithm.end
        globals()["UPDATES_MADE"] = COUNTERS[algorithm.name]
        found = run_until_optimal(*arguments)
    updates, episodes, steps, reached = found
    return Result(int(updates), int(episodes), int(steps), bool(reached))
