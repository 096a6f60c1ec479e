"""Exact answers for environments with a transition table: value iteration and evaluation.

Gymnasium's toy-text environments (FrozenLake, Taxi, CliffWalking) expose their dynamics as
``env.unwrapped.P[s][a] = [(probability, next_state, reward, terminated), ...]``. From such a
table (a :class:`TabularModel`, plain NumPy) this module computes, from the start
distribution ``initial``:

- :func:`value_iteration`: the optimal values ``V*(s) = max_a Q*(s, a)`` of the discounted
  infinite-horizon problem, ``Q*(s, a) = sum p * (r + gamma * V*(s') * (not terminated))``,
  iterated until no value moves by more than ``tolerance``; and its greedy policy
  (lowest action among the maxima);
- :func:`finite_horizon`: the best expected *undiscounted* return within ``horizon`` steps
  (backward induction: ``V_0 = 0``, ``V_h = max_a Q(V_{h-1})``), which is what an episode
  with a time limit of ``horizon`` steps can earn at best (the best policy may depend on
  the steps left); for FrozenLake it is the highest probability of reaching the goal in
  time;
- :func:`policy_values` and :func:`policy_horizon_values`: the same two quantities for one
  given deterministic, stationary policy (a learned greedy policy), exactly: the
  discounted one by solving the linear system ``(I - gamma P_pi) v = r_pi``, the
  time-limited one by ``horizon`` backups of that policy.

A terminated transition contributes its reward and nothing after it; a transition that is
not terminated continues from ``next_state``.

The three-state chain below moves right with probability 0.5 (else stays) and pays 1 on
reaching the end: with ``gamma = 0.9`` the middle state is worth ``v1 = 0.5 + 0.45 v1``,
so ``0.5 / 0.55``, and the first ``v0 = 0.45 v1 + 0.45 v0``, so ``0.45 * 0.5 / 0.55 ** 2``.

>>> P = {0: {0: [(0.5, 1, 0.0, False), (0.5, 0, 0.0, False)]},
...      1: {0: [(0.5, 2, 1.0, True), (0.5, 1, 0.0, False)]}, 2: {0: [(1.0, 2, 0.0, True)]}}
>>> model = TabularModel.from_transitions(P, initial=[1.0, 0.0, 0.0])
>>> round(value_iteration(model, 0.9).start_value, 10), round(0.45 * 0.5 / 0.55**2, 10)
(0.7438016529, 0.7438016529)
>>> finite_horizon(model, 2).start_value  # both moves must succeed within two steps
0.25
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

MAX_DENSE_STATES = 4096
"""above this many states, :func:`policy_values` iterates instead of solving densely"""


@dataclass(frozen=True)
class TabularModel:
    """A finite MDP as flat arrays: one entry per possible outcome of a (state, action)."""

    n_states: int
    n_actions: int
    state: np.ndarray
    """int64: the state each outcome starts from"""
    action: np.ndarray
    """int64: the action taken"""
    probability: np.ndarray
    """float64: the outcome's probability (a (state, action)'s outcomes sum to 1)"""
    next_state: np.ndarray
    """int64: where the outcome leads"""
    reward: np.ndarray
    """float64: its reward"""
    terminated: np.ndarray
    """bool: whether the episode ends there (no value after it)"""
    initial: np.ndarray
    """float64, ``(n_states,)``: the distribution of the start state"""

    @classmethod
    def from_transitions(
        cls,
        transitions: Mapping[int, Mapping[int, Sequence[tuple[float, int, float, bool]]]],
        initial: Sequence[float] | np.ndarray,
        n_actions: int | None = None,
    ) -> TabularModel:
        """Build a model from Gymnasium's ``P[s][a] = [(p, s', r, terminated), ...]``.

        States are ``0 .. len(transitions) - 1``; a (state, action) missing from the table
        (or with no outcome) is refused.

        Raises:
            ValueError: a state or action is missing, a next state out of range, or a
                probability negative or not summing to 1.
        """
        n_states = len(transitions)
        n_actions = n_actions or max(len(actions) for actions in transitions.values())
        rows: list[tuple[int, int, float, int, float, bool]] = []
        for s in range(n_states):
            for a in range(n_actions):
                outcomes = transitions.get(s, {}).get(a)
                if not outcomes:
                    raise ValueError(
                        f"the transition table has no outcome for state {s}, action {a}"
                    )
                total = 0.0
                for probability, next_state, reward, terminated in outcomes:
                    if not 0 <= int(next_state) < n_states or probability < 0:
                        raise ValueError(
                            f"state {s}, action {a}: bad outcome {next_state, probability}"
                        )
                    total += float(probability)
                    rows.append(
                        (s, a, float(probability), int(next_state), float(reward), bool(terminated))
                    )
                if abs(total - 1.0) > 1e-9:
                    raise ValueError(f"state {s}, action {a}: probabilities sum to {total}")
        columns = list(zip(*rows, strict=True))
        start = np.asarray(initial, dtype=np.float64)
        if start.shape != (n_states,) or abs(start.sum() - 1.0) > 1e-9:
            raise ValueError(f"initial must be a distribution over the {n_states} states")
        return cls(
            n_states=n_states,
            n_actions=n_actions,
            state=np.array(columns[0], dtype=np.int64),
            action=np.array(columns[1], dtype=np.int64),
            probability=np.array(columns[2], dtype=np.float64),
            next_state=np.array(columns[3], dtype=np.int64),
            reward=np.array(columns[4], dtype=np.float64),
            terminated=np.array(columns[5], dtype=bool),
            initial=start,
        )

    def backup(self, values: np.ndarray, gamma: float) -> np.ndarray:
        """``Q(s, a) = sum p * (r + gamma * values[s'] * (not terminated))``, ``(S, A)``."""
        flat = self.state * self.n_actions + self.action
        continued = np.where(self.terminated, 0.0, values[self.next_state])
        weights = self.probability * (self.reward + gamma * continued)
        size = self.n_states * self.n_actions
        return np.bincount(flat, weights=weights, minlength=size).reshape(
            self.n_states, self.n_actions
        )

    def policy_matrix(self, policy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The policy's expected reward per state and its continuing transition matrix."""
        chosen = policy[self.state] == self.action
        expected = np.bincount(
            self.state[chosen],
            weights=(self.probability * self.reward)[chosen],
            minlength=self.n_states,
        )
        going_on = chosen & ~self.terminated
        matrix = np.zeros((self.n_states, self.n_states))
        np.add.at(
            matrix,
            (self.state[going_on], self.next_state[going_on]),
            self.probability[going_on],
        )
        return expected, matrix

    def stochastic_policy_matrix(self, pi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`policy_matrix` of a stochastic policy, ``pi[s, a]`` the probability of ``a``."""
        weight = pi[self.state, self.action] * self.probability
        expected = np.bincount(self.state, weights=weight * self.reward, minlength=self.n_states)
        going_on = ~self.terminated
        matrix = np.zeros((self.n_states, self.n_states))
        np.add.at(matrix, (self.state[going_on], self.next_state[going_on]), weight[going_on])
        return expected, matrix

    def terminal_states(self) -> np.ndarray:
        """bool, ``(n_states,)``: the absorbing states where every action ends the episode.

        Every outcome of every action stays in the state, pays 0 and terminates: the
        book's terminal states (the ends of a random walk, FrozenLake's holes and goal),
        whose value is 0 under every policy; prediction errors leave them out.
        """
        ends = np.ones(self.n_states, dtype=bool)
        absorbing = self.terminated & (self.reward == 0.0) & (self.next_state == self.state)
        np.logical_and.at(ends, self.state, absorbing)
        return ends


def reachable_states(model: TabularModel, pi: np.ndarray) -> np.ndarray:
    """bool, ``(n_states,)``: the states an episode under ``pi`` can be in before it ends.

    From the start distribution's states, along the outcomes of positive probability under
    ``pi`` that do not terminate. (A prediction run measures its error on these: a state no
    episode visits keeps its initial value whatever the algorithm.)

    >>> P = {0: {0: [(1.0, 1, 0.0, False)]}, 1: {0: [(1.0, 1, 0.0, True)]}, 2: {0: [(1.0, 0, 0.0, False)]}}
    >>> model = TabularModel.from_transitions(P, initial=[1.0, 0.0, 0.0])
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
    model: TabularModel, pi: np.ndarray, gamma: float, states: np.ndarray | None = None
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
    >>> model = TabularModel.from_transitions(P, initial=[0, 0, 0, 1, 0, 0, 0])
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
    values: np.ndarray = np.linalg.solve(system, expected[chosen])
    return values


def on_policy_distribution(model: TabularModel, pi: np.ndarray, states: np.ndarray) -> np.ndarray:
    """The on-policy distribution ``mu`` of an episodic task (Sutton & Barto 9.2, eq. 9.2-9.3).

    ``eta(s) = h(s) + sum over s' of eta(s') * P_pi(s', s)``, the expected visits to ``s``
    in an episode (``h`` the start distribution, ``P_pi`` the continuing, undiscounted
    transitions), solved on ``states`` (closed under the policy's continuing outcomes, as
    :func:`reachable_states` are), then ``mu = eta / sum(eta)``: the fraction of the time
    steps spent in each state. On the 5-state walk the middle is visited most:

    >>> P = {s: {a: [(1.0, s + (1 if a else -1), 0.0, s + (1 if a else -1) in (0, 6))]
    ...          for a in (0, 1)} for s in range(1, 6)}
    >>> P = {s: (P.get(s) or {a: [(1.0, s, 0.0, True)] for a in (0, 1)}) for s in range(7)}
    >>> model = TabularModel.from_transitions(P, initial=[0, 0, 0, 1, 0, 0, 0])
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
    visits: np.ndarray = np.linalg.solve(system.T, model.initial[chosen])
    distribution: np.ndarray = visits / visits.sum()
    return distribution


def _never_ending(model: TabularModel, pi: np.ndarray, states: np.ndarray) -> int | None:
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
    model: TabularModel, gamma: float, tolerance: float = 1e-12, max_iterations: int = 1_000_000
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
        q = model.backup(values, gamma)
        updated = q.max(axis=1)
        change = float(np.max(np.abs(updated - values)))
        values = updated
        if change <= tolerance:
            q = model.backup(values, gamma)
            policy = np.argmax(q, axis=1).astype(np.int64)
            return Solution(values, q, policy, float(model.initial @ values), iteration)
    raise ValueError(f"value iteration did not converge in {max_iterations} sweeps")


def finite_horizon(model: TabularModel, horizon: int, gamma: float = 1.0) -> Solution:
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
        q = model.backup(values, gamma)
        updated = q.max(axis=1)
        if np.array_equal(updated, values):  # a fixed point: more steps change nothing
            steps = step
            break
        values = updated
    policy = np.argmax(q, axis=1).astype(np.int64)
    return Solution(values, q, policy, float(model.initial @ values), steps)


def policy_values(
    model: TabularModel, policy: np.ndarray, gamma: float, tolerance: float = 1e-12
) -> Solution:
    """The exact discounted values of a deterministic stationary policy (``gamma < 1``).

    Solves ``(I - gamma P_pi) v = r_pi`` (iterates ``v = r_pi + gamma P_pi v`` to
    ``tolerance`` above :data:`MAX_DENSE_STATES` states).
    """
    if not 0.0 <= gamma < 1.0:
        raise ValueError(f"policy_values needs gamma in [0, 1), got {gamma}")
    policy = np.asarray(policy, dtype=np.int64)
    if model.n_states <= MAX_DENSE_STATES:
        expected, matrix = model.policy_matrix(policy)
        values = np.linalg.solve(np.eye(model.n_states) - gamma * matrix, expected)
        iterations = 1
    else:
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
    model: TabularModel, policy: np.ndarray, horizon: int, gamma: float = 1.0
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
