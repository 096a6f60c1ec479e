"""Dynamic programming on a finite model (Sutton & Barto, chapters 3-4), with its sweeps recorded.

A :class:`DenseModel` is a finite MDP as dense arrays: ``transition[s, a, s']``, the
probability of going on from ``s`` to ``s'`` under ``a`` (outcomes that end the episode are
left out, so a row sums to 1 minus the probability of ending); ``reward[s, a]``, the
expected reward of taking ``a`` in ``s``; ``allowed[s, a]``, the actions the world offers
in ``s`` (the gambler's stakes up to ``min(s, 100 - s)``, Jack's moves of the cars there).
A backup is then ``q = reward + gamma * transition @ v``, exactly the book's
``sum p(s', r | s, a) [r + gamma v(s')]``.

- :func:`evaluate_sweeps`: iterative policy evaluation of a stochastic policy (section 4.1),
  the values after each sweep;
- :func:`value_iteration_sweeps`: value iteration (section 4.4), the values after each
  sweep, then the greedy policy;
- :func:`policy_iteration`: policy iteration (section 4.3), each policy and its exact values.

**Sweeps.** ``synchronous`` (the default) computes every state's new value from the
previous sweep's values (two arrays): Figure 4.1's values at k = 1, 2, 3 are those of
synchronous sweeps (-1.7 at k = 2 next to a terminal state, which an in-place sweep would
not give). ``in_place`` updates the states one at a time in ascending order, each from the
latest values (one array, the book's pseudocode boxes, and Zhang's gambler).

**Stopping.** A sweep loop stops after the first sweep whose largest change of a value,
``max |v_k(s) - v_{k-1}(s)|``, is below ``tolerance`` (the book's ``Delta < theta``), or
fails after ``max_sweeps``.

**Ties.** :func:`greedy` takes, in each state, the allowed actions whose value is within
``tie_tolerance`` of the best allowed one as tied (float sums of equal returns differ in
their last bits), and chooses the lowest of them. Policy iteration keeps a state's action
while it is still among the tied best (so that it stops: Exercise 4.4), else takes the
lowest.

A two-state world: state 0 has ended; from state 1 every step costs 1 and ends the
episode with probability 1/2, so its value is ``v = -1 + v / 2 = -2``:

>>> transition = np.zeros((2, 1, 2))
>>> transition[1, 0, 1] = 0.5
>>> model = DenseModel(transition, np.array([[0.0], [-1.0]]))
>>> sweeps = evaluate_sweeps(model, uniform_policy(model), 1.0, tolerance=1e-12)
>>> sweeps.values[:3].tolist(), round(float(sweeps.values[-1, 1]), 9)
([[0.0, 0.0], [0.0, -1.0], [0.0, -1.5]], -2.0)
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from cartpole_q.rl.value_iteration import TabularModel

SWEEP_ORDERS = ("synchronous", "in_place")
"""how a sweep updates the states: from the previous sweep's values, or one by one in place"""


@dataclass(frozen=True)
class DenseModel:
    """A finite MDP as dense arrays (see the module's notes)."""

    transition: np.ndarray
    """float64, ``(S, A, S)``: the probability of going on to ``s'`` (ending outcomes left out)"""
    reward: np.ndarray
    """float64, ``(S, A)``: the expected reward of ``a`` in ``s``"""
    allowed: np.ndarray = field(default_factory=lambda: np.zeros((0, 0), dtype=bool))
    """bool, ``(S, A)``: the actions offered in each state (empty: every action everywhere)"""

    def __post_init__(self) -> None:
        states, actions = self.reward.shape
        if self.transition.shape != (states, actions, states):
            raise ValueError(
                f"transition has shape {self.transition.shape}, not {(states, actions, states)}"
            )
        if self.allowed.size == 0:
            object.__setattr__(self, "allowed", np.ones((states, actions), dtype=bool))
        if self.allowed.shape != (states, actions) or not self.allowed.any(axis=1).all():
            raise ValueError("allowed must be (states, actions) with an action in every state")

    @property
    def n_states(self) -> int:
        """The number of states."""
        return int(self.reward.shape[0])

    @property
    def n_actions(self) -> int:
        """The number of actions."""
        return int(self.reward.shape[1])

    @classmethod
    def from_tabular(cls, model: TabularModel, allowed: np.ndarray | None = None) -> DenseModel:
        """The dense form of a :class:`TabularModel` (Gymnasium's ``P[s][a]`` lists)."""
        states, actions = model.n_states, model.n_actions
        transition = np.zeros((states, actions, states))
        going_on = ~model.terminated
        np.add.at(
            transition,
            (model.state[going_on], model.action[going_on], model.next_state[going_on]),
            model.probability[going_on],
        )
        reward = np.zeros((states, actions))
        np.add.at(reward, (model.state, model.action), model.probability * model.reward)
        shown = np.zeros((0, 0), dtype=bool) if allowed is None else np.asarray(allowed, bool)
        return cls(transition, reward, shown)

    def q_values(self, values: np.ndarray, gamma: float) -> np.ndarray:
        """``q(s, a) = reward(s, a) + gamma * sum_s' transition(s, a, s') v(s')``, ``(S, A)``."""
        backed: np.ndarray = self.reward + gamma * (self.transition @ values)
        return backed

    def state_q(self, state: int, values: np.ndarray, gamma: float) -> np.ndarray:
        """One state's action values, ``(A,)`` (an in-place sweep's update)."""
        backed: np.ndarray = self.reward[state] + gamma * (self.transition[state] @ values)
        return backed


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


def uniform_policy(model: DenseModel) -> np.ndarray:
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
    model: DenseModel,
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
            q = model.q_values(previous, gamma)
            values = (q * policy).sum(axis=1) if policy is not None else (q + blocked).max(axis=1)
        else:
            for state in range(model.n_states):
                q_state = model.state_q(state, values, gamma)
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
    model: DenseModel,
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
    model: DenseModel,
    gamma: float,
    tolerance: float = 1e-10,
    max_sweeps: int = 100_000,
    order: str = "synchronous",
) -> Sweeps:
    """Value iteration from zero, every sweep recorded: ``v_{k+1}(s) = max_a q_k(s, a)``.

    The maximum is over the allowed actions. Its greedy policy: :func:`greedy` of
    ``model.q_values(sweeps.values[-1], gamma)``.

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


def policy_values(model: DenseModel, actions: np.ndarray, gamma: float) -> np.ndarray:
    """The exact values of a deterministic policy: ``(I - gamma P_pi) v = r_pi``.

    Raises:
        ValueError: the system is singular (``gamma = 1`` and a state from which the policy
            never ends the episode).
    """
    rows = np.arange(model.n_states)
    chosen = np.asarray(actions, dtype=np.int64)
    system = np.eye(model.n_states) - gamma * model.transition[rows, chosen]
    try:
        values: np.ndarray = np.linalg.solve(system, model.reward[rows, chosen])
    except np.linalg.LinAlgError:
        raise ValueError(
            "the policy's values are not finite: with gamma 1 it never ends the episode from "
            "some state; use gamma below 1 or a policy that ends every episode"
        ) from None
    return values


def policy_values_stochastic(model: DenseModel, policy: np.ndarray, gamma: float) -> np.ndarray:
    """The exact values of a stochastic policy ``policy[s, a]``: ``(I - gamma P_pi) v = r_pi``.

    Raises:
        ValueError: the system is singular (as :func:`policy_values`).
    """
    pi = np.asarray(policy, dtype=np.float64)
    matrix = np.einsum("sa,sat->st", pi, model.transition)
    try:
        values: np.ndarray = np.linalg.solve(
            np.eye(model.n_states) - gamma * matrix, (pi * model.reward).sum(axis=1)
        )
    except np.linalg.LinAlgError:
        raise ValueError(
            "the policy's values are not finite: with gamma 1 it may never end the episode "
            "from some state"
        ) from None
    return values


def policy_iteration(
    model: DenseModel,
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
    policies, values = [policy.copy()], [policy_values(model, policy, gamma)]
    for _ in range(max_iterations):
        tied = tied_best(model.q_values(values[-1], gamma), model.allowed, tie_tolerance)
        improved = np.where(tied[rows, policy], policy, np.argmax(tied, axis=1))
        if np.array_equal(improved, policy):
            return PolicyIteration(np.array(policies), np.array(values))
        policy = improved.astype(np.int64)
        policies.append(policy.copy())
        values.append(policy_values(model, policy, gamma))
    raise ValueError(f"policy iteration did not settle in {max_iterations} improvements")
