"""The MountainCar and Acrobot twins against real Gymnasium, by exact equality.

Every trajectory is played by the twin inside a compiled loop (as the engine runs it) and
then replayed in ``gymnasium.make(env_id)``: after every reset and every step the float64
state, the float32 observation's bytes, the reward and the flags must be identical.
"""

from __future__ import annotations

import time
from types import ModuleType
from typing import Any

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils import seeding
from numba import njit

from cartpole_q.families.acrobot import twin as acrobot
from cartpole_q.families.mountaincar import twin as mountaincar

# For each twin: the observation index a swing-up heuristic follows (push with the car's
# velocity, or with the second link's), which makes episodes reach the goal.
HEURISTIC_INDEX = {mountaincar: 1, acrobot: 5}


def _ids(twin):  # type: ignore[no-untyped-def]
    """The ids a twin module reproduces, as its profile names them."""
    from cartpole_q.families import all_profiles

    return next(p.ids for p in all_profiles() if callable(p.twin) and p.twin() is twin)


def _make_recorder(twin: ModuleType) -> Any:
    """A compiled loop that plays ``twin`` and records everything Gymnasium must repeat."""
    reset, step = twin.reset, twin.step
    state_size, observation_size = twin.STATE_SIZE, twin.OBSERVATION_SIZE
    heuristic_index = HEURISTIC_INDEX[twin]

    @njit(cache=False)
    def record(rng, params, max_steps, random_actions, heuristic):
        steps = random_actions.size
        states = np.empty((steps + 1, state_size))
        observations = np.empty((steps + 1, observation_size), dtype=np.float32)
        reset_states = np.empty((steps + 1, state_size))
        reset_observations = np.empty((steps + 1, observation_size), dtype=np.float32)
        actions = np.empty(steps, dtype=np.int64)
        rewards = np.empty(steps)
        terminated = np.zeros(steps, dtype=np.bool_)
        truncated = np.zeros(steps, dtype=np.bool_)
        state = np.empty(state_size)
        observation = np.empty(observation_size, dtype=np.float32)
        reset(state, observation, rng, params)
        states[0], observations[0] = state, observation
        length = 0
        for t in range(steps):
            if heuristic[t]:
                action = 2 if observation[heuristic_index] >= 0 else 0
            else:
                action = random_actions[t]
            actions[t] = action
            rewards[t], terminated[t] = step(state, action, observation, rng, params)
            states[t + 1], observations[t + 1] = state, observation
            length += 1
            truncated[t] = length >= max_steps
            if terminated[t] or truncated[t]:
                reset(state, observation, rng, params)
                reset_states[t + 1], reset_observations[t + 1] = state, observation
                length = 0
        return (
            states,
            observations,
            reset_states,
            reset_observations,
            actions,
            rewards,
            terminated,
            truncated,
        )

    return record


RECORDERS = {twin: _make_recorder(twin) for twin in (mountaincar, acrobot)}


def _gym_state(env: gym.Env) -> Any:
    """The environment's ``state`` attribute (not part of ``gym.Env``'s interface)."""
    return vars(env.unwrapped)["state"]


def _same_state(twin_state: np.ndarray, gym_state: Any) -> bool:
    """Equal to the bit (signed zeros included); Gymnasium's state may be a tuple or float32."""
    return twin_state.tobytes() == np.asarray(gym_state, dtype=np.float64).tobytes()


def _compare(
    twin: ModuleType, env_kwargs: dict, seed: int, steps: int, heuristic_share: float
) -> dict[str, int]:
    """Play the twin, replay its actions in Gymnasium, compare; return what happened."""
    params = twin.twin_params(env_kwargs)
    assert isinstance(params, tuple)
    (env_id,) = _ids(twin)
    env = gym.make(env_id, **env_kwargs)
    max_steps = env_kwargs.get("max_episode_steps", twin.MAX_EPISODE_STEPS)
    assert env.spec is not None and env.spec.max_episode_steps == max_steps
    choices = np.random.default_rng(seed + 1000)
    random_actions = choices.integers(0, twin.N_ACTIONS, size=steps)
    heuristic = choices.random(steps) < heuristic_share
    rng = seeding.np_random(seed)[0]
    record = RECORDERS[twin](rng, params, max_steps, random_actions, heuristic)
    states, observations, reset_states, reset_observations = record[:4]
    actions, rewards, terminated, truncated = record[4:]

    gym_observation, _ = env.reset(seed=seed)
    assert _same_state(states[0], _gym_state(env)), "state differs at the first reset"
    assert observations[0].tobytes() == gym_observation.tobytes(), "observation at reset"
    episodes = 0
    for t in range(steps):
        gym_observation, gym_reward, gym_terminated, gym_truncated, _ = env.step(int(actions[t]))
        assert _same_state(states[t + 1], _gym_state(env)), f"state differs at step {t}"
        assert observations[t + 1].tobytes() == gym_observation.tobytes(), (
            f"observation differs at step {t}"
        )
        assert (rewards[t], terminated[t], truncated[t]) == (
            gym_reward,
            gym_terminated,
            gym_truncated,
        ), f"reward or flags differ at step {t}"
        if gym_terminated or gym_truncated:
            episodes += 1
            gym_observation, _ = env.reset()
            assert _same_state(reset_states[t + 1], _gym_state(env)), (
                f"state differs at the reset after step {t}"
            )
            assert reset_observations[t + 1].tobytes() == gym_observation.tobytes(), (
                f"observation differs at the reset after step {t}"
            )
    # Both generators drew the same numbers: they are in the same state.
    assert rng.bit_generator.state == env.unwrapped.np_random.bit_generator.state
    summary = {"episodes": episodes, "terminations": int(terminated.sum())}
    if twin is acrobot:  # angle jumps of more than pi within an episode are wraps
        in_episode = ~(terminated | truncated)[:-1]
        summary["wraps"] = int((np.abs(np.diff(states[1:, 0]))[in_episode] > np.pi).sum())
        summary["velocity_bounds_hit"] = int(
            (np.abs(states[:, 2]) == acrobot.MAX_VEL_1).sum()
            + (np.abs(states[:, 3]) == acrobot.MAX_VEL_2).sum()
        )
    else:
        summary["left_wall_hits"] = int((states[:, 0] == mountaincar.MIN_POSITION).sum())
    print(f"{env_id} {env_kwargs} seed {seed}: {steps} steps, {summary}")
    return summary


@pytest.mark.parametrize("seed", [0, 7, 123])
@pytest.mark.parametrize(
    ("env_kwargs", "heuristic_share"),
    [({}, 0.0), ({}, 0.8), ({"goal_velocity": 0.02}, 0.9), ({"max_episode_steps": 400}, 0.7)],
)
def test_mountaincar_twin_is_exact(env_kwargs: dict, heuristic_share: float, seed: int) -> None:
    run = _compare(mountaincar, env_kwargs, seed, 10_000, heuristic_share)
    assert run["episodes"] >= 10_000 // 400
    if heuristic_share > 0:
        assert run["terminations"] >= 10, "episodes should reach the goal"
        assert run["left_wall_hits"] > 0, "the left wall was never hit"


# One worker for all: they compile the same recorder, once.
@pytest.mark.xdist_group("acrobot-recorder")
@pytest.mark.parametrize("seed", [0, 7, 123])
@pytest.mark.parametrize("heuristic_share", [0.0, 0.7])
def test_acrobot_twin_is_exact(heuristic_share: float, seed: int) -> None:
    run = _compare(acrobot, {}, seed, 10_000, heuristic_share)
    assert run["episodes"] >= 10_000 // 500
    if heuristic_share > 0:
        assert run["terminations"] >= 10, "episodes should swing up"
        assert run["wraps"] > 0, "the links never turned over (wrap was not exercised)"


@pytest.mark.parametrize("twin", [mountaincar, acrobot], ids=lambda twin: _ids(twin)[0])
def test_twin_called_from_python_is_exact(twin: ModuleType) -> None:
    # The same functions, dispatched one call at a time (not inlined in a loop).
    (env_id,) = _ids(twin)
    env = gym.make(env_id)
    params = twin.twin_params({})
    assert isinstance(params, tuple)
    rng = seeding.np_random(5)[0]
    state = np.empty(twin.STATE_SIZE)
    observation = np.empty(twin.OBSERVATION_SIZE, dtype=np.float32)
    actions = np.random.default_rng(6).integers(0, twin.N_ACTIONS, size=10_000)
    gym_observation, _ = env.reset(seed=5)
    twin.reset(state, observation, rng, params)
    length = 0
    for t, action in enumerate(actions):
        assert _same_state(state, _gym_state(env)), f"state differs before step {t}"
        assert observation.tobytes() == gym_observation.tobytes(), f"observation, step {t}"
        gym_observation, gym_reward, gym_terminated, gym_truncated, _ = env.step(int(action))
        reward, terminated = twin.step(state, int(action), observation, rng, params)
        length += 1
        truncated = length >= twin.MAX_EPISODE_STEPS
        assert (reward, terminated, truncated) == (gym_reward, gym_terminated, gym_truncated), t
        if terminated or truncated:
            gym_observation, _ = env.reset()
            twin.reset(state, observation, rng, params)
            length = 0


def test_acrobot_velocity_bounds_and_wraps_are_exact() -> None:
    # Random play never reaches the velocity bounds: start from states that do.
    env = gym.make("Acrobot-v1").unwrapped
    env.reset(seed=0)
    params = acrobot.twin_params({})
    assert isinstance(params, tuple)
    starts = np.random.default_rng(2).uniform(-1.0, 1.0, size=(300, 4)) * [
        np.pi,
        np.pi,
        acrobot.MAX_VEL_1 * 1.2,
        acrobot.MAX_VEL_2 * 1.2,
    ]
    rng = np.random.default_rng(3)  # the step draws nothing from it
    clipped = 0
    for start in starts:
        for action in range(acrobot.N_ACTIONS):
            vars(env)["state"] = start.copy()
            state, observation = start.copy(), np.empty(6, dtype=np.float32)
            for _ in range(3):
                gym_observation, gym_reward, gym_terminated, _, _ = env.step(action)
                reward, terminated = acrobot.step(state, action, observation, rng, params)
                assert _same_state(state, _gym_state(env))
                assert observation.tobytes() == gym_observation.tobytes()
                assert (reward, terminated) == (gym_reward, gym_terminated)
                clipped += abs(state[2]) == acrobot.MAX_VEL_1 or abs(state[3]) == acrobot.MAX_VEL_2
    assert clipped > 0


@njit(cache=False)
def _numpy_trig_f32(values):
    cosines = np.empty_like(values)
    sines = np.empty_like(values)
    for i in range(values.size):
        cosines[i] = acrobot.numpy_cos_f32(values[i])
        sines[i] = acrobot.numpy_sin_f32(values[i])
    return cosines, sines


@njit(cache=False)
def _libm_squares(values):
    squares = np.empty_like(values)
    for i in range(values.size):
        squares[i] = acrobot.libm_pow(values[i], 2.0)
    return squares


def test_float32_trigonometry_is_numpys() -> None:
    # Acrobot's reset observation is NumPy's float32 cos/sin of the float32 start state.
    rng = np.random.default_rng(0)
    values = np.concatenate(
        [
            rng.uniform(-0.1, 0.1, 1_000_000),  # the reset range
            rng.uniform(-100.0, 100.0, 200_000),  # other quadrants, rounding ties
            rng.uniform(-2e5, 2e5, 200_000),  # beyond NumPy's vectorised range too
        ]
    ).astype(np.float32)
    cosines, sines = _numpy_trig_f32(values)
    assert cosines.tobytes() == np.cos(values).tobytes()
    assert sines.tobytes() == np.sin(values).tobytes()
    # ... which is not simply the float64 result rounded: the test above means something.
    assert (np.cos(values.astype(np.float64)).astype(np.float32) != np.cos(values)).any()


def test_squares_are_libm_pow() -> None:
    # Gymnasium's x**2 is libm's pow(x, 2.0), which is sometimes one ulp from x * x.
    values = np.random.default_rng(1).normal(0.0, 10.0, 100_000)
    expected = np.array([np.float64(value) ** 2 for value in values])
    assert _libm_squares(values).tobytes() == expected.tobytes()
    assert (values * values != expected).any()


def test_twin_params() -> None:
    assert mountaincar.twin_params({}) == (0.0,)
    assert mountaincar.twin_params({"goal_velocity": -0.01, "max_episode_steps": 300}) == (-0.01,)
    assert mountaincar.twin_params({"goal_velocity": 1}) == (1.0,)
    assert isinstance(mountaincar.twin_params({"goal_velocity": 1})[0], float)  # type: ignore[index]
    assert acrobot.twin_params({"max_episode_steps": 100}) == ()
    refused = mountaincar.twin_params({"goal_velocity": 0.0, "render_mode": "rgb_array"})
    assert isinstance(refused, str) and "'render_mode'" in refused
    assert "'goal_velocity'" in str(mountaincar.twin_params({"goal_velocity": "fast"}))
    assert "'goal_velocity'" in str(mountaincar.twin_params({"goal_velocity": True}))
    assert "'goal_velocity'" in str(mountaincar.twin_params({"goal_velocity": float("nan")}))
    assert "'render_mode'" in str(acrobot.twin_params({"render_mode": "human"}))
    assert "'goal_velocity'" in str(acrobot.twin_params({"goal_velocity": 0.0}))
    for twin in (mountaincar, acrobot):
        (env_id,) = _ids(twin)
        spec = gym.spec(env_id)
        assert spec.max_episode_steps == twin.MAX_EPISODE_STEPS
        env = gym.make(env_id)
        assert env.action_space.n == twin.N_ACTIONS  # type: ignore[attr-defined]
        assert env.observation_space.shape == (twin.OBSERVATION_SIZE,)
    assert gym.make("Acrobot-v1").unwrapped.torque_noise_max == 0  # type: ignore[attr-defined]


def _make_random_loop(twin: ModuleType) -> Any:
    reset, step = twin.reset, twin.step
    state_size, observation_size = twin.STATE_SIZE, twin.OBSERVATION_SIZE
    n_actions, max_steps = twin.N_ACTIONS, twin.MAX_EPISODE_STEPS

    @njit(cache=False)
    def run(rng, params, steps):
        state = np.empty(state_size)
        observation = np.empty(observation_size, dtype=np.float32)
        reset(state, observation, rng, params)
        total, length = 0.0, 0
        for _ in range(steps):
            reward, terminated = step(state, rng.integers(0, n_actions), observation, rng, params)
            total += reward
            length += 1
            if terminated or length >= max_steps:
                reset(state, observation, rng, params)
                length = 0
        return total

    return run


@pytest.mark.parametrize(
    ("twin", "steps"),
    [(mountaincar, 2_000_000), (acrobot, 500_000)],
    ids=["MountainCar", "Acrobot"],
)
def test_report_throughput(twin: ModuleType, steps: int) -> None:
    # Printed for the record (pytest -s), not asserted: the machine is shared.
    run = _make_random_loop(twin)
    params = twin.twin_params({})
    run(np.random.default_rng(0), params, 10)  # compile
    started = time.perf_counter()
    run(np.random.default_rng(0), params, steps)
    elapsed = time.perf_counter() - started
    print(f"{_ids(twin)[0]} twin: {steps / elapsed:,.0f} steps/s (random actions, one thread)")
