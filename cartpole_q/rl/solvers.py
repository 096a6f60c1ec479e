"""The solvers of a finite MDP (:class:`~cartpole_q.rl.mdp.FiniteMDP`): one module for all.

Exact answers, from the start distribution ``initial``:

- :func:`value_iteration`: the optimal values ``V*(s) = max_a Q*(s, a)`` of the discounted
  infinite-horizon problem, iterated until no value moves by more than ``tolerance``, and
  its greedy policy (lowest action among the maxima); :func:`finite_horizon`: the best
  expected *undiscounted* return within ``horizon`` steps (backward induction), what an
  episode with a time limit can earn at best (for FrozenLake the highest probability of
  reaching the goal in time);
- :func:`policy_values` and :func:`policy_horizon_values`: the same two for one
  deterministic stationary policy (a learned greedy policy), exactly (a linear solve, or
  ``horizon`` backups); :func:`evaluate_policy`: a stochastic policy's values on the
  states an episode can reach (:func:`reachable_states`), what a prediction run is
  measured against; :func:`on_policy_distribution`: the fraction of time spent in each;

and dynamic programming with its sweeps recorded (Sutton & Barto, chapters 3-4):

- :func:`evaluate_sweeps`: iterative policy evaluation of a stochastic policy (section
  4.1), the values after each sweep; :func:`value_iteration_sweeps`: value iteration
  (section 4.4), the values after each sweep; :func:`policy_iteration`: policy iteration
  (section 4.3), each policy and its exact values.

**Sweeps.** ``synchronous`` (the default) computes every state's new value from the
previous sweep's values (two arrays): Figure 4.1's values at k = 1, 2, 3 are those of
synchronous sweeps (-1.7 at k = 2 next to a terminal state, which an in-place sweep would
not give). ``in_place`` updates the states one at a time in ascending order, each from the
latest values (one array, the book's pseudocode boxes, and Zhang's gambler). A sweep loop
stops after the first sweep whose largest change of a value, ``max |v_k(s) - v_{k-1}(s)|``,
is below ``tolerance`` (the book's ``Delta < theta``), or fails after ``max_sweeps``; the
maximum of value iteration is over the actions each state offers.

**Ties.** :func:`greedy` takes, in each state, the offered actions whose value is within
``tie_tolerance`` of the best one as tied (float sums of equal returns differ in their
last bits), and chooses the lowest of them. Policy iteration keeps a state's action while
it is still among the tied best (so that it stops: Exercise 4.4), else takes the lowest.

The three-state chain below moves right with probability 0.5 (else stays) and pays 1 on
reaching the end: with ``gamma = 0.9`` the middle state is worth ``v1 = 0.5 + 0.45 v1``,
so ``0.5 / 0.55``, and the first ``v0 = 0.45 v1 + 0.45 v0``, so ``0.45 * 0.5 / 0.55 ** 2``.

>>> P = {0: {0: [(0.5, 1, 0.0, False), (0.5, 0, 0.0, False)]},
...      1: {0: [(0.5, 2, 1.0, True), (0.5, 1, 0.0, False)]}, 2: {0: [(1.0, 2, 0.0, True)]}}
>>> model = FiniteMDP.from_transitions(P, initial=[1.0, 0.0, 0.0])
>>> round(value_iteration(model, 0.9).start_value, 10), round(0.45 * 0.5 / 0.55**2, 10)
(0.7438016529, 0.7438016529)
>>> finite_horizon(model, 2).start_value  # both moves must succeed within two steps
0.25
>>> sweeps = evaluate_sweeps(model, uniform_policy(model), 0.9, tolerance=1e-12)
>>> round(float(sweeps.values[-1, 0]), 10)
0.7438016529
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np

from cartpole_q.rl.mdp import FiniteMDP

MAX_DENSE_STATES = 4096
"""above this many states, :func:`policy_values` iterates instead of solving densely"""
SWEEP_ORDERS = ("synchronous", "in_place")
"""how a sweep updates the states: from the previous sweep's values, or one by one in place"""


@contextlib.contextmanager
def one_thread() -> Iterator[None]:
    """LAPACK (``numpy.linalg``) on one thread inside: the same bits whatever the threads.

    A multi-threaded LU or SVD of a large matrix (the 1000-state walk's) orders its sums by
    the thread count, so its last bits follow ``OMP_NUM_THREADS`` (Ray's workers set it to
    1): an exact value solved on a Ray worker differed from the same solve on this
    machine's two threads. Inside this scope the BLAS that NumPy loaded runs on one thread
    (``threadpoolctl``), so every solve of the package gives one answer on a given
    installation, whichever backend or worker runs it.
    """
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1, user_api="blas"):
        yield


def reachable_states(model: FiniteMDP, pi: np.ndarray) -> np.ndarray:
    """bool, ``(n_states,)``: the states an episode under ``pi`` can be in before it ends.

    From the start distribution's states, along the outcomes of positive probability under
    ``pi`` that do not terminate. (A prediction run measures its error on these: a state no
    episode visits keeps its initial value whatever the algorithm.)

    >>> P = {0: {0: [(1.0, 1, 0.0, False)]}, 1: {0: [(1.0, 1, 0.0, True)]}, 2: {0: [(1.0, 0, 0.0, False)]}}
    >>> model = FiniteMDP.from_transitions(P, initial=[1.0, 0.0, 0.0])
    >>> reachable_states(model, np.ones((3, 1))).tolist()
    [True, True, False]
    """
    weight = pi[model.state, model.action] * model.probability
    going = ~model.terminated & (weight > 0.0)
    following: list[list[int]] = [[] for _ in range(model.n_states)]
    for state, next_state in zip(model.state[going], model.next_state[going], strict=True):
        following[int(state)].append(int(next_state))
    reached = model.initial > 0.0
    frontier = [int(state) for state in np.flatnonzero(reached)]
    while frontier:
        state = frontier.pop()
        for next_state in following[state]:
            if not reached[next_state]:
                reached[next_state] = True
                frontier.append(next_state)
    return reached


def evaluate_policy(
    model: FiniteMDP, pi: np.ndarray, gamma: float, states: np.ndarray | None = None
) -> np.ndarray:
    """The exact values ``v_pi`` of a stochastic stationary policy: ``(I - gamma P_pi) v = r_pi``.

    ``pi[s, a]`` is the probability of ``a`` in ``s`` (each row sums to 1). ``states``
    (indices, ascending) restricts the system to them; they must be closed under the
    policy's non-terminating outcomes, as :func:`reachable_states` are (states outside,
    such as unreachable loops, cannot then make it singular). Sutton & Barto's 5-state random
    walk (Example 6.2), uniformly random, undiscounted:

    >>> P = {s: {a: [(1.0, s + (1 if a else -1), float(s == 5 and a == 1), s + (1 if a else -1) in (0, 6))]
    ...          for a in (0, 1)} for s in range(1, 6)}
    >>> P[0] = P[6] = None
    >>> P = {s: (P[s] or {a: [(1.0, s, 0.0, True)] for a in (0, 1)}) for s in range(7)}
    >>> model = FiniteMDP.from_transitions(P, initial=[0, 0, 0, 1, 0, 0, 0])
    >>> [round(float(v) * 6, 12) for v in evaluate_policy(model, np.full((7, 2), 0.5), 1.0)]
    [0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 0.0]

    Returns:
        The values of ``states`` (of every state when ``None``), in order.

    Raises:
        ValueError: ``gamma`` outside [0, 1], or (``gamma = 1``) a state from which the
            policy may never end an episode.
    """
    if not 0.0 <= gamma <= 1.0:
        raise ValueError(f"gamma must be in [0, 1], got {gamma}")
    chosen = np.arange(model.n_states) if states is None else np.asarray(states, dtype=np.int64)
    expected, matrix = model.stochastic_policy_matrix(np.asarray(pi, dtype=np.float64))
    if gamma == 1.0:
        stuck = _never_ending(model, pi, chosen)
        if stuck is not None:
            raise ValueError(f"from state {stuck} the policy may never end an episode")
    system = np.eye(len(chosen)) - gamma * matrix[np.ix_(chosen, chosen)]
    with one_thread():
        values: np.ndarray = np.linalg.solve(system, expected[chosen])
    return values


def on_policy_distribution(model: FiniteMDP, pi: np.ndarray, states: np.ndarray) -> np.ndarray:
    """The on-policy distribution ``mu`` of an episodic task (Sutton & Barto 9.2, eq. 9.2-9.3).

    ``eta(s) = h(s) + sum over s' of eta(s') * P_pi(s', s)``, the expected visits to ``s``
    in an episode (``h`` the start distribution, ``P_pi`` the continuing, undiscounted
    transitions), solved on ``states`` (closed under the policy's continuing outcomes, as
    :func:`reachable_states` are), then ``mu = eta / sum(eta)``: the fraction of the time
    steps spent in each state. On the 5-state walk the middle is visited most:

    >>> P = {s: {a: [(1.0, s + (1 if a else -1), 0.0, s + (1 if a else -1) in (0, 6))]
    ...          for a in (0, 1)} for s in range(1, 6)}
    >>> P = {s: (P.get(s) or {a: [(1.0, s, 0.0, True)] for a in (0, 1)}) for s in range(7)}
    >>> model = FiniteMDP.from_transitions(P, initial=[0, 0, 0, 1, 0, 0, 0])
    >>> mu = on_policy_distribution(model, np.full((7, 2), 0.5), np.arange(1, 6))
    >>> [round(float(m) * 9, 12) for m in mu]
    [1.0, 2.0, 3.0, 2.0, 1.0]

    Returns:
        ``mu`` on ``states``, in order (float64, summing to 1).

    Raises:
        ValueError: the policy may never end an episode from one of ``states``.
    """
    chosen = np.asarray(states, dtype=np.int64)
    stuck = _never_ending(model, pi, chosen)
    if stuck is not None:
        raise ValueError(f"from state {stuck} the policy may never end an episode")
    _, matrix = model.stochastic_policy_matrix(np.asarray(pi, dtype=np.float64))
    system = np.eye(len(chosen)) - matrix[np.ix_(chosen, chosen)]
    with one_thread():
        visits: np.ndarray = np.linalg.solve(system.T, model.initial[chosen])
    distribution: np.ndarray = visits / visits.sum()
    return distribution


def _never_ending(model: FiniteMDP, pi: np.ndarray, states: np.ndarray) -> int | None:
    """A state of ``states`` from which no outcome of positive probability ends the episode."""
    weight = pi[model.state, model.action] * model.probability
    positive = weight > 0.0
    can_end = np.zeros(model.n_states, dtype=bool)
    can_end[model.state[positive & model.terminated]] = True
    going = positive & ~model.terminated
    sources, targets = model.state[going], model.next_state[going]
    while True:  # backwards: a state that can step to one that can end can end
        grown = can_end.copy()
        grown[sources[can_end[targets]]] = True
        if np.array_equal(grown, can_end):
            break
        can_end = grown
    stuck = [int(state) for state in states if not can_end[state]]
    return stuck[0] if stuck else None


@dataclass(frozen=True)
class Solution:
    """Values of every state, the greedy (or given) policy, and the start distribution's value."""

    values: np.ndarray
    """float64, ``(n_states,)``"""
    q: np.ndarray
    """float64, ``(n_states, n_actions)``: the action values under ``values``"""
    policy: np.ndarray
    """int64, ``(n_states,)``: the lowest action among the maxima of ``q`` (or the given one)"""
    start_value: float
    """``initial @ values``: the expected return from the start distribution"""
    iterations: int

    def to_dict(self) -> dict[str, Any]:
        """The start value and the iterations, for JSON."""
        return {"start_value": self.start_value, "iterations": self.iterations}


def value_iteration(
    model: FiniteMDP, gamma: float, tolerance: float = 1e-12, max_iterations: int = 1_000_000
) -> Solution:
    """The optimal discounted values, by value iteration from zero.

    Stops when no value changes by more than ``tolerance`` in one sweep (with ``gamma < 1``
    the values are then within ``tolerance * gamma / (1 - gamma)`` of the optimum). With
    ``gamma = 1`` it converges when every policy ends episodes, or the rewards are negative
    until they end (Taxi, CliffWalking); FrozenLake's goal probability converges too.

    Raises:
        ValueError: ``gamma`` outside [0, 1], or no convergence in ``max_iterations``.
    """
    if not 0.0 <= gamma <= 1.0:
        raise ValueError(f"gamma must be in [0, 1], got {gamma}")
    values = np.zeros(model.n_states)
    for iteration in range(1, max_iterations + 1):
        q = model.masked(model.backup(values, gamma))
        updated = q.max(axis=1)
        change = float(np.max(np.abs(updated - values)))
        values = updated
        if change <= tolerance:
            q = model.masked(model.backup(values, gamma))
            policy = np.argmax(q, axis=1).astype(np.int64)
            return Solution(values, q, policy, float(model.initial @ values), iteration)
    raise ValueError(f"value iteration did not converge in {max_iterations} sweeps")


def finite_horizon(model: FiniteMDP, horizon: int, gamma: float = 1.0) -> Solution:
    """The best expected return within ``horizon`` steps, by backward induction.

    ``values`` are those with all ``horizon`` steps left; ``policy`` is the best first
    action (the best policy may change as the steps run out). Stops early at a fixed point
    (values that one more step leaves exactly as they are).
    """
    if horizon < 1:
        raise ValueError(f"horizon must be at least 1, got {horizon}")
    values = np.zeros(model.n_states)
    q = model.backup(values, gamma)
    steps = horizon
    for step in range(1, horizon + 1):
        q = model.masked(model.backup(values, gamma))
        updated = q.max(axis=1)
        if np.array_equal(updated, values):  # a fixed point: more steps change nothing
            steps = step
            break
        values = updated
    policy = np.argmax(q, axis=1).astype(np.int64)
    return Solution(values, q, policy, float(model.initial @ values), steps)


def policy_values(
    model: FiniteMDP, policy: np.ndarray, gamma: float, tolerance: float = 1e-12
) -> Solution:
    """The exact values of a deterministic stationary policy: ``(I - gamma P_pi) v = r_pi``.

    Solved densely up to :data:`MAX_DENSE_STATES` states (else ``v = r_pi + gamma P_pi v``
    iterated to ``tolerance``, ``gamma`` below 1).

    Raises:
        ValueError: ``gamma`` outside [0, 1], or its values are not finite (``gamma`` 1 and
            a state from which the policy never ends the episode).
    """
    if not 0.0 <= gamma <= 1.0:
        raise ValueError(f"gamma must be in [0, 1], got {gamma}")
    policy = np.asarray(policy, dtype=np.int64)
    if model.n_states <= MAX_DENSE_STATES:
        expected, matrix = model.policy_matrix(policy)
        try:
            with one_thread():
                values = np.linalg.solve(np.eye(model.n_states) - gamma * matrix, expected)
        except np.linalg.LinAlgError:
            raise ValueError(
                "the policy's values are not finite: with gamma 1 it never ends the episode "
                "from some state; use gamma below 1 or a policy that ends every episode"
            ) from None
        iterations = 1
    else:
        if gamma >= 1.0:
            raise ValueError(f"above {MAX_DENSE_STATES} states policy_values needs gamma < 1")
        values = np.zeros(model.n_states)
        rows = np.arange(model.n_states)
        iterations = 0
        while True:
            iterations += 1
            updated = model.backup(values, gamma)[rows, policy]
            change = float(np.max(np.abs(updated - values)))
            values = updated
            if change <= tolerance:
                break
    q = model.backup(values, gamma)
    return Solution(values, q, policy, float(model.initial @ values), iterations)


def policy_horizon_values(
    model: FiniteMDP, policy: np.ndarray, horizon: int, gamma: float = 1.0
) -> Solution:
    """A stationary policy's exact expected return within ``horizon`` steps."""
    if horizon < 1:
        raise ValueError(f"horizon must be at least 1, got {horizon}")
    policy = np.asarray(policy, dtype=np.int64)
    rows = np.arange(model.n_states)
    values = np.zeros(model.n_states)
    q = model.backup(values, gamma)
    steps = horizon
    for step in range(1, horizon + 1):
        q = model.backup(values, gamma)
        updated = q[rows, policy]
        if np.array_equal(updated, values):  # a fixed point: more steps change nothing
            steps = step
            break
        values = updated
    return Solution(values, q, policy, float(model.initial @ values), steps)


@dataclass(frozen=True)
class Sweeps:
    """The values after each sweep of a sweep loop, from the start values (sweep 0)."""

    values: np.ndarray
    """float64, ``(sweeps + 1, S)``: row ``k`` is the values after sweep ``k``"""
    changes: np.ndarray
    """float64, ``(sweeps,)``: each sweep's largest change of a value"""

    @property
    def sweeps(self) -> int:
        """How many sweeps were made (the last one's change was below the tolerance)."""
        return int(self.changes.size)


@dataclass(frozen=True)
class PolicyIteration:
    """Each policy of policy iteration, from the start, and its exact values."""

    policies: np.ndarray
    """int64, ``(iterations + 1, S)``: ``policies[i]`` is pi_i; the last is stable"""
    values: np.ndarray
    """float64, ``(iterations + 1, S)``: ``values[i]`` is v_{pi_i}"""

    @property
    def improvements(self) -> int:
        """The improvements that changed the policy (the last policy is pi_improvements)."""
        return int(self.policies.shape[0]) - 1


def _check(gamma: float, tolerance: float, order: str) -> None:
    if not 0.0 <= gamma <= 1.0:
        raise ValueError(f"gamma must be in [0, 1], got {gamma}")
    if not tolerance > 0.0:
        raise ValueError(f"tolerance must be positive, got {tolerance}")
    if order not in SWEEP_ORDERS:
        raise ValueError(f"sweeps must be one of {', '.join(SWEEP_ORDERS)}, got {order!r}")


def uniform_policy(model: FiniteMDP) -> np.ndarray:
    """The equiprobable random policy over each state's allowed actions, ``(S, A)``."""
    allowed = model.allowed.astype(np.float64)
    policy: np.ndarray = allowed / allowed.sum(axis=1, keepdims=True)
    return policy


def deterministic_policy(actions: np.ndarray, n_actions: int) -> np.ndarray:
    """The ``(S, A)`` probabilities of taking ``actions[s]`` in ``s``."""
    chosen = np.asarray(actions, dtype=np.int64)
    policy = np.zeros((chosen.size, n_actions))
    policy[np.arange(chosen.size), chosen] = 1.0
    return policy


def _sweep_loop(
    model: FiniteMDP,
    gamma: float,
    update: str,
    policy: np.ndarray | None,
    start: np.ndarray | None,
    tolerance: float,
    max_sweeps: int,
    order: str,
) -> Sweeps:
    """Sweep until the largest change is below ``tolerance``: ``update`` is ``expect`` or ``max``."""
    _check(gamma, tolerance, order)
    values = np.zeros(model.n_states) if start is None else np.array(start, dtype=np.float64)
    history = [values.copy()]
    changes: list[float] = []
    blocked = np.where(model.allowed, 0.0, -np.inf)
    for _ in range(max_sweeps):
        previous = values.copy()
        if order == "synchronous":
            q = model.backup(previous, gamma)
            values = (q * policy).sum(axis=1) if policy is not None else (q + blocked).max(axis=1)
        else:
            for state in range(model.n_states):
                q_state = model.state_backup(state, values, gamma)
                values[state] = (
                    q_state @ policy[state]
                    if policy is not None
                    else (q_state + blocked[state]).max()
                )
        change = float(np.max(np.abs(values - previous)))
        history.append(values.copy())
        changes.append(change)
        if change < tolerance:
            return Sweeps(np.array(history), np.array(changes))
    raise ValueError(
        f"{'policy evaluation' if update == 'expect' else 'value iteration'} did not converge "
        f"in {max_sweeps} sweeps (the last changed a value by {changes[-1]:.3g}, tolerance "
        f"{tolerance:g})"
    )


def evaluate_sweeps(
    model: FiniteMDP,
    policy: np.ndarray,
    gamma: float,
    tolerance: float = 1e-10,
    max_sweeps: int = 100_000,
    order: str = "synchronous",
    start: np.ndarray | None = None,
) -> Sweeps:
    """Iterative policy evaluation of ``policy[s, a]`` (probabilities), every sweep recorded.

    ``v_{k+1}(s) = sum_a pi(a|s) q_k(s, a)``, from ``start`` (zeros by default).

    Raises:
        ValueError: a bad argument, or no convergence within ``max_sweeps``.
    """
    pi = np.asarray(policy, dtype=np.float64)
    if pi.shape != (model.n_states, model.n_actions):
        raise ValueError(f"policy has shape {pi.shape}, not {(model.n_states, model.n_actions)}")
    return _sweep_loop(model, gamma, "expect", pi, start, tolerance, max_sweeps, order)


def value_iteration_sweeps(
    model: FiniteMDP,
    gamma: float,
    tolerance: float = 1e-10,
    max_sweeps: int = 100_000,
    order: str = "synchronous",
) -> Sweeps:
    """Value iteration from zero, every sweep recorded: ``v_{k+1}(s) = max_a q_k(s, a)``.

    The maximum is over the allowed actions. Its greedy policy: :func:`greedy` of
    ``model.backup(sweeps.values[-1], gamma)``.

    Raises:
        ValueError: a bad argument, or no convergence within ``max_sweeps``.
    """
    return _sweep_loop(model, gamma, "max", None, None, tolerance, max_sweeps, order)


def tied_best(q: np.ndarray, allowed: np.ndarray, tie_tolerance: float) -> np.ndarray:
    """bool, ``(S, A)``: the allowed actions within ``tie_tolerance`` of the best allowed one.

    >>> tied_best(np.array([[1.0, 1.0 + 1e-12, 0.5]]), np.ones((1, 3), bool), 1e-9).tolist()
    [[True, True, False]]
    """
    masked = np.where(allowed, q, -np.inf)
    best = masked.max(axis=1, keepdims=True)
    tied: np.ndarray = allowed & (masked >= best - tie_tolerance)
    return tied


def greedy(q: np.ndarray, allowed: np.ndarray, tie_tolerance: float = 1e-9) -> np.ndarray:
    """int64, ``(S,)``: in each state the lowest of the tied best allowed actions.

    >>> greedy(np.array([[0.0, 2.0, 2.0 - 1e-12], [3.0, 1.0, 5.0]]), np.array([[1, 1, 1], [1, 1, 0]], bool)).tolist()
    [1, 0]
    """
    chosen: np.ndarray = np.argmax(tied_best(q, allowed, tie_tolerance), axis=1).astype(np.int64)
    return chosen


def policy_iteration(
    model: FiniteMDP,
    gamma: float,
    start: np.ndarray,
    tie_tolerance: float = 1e-9,
    max_iterations: int = 1_000,
) -> PolicyIteration:
    """Policy iteration from the deterministic policy ``start`` (an action per state).

    Each policy is evaluated exactly (:func:`policy_values`), then improved greedily: a
    state keeps its action while it is among the tied best (:func:`tied_best`), else takes
    the lowest of them. Stops at the first improvement that changes nothing.

    Raises:
        ValueError: ``start`` takes an action not allowed, a policy's values are not finite,
            or the policy still changes after ``max_iterations`` improvements.
    """
    if not 0.0 <= gamma <= 1.0:
        raise ValueError(f"gamma must be in [0, 1], got {gamma}")
    policy = np.asarray(start, dtype=np.int64).copy()
    rows = np.arange(model.n_states)
    if policy.shape != (model.n_states,) or not model.allowed[rows, policy].all():
        raise ValueError("the start policy must take an allowed action in every state")
    policies, values = [policy.copy()], [policy_values(model, policy, gamma).values]
    for _ in range(max_iterations):
        tied = tied_best(model.backup(values[-1], gamma), model.allowed, tie_tolerance)
        improved = np.where(tied[rows, policy], policy, np.argmax(tied, axis=1))
        if np.array_equal(improved, policy):
            return PolicyIteration(np.array(policies), np.array(values))
        policy = improved.astype(np.int64)
        policies.append(policy.copy())
        values.append(policy_values(model, policy, gamma).values)
    raise ValueError(f"policy iteration did not settle in {max_iterations} improvements")


@dataclass(frozen=True)
class GainSolution:
    """An average-reward solution: the gain, the differential values and the greedy policy."""

    gain: float
    """the reward per step (the average reward ``r(π)``, section 10.3)"""
    values: np.ndarray
    """float64, ``(n_states,)``: the differential values, 0 at the reference state"""
    q: np.ndarray
    """float64, ``(n_states, n_actions)``: ``r(s, a) - gain + sum p v(s')``"""
    policy: np.ndarray
    """int64, ``(n_states,)``: the lowest action among the tied best of ``q``"""
    iterations: int
    bounds: tuple[float, float]
    """the last sweep's ``(min, max)`` of ``T v - v``: the optimal gain lies between them"""


def relative_value_iteration(
    model: FiniteMDP, reference: int = 0, tolerance: float = 1e-12,
    max_iterations: int = 1_000_000,
) -> GainSolution:  # fmt: skip
    """The optimal gain and differential values of a continuing MDP (relative value iteration).

    From ``v = 0``: ``T v(s) = max_a sum p (r + v(s'))`` (:meth:`FiniteMDP.backup` with gamma
    1), then ``v = T v - T v(reference)``; stop after the first sweep whose span
    ``max(T v - v) - min(T v - v)`` is at most ``tolerance``, the gain being ``T v(reference)``
    of that sweep (Puterman, section 8.5.5). It converges on an aperiodic unichain MDP (one
    whose every policy has one recurrent class and a state that can stay put, as access
    control's). The policy is :func:`greedy` on ``q`` (ties within ``1e-9``: the lowest).

    Raises:
        ValueError: an outcome that ends (not a continuing MDP), or no convergence.
    """
    if bool(model.terminated.any()):
        raise ValueError("relative value iteration needs a continuing MDP: an outcome ends")
    values = np.zeros(model.n_states)
    for iteration in range(1, max_iterations + 1):
        updated = model.masked(model.backup(values, 1.0)).max(axis=1)
        change = updated - values
        low, high = float(change.min()), float(change.max())
        gain = float(updated[reference])
        values = updated - gain
        if high - low <= tolerance:
            q = model.masked(model.backup(values, 1.0)) - gain
            policy = greedy(q, model.allowed)
            return GainSolution(gain, values, q, policy, iteration, (low, high))
    raise ValueError(f"relative value iteration did not converge in {max_iterations} sweeps")


def policy_gain(
    model: FiniteMDP, policy: np.ndarray, reference: int = 0
) -> tuple[float, np.ndarray]:
    """A deterministic policy's exact gain and differential values (a unichain policy).

    Solves ``v(s) + g = r_pi(s) + sum_s' P_pi(s, s') v(s')`` with ``v(reference) = 0``: one
    dense linear system in ``(v, g)``.

    Raises:
        ValueError: an outcome that ends, or a singular system (a policy with more than one
            recurrent class has no single gain).
    """
    if bool(model.terminated.any()):
        raise ValueError("a gain needs a continuing MDP: an outcome ends")
    n = model.n_states
    expected, matrix = model.policy_matrix(np.asarray(policy, dtype=np.int64))
    system = np.zeros((n + 1, n + 1))
    system[:n, :n] = np.eye(n) - matrix
    system[:n, n] = 1.0
    system[n, reference] = 1.0
    right = np.concatenate([expected, [0.0]])
    try:
        with one_thread():
            solved = np.linalg.solve(system, right)
    except np.linalg.LinAlgError:
        raise ValueError("the policy has no single gain (more than one recurrent class)") from None
    return float(solved[n]), solved[:n]
