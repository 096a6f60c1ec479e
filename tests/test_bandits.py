"""Bandits (chapter 2): the testbed, its twin, both engines and the re-derivation agree exactly.

``tests/reference_bandits.py`` re-derives every rule from docs/algorithms.md ("Bandits")
without the package; each rule's rewards and optimal flags must be its floats, byte for byte,
on the numba engine (the compiled twin) and on the gymnasium engine (``gymnasium.make``).
"""

from __future__ import annotations

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import cartpole_q  # noqa: F401  (registers the worlds)
from cartpole_q.engines.bandit import (
    make_env,
    play_curve,
    play_run_gymnasium,
    play_run_numba,
    run_generators,
)
from cartpole_q.envs.twins.bandit import ArmedTestbed, reset_testbed, step_testbed
from cartpole_q.rl.bandits import RULES, BanditAgent
from tests.reference_bandits import Learner, reference_run

STEPS = 150
SEEDS = (0, 1, 7)

LEARNERS = {
    "greedy": Learner("epsilon_greedy"),
    "epsilon 0.01": Learner("epsilon_greedy", epsilon=0.01),
    "epsilon 0.1": Learner("epsilon_greedy", epsilon=0.1),
    "epsilon 1": Learner("epsilon_greedy", epsilon=1.0),
    "optimistic": Learner("epsilon_greedy", alpha=0.1, q_init=5.0),
    "epsilon 0.1 constant alpha": Learner("epsilon_greedy", epsilon=0.1, alpha=0.1),
    "ucb c 2": Learner("ucb", c=2.0),
    "ucb c 1 constant alpha": Learner("ucb", c=1.0, alpha=0.1),
    "gradient baseline": Learner("gradient", alpha=0.1, baseline=True),
    "gradient no baseline": Learner("gradient", alpha=0.4),
}
TESTBEDS = {
    "stationary": ArmedTestbed(10, 0.0, 1.0, 0.0),
    "mean 4": ArmedTestbed(10, 4.0, 1.0, 0.0),
    "walk": ArmedTestbed(10, 0.0, 0.0, 0.01),
    "5 arms": ArmedTestbed(5, 0.0, 1.0, 0.0),
}


def agent_of(learner: Learner) -> BanditAgent:
    return BanditAgent(
        RULES[learner.method], learner.epsilon, learner.c, learner.alpha, learner.q_init,
        learner.baseline,
    )  # fmt: skip


def test_the_testbed_is_registered_and_passes_check_env() -> None:
    env = gymnasium.make("cartpole_q/Bandit-v0")
    check_env(env.unwrapped)
    assert env.action_space == gymnasium.spaces.Discrete(10)
    assert env.observation_space == gymnasium.spaces.Discrete(1)
    assert env.spec is not None and env.spec.max_episode_steps is None


def test_reset_draws_the_true_values_in_arm_order_from_the_envs_generator() -> None:
    env = gymnasium.make("cartpole_q/Bandit-v0", mean=4.0)
    _, info = env.reset(seed=12)
    expected = np.random.Generator(np.random.PCG64(np.random.SeedSequence(12))).normal(
        4.0, 1.0, size=10
    )
    assert info["q_star"].tobytes() == expected.tobytes()
    best = int(np.argmax(expected))
    assert env.step(best)[4]["optimal"] and not env.step((best + 1) % 10)[4]["optimal"]


@pytest.mark.parametrize("name", TESTBEDS)
def test_the_twin_draws_what_the_environment_draws(name: str) -> None:
    from cartpole_q.engines.compile import jit

    testbed = TESTBEDS[name]
    env = make_env(testbed)
    _, info = env.reset(seed=3)
    rng = np.random.Generator(np.random.PCG64(np.random.SeedSequence(3)))
    q_star = np.empty(testbed.k)
    jit(reset_testbed)(testbed, q_star, rng)
    assert q_star.tobytes() == info["q_star"].tobytes()
    step = jit(step_testbed)
    arms = np.random.default_rng(0).integers(0, testbed.k, size=300)
    for arm in arms:
        _, reward, terminated, truncated, info = env.step(int(arm))
        twin_reward, twin_optimal = step(testbed, q_star, int(arm), rng)
        assert (reward, info["optimal"]) == (twin_reward, twin_optimal)
        assert not terminated and not truncated
    assert q_star.tobytes() == env.unwrapped.q_star.tobytes()  # type: ignore[attr-defined]


@pytest.mark.parametrize("name", LEARNERS)
def test_both_engines_equal_the_rederivation_byte_for_byte(name: str) -> None:
    learner = LEARNERS[name]
    testbed = TESTBEDS["mean 4"] if learner.method == "gradient" else TESTBEDS["stationary"]
    agent = agent_of(learner)
    for seed in SEEDS:
        rewards, optimal = reference_run(learner, seed, STEPS, *testbed)
        expected = (np.array(rewards).tobytes(), np.array(optimal).tobytes())
        for play in (play_run_numba, play_run_gymnasium):
            got_rewards, got_optimal = play(agent, testbed, seed, STEPS)
            assert (got_rewards.tobytes(), got_optimal.tobytes()) == expected, (name, play, seed)


@pytest.mark.parametrize("testbed_name", ["walk", "5 arms"])
def test_the_walk_and_other_arm_counts_equal_the_rederivation(testbed_name: str) -> None:
    testbed = TESTBEDS[testbed_name]
    for learner in (LEARNERS["epsilon 0.1 constant alpha"], LEARNERS["ucb c 2"]):
        rewards, optimal = reference_run(learner, 5, STEPS, *testbed)
        for play in (play_run_numba, play_run_gymnasium):
            got = play(agent_of(learner), testbed, 5, STEPS)
            assert got[0].tobytes() == np.array(rewards).tobytes()
            assert got[1].tobytes() == np.array(optimal).tobytes()


def test_a_curve_averages_each_step_over_the_runs_in_seed_order() -> None:
    learner = LEARNERS["epsilon 0.1"]
    testbed = TESTBEDS["stationary"]
    seeds = [4, 2, 9]
    curve = play_curve(agent_of(learner), testbed, seeds, 50, keep_runs=True)
    runs = [reference_run(learner, seed, 50) for seed in seeds]
    total = [0.0] * 50
    for rewards, _ in runs:
        total = [a + b for a, b in zip(total, rewards, strict=True)]
    assert curve.average_reward.tolist() == [value / 3 for value in total]
    counts = [sum(optimal[t] for _, optimal in runs) for t in range(50)]
    assert curve.optimal_percent.tolist() == [100.0 * count / 3 for count in counts]
    gymnasium_curve = play_curve(agent_of(learner), testbed, seeds, 50, engine="gymnasium")
    assert gymnasium_curve.average_reward.tobytes() == curve.average_reward.tobytes()
    assert gymnasium_curve.optimal_percent.tobytes() == curve.optimal_percent.tobytes()


def test_run_seeds_follow_the_package_convention() -> None:
    agent_rng, env_seed = run_generators(0)
    agent_seq, env_seq = np.random.SeedSequence(0).spawn(2)
    assert agent_rng.random() == np.random.Generator(np.random.PCG64(agent_seq)).random()
    assert env_seed == int(env_seq.generate_state(1, dtype=np.uint32)[0])
