"""Chapter 8's planning studies: expected against sample updates, and trajectory sampling.

Two computations of Sutton & Barto (2018) section 8.5 and 8.6 that run outside the episode
loop (``cartpole-q updates``; the contract, every draw included, is in ``docs/algorithms.md``,
"Planning updates"):

- **Figure 8.7** (:func:`sample_update_errors`): a problem is ``b`` successor values drawn
  ``N(0, 1)``, all equally likely, the true value their mean; an estimate starting with an
  error of exactly 1 is moved by sample updates with ``alpha = 1/t`` (the running average of
  the sampled successors' values), one successor drawn per computation. The expected update
  needs all ``b`` computations and is exact after them.
- **Figure 8.8** (:func:`trajectory_run`): a random task of ``n`` states, each with a few
  actions leading to ``b`` equally likely next states; expected updates distributed
  uniformly (cycling over the state-action pairs) or on-policy (along simulated
  epsilon-greedy episodes from the start state); every ``every`` updates the start state's
  value under the greedy policy, by iterative policy evaluation.

The Figure 8.8 functions are plain Python that numba compiles (:func:`compilable`;
:mod:`cartpole_q.engines.trajectory` runs them), so they run as they are in a doctest:

>>> import numpy as np
>>> next_states = np.array([[[1], [0]], [[1], [1]]])
>>> rewards = np.array([[[1.0], [0.0]], [[2.0], [0.5]]])
>>> q = np.zeros((2, 2))
>>> expected_update(q, next_states, rewards, 0, 0, 0.9)
>>> float(q[0, 0])  # 0.9 * (1 + max(Q(1, .)))
0.9
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from cartpole_q.rl.tabular import Rng, compilable


def problem_draws(seed: int, branching: int) -> tuple[np.ndarray, np.ndarray]:
    """Figure 8.7's problem ``seed`` with ``branching`` successors: their values, the picks.

    ``rng = Generator(PCG64(SeedSequence([seed, branching])))``; the values are
    ``rng.standard_normal(branching)``, then the successors sampled by the ``2 * branching``
    sample updates ``rng.integers(0, branching, size=2 * branching)``.
    """
    rng = np.random.Generator(np.random.PCG64(np.random.SeedSequence([seed, branching])))
    values = rng.standard_normal(branching)
    picks = rng.integers(0, branching, size=2 * branching)
    return values, picks


def ordered_mean(values: np.ndarray) -> float:
    """The mean as the contract sums it: from 0.0, in order, then divided by the count."""
    total = 0.0
    for value in values.tolist():
        total += value
    return total / len(values)


def sample_update_errors(
    seeds: list[int], branching: int, initial_error: float = 1.0
) -> tuple[np.ndarray, np.ndarray]:
    """Figure 8.7's errors: every problem's, after ``t = 0, 1, ..., 2 * branching`` computations.

    Per problem: ``true`` = :func:`ordered_mean` of its values; the estimate starts at
    ``Q = true + initial_error`` (its error at ``t = 0`` is ``initial_error`` by
    construction); sample update ``t`` (1-based): ``Q = Q + (1.0 / t) * (values[picks[t - 1]]
    - Q)``, error ``Q - true``. The expected update's error is ``initial_error`` until ``t =
    branching``, then ``ordered_mean(values) - true``: exactly 0.

    Returns:
        ``(sample, expected)``, float64 ``(len(seeds), 2 * branching + 1)``.
    """
    count = 2 * branching + 1
    sample = np.empty((len(seeds), count))
    expected = np.empty((len(seeds), count))
    draws = [problem_draws(seed, branching) for seed in seeds]
    truth = np.array([ordered_mean(values) for values, _ in draws])
    sampled = np.array([values[picks] for values, picks in draws]).reshape(len(seeds), -1)
    estimate = truth + initial_error
    sample[:, 0] = initial_error
    for t in range(1, count):
        estimate = estimate + (1.0 / t) * (sampled[:, t - 1] - estimate)
        sample[:, t] = estimate - truth
    expected[:, :branching] = initial_error
    expected[:, branching:] = (np.array([ordered_mean(values) for values, _ in draws]) - truth)[
        :, None
    ]
    return sample, expected


def rms_over_problems(errors: np.ndarray) -> np.ndarray:
    """Each column's root mean square: squares summed over the rows in order from 0.0."""
    total = np.zeros(errors.shape[1])
    for row in errors:
        total = total + row * row
    result: np.ndarray = np.sqrt(total / errors.shape[0])
    return result


def task_draws(
    seed: int, states: int, actions: int, branching: int
) -> tuple[np.ndarray, np.ndarray, np.random.Generator]:
    """Figure 8.8's task ``seed``: next states, rewards, and the on-policy run's generator.

    ``task_seq, run_seq = SeedSequence(seed).spawn(2)``; ``task = Generator(PCG64(task_seq))``
    draws ``next_states = task.integers(0, states, size=(states, actions, branching))`` then
    ``rewards = task.standard_normal((states, actions, branching))``; the on-policy
    simulation draws from ``Generator(PCG64(run_seq))`` (the uniform one draws nothing).
    """
    task_seq, run_seq = np.random.SeedSequence(seed).spawn(2)
    task = np.random.Generator(np.random.PCG64(task_seq))
    next_states = task.integers(0, states, size=(states, actions, branching))
    rewards = task.standard_normal((states, actions, branching))
    return next_states, rewards, np.random.Generator(np.random.PCG64(run_seq))


@compilable
def greedy_action(q: np.ndarray, state: int) -> int:
    """The lowest action with the largest ``Q(state, .)``."""
    best, greedy = q[state, 0], 0
    for action in range(1, q.shape[1]):
        if q[state, action] > best:
            best, greedy = q[state, action], action
    return greedy


@compilable
def expected_update(
    q: np.ndarray,
    next_states: np.ndarray,
    rewards: np.ndarray,
    state: int,
    action: int,
    continuing: float,
) -> None:
    """``Q(s, a) = continuing * (sum_j (r(s, a, j) + max_a' Q(s_j, a')) / b)``, in place.

    The sum runs over the branches ``j`` in order from 0.0; the end of an episode (probability
    ``1 - continuing``) pays 0 and is worth 0.
    """
    branching = next_states.shape[2]
    total = 0.0
    for branch in range(branching):
        successor = next_states[state, action, branch]
        total += rewards[state, action, branch] + q[successor, greedy_action(q, successor)]
    q[state, action] = continuing * (total / branching)


@compilable
def greedy_value(
    q: np.ndarray,
    next_states: np.ndarray,
    rewards: np.ndarray,
    continuing: float,
    tolerance: float,
    values: np.ndarray,
    fresh: np.ndarray,
    policy: np.ndarray,
) -> float:
    """The start state's (state 0's) value under the greedy policy of ``q``.

    Synchronous sweeps from ``values`` as they are (the previous evaluation's: a warm
    start): ``fresh(s) = continuing * (sum_j (r(s, g, j) + values(s_j)) / b)`` with ``g`` the
    greedy action, summed over ``j`` in order from 0.0; then ``values = fresh``; stop after
    the first sweep whose largest ``|fresh(s) - values(s)|`` is below ``tolerance``.
    """
    states, branching = next_states.shape[0], next_states.shape[2]
    for state in range(states):
        policy[state] = greedy_action(q, state)
    while True:
        largest = 0.0
        for state in range(states):
            action = policy[state]
            total = 0.0
            for branch in range(branching):
                total += rewards[state, action, branch] + values[next_states[state, action, branch]]
            fresh[state] = continuing * (total / branching)
            change = abs(fresh[state] - values[state])
            if change > largest:
                largest = change
        values[:] = fresh
        if largest < tolerance:
            return float(values[0])


TRAJECTORY_CARRY = 2
NEXT_UPDATE, STATE = range(TRAJECTORY_CARRY)
"""a run's state between chunks of :func:`trajectory_run` (int64 ``[TRAJECTORY_CARRY]``): the
number of the next update (0: not started, the start state not valued yet), and the state
of the on-policy simulation"""


class Task(NamedTuple):
    """One of Figure 8.8's random tasks: its size and how episodes end."""

    states: int
    actions: int
    branching: int
    """``b``: the next states each pair may lead to, equally likely"""
    termination: float
    """the probability that a transition ends the episode"""


class Curve(NamedTuple):
    """How a task's curve is drawn: its updates, how often it is valued, and how."""

    updates: int
    """the updates in all"""
    every: int
    """the start state's greedy value is computed after every this many updates"""
    epsilon: float
    """the on-policy updates' exploration"""
    tolerance: float
    """policy evaluation of the greedy policy stops at this largest change"""


class TrajectoryProgress(NamedTuple):
    """A curve's run between chunks of :func:`trajectory_run`: what it drew and where it is."""

    out: np.ndarray
    """float64 ``[updates // every + 1]``: the start state's greedy values so far"""
    tables: tuple[np.ndarray, ...]
    """``Q``, the values, their next sweep, the policy (:func:`trajectory_tables`)"""
    carry: np.ndarray
    """int64 ``[TRAJECTORY_CARRY]``: the next update and the on-policy state"""


def trajectory_tables(states: int, actions: int) -> tuple[np.ndarray, ...]:
    """A run's tables, kept across its chunks: ``Q`` (zeros), the values, their next sweep, the policy."""
    return (
        np.zeros((states, actions)),
        np.zeros(states),
        np.zeros(states),
        np.zeros(states, np.int64),
    )


def trajectory_progress(task: Task, curve: Curve) -> TrajectoryProgress:
    """A curve's run at its start: no value drawn, ``Q`` at 0, at the start state."""
    return TrajectoryProgress(
        np.empty(curve.updates // curve.every + 1),
        trajectory_tables(task.states, task.actions),
        np.zeros(TRAJECTORY_CARRY, dtype=np.int64),
    )


@compilable
def trajectory_run(
    next_states: np.ndarray,
    rewards: np.ndarray,
    task: Task,
    curve: Curve,
    on_policy: bool,
    rng: Rng,
    progress: TrajectoryProgress,
    budget: int,
) -> bool:
    """One task's curve: ``progress.out[i]``, the start state's greedy value after ``i * every`` updates.

    ``Q`` starts at 0. Update ``k = 1, 2, ...``: uniform: the pair ``(k - 1) mod (S * A)``
    in order ``(0, 0), (0, 1), ..., (1, 0), ...``; on-policy: the pair ``(s, a)`` with ``a``
    epsilon-greedy on ``Q`` (``rng.random() < epsilon``, then ``rng.integers(0, A)`` when
    exploring, else the lowest greedy action), then, after the update, ``rng.random() <
    termination`` ends the episode (the next starts at state 0), else ``s =
    next_states[s, a, rng.integers(0, b)]``.

    A call goes on from ``progress`` (:func:`trajectory_progress`: the start) for about
    ``budget`` units of work (an update counts ``b``, a valuation ``S * b``, one sweep's
    worth; ``budget >= 1``) and returns whether the curve is complete: the run in chunks is
    the run in one call, draw for draw.
    """
    out, carry = progress.out, progress.carry
    q, values, fresh, policy = progress.tables
    states, actions, branching = next_states.shape
    termination, epsilon = task.termination, curve.epsilon
    every, tolerance = curve.every, curve.tolerance
    continuing = 1.0 - termination
    if carry[NEXT_UPDATE] == 0:
        out[0] = greedy_value(q, next_states, rewards, continuing, tolerance, values, fresh, policy)
        carry[NEXT_UPDATE] = 1
    state = carry[STATE]
    last = (out.shape[0] - 1) * every
    update = carry[NEXT_UPDATE]
    work = 0
    while update <= last and work < budget:
        if on_policy:
            if epsilon >= 1.0 or (epsilon > 0.0 and rng.random() < epsilon):
                action = int(rng.integers(0, actions))
            else:
                action = greedy_action(q, state)
            expected_update(q, next_states, rewards, state, action, continuing)
            if rng.random() < termination:
                state = 0
            else:
                state = next_states[state, action, rng.integers(0, branching)]
        else:
            pair = (update - 1) % (states * actions)
            expected_update(q, next_states, rewards, pair // actions, pair % actions, continuing)
        work += branching
        if update % every == 0:
            out[update // every] = greedy_value(
                q, next_states, rewards, continuing, tolerance, values, fresh, policy
            )
            work += states * branching
        update += 1
    carry[NEXT_UPDATE], carry[STATE] = update, state
    return bool(update > last)
