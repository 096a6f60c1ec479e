"""Playing a linear study's run: the world stepped by a behaviour policy, a learner updated.

Two engines play a sampled run with the same compiled updates (:mod:`cartpole_q.rl.linear`)
and the same draws, so their weights and errors agree byte for byte
(``tests/test_linear.py``):

- ``numba``: compiled loops over the world's table (the twin of every table world,
  :mod:`cartpole_q.families.tables.twin`), a chunk of episodes or steps per call;
- ``gymnasium``: a Python loop over ``gymnasium.make(world)``, the behaviour's draws and the
  updates compiled, one call per step.

A run goes in chunks of ``record_every`` episodes (or steps, or sweeps), after each of
which the errors are measured; a compiled call runs at most :data:`EPISODES_PER_CALL`
episodes (ending sooner, after the episode that reaches :data:`STEPS_PER_CALL` steps),
:data:`STEPS_PER_CALL` steps or :data:`SWEEPS_PER_CALL` sweeps, and between calls
the run's ``should_stop`` is asked, so a stop is seen within a fraction of a second. An expected algorithm sweeps the model and never steps the world (one engine).

**Seeds** (docs/algorithms.md, "Linear function approximation"): run ``seed``:
``agent_seq, env_seq = np.random.SeedSequence(seed).spawn(2)``; the behaviour draws from
``Generator(PCG64(agent_seq))``; the world is reset first with ``seed =
int(env_seq.generate_state(1, dtype=np.uint32)[0])``, later without one.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np

from cartpole_q.engines.compile import LoopSet
from cartpole_q.families.tables.twin import initial_state, table_step
from cartpole_q.rl.linear import (
    GRADIENT_MC,
    SAMPLED,
    Errors,
    Learner,
    Model,
    learn_episode,
    learn_step,
    root_pbe,
    root_ve,
    sweep,
)
from cartpole_q.rl.tabular import compilable

ENGINES = ("numba", "gymnasium")
EPISODE_CAP = 10_000
"""an episodic world without a time limit is cut (truncated) at this many steps"""
EPISODES_PER_CALL = 1_000
STEPS_PER_CALL = 100_000
SWEEPS_PER_CALL = 10_000
"""the most a compiled call runs before it returns (to see a stop, to report progress)"""


class Behaviour(NamedTuple):
    """The behaviour policy as the compiled draw takes it, with each action's ratio ``π / b``."""

    uniform: int
    """``n`` for ``random`` (one ``rng.integers(0, n)``), 0 for a list of probabilities"""
    cumulative: np.ndarray
    """float64 ``(n,)``: the running sums ``b(0) + ... + b(a)``"""
    last: int
    """the last action with ``b(a) > 0`` (when rounding leaves none above the draw)"""
    ratio: np.ndarray
    """float64 ``(n,)``: ``π(a) / b(a)`` (0 where ``b(a)`` is 0: never taken)"""


def make_behaviour(target: np.ndarray, behaviour: np.ndarray, uniform: bool) -> Behaviour:
    """The behaviour's draw and ratios from the two policies' probabilities per action."""
    n = behaviour.shape[0]
    cumulative = np.empty(n)
    running = 0.0
    for a in range(n):
        running = running + float(behaviour[a])
        cumulative[a] = running
    ratio = np.zeros(n)
    for a in range(n):
        if behaviour[a] > 0.0:
            ratio[a] = float(target[a]) / float(behaviour[a])
    last = int(np.flatnonzero(behaviour > 0.0)[-1])
    return Behaviour(n if uniform else 0, cumulative, last, ratio)


@compilable
def choose(behaviour: Any, rng: Any) -> int:
    """The behaviour's action: ``rng.integers(0, n)``, or one ``rng.random()`` against the sums."""
    if behaviour.uniform > 0:
        return int(rng.integers(0, behaviour.uniform))
    u = rng.random()
    for a in range(behaviour.cumulative.shape[0]):
        if u < behaviour.cumulative[a]:
            return a
    last: int = behaviour.last
    return last


def _play_episodes(
    learner: Any, behaviour: Any, params: Any, agent_rng: Any, env_rng: Any, episodes: int,
    cap: int, buffers: Any,
) -> int:  # fmt: skip
    """Up to ``episodes`` episodes on the table (compiled): reset, step to the end, learn.

    ``buffers`` is ``(states, rewards, returns)``, room for an episode of ``cap`` steps.
    Returns after the episode that brings the steps to :data:`STEPS_PER_CALL` (a call stays
    short when episodes are long): the number of episodes played.
    """
    states, rewards, returns = buffers
    steps = 0
    for episode in range(episodes):
        state = initial_state(params, env_rng)
        states[0] = state
        length = 0
        truncated = False
        while True:
            action = choose(behaviour, agent_rng)
            following, reward, terminated = table_step(state, action, env_rng, params)
            rewards[length] = reward
            length += 1
            states[length] = following
            if learner.code != GRADIENT_MC:
                learn_step(learner, state, behaviour.ratio[action], reward, following, terminated)
            state = following
            if terminated:
                break
            if length >= cap:
                truncated = True
                break
        if learner.code == GRADIENT_MC:
            learn_episode(learner, states, rewards, length, truncated, returns)
        steps += length
        if steps >= STEPS_PER_CALL:
            return episode + 1
    return episodes


def _play_steps(
    learner: Any, behaviour: Any, params: Any, agent_rng: Any, env_rng: Any, steps: int,
    position: Any,
) -> None:  # fmt: skip
    """``steps`` steps of a continuing world from ``position[0]`` (compiled); it is left there."""
    state = position[0]
    for _ in range(steps):
        action = choose(behaviour, agent_rng)
        following, reward, terminated = table_step(state, action, env_rng, params)
        learn_step(learner, state, behaviour.ratio[action], reward, following, terminated)
        state = following
    position[0] = state


def _first_state(params: Any, env_rng: Any) -> int:
    """The reset's draw of the start state (compiled)."""
    return initial_state(params, env_rng)


def _sweeps(learner: Any, model: Any, count: int) -> None:
    """``count`` sweeps of an expected algorithm (compiled)."""
    for _ in range(count):
        sweep(learner, model)


LOOP_NAMES = (
    "linear_play_episodes", "linear_play_steps", "linear_first_state", "linear_sweeps",
    "linear_choose", "linear_learn_step", "linear_learn_episode", "linear_root_ve",
    "linear_root_pbe",
)  # fmt: skip
"""the compiled functions, by their cache names"""
LOOPS = LoopSet(
    dict(zip(LOOP_NAMES, (
        _play_episodes, _play_steps, _first_state, _sweeps, choose, learn_step, learn_episode,
        root_ve, root_pbe,
    ), strict=True)),
    "compiling the linear methods' loops: once per machine and version, a few seconds...",
)  # fmt: skip
compiled = LOOPS
"""``compiled(name)``: the compiled function cached on disk under ``name``"""
compile_notice = LOOPS.notice
"""a sentence when the loops are not compiled yet (the first run), else ``None``"""


def run_generators(seed: int) -> tuple[np.random.Generator, int]:
    """A run's behaviour generator and the seed its world is first reset with."""
    agent_seq, env_seq = np.random.SeedSequence(seed).spawn(2)
    return (
        np.random.Generator(np.random.PCG64(agent_seq)),
        int(env_seq.generate_state(1, dtype=np.uint32)[0]),
    )


@dataclass(frozen=True)
class World:
    """What a run needs of its world: the table's arrays, its time limit, a maker for gymnasium."""

    params: tuple[np.ndarray, ...]
    """the table twin's arrays (:func:`~cartpole_q.families.tables.twin.table_params`)"""
    continuing: bool
    cap: int
    """the steps after which an episode is truncated (the time limit, or :data:`EPISODE_CAP`)"""
    make: Callable[[], Any]
    """``gymnasium.make`` of the world (the gymnasium engine)"""


@dataclass
class Records:
    """What a run recorded: the points, the weights and the errors at each."""

    at: list[int]
    weights: list[np.ndarray]
    errors: dict[str, list[float]]

    def arrays(self) -> dict[str, np.ndarray]:
        """As a run's arrays: ``at``, ``weights`` and one per error."""
        arrays = {
            "at": np.asarray(self.at, dtype=np.int64),
            "weights": np.asarray(self.weights, dtype=np.float64),
        }
        arrays.update({name: np.asarray(values) for name, values in self.errors.items()})
        return arrays


class Schedule(NamedTuple):
    """How long a run lasts, what it records and where it plays."""

    seed: int
    length: int
    """episodes, steps or sweeps"""
    record_every: int
    measures: tuple[str, ...]
    """the errors recorded: ``ve``, ``pbe``"""
    engine: str


def run(
    learner: Learner, behaviour: Behaviour, world: World, model: Model, errors: Errors,
    schedule: Schedule, should_stop: Callable[[], bool] = lambda: False,
    report: Callable[[int], None] = lambda n: None,
) -> Records | None:  # fmt: skip
    """Play one run of ``schedule.length`` episodes (steps, sweeps), recording as it says.

    Returns:
        The records, or ``None`` when ``should_stop`` ended the run early.
    """
    seed, count, record_every, measures, engine = schedule
    records = Records([], [], {name: [] for name in measures})

    def record(at: int) -> None:
        records.at.append(at)
        records.weights.append(learner.w.copy())
        for name in measures:
            value = (
                compiled("linear_root_ve")(learner, errors)
                if name == "ve"
                else compiled("linear_root_pbe")(learner, model, errors)
            )
            records.errors[name].append(float(value))

    record(0)
    if learner.code >= len(SAMPLED):
        chunk = _sweep_chunk(learner, model)
    elif engine == "numba":
        chunk = _numba_chunk(learner, behaviour, world, seed)
    else:
        chunk = _gymnasium_chunk(learner, behaviour, world, seed)
    most = _most_per_call(learner, world)
    done = 0
    while done < count:
        target = min(done + record_every, count)
        while done < target:  # a long stretch between records still returns to Python often
            if should_stop():
                return None
            done += chunk(min(most, target - done))
            report(done)
        record(done)
    return records


def _most_per_call(learner: Learner, world: World) -> int:
    """Episodes, steps or sweeps per compiled call: a few hundredths of a second each."""
    if learner.code >= len(SAMPLED):
        return SWEEPS_PER_CALL
    return STEPS_PER_CALL if world.continuing else EPISODES_PER_CALL


Chunk = Callable[[int], int]
"""plays up to ``size`` episodes, steps or sweeps; returns how many it played (fewer
episodes only, once they took :data:`STEPS_PER_CALL` steps)"""


def _sweep_chunk(learner: Learner, model: Model) -> Chunk:
    """Sweeps of an expected algorithm."""
    sweeps = compiled("linear_sweeps")

    def chunk(size: int) -> int:
        sweeps(learner, model, size)
        return size

    return chunk


def _numba_chunk(learner: Learner, behaviour: Behaviour, world: World, seed: int) -> Chunk:
    """Episodes or steps on the compiled table."""
    agent_rng, env_seed = run_generators(seed)
    env_rng = np.random.Generator(np.random.PCG64(np.random.SeedSequence(env_seed)))
    if world.continuing:
        position = np.array([compiled("linear_first_state")(world.params, env_rng)])
        steps = compiled("linear_play_steps")

        def step_chunk(size: int) -> int:
            steps(learner, behaviour, world.params, agent_rng, env_rng, size, position)
            return size

        return step_chunk
    buffers = (np.zeros(world.cap + 1, dtype=np.int64), np.zeros(world.cap), np.zeros(world.cap))
    episodes = compiled("linear_play_episodes")
    return lambda size: int(
        episodes(learner, behaviour, world.params, agent_rng, env_rng, size, world.cap, buffers)
    )


def _gymnasium_chunk(learner: Learner, behaviour: Behaviour, world: World, seed: int) -> Chunk:
    """Episodes or steps on ``gymnasium.make``: the loop in Python, the rules compiled."""
    agent_rng, env_seed = run_generators(seed)
    env = world.make()
    choose_action = compiled("linear_choose")
    step_update = compiled("linear_learn_step")
    episode_update = compiled("linear_learn_episode")
    ratio = behaviour.ratio
    seeds = [env_seed]

    def reset() -> int:
        seed_now = seeds.pop() if seeds else None
        env.reset(seed=seed_now)
        return int(env.unwrapped.s)

    if world.continuing:
        position = [reset()]

        def steps(size: int) -> int:
            state = position[0]
            for _ in range(size):
                action = int(choose_action(behaviour, agent_rng))
                _, reward, terminated, _, _ = env.step(action)
                following = int(env.unwrapped.s)
                step_update(
                    learner, state, ratio[action], float(reward), following, bool(terminated)
                )
                state = following
            position[0] = state
            return size

        return steps
    returns = np.zeros(world.cap)

    def episodes(size: int) -> int:
        played = 0
        for episode in range(size):
            state = reset()
            states, rewards = [state], []
            truncated = False
            while True:
                action = int(choose_action(behaviour, agent_rng))
                _, reward, terminated, cut, _ = env.step(action)
                following = int(env.unwrapped.s)
                states.append(following)
                rewards.append(float(reward))
                if learner.code != GRADIENT_MC:
                    step_update(
                        learner, state, ratio[action], float(reward), following, bool(terminated)
                    )
                state = following
                if terminated:
                    break
                if cut or len(rewards) >= world.cap:
                    truncated = True
                    break
            if learner.code == GRADIENT_MC:
                episode_update(
                    learner, np.asarray(states, dtype=np.int64), np.asarray(rewards), len(rewards),
                    truncated, returns,
                )  # fmt: skip
            played += len(rewards)
            if played >= STEPS_PER_CALL:
                return episode + 1
        return size

    return episodes


def warm_up_world(world_id: str, continuing: bool, cap: int) -> tuple[World, int, int]:
    """A registered table world as the loops take it, for a warm-up: ``(world, N, n)``."""
    import gymnasium

    from cartpole_q.families.tables.twin import table_params

    env = gymnasium.make(world_id)
    table: Any = env.unwrapped
    params = table_params(table, aggregated=True)
    assert not isinstance(params, str)
    world = World(params, continuing, cap, functools.partial(gymnasium.make, world_id))
    sizes = len(table.P), int(table.action_space.n)
    env.close()
    return world, sizes[0], sizes[1]


def warm_up() -> None:
    """Compile (or load from the cache) every loop: tiny runs of each kind, on both engines.

    The loops take every layer, world and algorithm alike (their argument types do not
    change), so these runs compile what every linear study plays (``cartpole-q compile
    --all``): Baird's world with its declared features (sampled and expected, both errors)
    and the 5-state walk with its table (an episodic gradient MC run).
    """
    import gymnasium

    from cartpole_q.families.tables.twin import table_params
    from cartpole_q.rl.features import declared_rows, table_rows
    from cartpole_q.rl.linear import new_learner
    from cartpole_q.rl.mdp import FiniteMDP

    for world_id, continuing, algorithms in (
        ("cartpole_q/Baird-v0", True, ("tdc", "expected_tdc")),
        ("cartpole_q/RandomWalk5-v0", False, ("gradient_mc",)),
    ):
        env = gymnasium.make(world_id)
        table: Any = env.unwrapped
        params = table_params(table, aggregated=True)
        assert not isinstance(params, str)
        n_states, n_actions = len(table.P), int(table.action_space.n)
        rows = (
            declared_rows(table.features_of_state)
            if continuing
            else table_rows(np.arange(n_states), n_states)
        )
        model = FiniteMDP.from_transitions(table.P, table.initial_state_distrib, n_actions)
        first = np.searchsorted(model.state, np.arange(n_states + 1)).astype(np.int64)
        uniform = np.full(n_actions, 1.0 / n_actions)
        mu = np.full(n_states, 1.0 / n_states)
        world = World(params, continuing, 10, functools.partial(gymnasium.make, world_id))
        errors = Errors(
            np.arange(n_states, dtype=np.int64), mu, np.zeros(n_states), np.eye(rows.weights),
            np.zeros(n_states),
        )  # fmt: skip
        for algorithm in algorithms:
            for engine in ENGINES:
                learner = new_learner(
                    algorithm, 0.1, 0.1, 0.9, 1.0, rows.index, rows.value, np.zeros(rows.weights)
                )
                model_arrays = Model(
                    first, model.action, model.probability, model.next_state, model.reward,
                    model.terminated, uniform, mu, mu * 1.0, np.zeros(n_states),
                )  # fmt: skip
                run(
                    learner, make_behaviour(uniform, uniform, True), world, model_arrays, errors,
                    Schedule(0, 1, 1, ("ve", "pbe"), engine),
                )  # fmt: skip
        env.close()
