"""True online SARSA(lambda) (van Seijen et al. 2016; Sutton & Barto 12.8, tabular features).

Per step: ``a'`` drawn first (as SARSA); ``delta = r + gamma * Q(s', a') - Q(s, a)`` (``Q(s', a')
= 0`` after a terminal state); dutch traces: every trace decays by ``gamma * lambda``, then
``(s, a)``'s grows by ``1 - alpha * gamma * lambda * z_old(s, a)``; every traced pair moves by
``alpha * (delta + Q(s, a) - q_old) * z`` and ``(s, a)`` back by ``alpha * (Q(s, a) - q_old)``;
``q_old = Q(s', a')``. The contract: docs/algorithms.md.

>>> import numpy as np
>>> q = np.array([[0.0, 0.0], [2.0, 4.0]])
>>> memory = true_online_memory(MemoryContext(2, 2, 0.0, {}, 10))
>>> step(q, memory, (0.5, 0.0), Transition(0, 0, 1.0, 1, False, False),
...     Rates(0.5, 1.0, 0.0), np.random.default_rng(0))
1
>>> float(q[0, 0]), float(memory[5][0])  # 0.5 * 5 * 1 - 0.5 * 0; q_old = Q(s', a') = 4
(2.5, 4.0)
"""

from __future__ import annotations

import numpy as np

from cartpole_q.rl.algorithm import Algorithm, MemoryContext, param_index
from cartpole_q.rl.tabular import (
    ENDED,
    Memory,
    Params,
    Rates,
    Rng,
    Table,
    Transition,
    action_count,
    behaviour_action,
    feature_alpha,
    shift,
    value,
)
from cartpole_q.rl.traces import (
    LAMBDA,
    TRUE_ONLINE_NOT_AVERAGED,
    apply_traces,
    clear_traces,
    decay_traces,
    grow_trace,
    trace_dot,
    trace_memory,
)


def step(
    q: Table, memory: Memory, params: Params, transition: Transition, rates: Rates, rng: Rng
) -> int:
    """The true online update with dutch traces and the ``q_old`` correction."""
    state, action, reward = transition.state, transition.action, transition.reward
    next_state, terminated = transition.next_state, transition.terminated
    truncated = transition.truncated
    alpha, gamma, epsilon = rates.alpha, rates.gamma, rates.epsilon
    values, states, actions, slots, count = memory[0], memory[1], memory[2], memory[3], memory[4]
    q_old_cell = memory[5]
    lam = params[LAMBDA_AT]
    n_actions = action_count(q)
    next_action = ENDED
    q_next = 0.0
    if not terminated:
        next_action = behaviour_action(q, params, next_state, epsilon, rng)
        q_next = value(q, next_state, next_action)
    q_sa = value(q, state, action)
    q_old = q_old_cell[0]
    delta = reward + gamma * q_next - q_sa
    z_sa = trace_dot(q, slots, values, state, action)
    decay_traces(values, states, actions, slots, count, gamma * lam, n_actions)
    grow = 1.0 - feature_alpha(q, alpha) * gamma * lam * z_sa
    grow_trace(q, values, states, actions, slots, count, state, action, grow, n_actions)
    apply_traces(q, values, states, actions, count, alpha, delta + q_sa - q_old)
    shift(q, state, action, -(alpha * (q_sa - q_old)))
    q_old_cell[0] = q_next
    if terminated or truncated:
        clear_traces(states, actions, slots, count, n_actions)
        q_old_cell[0] = 0.0
        return ENDED
    return next_action


def true_online_memory(context: MemoryContext) -> tuple[np.ndarray, ...]:
    """No traces yet, and ``q_old = 0``."""
    return (*trace_memory(context.n_states, context.n_actions), np.zeros(1, dtype=np.float64))


PARAMS = (LAMBDA,)
"""the parameters, in the order the hooks get them"""
LAMBDA_AT = param_index(PARAMS, LAMBDA)


ALGORITHM = Algorithm(
    name="true_online_sarsa_lambda",
    no_sample_average=TRUE_ONLINE_NOT_AVERAGED,
    description="True online SARSA(lambda): dutch traces with the exact online lambda-return",
    book="12.8",
    step=step,
    params=PARAMS,
    memory=true_online_memory,
    memory_names=(
        "trace_values", "trace_states", "trace_actions", "trace_slots", "trace_count", "q_old",
    ),
)  # fmt: skip
