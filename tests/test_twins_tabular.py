"""The tabular twins (FrozenLake, Taxi, CliffWalking, Blackjack) against real Gymnasium.

Gymnasium's toy-text worlds draw from ``env.np_random``: ``random()`` for every step and
reset of a world that moves by its transition table, ``choice`` of a list (which NumPy
draws as ``integers(0, len)``) for Blackjack's cards and Taxi's fickle passenger. The twins
make those draws in compiled code from the same generator. Here:

- numba's ``Generator.random`` and ``Generator.integers`` equal NumPy's ``random`` and
  ``choice``, draw for draw, with the same generator state after;
- each twin and ``gymnasium.make`` are stepped side by side for 10,000 steps and more
  across resets, with random and purposeful actions, in several settings and seeds: the
  observation, reward, terminated and truncated of every step are equal, and so is the
  generator's state after every reset and step;
- training is byte-identical on the two engines (the tables, visits, every metric, the
  periodic and final evaluations), for every algorithm on FrozenLake and for Q-learning and
  one multi-step method on each other world; ``engine: auto`` picks the twin.
"""

from __future__ import annotations

from collections import Counter
from typing import Any

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils import seeding
from numba import njit

from cartpole_q import load_config, train
from cartpole_q.engines import resolve_engine
from cartpole_q.envs.gym import inspect_env
from cartpole_q.envs.registry import TwinSettings, twin_settings
from cartpole_q.families.blackjack import twin as blackjack
from cartpole_q.families.tables import twin as transition_table
from cartpole_q.families.toy_text import taxi_twin as taxi
from cartpole_q.rl.mdp import FiniteMDP
from cartpole_q.rl.solvers import value_iteration
from cartpole_q.store.rundir import metrics_csv

CUSTOM_LAKE = ["SFFS", "FHFH", "FFFH", "HFSG"]
"""three start cells: the reset draws among them"""

# id, gymnasium.make arguments, the share of purposeful actions (the rest are random)
SETTINGS: dict[str, tuple[str, dict[str, Any], float]] = {
    "lake": ("FrozenLake-v1", {}, 0.5),
    "lake-not-slippery": ("FrozenLake-v1", {"is_slippery": False}, 0.5),
    "lake8x8": ("FrozenLake8x8-v1", {}, 0.7),
    "lake8x8-not-slippery-20": (
        "FrozenLake8x8-v1",
        {"is_slippery": False, "max_episode_steps": 20},
        0.7,
    ),
    "lake-custom": (
        "FrozenLake-v1",
        {"desc": CUSTOM_LAKE, "success_rate": 0.5, "reward_schedule": [2, -1, 0.25]},
        0.5,
    ),
    "taxi": ("Taxi-v4", {}, 0.8),
    "taxi-rainy": ("Taxi-v4", {"is_rainy": True}, 0.8),
    "taxi-fickle": ("Taxi-v4", {"fickle_passenger": True}, 0.9),
    "taxi-rainy-fickle": (
        "Taxi-v4",
        {
            "is_rainy": True,
            "rainy_probability": 0.6,
            "fickle_passenger": True,
            "fickle_probability": 0.7,
            "max_episode_steps": 25,
        },
        0.9,
    ),
    "cliff": ("CliffWalking-v1", {}, 0.8),
    "cliff-slippery": ("CliffWalkingSlippery-v1", {}, 0.8),
    "cliff-slippery-40": ("CliffWalking-v1", {"is_slippery": True, "max_episode_steps": 40}, 0.5),
    "blackjack": ("Blackjack-v1", {}, 0.7),
    "blackjack-no-sab": ("Blackjack-v1", {"sab": False}, 0.7),
    "blackjack-natural": ("Blackjack-v1", {"sab": False, "natural": True}, 0.7),
    "blackjack-sab-natural": ("Blackjack-v1", {"natural": True}, 0.7),
    # Sutton & Barto's Example 5.3: a uniformly random one of 200 states every episode
    "blackjack-es": ("cartpole_q/BlackjackES-v0", {}, 0.7),
    "blackjack-es-no-sab": ("cartpole_q/BlackjackES-v0", {"sab": False, "natural": True}, 0.7),
    # Sutton & Barto's worlds that play their table (cartpole_q/worlds/)
    "windy": ("cartpole_q/WindyGridworld-v0", {}, 0.5),
    "kings-stay": ("cartpole_q/KingsWindyGridworld-v0", {"stay": True}, 0.5),
    "windy-stochastic": ("cartpole_q/StochasticWindyGridworld-v0", {}, 0.5),
    "dyna-maze": ("cartpole_q/DynaMaze-v0", {"max_episode_steps": 30}, 0.5),
    "random-walk": ("cartpole_q/RandomWalk-v0", {}, 0.0),
    # Example 9.1's walk, its states observed as themselves and in groups (aggregated_table)
    "walk1000": ("cartpole_q/RandomWalk1000-v0", {}, 0.0),
    "walk1000-groups": (
        "cartpole_q/RandomWalk1000-v0",
        {"groups": 20, "max_episode_steps": 60},
        0.0,
    ),
}
STEPS = 10_000


@njit(cache=False)
def _numba_draws(rng: Any, kinds: np.ndarray) -> np.ndarray:
    out = np.empty(kinds.size)
    for i in range(kinds.size):
        out[i] = rng.random() if kinds[i] == 0 else rng.integers(0, kinds[i])
    return out


def test_numba_draws_what_numpy_draws_for_random_and_choice() -> None:
    """``random()`` and ``choice`` of a list of k: the only draws the twins make."""
    for seed in range(200):
        kinds = np.random.default_rng(seed + 500).choice([0, 2, 3, 4, 6, 13, 500], size=1000)
        numpy_generator = seeding.np_random(seed)[0]
        numba_generator = seeding.np_random(seed)[0]
        expected = [
            numpy_generator.random() if k == 0 else float(numpy_generator.choice(list(range(k))))
            for k in kinds
        ]
        drawn = _numba_draws(numba_generator, kinds.astype(np.int64))
        assert drawn.tolist() == expected, seed
        assert numba_generator.bit_generator.state == numpy_generator.bit_generator.state


def _purposeful_policy(env_id: str, kwargs: dict[str, Any]) -> Any:
    """An action for an observation that tends to end episodes (the goal, a drop-off, a stick)."""
    env = gym.make(env_id, **kwargs).unwrapped
    if "Blackjack" in env_id:
        return lambda observation: int(observation[0] < 17)
    n_actions = int(env.action_space.n)  # type: ignore[attr-defined]
    model = FiniteMDP.from_transitions(env.P, env.initial_state_distrib, n_actions)  # type: ignore[attr-defined]
    policy = value_iteration(model, 0.95, tolerance=1e-9).policy
    return lambda observation: int(policy[observation])


def _components(observation: Any) -> tuple[int, ...]:
    """A Discrete or Tuple observation as a tuple of Python integers."""
    if isinstance(observation, tuple):
        return tuple(int(value) for value in observation)
    return (int(observation),)


def _side_by_side(name: str, seed: int, steps: int) -> Counter[str]:
    """Step the twin and ``gymnasium.make`` with the same actions; assert every step equal.

    Returns:
        How often episodes ended each way, and what else happened (for the callers to
        check that the comparison exercised the world).
    """
    env_id, kwargs, share = SETTINGS[name]
    env = gym.make(env_id, **kwargs)
    assert env.spec is not None
    settings = twin_settings(env_id, kwargs, env.spec.max_episode_steps)
    assert isinstance(settings, TwinSettings), settings
    twin, params, limit = settings.twin, settings.params, settings.max_episode_steps
    policy = _purposeful_policy(env_id, kwargs)
    n_actions = int(env.action_space.n)  # type: ignore[attr-defined]
    choices = np.random.default_rng(seed + 1000)
    rng = seeding.np_random(seed)[0]
    state = np.zeros(twin.state_size, dtype=twin.state_dtype)
    observation = np.zeros(twin.observation_size, dtype=twin.observation_dtype)
    seen: Counter[str] = Counter()
    gym_observation, _ = env.reset(seed=seed)
    twin.reset(state, observation, rng, params)
    length = 0
    for t in range(steps):
        assert tuple(observation.tolist()) == _components(gym_observation), f"step {t}"
        assert rng.bit_generator.state == env.unwrapped.np_random.bit_generator.state, t
        if choices.random() < share:
            action = policy(gym_observation)
        else:
            action = int(choices.integers(0, n_actions))
        before = _components(gym_observation)
        gym_observation, gym_reward, gym_terminated, gym_truncated, _ = env.step(action)
        reward, terminated = twin.step(state, action, observation, rng, params)
        length += 1
        truncated = limit is not None and length >= limit
        assert (reward, terminated, truncated) == (gym_reward, gym_terminated, gym_truncated), t
        seen[f"reward {float(reward):g}"] += 1
        if env_id.startswith("Taxi") and before[0] % 4 != _components(gym_observation)[0] % 4:
            seen["new destination"] += 1
        if terminated or truncated:
            seen["terminated" if terminated else "truncated"] += 1
            gym_observation, _ = env.reset()
            twin.reset(state, observation, rng, params)
            if env_id.startswith(("FrozenLake", "cartpole_q/BlackjackES")):
                seen["start " + str(_components(gym_observation))] += 1
            length = 0
    assert tuple(observation.tolist()) == _components(gym_observation)
    assert rng.bit_generator.state == env.unwrapped.np_random.bit_generator.state
    return seen


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("name", sorted(SETTINGS))
def test_twin_steps_as_gymnasium_does(name: str, seed: int) -> None:
    seen = _side_by_side(name, seed, STEPS)
    assert seen["terminated"] + seen["truncated"] >= 30, seen  # many resets
    env_id, kwargs, _ = SETTINGS[name]
    if "max_episode_steps" in kwargs:
        assert seen["truncated"] > 0, seen
    if env_id.startswith("FrozenLake") and name != "lake-custom":
        assert seen["terminated"] > 0 and seen["reward 1"] > 0, seen  # the goal, reached
    if name == "lake-custom":  # the reset draws among three starts; all three rewards paid
        assert sum(1 for key in seen if key.startswith("start")) == 3, seen
        assert seen["reward 2"] and seen["reward -1"] and seen["reward 0.25"], seen
    if env_id.startswith("Taxi"):  # only a fickle passenger changes their destination
        assert (seen["new destination"] > 0) == ("fickle_passenger" in kwargs), seen
    if env_id.startswith("Taxi"):
        assert seen["reward 20"] > 0 and seen["reward -10"] > 0, seen
    if env_id.startswith("CliffWalking"):
        assert seen["reward -100"] > 0 and seen["terminated"] > 0, seen
    if name == "blackjack-natural":
        assert seen["reward 1.5"] > 0, seen
    if "Blackjack" in env_id:
        assert seen["reward 1"] and seen["reward -1"] and seen["reward 0"], seen
    if env_id.startswith("cartpole_q/BlackjackES"):  # every one of the 200 states, no natural
        starts = {key for key in seen if key.startswith("start")}
        assert len(starts) == 200, len(starts)
        assert seen["reward 1.5"] == 0, seen


def test_exploring_starts_deal_the_drawn_state_never_a_natural() -> None:
    """The ES world's reset: three draws pick the state, a fourth the dealer's hidden card."""
    env = gym.make("cartpole_q/BlackjackES-v0").unwrapped
    for seed in range(40):
        observation, _ = env.reset(seed=seed)
        draws = seeding.np_random(seed)[0]
        player_sum = 12 + int(draws.integers(0, 10))
        card = 1 + int(draws.integers(0, 10))
        usable = int(draws.integers(0, 2))
        hidden = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 10, 10, 10][int(draws.integers(0, 13))]
        assert tuple(int(v) for v in observation) == (player_sum, card, usable), seed
        assert env.dealer == [card, hidden]  # type: ignore[attr-defined]
        assert sorted(env.player) != [1, 10]  # type: ignore[attr-defined]
        assert draws.bit_generator.state == env.np_random.bit_generator.state
    assert len(env.measured_states) == 200  # type: ignore[attr-defined]


def test_the_table_is_the_environments_own() -> None:
    """The twin's arrays are ``P`` and ``np.cumsum`` of its probabilities, outcome by outcome."""
    lake = gym.make("FrozenLake8x8-v1").unwrapped
    params = transition_table.twin_params({}, "FrozenLake8x8-v1")
    assert isinstance(params, tuple)
    initial, cumulative, outcomes, next_states, rewards, terminations = params
    assert initial.tobytes() == np.cumsum(lake.initial_state_distrib).tobytes()  # type: ignore[attr-defined]
    for s, by_action in lake.P.items():  # type: ignore[attr-defined]
        for a, listed in by_action.items():
            count = outcomes[s, a]
            assert count == len(listed)
            sums = np.cumsum([p for p, *_ in listed])
            assert cumulative[s, a, :count].tobytes() == sums.tobytes()
            assert next_states[s, a, :count].tolist() == [t[1] for t in listed]
            assert rewards[s, a, :count].tolist() == [t[2] for t in listed]
            assert terminations[s, a, :count].tolist() == [t[3] for t in listed]


def test_what_the_twins_refuse_and_auto_picks() -> None:
    assert "'render_mode'" in str(twin_settings("FrozenLake-v1", {"render_mode": "ansi"}, 100))
    assert "'render_mode'" in str(twin_settings("Taxi-v4", {"render_mode": "ansi"}, 200))
    assert "'render_mode'" in str(twin_settings("Blackjack-v1", {"render_mode": "rgb_array"}, None))
    random_map = twin_settings("FrozenLake-v1", {"map_name": None}, 100)
    assert isinstance(random_map, str) and "random map" in random_map
    assert isinstance(twin_settings("CliffWalking-v1", {}, None), TwinSettings)  # no time limit
    assert blackjack.twin_params({}, "Blackjack-v1") == (1.0, 0.0)  # registered with sab=True
    assert blackjack.twin_params({"sab": False, "natural": True}, "Blackjack-v1") == (0.0, 1.0)
    fickle = taxi.twin_params({"fickle_passenger": True, "fickle_probability": 0.5}, "Taxi-v4")
    assert isinstance(fickle, tuple) and fickle[-2:] == (1.0, 0.5)
    for env_id in ("FrozenLake-v1", "FrozenLake8x8-v1", "Taxi-v4", "CliffWalking-v1",
                   "CliffWalkingSlippery-v1", "Blackjack-v1"):  # fmt: skip
        auto = load_config(overrides={"env.id": env_id})
        assert resolve_engine(auto, inspect_env(auto)) == "numba", env_id
    for env_id in ("cartpole_q/WindyGridworld-v0", "cartpole_q/DynaMaze-v0"):
        auto = load_config(overrides={"env.id": env_id})
        assert resolve_engine(auto, inspect_env(auto)) == "numba", env_id
    # A world whose table changes while it is played, or whose rewards are drawn, is not
    # played by a table baked once: the gymnasium engine plays it.
    for env_id in (
        "cartpole_q/BlockingMaze-v0", "cartpole_q/ShortcutMaze-v0", "cartpole_q/MaximizationBias-v0"
    ):  # fmt: skip
        reason = transition_table.twin_params({}, env_id)
        assert isinstance(reason, str) and "does not play its transition table" in reason
        auto = load_config(overrides={"env.id": env_id})
        assert resolve_engine(auto, inspect_env(auto)) == "gymnasium", env_id
    # (A config can no longer set render_mode, the one argument the table twins refuse; any
    # other argument changes the table the twin is baked from, and the twin plays it.)
    unchecked = load_config(
        overrides={"env.id": "Taxi-v4", "env.kwargs": {"disable_env_checker": True}}
    )
    assert resolve_engine(unchecked, inspect_env(unchecked)) == "numba"


# Training: each (algorithm, twin) pair is a compilation of several seconds.
WORLDS: dict[str, dict[str, Any]] = {
    "lake": {"env": {"id": "FrozenLake-v1"}, "episodes": 300, "q_init": 0.5},
    "lake-custom": {
        "env": {"id": "FrozenLake-v1", "kwargs": {"desc": CUSTOM_LAKE, "success_rate": 0.6}},
        "episodes": 200,
        "q_init": 0.0,
    },
    "taxi-rainy-fickle": {
        "env": {
            "id": "Taxi-v4",
            "kwargs": {"is_rainy": True, "fickle_passenger": True, "max_episode_steps": 100},
        },
        "episodes": 60,
        "q_init": 0.0,
    },
    "cliff-slippery": {"env": {"id": "CliffWalkingSlippery-v1"}, "episodes": 30, "q_init": 0.0},
    "blackjack-natural": {
        "env": {"id": "Blackjack-v1", "kwargs": {"sab": False, "natural": True}},
        "episodes": 500,
        "q_init": 0.0,
    },
}
WORLDS["windy-stochastic"] = {
    "env": {"id": "cartpole_q/StochasticWindyGridworld-v0", "kwargs": {"max_episode_steps": 300}},
    "episodes": 40,
    "q_init": 0.0,
}
MULTI_STEP = {
    "lake-custom": "sarsa_lambda",
    "taxi-rainy-fickle": "n_step_tree_backup",
    "cliff-slippery": "dyna_q",
    "blackjack-natural": "monte_carlo",
    "windy-stochastic": "true_online_sarsa_lambda",
}


def _trained(world: str, algorithm: str, engine: str) -> Any:
    case = WORLDS[world]
    config = load_config(
        {
            "env": case["env"],
            "engine": engine,
            "seed": 5,
            "agent": {
                "algorithm": algorithm,
                "gamma": 0.95,
                "alpha": {"type": "exponential", "start": 0.5, "decay": 0.99, "end": 0.05},
                "epsilon": {"type": "exponential", "start": 1.0, "decay": 0.98, "end": 0.05},
                "q_init": case["q_init"],
            },
            "train": {
                "episodes": case["episodes"],
                "eval_every": case["episodes"] // 3,
                "eval_episodes": 5,
                "checkpoint_every": 0,
            },
            "eval": {"episodes": 20},
        }
    )
    return train(config)


def _assert_same_training(world: str, algorithm: str) -> None:
    numba, gymnasium = (_trained(world, algorithm, engine) for engine in ("numba", "gymnasium"))
    assert (numba.engine, gymnasium.engine) == ("numba", "gymnasium")
    assert numba.q_table.tobytes() == gymnasium.q_table.tobytes()
    assert numba.q_table.shape == gymnasium.q_table.shape
    assert numba.visits.tobytes() == gymnasium.visits.tobytes()
    assert metrics_csv(numba.metrics) == metrics_csv(gymnasium.metrics)
    assert (numba.env_steps, numba.solved_episode, numba.kept_episode) == (
        gymnasium.env_steps,
        gymnasium.solved_episode,
        gymnasium.kept_episode,
    )
    assert numba.evaluations == gymnasium.evaluations and len(numba.evaluations) == 3
    assert numba.eval == gymnasium.eval
    assert numba.visits.sum() == numba.env_steps > 0


# One algorithm or two of each family: each (algorithm, twin) pair is a numba compilation of
# ~15 s on a cold cache. Every algorithm is trained alike on both engines on CartPole's twin
# (test_engines.py, test_rederivation.py) and on the gymnasium engine on every world.
FROZENLAKE_ALGORITHMS = (
    "q_learning",
    "sarsa",
    "n_step_tree_backup",
    "sarsa_lambda",
    "true_online_sarsa_lambda",
    "dyna_q",
    "monte_carlo",
)


@pytest.mark.parametrize(
    "algorithm",
    [
        pytest.param(name, marks=[] if name == "q_learning" else [pytest.mark.slow])
        for name in FROZENLAKE_ALGORITHMS
    ],
)
def test_algorithms_of_every_family_train_frozenlake_alike_on_both_engines(algorithm: str) -> None:
    _assert_same_training("lake", algorithm)


@pytest.mark.parametrize(
    ("world", "algorithm"),
    [
        pytest.param(world, algorithm, marks=[pytest.mark.slow], id=f"{world}-{algorithm}")
        for world in MULTI_STEP
        for algorithm in ("q_learning", MULTI_STEP[world])
    ],
)
def test_the_other_worlds_train_alike_on_both_engines(world: str, algorithm: str) -> None:
    _assert_same_training(world, algorithm)
