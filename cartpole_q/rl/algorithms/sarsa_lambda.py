"""SARSA(lambda) (Sutton & Barto 12.7, tabular): SARSA with eligibility traces.

Per step: ``a'`` is drawn for ``s'`` first (as SARSA draws it); ``delta = y - Q(s, a)`` with
``y = r + gamma * Q(s', a')`` (``r`` when terminated); ``(s, a)`` gets its trace
(``agent.trace``: accumulating, replacing or dutch); every pair with a trace moves by
``alpha * delta * z``; then the traces decay by ``gamma * lambda`` (and are cleared when the
episode ends). Traces are sparse (:mod:`cartpole_q.rl.traces`). With ``lambda = 0`` this is
SARSA, byte for byte. The contract: docs/algorithms.md.

>>> import numpy as np
>>> q = np.array([[0.0, 0.0], [2.0, 4.0]])
>>> memory = trace_memory(2, 2)
>>> step(q, memory, (0.5, 1.0, 0.0), Transition(0, 0, 1.0, 1, False, False),
...     Rates(0.5, 1.0, 0.0), np.random.default_rng(0))
1
>>> float(q[0, 0]), float(memory[0][0])  # as SARSA; the trace decayed to 0.5
(2.5, 0.5)
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
    value,
)
from cartpole_q.rl.traces import (
    LAMBDA,
    TRACE,
    apply_and_decay,
    apply_traces,
    clear_traces,
    give_trace,
    trace_memory,
)


def step(
    q: Table, memory: Memory, params: Params, transition: Transition, rates: Rates, rng: Rng
) -> int:
    """Draw ``a'``, give ``(s, a)`` its trace, move every traced pair, decay the traces."""
    state, action, reward = transition.state, transition.action, transition.reward
    next_state, terminated = transition.next_state, transition.terminated
    truncated = transition.truncated
    alpha, gamma, epsilon = rates.alpha, rates.gamma, rates.epsilon
    values, states, actions, slots, count = memory[0], memory[1], memory[2], memory[3], memory[4]
    decay, kind = gamma * params[LAMBDA_AT], int(params[TRACE_AT])
    n_actions = action_count(q)
    next_action = ENDED
    target = reward
    if not terminated:
        next_action = behaviour_action(q, params, next_state, epsilon, rng)
        target = reward + gamma * value(q, next_state, next_action)
    delta = target - value(q, state, action)
    give_trace(q, values, states, actions, slots, count, state, action, kind, alpha, n_actions)
    if terminated or truncated:
        apply_traces(q, values, states, actions, count, alpha, delta)
        clear_traces(states, actions, slots, count, n_actions)
        return ENDED
    apply_and_decay(q, values, states, actions, slots, count, alpha, delta, decay)
    return next_action


def memory(context: MemoryContext) -> tuple[np.ndarray, ...]:
    """No traces yet."""
    return trace_memory(context.n_states, context.n_actions)


PARAMS = (LAMBDA, TRACE)
"""the parameters, in the order the hooks get them"""
LAMBDA_AT = param_index(PARAMS, LAMBDA)
TRACE_AT = param_index(PARAMS, TRACE)


ALGORITHM = Algorithm(
    name="sarsa_lambda",
    no_sample_average="",  # every step size reaches update and the trace functions
    description="SARSA(lambda): SARSA with eligibility traces (agent.lambda, agent.trace)",
    book="12.7",
    step=step,
    params=PARAMS,
    memory=memory,
    memory_names=("trace_values", "trace_states", "trace_actions", "trace_slots", "trace_count"),
)
