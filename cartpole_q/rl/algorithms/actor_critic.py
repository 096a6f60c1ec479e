"""Actor-critic with eligibility traces (Sutton & Barto 13.5; Barto, Sutton & Anderson 1983).

The **actor** is the learned table itself: ``Q`` holds action *preferences* ``theta(s, a)``,
and the policy is their softmax, ``pi(a | s) = exp(theta(s, a)) / sum_b exp(theta(s, b))``
(so ``q_table.npy`` is a policy table, its greedy action the most probable one, which
``eval`` plays). The **critic** is a state-value table ``v(s)`` in memory. Per step, with
``delta = r + gamma v(s') - v(s)`` (``v(s') = 0`` when terminated): the critic's trace
``z_w = gamma lambda_w z_w + grad v(s)``, the actor's ``z_theta = gamma lambda_theta
z_theta + I grad ln pi(a | s)``, then ``v += alpha_w delta z_w`` and ``theta += alpha delta
z_theta``, ``I = gamma I``; the next action is drawn from ``pi(. | s')``. With one-hot
features ``grad ln pi(a | s)`` is ``1 - pi(a | s)`` at ``(s, a)`` and ``-pi(b | s)`` at
each other ``(s, b)``. Exploration is the softmax's own: ``agent.epsilon`` is not used.
Traces are sparse (:mod:`cartpole_q.rl.traces`) and cleared when an episode ends. The
contract: docs/algorithms.md.

>>> import numpy as np
>>> q = np.zeros((2, 2))
>>> memory = actor_critic_memory(2, 2)
>>> first = start(q, memory, (0.1, 0.0, 0.0, 0.0), 0, 0.0, np.random.default_rng(0))
>>> step(q, memory, (0.1, 0.0, 0.0, 0.0), Transition(0, first, 1.0, 1, True, False),
...     Rates(0.5, 1.0, 0.0), np.random.default_rng(0))
-1
>>> first, float(memory[0][0, 0]), q[0].tolist()  # v(0) = 0.1 * 1; theta(0, 1) by 0.5 * (1 - 0.5)
(1, 0.1, [-0.25, 0.25])
"""

from __future__ import annotations

import math

import numpy as np

from cartpole_q.rl.algorithm import Algorithm, MemoryContext, Param, param_index
from cartpole_q.rl.tabular import (
    ENDED,
    Memory,
    Params,
    Rates,
    Rng,
    Table,
    Transition,
    action_count,
    compilable,
)
from cartpole_q.rl.traces import apply_and_decay, apply_traces, clear_traces, trace_slot

ALPHA_W = Param("alpha_w", 0.1, "the critic's step size alpha^w", low=0.0, low_open=True)
LAMBDA_THETA = Param("lambda_theta", 0.9, "the actor's trace decay lambda^theta", low=0.0, high=1.0)
LAMBDA_W = Param("lambda_w", 0.9, "the critic's trace decay lambda^w", low=0.0, high=1.0)
V_INIT = Param("v_init", 0.0, "the critic's initial value of every state")
PARAMS = (ALPHA_W, LAMBDA_THETA, LAMBDA_W, V_INIT)
"""the parameters, in the order the hooks get them"""
ALPHA_W_AT = param_index(PARAMS, ALPHA_W)
LAMBDA_THETA_AT = param_index(PARAMS, LAMBDA_THETA)
LAMBDA_W_AT = param_index(PARAMS, LAMBDA_W)

CRITIC, DISCOUNT, CHANCES = 0, 1, 2
"""memory: ``v`` as ``(n_states, 1)``, ``I`` as ``(1,)``, room for ``π(· | s)``; then the
critic's five trace arrays (from 3) and the actor's (from 8)"""
CRITIC_TRACES, ACTOR_TRACES = 3, 8


@compilable
def softmax(q: Table, state: int, out: np.ndarray) -> None:
    """``out = π(· | state)``: the softmax of the preferences ``q[state]``, from the largest."""
    n = action_count(q)
    largest = q[state, 0]
    for b in range(1, n):
        if q[state, b] > largest:
            largest = q[state, b]
    total = 0.0
    for b in range(n):
        out[b] = math.exp(q[state, b] - largest)
        total = total + out[b]
    for b in range(n):
        out[b] = out[b] / total


@compilable
def draw(q: Table, memory: Memory, state: int, rng: Rng) -> int:
    """An action from ``π(· | state)``: one ``rng.random()`` against the running sums."""
    chances = memory[CHANCES]
    softmax(q, state, chances)
    u = rng.random()
    running = 0.0
    last = 0
    for b in range(chances.shape[0]):
        running = running + chances[b]
        if chances[b] > 0.0:
            last = b
        if u < running:
            return b
    return last


@compilable
def start(q: Table, memory: Memory, params: Params, state: int, epsilon: float, rng: Rng) -> int:
    """``I = 1``; the first action drawn from ``π(· | state)``."""
    memory[DISCOUNT][0] = 1.0
    return draw(q, memory, state, rng)


@compilable
def step(
    q: Table, memory: Memory, params: Params, transition: Transition, rates: Rates, rng: Rng
) -> int:
    """The traces, then ``v`` and ``θ`` by ``δ``; the next action from ``π(· | s')``."""
    state, action, reward = transition.state, transition.action, transition.reward
    next_state, terminated = transition.next_state, transition.terminated
    truncated = transition.truncated
    alpha, gamma = rates.alpha, rates.gamma
    v, discount, chances = memory[CRITIC], memory[DISCOUNT], memory[CHANCES]
    w_values, w_states, w_actions, w_slots, w_count = memory[3], memory[4], memory[5], memory[6], memory[7]  # fmt: skip
    t_values, t_states, t_actions, t_slots, t_count = memory[8], memory[9], memory[10], memory[11], memory[12]  # fmt: skip
    n = action_count(q)
    later = 0.0 if terminated else v[next_state, 0]
    delta = (reward + gamma * later) - v[state, 0]
    where = trace_slot(w_values, w_states, w_actions, w_slots, w_count, state, 0, 1)
    w_values[where] = w_values[where] + 1.0
    softmax(q, state, chances)
    for b in range(n):
        gradient = (1.0 if b == action else 0.0) - chances[b]
        where = trace_slot(t_values, t_states, t_actions, t_slots, t_count, state, b, n)
        t_values[where] = t_values[where] + discount[0] * gradient
    if terminated or truncated:
        apply_traces(v, w_values, w_states, w_actions, w_count, params[ALPHA_W_AT], delta)
        apply_traces(q, t_values, t_states, t_actions, t_count, alpha, delta)
        clear_traces(w_states, w_actions, w_slots, w_count, 1)
        clear_traces(t_states, t_actions, t_slots, t_count, n)
        return ENDED
    apply_and_decay(v, w_values, w_states, w_actions, w_slots, w_count, params[ALPHA_W_AT],
                    delta, gamma * params[LAMBDA_W_AT])  # fmt: skip
    apply_and_decay(q, t_values, t_states, t_actions, t_slots, t_count, alpha, delta,
                    gamma * params[LAMBDA_THETA_AT])  # fmt: skip
    discount[0] = gamma * discount[0]
    return draw(q, memory, next_state, rng)


def actor_critic_memory(
    n_states: int, n_actions: int, v_init: float = 0.0
) -> tuple[np.ndarray, ...]:
    """``v = v_init``, ``I = 1``, room for ``π``, no traces."""
    return (
        np.full((n_states, 1), float(v_init)), np.ones(1), np.zeros(n_actions),
        np.zeros(n_states), np.zeros(n_states, dtype=np.int64),
        np.zeros(n_states, dtype=np.int64), np.full(n_states, -1, dtype=np.int64),
        np.zeros(1, dtype=np.int64),
        np.zeros(n_states * n_actions), np.zeros(n_states * n_actions, dtype=np.int64),
        np.zeros(n_states * n_actions, dtype=np.int64),
        np.full(n_states * n_actions, -1, dtype=np.int64), np.zeros(1, dtype=np.int64),
    )  # fmt: skip


def memory(context: MemoryContext) -> tuple[np.ndarray, ...]:
    """The critic at ``agent.v_init``, no traces."""
    return actor_critic_memory(
        context.n_states, context.n_actions, float(context.params[V_INIT.key])
    )


ALGORITHM = Algorithm(
    name="actor_critic",
    description="actor-critic with eligibility traces: a softmax policy on the table's "
    "preferences and a critic v(s) (agent.alpha_w, agent.lambda_theta, agent.lambda_w, "
    "agent.v_init); "
    "agent.epsilon is not used",
    book="13.5",
    step=step,
    start=start,
    params=PARAMS,
    memory=memory,
    memory_names=(
        "critic_values",
        "discount",
        "probabilities",
        "critic_trace_values",
        "critic_trace_states",
        "critic_trace_actions",
        "critic_trace_slots",
        "critic_trace_count",
        "actor_trace_values",
        "actor_trace_states",
        "actor_trace_actions",
        "actor_trace_slots",
        "actor_trace_count",
    ),
    not_on_tiles="its softmax policy and critic are tables of states (the tile variant is "
    "not written)",
    no_sample_average="the actor moves by a policy gradient, not toward a target: a sample "
    "average of its steps has no meaning",
)
