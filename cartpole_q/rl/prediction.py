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
from cartpole_q.rl.tabular import Memory, Params, Rng, Table, compilable, weights_of

POLICIES = ("random", "stick_20", "left", "greedy", "epsilon_greedy")
"""``agent.policy`` values, in the order of their codes: ``random`` is uniform over the
actions (Sutton & Barto's random walks); ``stick_20`` and ``left`` are deterministic rules a
world declares (its profile's ``policies``): Blackjack's "stick on 20 or 21" (Example 5.1),
the one-state MDP's "always left" (Example 5.5); ``greedy`` and ``epsilon_greedy`` are a
control run's policy (``agent.policy_run``: its ``q_table.npy``), greedy or epsilon-greedy
with ``agent.policy_epsilon``"""

RUN_POLICIES = ("greedy", "epsilon_greedy")
"""the policies a control run's table gives (``agent.policy_run``)"""

DRAWN = POLICIES.index("epsilon_greedy")
"""the code of the one policy whose actions are drawn from its table's probabilities"""

POLICY = Param(
    "policy", "random",
    "the policy whose values are learnt: random (uniform over the actions), a rule the "
    "world declares (stick_20: Blackjack's stick on 20 or 21; left: the one-state MDP's), "
    "or the greedy or epsilon_greedy policy of the run agent.policy_run",
    kind="choice", choices=POLICIES,
)  # fmt: skip
"""``agent.policy`` of every prediction algorithm (its first parameter)"""

POLICY_AT = 0
"""where ``agent.policy`` stands in a prediction algorithm's ``params``: first (the
registry refuses a prediction algorithm that declares it elsewhere)"""

POLICY_RUN = Param(
    "policy_run", "",
    "agent.policy greedy or epsilon_greedy: the run directory whose q_table.npy gives the "
    "greedy actions (a control run on the same env and discretization)",
    kind="str",
)  # fmt: skip
"""``agent.policy_run`` of every prediction algorithm (read when memory is made; the hooks
get 0.0 in its place)"""

POLICY_EPSILON = Param(
    "policy_epsilon", 0.1,
    "agent.policy epsilon_greedy: the probability of a uniform action (pi gives epsilon / n "
    "to every action and 1 - epsilon more to the greedy one)",
    low=0.0, high=1.0,
)  # fmt: skip
"""``agent.policy_epsilon`` of every prediction algorithm"""

POLICY_SOURCE = (POLICY_RUN, POLICY_EPSILON)
"""the keys that say where a run's policy comes from: every prediction algorithm's last two"""


@compilable
def policy_action(policy: np.ndarray, state: int, params: Params, rng: Rng) -> int:
    """The evaluated policy's action in ``state``.

    ``random``: ``rng.integers(0, n)``; ``epsilon_greedy``: one ``u = rng.random()``, then
    the lowest action whose running sum of the row's probabilities exceeds ``u`` (the last
    action of positive probability if rounding leaves none); a rule or ``greedy``: the
    lowest action of the row's largest probability (no draw).
    """
    if params[POLICY_AT] == 0.0:
        return int(rng.integers(0, policy.shape[1]))
    if params[POLICY_AT] == DRAWN:
        return drawn_action(policy, state, rng.random())
    chosen = 0
    for action in range(1, policy.shape[1]):
        if policy[state, action] > policy[state, chosen]:
            chosen = action
    return chosen


@compilable
def drawn_action(policy: np.ndarray, state: int, u: float) -> int:
    """The action a uniform ``u`` in ``[0, 1)`` draws from the row ``state`` of ``policy``.

    The lowest ``b`` with ``u < policy[state, 0] + ... + policy[state, b]`` (summed in
    action order from 0.0); if rounding leaves none, the last ``b`` of positive probability.

    >>> import numpy as np
    >>> row = np.array([[0.05, 0.9, 0.05]])
    >>> [drawn_action(row, 0, u) for u in (0.0, 0.05, 0.94, 0.96, 0.999)]
    [0, 1, 1, 2, 2]
    """
    total = 0.0
    last = 0
    for action in range(policy.shape[1]):
        total += policy[state, action]
        if u < total:
            return action
        if policy[state, action] > 0.0:
            last = action
    return last


@compilable
def first_policy_action(
    q: Table, memory: Memory, params: Params, state: int, epsilon: float, rng: Rng
) -> int:
    """An episode's first action: the evaluated policy's, in the reset state."""
    return policy_action(memory[0], state, params, rng)


def policy_table(context: MemoryContext) -> np.ndarray:
    """``pi`` as a table, one row per state.

    ``random`` gives every action ``1 / n`` in every state; a named rule and ``greedy``, 1.0
    to its action in each state (``context.policy``: the world's rule, or the greedy actions
    of ``agent.policy_run``); ``epsilon_greedy``, ``(1 - epsilon) + epsilon / n`` to the
    greedy action and ``epsilon / n`` to each other (``epsilon`` = ``agent.policy_epsilon``).

    >>> context = MemoryContext(2, 2, 0.0, {"policy": "epsilon_greedy", "policy_epsilon": 0.2}, 10, policy=[1, 0])
    >>> policy_table(context).tolist()
    [[0.1, 0.9], [0.9, 0.1]]

    Raises:
        ValueError: a named rule or a run's policy without its actions in ``context.policy``.
    """
    name = context.params.get("policy", "random")
    if name == "random":
        return np.full((context.n_states, context.n_actions), 1.0 / context.n_actions)
    if context.policy is None or len(context.policy) != context.n_states:
        raise ValueError(f"agent.policy {name} needs its actions per state")
    rows, actions = np.arange(context.n_states), np.asarray(context.policy, dtype=np.int64)
    if name == "epsilon_greedy":
        epsilon = float(context.params.get("policy_epsilon", POLICY_EPSILON.default))
        table = np.full((context.n_states, context.n_actions), epsilon / context.n_actions)
        table[rows, actions] = (1.0 - epsilon) + epsilon / context.n_actions
        return table
    table = np.zeros((context.n_states, context.n_actions))
    table[rows, actions] = 1.0
    return table


@compilable
def value_error(q: Table, rows: np.ndarray, values: np.ndarray) -> float:
    """The root mean square error of ``V`` on the ``k`` states of ``rows`` against ``values``.

    ``rows`` is ``(k, T)``: state ``i``'s estimate is ``0.0 + q[rows[i, 0], 0] + ... +
    q[rows[i, T-1], 0]`` (its row on a table, ``T = 1``; its tiles' weights summed in tiling
    order on tiles). ``sqrt(S / k)``: ``S`` sums ``(estimate - value) * (estimate - value)``
    over the states in order, from 0.0 (each state weighs the same, as Sutton & Barto's random
    walks do).

    >>> import numpy as np
    >>> value_error(np.array([[0.5], [0.5]]), np.array([[0], [1]]), np.array([0.0, 1.0]))
    0.5
    >>> value_error(np.array([[0.25], [0.5]]), np.array([[0, 1]]), np.array([1.0]))  # tiles
    0.25
    """
    weights = weights_of(q)  # the compiled loop on tiles hands (weights, features)
    total = 0.0
    for i in range(rows.shape[0]):
        estimate = 0.0
        for t in range(rows.shape[1]):
            estimate += weights[rows[i, t], 0]
        difference = estimate - values[i]
        total += difference * difference
    return math.sqrt(total / rows.shape[0])
