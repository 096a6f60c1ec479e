"""Prediction: learning the state values ``V`` of a fixed policy (Sutton & Barto 5-7, 9, 12).

A prediction algorithm does not choose its actions: the policy it evaluates does
(``agent.policy``), and it learns ``V(x)``, the expected return from ``x`` under that
policy. Its table is ``V`` as a table of one column, ``(n_states, 1)``: ``V(x)`` is
``Q(x, 0)``, so that everything written on table entries (:func:`~cartpole_q.rl.tabular.value`,
:func:`~cartpole_q.rl.tabular.update`, the sparse traces, tile coding's sums) works on it
with the action 0. ``v_table.npy`` holds it. The contract: docs/algorithms.md, "Prediction".

Every prediction algorithm's memory starts with the evaluated policy ``pi`` as a table,
float64 ``(n_states, n_actions)`` (``pi[x, b]`` the probability of ``b`` in ``x``), and its
hooks draw actions with :func:`policy_action`.

>>> import numpy as np
>>> pi = policy_table(MemoryContext(3, 2, 0.0, {"policy": "random"}, 10))
>>> pi.tolist()
[[0.5, 0.5], [0.5, 0.5], [0.5, 0.5]]
>>> policy_action(pi, 0, (0.0,), np.random.default_rng(0)) in (0, 1)
True
"""

from __future__ import annotations

import math

import numpy as np

from cartpole_q.rl.algorithm import MemoryContext, Param
from cartpole_q.rl.tabular import Memory, Params, Rng, Table, compilable, value

POLICIES = ("random", "stick_20", "left")
"""``agent.policy`` values, in the order of their codes: ``random`` is uniform over the
actions (Sutton & Barto's random walks); the others are deterministic rules a world declares
(its profile's ``policies``): ``stick_20`` is Blackjack's "stick on 20 or 21" (Example 5.1),
``left`` the one-state MDP's "always left" (Example 5.5)"""

POLICY = Param(
    "policy", "random",
    "the policy whose values are learnt: random (uniform over the actions), or a rule the "
    "world declares (stick_20: Blackjack's stick on 20 or 21; left: the one-state MDP's)",
    kind="choice", choices=POLICIES,
)  # fmt: skip
"""``agent.policy`` of every prediction algorithm (its first parameter)"""


@compilable
def policy_action(policy: np.ndarray, state: int, params: Params, rng: Rng) -> int:
    """The evaluated policy's action in ``state``.

    ``random``: ``rng.integers(0, n)``; a named rule: the action of probability 1 in the
    table (no draw).
    """
    if params[0] == 0.0:
        return int(rng.integers(0, policy.shape[1]))
    chosen = 0
    for action in range(1, policy.shape[1]):
        if policy[state, action] > policy[state, chosen]:
            chosen = action
    return chosen


@compilable
def first_policy_action(
    q: Table, memory: Memory, params: Params, state: int, epsilon: float, rng: Rng
) -> int:
    """An episode's first action: the evaluated policy's, in the reset state."""
    return policy_action(memory[0], state, params, rng)


def policy_table(context: MemoryContext) -> np.ndarray:
    """``pi`` as a table, one row per state.

    ``random`` gives every action ``1 / n`` in every state; a named rule, 1.0 to its action
    in each state (``context.policy``, from the world's profile).

    Raises:
        ValueError: a named rule without its actions in ``context.policy``.
    """
    if context.params.get("policy", "random") == "random":
        return np.full((context.n_states, context.n_actions), 1.0 / context.n_actions)
    if context.policy is None or len(context.policy) != context.n_states:
        raise ValueError(f"agent.policy {context.params['policy']} needs its actions per state")
    table = np.zeros((context.n_states, context.n_actions))
    table[np.arange(context.n_states), np.asarray(context.policy, dtype=np.int64)] = 1.0
    return table


@compilable
def value_error(q: Table, rows: np.ndarray, values: np.ndarray) -> float:
    """The root mean square error of ``V`` on ``rows`` against their true ``values``.

    ``sqrt(S / k)``: ``S`` sums ``(V(row) - value) * (V(row) - value)`` over the ``k`` rows
    in order, from 0.0 (each state weighs the same, as Sutton & Barto's random walks do).

    >>> import numpy as np
    >>> value_error(np.array([[0.5], [0.5]]), np.array([0, 1]), np.array([0.0, 1.0]))
    0.5
    """
    total = 0.0
    for i in range(rows.shape[0]):
        difference = value(q, rows[i], 0) - values[i]
        total += difference * difference
    return math.sqrt(total / rows.shape[0])
