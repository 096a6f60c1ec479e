"""The puddle world (Figure 12.14): its rules, and its twin against it by exact equality.

The twin plays inside a compiled loop, as the engine runs it; the same actions are then
replayed in ``gymnasium.make``: after every reset and step the float64 state, the float32
observation, the reward and the flags must be identical, and both generators end alike.
"""

from __future__ import annotations

import math
import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils import seeding
from gymnasium.utils.env_checker import check_env
from numba import njit

from cartpole_q.families.puddle import PUDDLE_TIME_LIMIT
from cartpole_q.families.puddle import twin as puddle
from cartpole_q.families.puddle.world import puddle_cost

ENV_ID = "cartpole_q/PuddleWorld-v0"
UP, DOWN, LEFT, RIGHT = range(4)


@njit(cache=False)
def _record(rng, max_steps, actions):  # type: ignore[no-untyped-def]
    steps = actions.size
    states = np.empty((steps + 1, 2))
    observations = np.empty((steps + 1, 2), dtype=np.float32)
    resets = np.full((steps + 1, 2), np.nan)
    rewards = np.empty(steps)
    terminated = np.zeros(steps, dtype=np.bool_)
    truncated = np.zeros(steps, dtype=np.bool_)
    state = np.empty(2)
    observation = np.empty(2, dtype=np.float32)
    params = ()
    puddle.reset(state, observation, rng, params)
    states[0], observations[0] = state, observation
    length = 0
    for t in range(steps):
        rewards[t], terminated[t] = puddle.step(state, actions[t], observation, rng, params)
        states[t + 1], observations[t + 1] = state, observation
        length += 1
        truncated[t] = length >= max_steps
        if terminated[t] or truncated[t]:
            puddle.reset(state, observation, rng, params)
            resets[t + 1] = state
            length = 0
    return states, observations, resets, rewards, terminated, truncated


@pytest.mark.parametrize("seed", [0, 11])
def test_the_twin_is_the_world_step_by_step(seed: int) -> None:
    """Random moves with a pull to the upper right: puddles, walls and goals all met."""
    steps = 20_000
    choices = np.random.default_rng(seed + 1000)
    actions = np.where(
        choices.random(steps) < 0.5,
        choices.integers(0, 4, steps),
        np.where(choices.random(steps) < 0.5, UP, RIGHT),
    ).astype(np.int64)
    rng = seeding.np_random(seed)[0]
    states, observations, resets, rewards, terminated, truncated = _record(
        rng, PUDDLE_TIME_LIMIT, actions
    )
    env = gym.make(ENV_ID)
    observation, _ = env.reset(seed=seed)
    assert env.unwrapped.state.tobytes() == states[0].tobytes()
    assert observation.tobytes() == observations[0].tobytes()
    for t in range(steps):
        observation, reward, done, cut, _ = env.step(int(actions[t]))
        assert env.unwrapped.state.tobytes() == states[t + 1].tobytes(), t
        assert observation.tobytes() == observations[t + 1].tobytes(), t
        assert (reward, done, cut) == (rewards[t], terminated[t], truncated[t]), t
        if done or cut:
            env.reset()
            assert env.unwrapped.state.tobytes() == resets[t + 1].tobytes(), t
    assert rng.bit_generator.state == env.unwrapped.np_random.bit_generator.state
    # What the comparison covered: goals, the puddles (rewards below -1), the walls.
    assert terminated.sum() > 20
    assert (rewards < -1.0).sum() > 100 and rewards.min() < -30.0
    assert (states == 0.0).any() and (states == 1.0).any()


def test_the_world_passes_gymnasiums_checker_and_starts_off_the_goal() -> None:
    env = gym.make(ENV_ID)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env.unwrapped)
    assert env.spec is not None and env.spec.max_episode_steps == PUDDLE_TIME_LIMIT
    starts = np.array([env.reset(seed=seed)[0] for seed in range(2_000)], dtype=np.float64)
    assert (starts.sum(axis=1) < 1.9).all() and starts.min() >= 0.0 and starts.max() <= 1.0


@pytest.mark.parametrize(
    ("x", "y", "cost"),
    [
        (0.3, 0.75, -40.0),  # on the first segment: the full depth, 400 * 0.1
        (0.45, 0.6, -40.0),  # on the second
        (0.45, 0.75, -80.0),  # on both: the two puddles add up
        (0.0, 0.75, -0.0),  # 0.1 left of the first segment's end: on the edge, no cost
        (0.3, 0.7, -400.0 * (0.1 - (0.75 - 0.7))),
        (0.5, 0.85, -400.0 * (0.1 - math.sqrt(0.05**2 + 0.05**2))),  # beyond both ends
        (0.9, 0.9, 0.0),
    ],
)
def test_the_puddles_cost_400_times_the_depth(x: float, y: float, cost: float) -> None:
    assert puddle_cost(x, y) == pytest.approx(cost, abs=1e-12)


def test_a_step_moves_0_05_with_noise_and_stops_at_the_walls() -> None:
    env = gym.make(ENV_ID)
    env.reset(seed=3)
    moved = []
    for _ in range(400):
        env.unwrapped.state[:] = (0.5, 0.2)
        env.step(RIGHT)
        moved.append(env.unwrapped.state - (0.5, 0.2))
    steps = np.array(moved)
    assert abs(steps[:, 0].mean() - 0.05) < 0.002 and abs(steps[:, 1].mean()) < 0.002
    assert 0.008 < steps[:, 0].std() < 0.012 and 0.008 < steps[:, 1].std() < 0.012
    env.unwrapped.state[:] = (0.99, 0.5)
    env.step(RIGHT)  # 0.99 + 0.05 + noise, beyond 1 by 4 standard deviations
    assert env.unwrapped.state[0] == 1.0
    env.unwrapped.state[:] = (0.5, 0.001)
    env.step(DOWN)
    assert env.unwrapped.state[1] == 0.0
