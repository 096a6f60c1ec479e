"""Acting on and learning a Q-table: the small functions every algorithm is written with.

Plain Python that numba compiles: the engines compile every function marked
:func:`compilable` (and the algorithms' hooks, which call them), so this module, and the
algorithms, import neither numba nor gymnasium, and run as they are in a doctest.

The Q-table is addressed as a 2-D ``(n_states, n_actions)`` array: the C-order view of the
``(*bins, n_actions)`` table that is saved. The functions index single entries instead of
taking row views: a view costs two atomic reference-count updates in compiled code, and
numba's ``np.max`` of a two-entry row costs more than a whole CartPole step. Every argmax is
the lowest action among the maxima, as ``np.argmax``.

The algorithms read and change entries only through :func:`value`, :func:`shift` (and
:func:`update`, written on them), :func:`action_count` and the trace functions: on tile
coding (:mod:`cartpole_q.rl.tiles`) the engines compile them with tiles variants of those
few, and every algorithm runs on tiles unchanged.

Epsilon-greedy, stated precisely: at ``epsilon <= 0`` greedy, nothing drawn; at
``epsilon >= 1`` ``rng.integers(0, n_actions)``; otherwise ``rng.random() < epsilon``
decides, then ``rng.integers(0, n_actions)`` when exploring.

>>> import numpy as np
>>> q = np.array([[1.0, 3.0, 3.0]])
>>> best_action(q, 0), best_value(q, 0)
(1, 3.0)
>>> update(q, 0, 0, 2.0, 0.5)
>>> float(q[0, 0])
1.5
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, NamedTuple, TypeVar

import numpy as np

ENDED = -1
"""the next action a step returns when the episode has ended"""

Table = np.ndarray
"""a Q-table (or a table of its shape) as the hooks see it: float64 ``(n_states, n_actions)``"""
Memory = tuple[np.ndarray, ...]
"""an algorithm's memory: the arrays :attr:`~cartpole_q.rl.algorithm.Algorithm.memory` made"""
Params = tuple[float, ...]
"""an algorithm's parameters as floats, in :attr:`~cartpole_q.rl.algorithm.Algorithm.params` order"""
Rng = np.random.Generator
"""the agent's random generator (numba compiles numpy's ``Generator`` methods)"""
TIE_BREAKS = ("lowest", "random")
"""``agent.tie_break``: which of equally valued best actions epsilon-greedy exploits"""
RANDOM_TIES = 1.0
"""``agent.tie_break: random`` as the hooks get it (the last of their parameters)"""


class Transition(NamedTuple):
    """One step of an episode, as an algorithm's ``step`` hook gets it.

    A named record, not six positional arguments: numba compiles it as a tuple that the
    inlined hook reads field by field, which costs nothing at run time.
    """

    state: int
    """the row the action was taken in"""
    action: int
    """the action taken"""
    reward: float
    """the reward of the step"""
    next_state: int
    """the row of the observation after it"""
    terminated: bool
    """the episode ended in a terminal state (no bootstrap)"""
    truncated: bool
    """the episode was cut by its time limit (a step that is only truncated bootstraps)"""


class Rates(NamedTuple):
    """The episode's step size, discount and exploration, as the ``step`` and ``end`` hooks get them."""

    alpha: Any
    """the step size (a float); under ``agent.alpha: sample_average`` the table of update
    counts (see :func:`averaged_update`)"""
    gamma: float
    """the discount"""
    epsilon: float
    """the episode's exploration rate"""


Function = TypeVar("Function", bound=Callable[..., Any])


def compilable(function: Function) -> Function:
    """Mark a plain function as one the engines compile with the algorithms that call it.

    The engines compile an algorithm's hooks with numba; a plain function they call must
    be compiled too, and this mark says it may be. It changes nothing else.
    """
    function.__compilable__ = True  # type: ignore[attr-defined]
    return function


def averaged_variant(original: Callable[..., Any]) -> Callable[[Function], Function]:
    """Mark the function below as ``original``'s version under sample averages.

    With ``agent.alpha: sample_average`` the engines compile every hook with each
    compilable helper replaced by its averaged variant where it has one, and pass the
    table of update counts where a hook's ``alpha`` goes: :func:`update` is the one such
    helper, so an algorithm whose every step size reaches :func:`update` averages
    unchanged.
    """

    def register(function: Function) -> Function:
        original.__averaged__ = function  # type: ignore[attr-defined]
        return compilable(function)

    return register


def tiles_variant(original: Callable[..., Any]) -> Callable[[Function], Function]:
    """Mark the function below as ``original``'s version for tile-coded tables.

    On tiles (``discretization.tilings > 1``) the engines compile every hook with each
    compilable helper replaced by its tiles variant where it has one: ``value``, ``shift``
    and the trace functions are the few that touch table entries, and everything written
    on them (greedy actions, updates, expectations) works on tiles unchanged.
    """

    def register(function: Function) -> Function:
        original.__tiled__ = function  # type: ignore[attr-defined]
        return compilable(function)

    return register


@compilable
def action_count(q: Table) -> int:
    """How many actions the table has."""
    n: int = q.shape[1]
    return n


@compilable
def value(q: Table, state: int, action: int) -> float:
    """``Q(state, action)``: the table's entry (a tile-coded table's sum over its tiles)."""
    entry: float = q[state, action]
    return entry


@compilable
def shift(q: Table, state: int, action: int, amount: float) -> None:
    """``Q(state, action) = Q(state, action) + amount`` (tiles: each tile by ``amount / T``)."""
    q[state, action] = q[state, action] + amount


@compilable
def feature_alpha(q: Table, alpha: float) -> float:
    """The step size of one feature: ``alpha`` (tiles: ``alpha / T``)."""
    return alpha


@compilable
def visit(visits: np.ndarray, q: Table, state: int, action: int) -> None:
    """Count a visit of ``(state, action)`` (tiles: of each of its tiles)."""
    visits[state, action] += 1


@compilable
def weights_of(q: Table) -> np.ndarray:
    """The table's entries as one 2-D array: ``q`` itself (on tiles, its tiles' weights)."""
    return q


@compilable
def with_weights(q: Table, weights: Table) -> Table:
    """Another table of ``q``'s shape addressed as ``q`` is (Double Q-learning's ``B``)."""
    return weights


@compilable
def best_action(q: Table, state: int) -> int:
    """``argmax_a Q(state, a)``, the lowest action on ties."""
    best = 0
    best_value_so_far = value(q, state, 0)
    for action in range(1, action_count(q)):
        entry = value(q, state, action)
        if entry > best_value_so_far:
            best, best_value_so_far = action, entry
    return best


@compilable
def best_value(q: Table, state: int) -> float:
    """``max_a Q(state, a)``."""
    best = value(q, state, 0)
    for action in range(1, action_count(q)):
        entry = value(q, state, action)
        if entry > best:
            best = entry
    return float(best)


@compilable
def epsilon_greedy(q: Table, state: int, epsilon: float, rng: Rng) -> int:
    """A uniform random action with probability ``epsilon``, else the greedy one."""
    if epsilon >= 1.0 or (epsilon > 0.0 and rng.random() < epsilon):
        return int(rng.integers(0, action_count(q)))
    return best_action(q, state)


@compilable
def greedy_and_ties(q: Table, state: int) -> tuple[int, float, int]:
    """The lowest best action, the largest value and how many actions have it, in one pass.

    Comparisons with NaN are false: a NaN at action 0 keeps it best, alone. One pass instead of
    :func:`best_action` and a count: compiled code inlines every call, so fewer calls
    compile faster.
    """
    greedy, best, tied = 0, value(q, state, 0), 1
    for action in range(1, action_count(q)):
        entry = value(q, state, action)
        if entry > best:
            greedy, best, tied = action, entry, 1
        elif entry == best:
            tied += 1
    return greedy, best, tied


@compilable
def tied_best_action(q: Table, state: int, rng: Rng) -> int:
    """One of the actions with the largest ``Q(state, .)``, uniformly at random.

    Among the ``k`` actions whose value equals the largest, the ``rng.integers(0, k)``-th in
    action order; nothing is drawn when one action is best (or none compares equal: NaN).
    """
    greedy, best, tied = greedy_and_ties(q, state)
    if tied <= 1:
        return greedy
    pick = int(rng.integers(0, tied))
    for action in range(greedy, action_count(q)):
        if value(q, state, action) == best:
            if pick == 0:
                return action
            pick -= 1
    return greedy


@compilable
def random_ties(params: Params) -> bool:
    """Whether ``agent.tie_break`` is ``random``: the last of the hooks' parameters."""
    return params[-1] == RANDOM_TIES


@compilable
def behaviour_action(q: Table, params: Params, state: int, epsilon: float, rng: Rng) -> int:
    """Epsilon-greedy as :func:`epsilon_greedy` draws it, ties broken as ``agent.tie_break`` says.

    With ``agent.tie_break: random`` the greedy branch takes :func:`tied_best_action` (after
    the exploration draw); with ``lowest`` it is :func:`epsilon_greedy` exactly.
    """
    if epsilon >= 1.0 or (epsilon > 0.0 and rng.random() < epsilon):
        return int(rng.integers(0, action_count(q)))
    if random_ties(params):
        return tied_best_action(q, state, rng)
    return best_action(q, state)


@compilable
def update(q: Table, state: int, action: int, target: float, alpha: float) -> None:
    """``Q(s, a) = Q(s, a) + alpha * (target - Q(s, a))`` (tiles: each tile by a T-th)."""
    shift(q, state, action, alpha * (target - value(q, state, action)))


@averaged_variant(update)
def averaged_update(q: Table, state: int, action: int, target: float, counts: np.ndarray) -> None:
    """:func:`update` under ``agent.alpha: sample_average``: a step of ``1 / N(s, a)``.

    ``counts`` is the table of update counts (float64, ``q``'s shape), which the engines
    pass where a hook's ``alpha`` goes: ``N(s, a) = N(s, a) + 1.0``, then ``Q(s, a) =
    Q(s, a) + (target - Q(s, a)) / N(s, a)``, the division last (Monte Carlo's
    ``agent.update: sample_average`` exactly). So the entry is the average of every target
    it was updated toward (``q_init`` weighs nothing).

    >>> q, counts = np.array([[5.0]]), np.zeros((1, 1))
    >>> averaged_update(q, 0, 0, 1.0, counts); averaged_update(q, 0, 0, 2.0, counts)
    >>> float(q[0, 0]), float(counts[0, 0])
    (1.5, 2.0)
    """
    counts[state, action] = counts[state, action] + 1.0
    shift(q, state, action, (target - value(q, state, action)) / counts[state, action])


@compilable
def expected_value(q: Table, state: int, epsilon: float) -> float:
    """``(1 - epsilon) * Q(s, g) + (epsilon / n) * S``: ``Q(s, .)`` under epsilon-greedy.

    ``g`` is the greedy action of ``s``, ``S = Q(s, 0) + Q(s, 1) + ...`` summed in action
    order (Expected SARSA's and tree backup's expectation).
    """
    n_actions = action_count(q)
    total = value(q, state, 0)
    for action in range(1, n_actions):
        total += value(q, state, action)
    greedy = best_action(q, state)
    return float((1.0 - epsilon) * value(q, state, greedy) + (epsilon / n_actions) * total)


@compilable
def policy_probability(action: int, greedy: int, epsilon: float, n_actions: int) -> float:
    """``pi(action | x)`` of epsilon-greedy, ``greedy`` being ``x``'s greedy action.

    >>> policy_probability(1, 1, 0.2, 2), policy_probability(0, 1, 0.2, 2)
    (0.9, 0.1)
    """
    if action == greedy:
        return (1.0 - epsilon) + epsilon / n_actions
    return epsilon / n_actions


@compilable
def behaviour_probability(
    q: Table, params: Params, state: int, action: int, epsilon: float
) -> float:
    """``b(action | state)``: the probability that :func:`behaviour_action` takes ``action``.

    Under the tie rule in force: with ``lowest`` it is :func:`policy_probability` of the
    greedy action; with ``random`` the greedy branch's share ``1 - epsilon`` is split among
    the ``k`` tied best actions, ``(1 - epsilon) / k + epsilon / n`` for each of them (the
    greedy action alone when ``k = 1``, so it is then byte for byte the ``lowest`` rule's
    value). Positive for every action the behaviour can take.

    >>> import numpy as np
    >>> q = np.array([[1.0, 1.0, 0.0]])
    >>> behaviour_probability(q, (1.0,), 0, 1, 0.0), behaviour_probability(q, (0.0,), 0, 1, 0.0)
    (0.5, 0.0)
    >>> behaviour_probability(q, (1.0,), 0, 2, 0.3)
    0.09999999999999999
    """
    n_actions = action_count(q)
    if not random_ties(params):
        return policy_probability(action, best_action(q, state), epsilon, n_actions)
    greedy, best, tied = greedy_and_ties(q, state)
    among = action == greedy if tied <= 1 else value(q, state, action) == best
    if among:
        return (1.0 - epsilon) / tied + epsilon / n_actions
    return epsilon / n_actions


@compilable
def first_action(
    q: Table, memory: Memory, params: Params, state: int, epsilon: float, rng: Rng
) -> int:
    """The default first action of an episode: epsilon-greedy on ``Q``."""
    return behaviour_action(q, params, state, epsilon, rng)


@compilable
def no_episode_end(q: Table, memory: Memory, params: Params, rates: Rates, rng: Rng) -> None:
    """The default end of an episode: nothing (one-step methods learn as they go)."""
