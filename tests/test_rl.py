"""The RL functions with hand-computed values: schedules, epsilon-greedy, solving.

Every function is plain Python that the engines compile with numba; each test runs it both
ways (``python`` and ``compiled``), which must agree to the last bit and draw. Each
algorithm's update is tested in ``test_algorithms.py``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from cartpole_q.engines.compile import jit
from cartpole_q.engines.kernel import reaches_threshold
from cartpole_q.rl import tabular
from cartpole_q.rl.algorithms import q_learning
from cartpole_q.rl.schedules import CONSTANT, EXPONENTIAL, LOG, smallest_positive_value
from cartpole_q.rl.schedules import schedule_value as python_schedule_value
from cartpole_q.rl.tabular import ENDED, Rates, Transition

VARIANTS = ["python", "compiled"]


def way(function, variant: str):  # type: ignore[no-untyped-def]
    """The function as it is, or compiled as the engines compile it."""
    return function if variant == "python" else jit(function)


@pytest.mark.parametrize("variant", VARIANTS)
def test_q_learning_picks_the_next_action_from_the_updated_table(variant: str) -> None:
    step = way(q_learning.step, variant)
    q = np.array([[0.0, 0.0], [0.0, 0.1]])
    rates = Rates(1.0, 0.0, 0.0)
    action = step(
        q, (), (0.0,), Transition(1, 1, 1.0, 1, False, False), rates, np.random.default_rng(0)
    )
    # Q(1, 1) becomes 1.0 before the greedy choice in state 1
    assert action == 1 and q[1, 1] == 1.0
    cut = Transition(1, 1, 1.0, 1, False, True)
    ended = step(q, (), (0.0,), cut, rates, np.random.default_rng(0))
    assert ended == ENDED  # truncated: the episode ended, no next action is drawn


@pytest.mark.parametrize(
    ("kind", "start", "end", "rate", "episode", "expected"),
    [
        (CONSTANT, 0.1, 0.1, 1.0, 0, 0.1),
        (CONSTANT, 0.1, 0.1, 1.0, 999, 0.1),
        # the blog's epsilon: 1.0 * 0.995^e, floor 0.01
        (EXPONENTIAL, 1.0, 0.01, 0.995, 0, 1.0),
        (EXPONENTIAL, 1.0, 0.01, 0.995, 1, 0.995),
        (EXPONENTIAL, 1.0, 0.01, 0.995, 100, 0.995**100),  # 0.6057704364907278
        (EXPONENTIAL, 1.0, 0.01, 0.995, 918, 0.995**918),  # 0.01004: just above the floor
        (EXPONENTIAL, 1.0, 0.01, 0.995, 1000, 0.01),  # floor reached at e = 919
        # log schedule with k = 25: max(end, min(1, 1 - log10((e + 1) / 25)))
        (LOG, 1.0, 0.1, 25.0, 0, 1.0),  # 1 - log10(1/25) = 2.398 -> capped at 1
        (LOG, 1.0, 0.1, 25.0, 24, 1.0),  # 1 - log10(1) = 1
        (LOG, 1.0, 0.1, 25.0, 49, 1 - math.log10(2)),  # 0.69897
        (LOG, 1.0, 0.1, 25.0, 99, 1 - math.log10(4)),  # 0.39794
        (LOG, 1.0, 0.1, 25.0, 199, 0.1),  # 1 - log10(8) = 0.0969 -> floor 0.1
        (LOG, 1.0, 0.0, 10.0, 999, 0.0),
        (LOG, 0.5, 0.05, 25.0, 0, 0.5),  # a start below 1 caps the schedule
    ],
)
def test_schedule_values(
    kind: int, start: float, end: float, rate: float, episode: int, expected: float
) -> None:
    value = python_schedule_value(kind, start, end, rate, episode)
    assert value == pytest.approx(expected, rel=1e-12)
    assert jit(python_schedule_value)(kind, start, end, rate, episode) == value  # to the bit


def test_exponential_floor_is_reached_exactly_where_the_product_drops_below_it() -> None:
    values = [python_schedule_value(EXPONENTIAL, 1.0, 0.01, 0.995, e) for e in range(1000)]
    first_floor = values.index(0.01)
    assert first_floor == 919
    assert 0.995**918 > 0.01 > 0.995**919


@pytest.mark.parametrize("variant", VARIANTS)
def test_epsilon_greedy_draws_one_uniform_per_greedy_choice(variant: str) -> None:
    epsilon_greedy = way(tabular.epsilon_greedy, variant)
    rng, mirror = np.random.default_rng(42), np.random.default_rng(42)
    q = np.array([[0.0, 5.0, 1.0]])
    for _ in range(200):
        action = epsilon_greedy(q, 0, 0.3, rng)
        if mirror.random() < 0.3:
            assert action == mirror.integers(0, 3)
        else:
            assert action == 1
    assert rng.bit_generator.state == mirror.bit_generator.state


@pytest.mark.parametrize("variant", VARIANTS)
def test_certain_choices_draw_nothing_they_do_not_need(variant: str) -> None:
    epsilon_greedy = way(tabular.epsilon_greedy, variant)
    q = np.array([[0.0, 1.0, 0.5]])
    rng = np.random.default_rng(1)
    before = rng.bit_generator.state
    assert epsilon_greedy(q, 0, 0.0, rng) == 1
    assert rng.bit_generator.state == before  # epsilon 0: greedy, no draw
    mirror = np.random.default_rng(1)
    for _ in range(50):
        assert epsilon_greedy(q, 0, 1.0, rng) == mirror.integers(0, 3)  # only the action is drawn
    assert rng.bit_generator.state == mirror.bit_generator.state


@pytest.mark.parametrize("variant", VARIANTS)
def test_ties_go_to_the_lowest_action_as_with_numpy_argmax(variant: str) -> None:
    best_action, best_value = way(tabular.best_action, variant), way(tabular.best_value, variant)
    epsilon_greedy = way(tabular.epsilon_greedy, variant)
    q = np.array([[2.0, 2.0, 1.0], [0.0, 3.0, 3.0], [-1.0, -1.0, -1.0], [1.0, 0.0, 4.0]])
    for state in range(4):
        assert best_action(q, state) == np.argmax(q[state])
        assert best_value(q, state) == np.max(q[state])
        assert epsilon_greedy(q, state, 0.0, np.random.default_rng(0)) == np.argmax(q[state])


def test_solve_needs_a_full_window_of_returns_at_the_threshold() -> None:
    returns = np.full(150, 500.0)
    assert not reaches_threshold(returns, 98, 475.0)  # 99 episodes: window not full
    assert reaches_threshold(returns, 99, 475.0)
    returns[50] = 0.0  # one failure in the window: average 495
    assert reaches_threshold(returns, 99, 475.0)
    returns[51:53] = 0.0  # three failures: average 485
    assert reaches_threshold(returns, 99, 485.0)
    assert not reaches_threshold(returns, 99, 485.01)
    assert not reaches_threshold(returns, 149, 500.0)


@given(
    kind=st.sampled_from([CONSTANT, EXPONENTIAL, LOG]),
    start=st.sampled_from([0.0, 1e-320, 0.3, 1.0]),
    end=st.sampled_from([0.0, 1e-320, 0.01]),
    rate=st.sampled_from([1e-100, 0.01, 0.5, 0.9, 1.0, 25.0]),
    episodes=st.integers(1, 1200),
)
def test_smallest_positive_schedule_value_is_the_brute_force_one(
    kind: int, start: float, end: float, rate: float, episodes: int
) -> None:
    if kind == EXPONENTIAL and rate > 1.0:
        rate = 0.5  # decay is at most 1
    values = [python_schedule_value(kind, start, end, rate, e) for e in range(episodes)]
    positive = [(value, e) for e, value in enumerate(values) if value > 0.0]
    expected = min(positive, key=lambda pair: (pair[0], -pair[1])) if positive else None
    assert smallest_positive_value(kind, start, end, rate, episodes) == expected
