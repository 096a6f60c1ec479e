"""Each algorithm's update, by hand: targets, the order of work, and every random draw.

Each hook runs as plain Python and compiled as the engines compile it (``VARIANTS``); the
two must agree to the last bit and draw.
"""

from __future__ import annotations

import numpy as np
import pytest

from cartpole_q.engines.compile import jit
from cartpole_q.rl import tabular
from cartpole_q.rl.algorithms import double_q_learning, get
from cartpole_q.rl.tabular import ENDED, Rates, Transition

VARIANTS = ["python", "compiled"]


def learn_step(algorithm: str, variant: str, q, memory, *values):  # type: ignore[no-untyped-def]
    """The algorithm's step hook, as it is or compiled, on one transition and its rates.

    ``values``: state, action, reward, next state, terminated, truncated, alpha, gamma,
    epsilon and the generator.
    """
    step = get(algorithm).step
    transition, rates = Transition(*values[:6]), Rates(*values[6:9])
    return (step if variant == "python" else jit(step))(
        q, memory, (0.0,), transition, rates, values[9]
    )


def _tables() -> np.ndarray:
    # state 0 is updated; state 1 is the next state: Q(1, .) = 2, 5, 3 (greedy action 1)
    return np.array([[1.0, 0.0, 0.0], [2.0, 5.0, 3.0]])


def _step(algorithm, variant, q, memory=(), *, reward=1.0, terminated=False, truncated=False,  # type: ignore[no-untyped-def]
          alpha=0.5, gamma=0.9, epsilon=0.0, rng=None):  # fmt: skip
    rng = rng if rng is not None else np.random.default_rng(0)
    return learn_step(algorithm, variant, q, memory, 0, 0, reward, 1, terminated, truncated,
                      alpha, gamma, epsilon, rng)  # fmt: skip


@pytest.mark.parametrize("variant", VARIANTS)
@pytest.mark.parametrize("algorithm", ["q_learning", "sarsa", "expected_sarsa"])
def test_terminated_step_targets_the_reward_alone(algorithm: str, variant: str) -> None:
    q = _tables()
    rng = np.random.default_rng(1)
    before = rng.bit_generator.state
    assert _step(algorithm, variant, q, terminated=True, epsilon=0.5, rng=rng) == ENDED
    assert q[0, 0] == 1.0 + 0.5 * (1.0 - 1.0)  # y = r = 1
    assert rng.bit_generator.state == before  # nothing drawn after a terminal step


@pytest.mark.parametrize("variant", VARIANTS)
def test_q_learning_ordinary_and_truncated_steps_bootstrap_from_the_max(variant: str) -> None:
    for truncated, expected_next in ((False, 1), (True, ENDED)):
        q = _tables()
        assert _step("q_learning", variant, q, truncated=truncated) == expected_next
        assert q[0, 0] == 1.0 + 0.5 * ((1.0 + 0.9 * 5.0) - 1.0)  # 3.25


@pytest.mark.parametrize("variant", VARIANTS)
def test_sarsa_draws_the_next_action_before_its_update(variant: str) -> None:
    # At epsilon 0 the next action is greedy on the table as it is; make the update change
    # the next state's greedy action (state 0 is also the next state here).
    q = np.array([[1.0, 1.5], [0.0, 0.0]])
    rng = np.random.default_rng(0)
    # action 0 in state 0, next state 0: a' = argmax Q(0, .) before the update = 1
    next_action = learn_step("sarsa", variant, q, (), 0, 0, 10.0, 0, False, False, 0.5, 1.0,
                             0.0, rng)  # fmt: skip
    assert next_action == 1
    assert q[0, 0] == 1.0 + 0.5 * ((10.0 + 1.0 * 1.5) - 1.0)  # 6.25: now action 0 is greedy


@pytest.mark.parametrize("variant", VARIANTS)
def test_sarsa_draws_at_truncation_but_does_not_play_it(variant: str) -> None:
    q = _tables()
    rng, replica = np.random.default_rng(3), np.random.default_rng(3)
    assert _step("sarsa", variant, q, truncated=True, epsilon=1.0, rng=rng) == ENDED
    drawn = int(replica.integers(0, 3))  # epsilon 1: exactly one integers() draw
    assert q[0, 0] == 1.0 + 0.5 * ((1.0 + 0.9 * [2.0, 5.0, 3.0][drawn]) - 1.0)
    assert rng.bit_generator.state == replica.bit_generator.state


@pytest.mark.parametrize("variant", VARIANTS)
def test_sarsa_exploring_draws_random_then_integers(variant: str) -> None:
    q = _tables()
    rng, replica = np.random.default_rng(7), np.random.default_rng(7)
    next_action = _step("sarsa", variant, q, epsilon=0.5, rng=rng)
    explores = replica.random() < 0.5
    expected = int(replica.integers(0, 3)) if explores else 1
    assert next_action == expected
    assert rng.bit_generator.state == replica.bit_generator.state


@pytest.mark.parametrize(
    ("epsilon", "expectation"),
    [
        (0.0, 5.0),  # greedy: Q(1, 1)
        (1.0, (2.0 + 5.0 + 3.0) / 3),  # uniform: (1 - 1) * 5 + (1 / 3) * 10
        (0.3, (1 - 0.3) * 5.0 + (0.3 / 3) * 10.0),  # 3.5 + 1.0
    ],
)
@pytest.mark.parametrize("variant", VARIANTS)
def test_expected_sarsa_target_is_the_expectation_under_epsilon_greedy(
    epsilon: float, expectation: float, variant: str
) -> None:
    q = _tables()
    _step("expected_sarsa", variant, q, epsilon=epsilon, truncated=True)
    assert q[0, 0] == 1.0 + 0.5 * ((1.0 + 0.9 * expectation) - 1.0)


@pytest.mark.parametrize("variant", VARIANTS)
def test_double_q_learning_heads_updates_a_with_b_valuing_a_greedy_action(variant: str) -> None:
    seed = next(s for s in range(100) if np.random.default_rng(s).random() < 0.5)
    q_a = np.array([[1.0, 0.0, 0.0], [2.0, 5.0, 3.0]])  # argmax A(1, .) = 1
    q_b = np.array([[4.0, 0.0, 0.0], [7.0, 0.5, 9.0]])  # B(1, 1) = 0.5
    _step("double_q_learning", variant, q_a, (q_b,), truncated=True,
          rng=np.random.default_rng(seed))  # fmt: skip
    assert q_a[0, 0] == 1.0 + 0.5 * ((1.0 + 0.9 * 0.5) - 1.0)
    assert q_b[0, 0] == 4.0  # untouched


@pytest.mark.parametrize("variant", VARIANTS)
def test_double_q_learning_tails_updates_b_with_a_valuing_b_greedy_action(variant: str) -> None:
    seed = next(s for s in range(100) if np.random.default_rng(s).random() >= 0.5)
    q_a = np.array([[1.0, 0.0, 0.0], [2.0, 5.0, 3.0]])  # A(1, 2) = 3
    q_b = np.array([[4.0, 0.0, 0.0], [7.0, 0.5, 9.0]])  # argmax B(1, .) = 2
    _step("double_q_learning", variant, q_a, (q_b,), truncated=True,
          rng=np.random.default_rng(seed))  # fmt: skip
    assert q_b[0, 0] == 4.0 + 0.5 * ((1.0 + 0.9 * 3.0) - 4.0)
    assert q_a[0, 0] == 1.0


@pytest.mark.parametrize("variant", VARIANTS)
def test_double_q_learning_draws_its_coin_even_on_a_terminal_step(variant: str) -> None:
    q_a, q_b = np.ones((2, 3)), np.ones((2, 3))
    rng, replica = np.random.default_rng(11), np.random.default_rng(11)
    heads = replica.random() < 0.5
    _step("double_q_learning", variant, q_a, (q_b,), terminated=True, reward=3.0, rng=rng)
    updated = q_a if heads else q_b
    assert updated[0, 0] == 1.0 + 0.5 * (3.0 - 1.0)
    assert rng.bit_generator.state == replica.bit_generator.state


@pytest.mark.parametrize("variant", VARIANTS)
def test_double_q_learning_acts_on_the_sum_of_its_tables(variant: str) -> None:
    q_a = np.array([[0.0, 3.0, 1.0]])
    q_b = np.array([[5.0, 1.0, 1.0]])  # sums 5, 4, 2
    rng = np.random.default_rng(0)
    start = double_q_learning.start if variant == "python" else jit(double_q_learning.start)
    epsilon_greedy = tabular.epsilon_greedy if variant == "python" else jit(tabular.epsilon_greedy)
    assert start(q_a, (q_b,), (0.0,), 0, 0.0, rng) == 0
    assert epsilon_greedy(q_a, 0, 0.0, rng) == 1


@pytest.mark.parametrize("variant", VARIANTS)
def test_random_ties_draw_one_of_the_tied_best_actions_and_only_then(variant: str) -> None:
    behaviour = tabular.behaviour_action if variant == "python" else jit(tabular.behaviour_action)
    q = np.array([[1.0, 3.0, 3.0, 0.0, 3.0], [1.0, 4.0, 3.0, 0.0, 3.0]])
    seen = set()
    for seed in range(40):
        rng = np.random.default_rng(seed)
        expected_pick = [1, 2, 4][int(np.random.default_rng(seed).integers(0, 3))]
        assert behaviour(q, (0.0, 1.0), 0, 0.0, rng) == expected_pick  # own param, then the rule
        seen.add(expected_pick)
    assert seen == {1, 2, 4}
    rng = np.random.default_rng(0)
    before = rng.bit_generator.state
    assert behaviour(q, (1.0,), 1, 0.0, rng) == 1  # one best action: nothing drawn
    assert behaviour(q, (0.0,), 0, 0.0, rng) == 1  # lowest: the first of the tied
    assert rng.bit_generator.state == before
    # the exploration draw comes first, as in epsilon_greedy
    rng, again = np.random.default_rng(5), np.random.default_rng(5)
    explored = again.random() < 0.5
    action = behaviour(q, (1.0,), 0, 0.5, rng)
    if explored:
        assert action == int(again.integers(0, 5))
    else:
        assert action == [1, 2, 4][int(again.integers(0, 3))]
    # Double Q-learning breaks ties on A + B the same way
    start = double_q_learning.start if variant == "python" else jit(double_q_learning.start)
    q_a, q_b = np.array([[0.0, 3.0, 1.0]]), np.array([[3.0, 0.0, 1.0]])  # sums 3, 3, 2
    picks = {start(q_a, (q_b,), (1.0,), 0, 0.0, np.random.default_rng(s)) for s in range(20)}
    assert picks == {0, 1}
