"""Example 8.4's measure, compiled: updates until the greedy path from the start is short enough.

One run of a planning algorithm on a deterministic maze (a :class:`~cartpole_q.families.tables.world.
TableWorld` whose every ``P[s][a]`` has one outcome), played from its table as arrays: per
episode, from the start state, the algorithm's ``start``, then per step the maze's outcome
and the algorithm's ``step`` (truncated after ``limit`` steps), then its ``end``, exactly as
the engines' loop calls the hooks (:mod:`cartpole_q.engines.kernel`; no visit counts, no
metrics). After each episode the greedy path is checked: from the start, the greedy action
(:func:`~cartpole_q.rl.tabular.best_action`, the lowest on ties) of each state; the run
stops at the first episode after which that path reaches the goal in at most
``optimal_within * shortest`` steps (:attr:`Settings.optimal_within`; 1.0, the book's
"optimal solution": a shortest path, the BFS length of
:func:`~cartpole_q.families.gridworlds.worlds.shortest_path`), or gives up once
``max_updates`` updates are made or ``max_steps`` real steps taken.

**Updates** are every change of ``Q`` (every call of ``update``), real and planning alike:

- ``dyna_q``: ``1 + planning_steps`` per real step (its direct update and its planning
  updates, always all of them);
- ``prioritized_sweeping``: its count ``sweep_updates`` (memory 8): the pairs taken off its
  queue, at most ``planning_steps`` per real step, fewer when the queue empties (no direct
  update);
- ``q_learning``: one per real step.

**Chunks.** :func:`until_optimal` runs the compiled loop in chunks of at most
:data:`CHUNK_UPDATES` updates' worth of real steps (0.1-0.15 s measured on 2 shared cores,
0.4 s at worst), pausing inside an episode if need be (the loop's state is a small int64
array, :data:`CARRY_SLOTS`; the generator goes on where it was), so that a caller can stop
it (``should_stop``) and show it (``progress``) between chunks; the result is the one call's.

**The mazes of Example 8.4.** The book's axis marks 47, 94, 186, 376, 752, 1,504, 3,008
and 6,016 states, doubling. Its mazes (Peng and Williams 1993) are not described; here the
Dyna maze with every cell a ``rows`` x ``columns`` block,
:func:`~cartpole_q.families.gridworlds.worlds.doubled_block`, the rows and the columns
doubled in turn: exactly ``47 * 2**j`` open cells (188 where the book marks 186), shortest
paths 14, 20, 28, 40, 56, 80, 112 and 160 steps. Chosen over ``k`` x ``k`` blocks (``47
k²``: 47, 188, 423, ..., 5,687 at ``k = 11``) because they are the book's sizes, evenly
spread on its logarithmic axis, and the largest is above 5,000. Measured with the heap
queue (2 shared cores, alpha 0.5, 5 planning steps, theta 1e-5, median of 3): one run at
6,016 states takes about 2.7 s (prioritized sweeping) and 1.2 s (Dyna-Q) to a shortest path,
0.9 s and 0.4 s to 1.2 x shortest; ten seeds of both methods at all eight sizes take about
2 minutes to a shortest path and 25 s to 1.2 x, on one core. ``theta`` must stay well
below the values' differences near the start (about ``gamma**shortest * (1 - gamma**2)``,
2.6e-5 at 6,016 states): with the 1e-4 of Shangtong Zhang's script, prioritized
sweeping's queue empties for good at 6,016 states (all ten seeds, either criterion) and a
run ends only by ``max_steps``. To a shortest path, a few prioritized sweeping runs (3 of
80 at alpha 0.5, theta 1e-5) do not get there in 2e7 steps whatever ``theta``: having
learned a route a step or two longer, the agent no longer explores towards the pairs the
shortest one needs (never tried, or at alpha 0.5 updated only halfway, which nothing
queues again until they are walked); ``max_steps`` ends them, not reached (2e7: ~10 s).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np

from cartpole_q.engines.compile import specialise
from cartpole_q.rl.algorithm import Algorithm, MemoryContext
from cartpole_q.rl.algorithms.dyna_q import PLANNING_STEPS_AT
from cartpole_q.rl.tabular import ENDED, Rates, Transition, best_action, compilable

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


CARRY_SLOTS = 7
IN_EPISODE, STATE, ACTION, LENGTH, STEPS, EPISODES, UPDATES = range(CARRY_SLOTS)
"""the loop's state between chunks (int64 ``[CARRY_SLOTS]``): whether an episode is under
way, its state, its action and its length so far, the steps of the episodes ended, the
episodes ended, and the updates made so far"""
RUNNING, REACHED, GAVE_UP = 0, 1, 2
"""what a chunk ends with: its work is done and the run is not; the greedy path is short
enough; ``max_updates`` updates are made or ``max_steps`` steps taken"""
MAX_STEPS = 2**62
"""no limit on the real steps (:attr:`Settings.max_steps`)"""
CHUNK_UPDATES = 250_000
"""a chunk's work, in updates at most (:func:`chunk_steps`): 0.1-0.15 s for prioritized
sweeping on 2 shared cores (0.4 s at worst under load), less for Dyna-Q"""


def chunk_steps(planning_steps: int) -> int:
    """The real steps of one chunk: each makes at most ``1 + planning_steps`` updates."""
    return max(1, CHUNK_UPDATES // (1 + planning_steps))


class MazeRecord(NamedTuple):
    """A :class:`Maze`'s arrays and start, as the compiled loop takes them."""

    next_states: np.ndarray
    rewards: np.ndarray
    terminals: np.ndarray
    start: int


class Limits(NamedTuple):
    """When a run's episodes are cut and when the run stops (see :class:`Settings`)."""

    most: int
    """the greedy path counts as optimal at this many steps or fewer"""
    limit: int
    """an episode is truncated after this many steps"""
    max_updates: int
    """give up after the episode in which this many updates are made"""
    max_steps: int
    """give up after the episode in which this many real steps are taken in all"""


def run_until_optimal(
    q: Any, memory: Any, params: Any, maze: MazeRecord, limits: Limits, rates: Rates,
    rng: np.random.Generator, carry: np.ndarray, budget: int,
) -> int:  # fmt: skip
    """At most ``budget`` more real steps of a run from ``carry``; ``RUNNING``, ``REACHED`` or ``GAVE_UP``.

    Episodes until the greedy path reaches the goal in at most ``limits.most`` steps. A
    chunk may end inside an episode: ``carry`` keeps where (the next chunk goes on with the
    same draws, as if never paused), and ``carry[UPDATES]`` the updates made so far.
    """
    # Unpacked before the loop: reading a record's array inside it costs reference counts.
    next_states, rewards, terminals = maze.next_states, maze.rewards, maze.terminals
    start, most, limit = maze.start, limits.most, limits.limit
    max_updates, max_steps, epsilon = limits.max_updates, limits.max_steps, rates.epsilon
    n_actions = q.shape[1]
    state, action, length = carry[STATE], carry[ACTION], carry[LENGTH]
    steps, episodes = carry[STEPS], carry[EPISODES]
    taken = 0
    while True:
        if carry[IN_EPISODE] == 0:
            state = start
            action = ALGORITHM_START(q, memory, params, state, epsilon, rng)
            length = 0
            carry[IN_EPISODE] = 1
        while action != ENDED:
            if taken == budget:
                carry[STATE], carry[ACTION], carry[LENGTH] = state, action, length
                carry[UPDATES] = UPDATES_MADE(memory, params, steps + length)
                return RUNNING
            flat = state * n_actions + action
            next_state = next_states[flat]
            length += 1
            taken += 1
            transition = Transition(
                state, action, rewards[flat], next_state, terminals[flat] != 0, length >= limit
            )
            action = ALGORITHM_STEP(q, memory, params, transition, rates, rng)
            state = next_state
        ALGORITHM_END(q, memory, params, rates, rng)
        carry[IN_EPISODE] = 0
        steps += length
        episodes += 1
        updates = UPDATES_MADE(memory, params, steps)
        carry[STEPS], carry[EPISODES], carry[UPDATES] = steps, episodes, updates
        if greedy_path_length(q, next_states, terminals, start, most) > 0:
            return REACHED
        if updates >= max_updates or steps >= max_steps:
            return GAVE_UP


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
    optimal_within: float = 1.0
    """the run stops when the greedy path reaches the goal in at most ``optimal_within *
    shortest`` steps (rounded down): 1.0 is a shortest path, the book's criterion;
    Shangtong Zhang's reproduction takes 1.2"""
    max_steps: int = MAX_STEPS
    """give up after the episode in which this many real steps are taken in all: a run whose
    updates stop growing never reaches ``max_updates`` (prioritized sweeping whose queue
    stays empty, every priority at most ``theta``, or whose greedy route is short of a
    pair it has never tried and no longer explores towards)"""

    def __post_init__(self) -> None:
        if not (math.isfinite(self.optimal_within) and self.optimal_within >= 1.0):
            raise ValueError(
                f"`optimal_within` must be a number >= 1 (1: a shortest path), got "
                f"{self.optimal_within!r}"
            )

    def longest_path(self, shortest: int) -> int:
        """The most steps a greedy path may take to count: ``optimal_within * shortest``, rounded down.

        Rounded at 9 decimals first, so that ``1.15 * 20`` is 23 steps, not 22.

        >>> [Settings("dyna_q", 0.5, 0.95, 0.1, 5, 0.0, "random", 10, 10, within).longest_path(20)
        ...  for within in (1.0, 1.15, 1.2)]
        [20, 23, 24]
        """
        return math.floor(round(self.optimal_within * shortest, 9))


@dataclass(frozen=True)
class Result:
    """One run: updates until the greedy path was short enough, and what it took."""

    updates: int
    episodes: int
    steps: int
    reached: bool


def until_optimal(
    maze: Maze,
    settings: Settings,
    seed: int,
    compiled: bool = True,
    *,
    should_stop: Callable[[], bool] | None = None,
    progress: Callable[[int], None] | None = None,
) -> Result | None:
    """One run from an all-zero table, the agent's generator ``np.random.default_rng(seed)``.

    The run goes in chunks of at most :data:`CHUNK_UPDATES` updates (a fraction of a second
    each), the same draws in the same order as one call would make. Between chunks
    ``progress`` is told the updates made so far and ``should_stop`` is asked (also before
    the first); when it says stop, the run is abandoned and ``None`` returned. ``compiled=
    False`` runs the same Python (tests on tiny mazes).
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
    carry = np.zeros(CARRY_SLOTS, dtype=np.int64)
    arguments = (
        q, memory, params, MazeRecord(maze.next_states, maze.rewards, maze.terminals, maze.start),
        Limits(settings.longest_path(maze.shortest), settings.limit, settings.max_updates,
               settings.max_steps),
        Rates(settings.alpha, settings.gamma, settings.epsilon), rng, carry,
        chunk_steps(settings.planning_steps),
    )  # fmt: skip
    if compiled:
        run = _loop(algorithm)
    else:
        globals()["ALGORITHM_START"] = algorithm.start
        globals()["ALGORITHM_STEP"] = algorithm.step
        globals()["ALGORITHM_END"] = algorithm.end
        globals()["UPDATES_MADE"] = COUNTERS[algorithm.name]
        run = run_until_optimal
    status = RUNNING
    while status == RUNNING:
        if should_stop is not None and should_stop():
            return None
        status = run(*arguments)
        if progress is not None:
            progress(int(carry[UPDATES]))
    return Result(int(carry[UPDATES]), int(carry[EPISODES]), int(carry[STEPS]), status == REACHED)
