"""Value iteration and exact policy evaluation against answers known without them."""

from __future__ import annotations

import gymnasium
import numpy as np
import pytest

from cartpole_q.config import load_config
from cartpole_q.envs.models import env_model
from cartpole_q.families.blackjack.model import blackjack_model
from cartpole_q.rl.mdp import FiniteMDP
from cartpole_q.rl.solvers import (
    finite_horizon,
    policy_horizon_values,
    policy_values,
    value_iteration,
)
from tests.conftest import invoke


def _three_states() -> FiniteMDP:
    """State 0: 'safe' pays 1 and ends; 'risky' reaches state 1 with 0.8 (else state 2).

    State 1 pays 10 and ends; state 2 pays -5 and ends. With discount g the risky value is
    g * (0.8 * 10 + 0.2 * -5) = 7 g, so risky is best exactly when g > 1/7.
    """
    P = {
        0: {0: [(1.0, 0, 1.0, True)], 1: [(0.8, 1, 0.0, False), (0.2, 2, 0.0, False)]},
        1: {0: [(1.0, 1, 10.0, True)], 1: [(1.0, 1, 10.0, True)]},
        2: {0: [(1.0, 2, -5.0, True)], 1: [(1.0, 2, -5.0, True)]},
    }
    return FiniteMDP.from_transitions(P, initial=[1.0, 0.0, 0.0])


@pytest.mark.parametrize("gamma", [0.0, 0.1, 0.5, 0.9, 1.0])
def test_three_state_mdp_has_its_closed_form_answer(gamma: float) -> None:
    model = _three_states()
    solution = value_iteration(model, gamma)
    assert solution.values[1:].tolist() == [10.0, -5.0]
    assert solution.values[0] == pytest.approx(max(1.0, 7.0 * gamma), abs=1e-12)
    assert solution.policy[0] == (1 if 7.0 * gamma > 1.0 else 0)
    assert solution.start_value == pytest.approx(max(1.0, 7.0 * gamma), abs=1e-12)
    if gamma < 1.0:
        safe = policy_values(model, np.array([0, 0, 0]), gamma)
        risky = policy_values(model, np.array([1, 0, 0]), gamma)
        assert (safe.start_value, risky.start_value) == pytest.approx((1.0, 7.0 * gamma))


def test_time_limited_values_count_only_the_steps_left() -> None:
    model = _three_states()
    # one step: only 'safe' pays within it; two steps: risky pays 7 on average.
    assert finite_horizon(model, 1).start_value == 1.0
    assert finite_horizon(model, 1).policy[0] == 0
    assert finite_horizon(model, 2).start_value == pytest.approx(7.0)
    assert policy_horizon_values(model, np.array([1, 0, 0]), 1).start_value == 0.0


def _policy_iteration(P: dict, n_states: int, n_actions: int, gamma: float) -> np.ndarray:
    """Howard's policy iteration with a dense linear solve: an independent optimum."""
    transition = np.zeros((n_actions, n_states, n_states))
    reward = np.zeros((n_states, n_actions))
    for s in range(n_states):
        for a in range(n_actions):
            for p, s2, r, done in P[s][a]:
                reward[s, a] += p * r
                if not done:
                    transition[a, s, s2] += p
    policy = np.zeros(n_states, dtype=int)
    while True:
        chosen = transition[policy, np.arange(n_states)]
        values = np.linalg.solve(np.eye(n_states) - gamma * chosen,
                                 reward[np.arange(n_states), policy])  # fmt: skip
        q = reward + gamma * np.einsum("ast,t->sa", transition, values)
        improved = np.where(q.max(1) > q[np.arange(n_states), policy] + 1e-12, q.argmax(1), policy)
        if np.array_equal(improved, policy):
            return values
        policy = improved


@pytest.mark.parametrize("gamma", [0.9, 0.99, 0.999999])
def test_frozenlake_optimum_equals_policy_iteration(gamma: float) -> None:
    env = gymnasium.make("FrozenLake-v1")
    P = env.unwrapped.P
    expected = _policy_iteration(P, 16, 4, gamma)
    model = FiniteMDP.from_transitions(P, env.unwrapped.initial_state_distrib)
    solution = value_iteration(model, gamma, tolerance=1e-13)
    assert np.allclose(solution.values, expected, atol=1e-6)
    # the optimal policy evaluated exactly gives the optimal values back
    assert np.allclose(policy_values(model, solution.policy, gamma).values, expected, atol=1e-6)


def test_frozenlake_known_optimum() -> None:
    model = FiniteMDP.from_transitions(gymnasium.make("FrozenLake-v1").unwrapped.P, np.eye(16)[0])
    # Without a time limit the best policy reaches the goal from the start with
    # probability 14/17 (0.8235); within FrozenLake-v1's 100 steps, 0.7442 (Gymnasium's
    # registration notes "optimum = 0.74").
    assert value_iteration(model, 1.0, tolerance=1e-14).start_value == pytest.approx(
        14 / 17, abs=1e-9
    )
    assert finite_horizon(model, 100).start_value == pytest.approx(0.74419, abs=1e-5)


def test_deterministic_worlds_have_their_shortest_paths() -> None:
    cliff = env_model(load_config(overrides={"env.id": "CliffWalking-v1"}).env)
    assert not isinstance(cliff, str)
    assert value_iteration(cliff.model, 1.0).start_value == -13.0  # 13 steps along the edge
    assert finite_horizon(cliff.model, cliff.horizon).start_value == -13.0
    lake = env_model(
        load_config(overrides={"env.id": "FrozenLake-v1", "env.kwargs.is_slippery": False}).env
    )
    assert not isinstance(lake, str) and lake.success_probability
    assert finite_horizon(lake.model, 5).start_value == 0.0  # six moves from S to G
    assert finite_horizon(lake.model, 6).start_value == 1.0


def test_taxi_optimum_matches_greedy_play_in_gymnasium() -> None:
    taxi = env_model(load_config(overrides={"env.id": "Taxi-v4"}).env)
    assert not isinstance(taxi, str)
    best = finite_horizon(taxi.model, taxi.horizon)
    assert best.start_value == pytest.approx(7.93, abs=1e-9)
    # Deterministic moves: each start's optimal return is exact, so playing the policy
    # from each of the 300 start states reproduces the mean without sampling error.
    env = gymnasium.make("Taxi-v4")
    env.reset(seed=0)
    policy = value_iteration(taxi.model, 0.99).policy
    starts = np.flatnonzero(taxi.model.initial)
    total = 0.0
    for start in starts:
        env.unwrapped.s = int(start)
        state, done, steps = int(start), False, 0
        while not done:
            state, reward, terminated, _, _ = env.step(int(policy[state]))
            total += reward
            steps += 1
            done = terminated or steps >= 200
    assert total / len(starts) == pytest.approx(best.start_value, abs=1e-9)


def test_blackjack_model_matches_simulated_play() -> None:
    model, rows = blackjack_model(sab=True, natural=False)
    solution = finite_horizon(model, 100)
    assert solution.start_value == pytest.approx(-0.0431131, abs=1e-6)
    table = np.zeros((32 * 11 * 2, 2))
    table[rows, :] = 0.0
    table[rows, solution.policy] = 1.0  # the optimal policy as a Q-table (naturals stick)
    env = gymnasium.make("Blackjack-v1")
    rng_returns = []
    observation, _ = env.reset(seed=5)
    for _ in range(40_000):
        done = False
        while not done:
            row = (observation[0] * 11 + observation[1]) * 2 + observation[2]
            observation, reward, terminated, truncated, _ = env.step(int(np.argmax(table[row])))
            done = terminated or truncated
        rng_returns.append(reward)
        observation, _ = env.reset()
    mean, error = np.mean(rng_returns), np.std(rng_returns) / np.sqrt(len(rng_returns))
    assert abs(mean - solution.start_value) < 4 * error


def test_optimum_command(in_tmp) -> None:  # type: ignore[no-untyped-def]
    import json

    result = invoke("optimum", "FrozenLake-v1", "--json", "--gamma", "0.99")
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    assert data["optimum"]["return"] == pytest.approx(0.7441903, abs=1e-6)
    assert data["optimum"]["gamma"] == 0.99 and len(data["policy"]) == 16
    text = invoke("optimum", "CliffWalking-v1")
    assert text.exit_code == 0 and "-13" in text.stdout and "C C C" in text.stdout
    refused = invoke("optimum", "CartPole-v1")
    assert refused.exit_code == 2 and "no transition table" in refused.stderr
    assert invoke("optimum", "FrozenLake-v1", "--set", "agent.gamma=0.5").exit_code == 2
    unknown = invoke("optimum", "FrozenLake-v1", "--set", "env.kwargs.no_such=1")
    assert unknown.exit_code == 2 and "env.kwargs" in unknown.stderr
