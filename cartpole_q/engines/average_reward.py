"""Playing an average-reward run: steps of a continuing world, the agent updated after each.

Two engines play a run with the same compiled updates (:mod:`cartpole_q.rl.average_reward`)
and the same draws, so their records agree byte for byte (``tests/test_average_reward.py``):

- ``numba``: compiled steps over the world's table (the table twin), up to
  :data:`~cartpole_q.engines.linear.STEPS_PER_CALL` steps per call;
- ``gymnasium``: a Python loop over ``gymnasium.make(world)``, the draws and the updates
  compiled.

Between calls the run's ``should_stop`` is asked, so a stop is seen within a fraction of a
second. **Seeds** as a linear run's (:func:`~cartpole_q.engines.linear.run_generators`): the
world is reset once, with the run's world seed, and the first action is drawn on the
reset state; nothing ends after that.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, NamedTuple

import numpy as np

from cartpole_q.engines.compile import LoopSet
from cartpole_q.engines.linear import STEPS_PER_CALL, World, run_generators
from cartpole_q.families.tables.twin import initial_state, table_step
from cartpole_q.rl.average_reward import Agent, choose, learn_step

ENGINES = ("numba", "gymnasium")


def _play_steps(
    agent: Any, params: Any, agent_rng: Any, env_rng: Any, steps: int, position: Any
) -> float:
    """``steps`` steps from ``position = [state, action]`` (compiled), left there after.

    Returns the rewards of the steps summed in order from 0.0.
    """
    state, action = position[0], position[1]
    total = 0.0
    for _ in range(steps):
        following, reward, _ = table_step(state, action, env_rng, params)
        next_action = choose(agent, following, agent_rng)
        learn_step(agent, state, action, reward, following, next_action)
        total = total + reward
        state, action = following, next_action
    position[0], position[1] = state, action
    return total


def _start(agent: Any, params: Any, agent_rng: Any, env_rng: Any, position: Any) -> None:
    """The reset's draw of the start state, then the first action on it (compiled)."""
    position[0] = initial_state(params, env_rng)
    position[1] = choose(agent, position[0], agent_rng)


LOOP_NAMES = (
    "average_reward_play_steps", "average_reward_start", "average_reward_choose",
    "average_reward_learn_step",
)  # fmt: skip
"""the compiled functions, by their cache names"""
LOOPS = LoopSet(
    dict(zip(LOOP_NAMES, (_play_steps, _start, choose, learn_step), strict=True)),
    "compiling the average-reward loops: once per machine and version, a few seconds...",
)
compiled = LOOPS
"""``compiled(name)``: the compiled function cached on disk under ``name``"""
compile_notice = LOOPS.notice
"""a sentence when the loops are not compiled yet (the first run), else ``None``"""


class Records(NamedTuple):
    """A run's records at every ``record_every`` steps: ``R̄`` and the reward per step since the last."""

    at: np.ndarray
    """int64: the steps taken at each record"""
    r_bar: np.ndarray
    """float64: ``R̄`` then"""
    rate: np.ndarray
    """float64: the rewards of the steps since the previous record, summed in order from
    0.0, divided by their count"""


def run(
    agent: Agent, world: World, seed: int, steps: int, record_every: int, engine: str,
    should_stop: Callable[[], bool] = lambda: False,
    report: Callable[[int], None] = lambda n: None,
) -> Records | None:  # fmt: skip
    """Play ``steps`` steps of one run, recording every ``record_every``; ``None`` when stopped."""
    chunk = (_numba_chunk if engine == "numba" else _gymnasium_chunk)(agent, world, seed)
    points = -(-steps // record_every)
    at = np.zeros(points, dtype=np.int64)
    r_bar = np.zeros(points)
    rate = np.zeros(points)
    done = 0
    for point in range(points):
        size = min(record_every, steps - done)
        total = 0.0
        taken = 0
        while taken < size:
            if should_stop():
                return None
            part = min(STEPS_PER_CALL, size - taken)
            total = total + chunk(part)
            taken += part
            report(done + taken)
        done += size
        at[point], r_bar[point], rate[point] = done, agent.r_bar[0], total / size
    return Records(at, r_bar, rate)


Chunk = Callable[[int], float]
"""plays that many steps; returns their rewards summed in order from 0.0"""


def _numba_chunk(agent: Agent, world: World, seed: int) -> Chunk:
    """Steps on the compiled table."""
    agent_rng, env_seed = run_generators(seed)
    env_rng = np.random.Generator(np.random.PCG64(np.random.SeedSequence(env_seed)))
    position = np.zeros(2, dtype=np.int64)
    compiled("average_reward_start")(agent, world.params, agent_rng, env_rng, position)
    play = compiled("average_reward_play_steps")
    return lambda size: float(play(agent, world.params, agent_rng, env_rng, size, position))


def _gymnasium_chunk(agent: Agent, world: World, seed: int) -> Chunk:
    """Steps on ``gymnasium.make``: the loop in Python, the draws and updates compiled."""
    agent_rng, env_seed = run_generators(seed)
    env = world.make()
    choose_action = compiled("average_reward_choose")
    update = compiled("average_reward_learn_step")
    env.reset(seed=env_seed)
    state = int(env.unwrapped.s)
    position = [state, int(choose_action(agent, state, agent_rng))]

    def steps(size: int) -> float:
        state, action = position
        total = 0.0
        for _ in range(size):
            _, reward, _, _, _ = env.step(action)
            following = int(env.unwrapped.s)
            next_action = int(choose_action(agent, following, agent_rng))
            update(agent, state, action, float(reward), following, next_action)
            total = total + float(reward)
            state, action = following, next_action
        position[:] = [state, action]
        return total

    return steps


def warm_up() -> None:
    """Compile (or load from the cache) every loop: a tiny run on each engine.

    The loops take every world and layer alike (their argument types do not change), so
    this compiles what every average-reward study plays (``cartpole-q compile --all``).
    """
    from cartpole_q.engines.linear import warm_up_world
    from cartpole_q.rl.average_reward import new_agent

    world, n_states, n_actions = warm_up_world("cartpole_q/AccessControl-v0", True, 0)
    rows = (
        np.arange(n_states * n_actions, dtype=np.int64).reshape(-1, 1),
        np.ones((n_states * n_actions, 1)),
    )
    for engine in ENGINES:
        agent = new_agent(
            "differential_sarsa", 0.01, 0.01, 0.1, n_actions, rows,
            np.zeros(n_states * n_actions), 0.0, n_states,
        )  # fmt: skip
        run(agent, world, 0, 4, 2, engine)
