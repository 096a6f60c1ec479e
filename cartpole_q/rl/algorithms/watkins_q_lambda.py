"""Watkins's Q(lambda) (Sutton & Barto 12.10): Q-learning with traces, cut after exploring.

Per step: ``delta = y - Q(s, a)`` with ``y = r + gamma * max_b Q(s', b)`` (``r`` when
terminated); ``(s, a)`` gets its trace (``agent.trace``); every pair with a trace moves by
``alpha * delta * z``; then ``a'`` is drawn from the updated table: if it is greedy (its value
is the largest, ties included) the traces decay by ``gamma * lambda``, else they are cleared,
since the greedy policy's return no longer follows. With ``lambda = 0`` this is Q-learning,
byte for byte. The contract: docs/algorithms.md.

>>> import numpy as np
>>> q = np.array([[0.0, 0.0], [2.0, 4.0]])
>>> memory = trace_memory(2, 2)
>>> step(q, memory, (0.5, 1.0, 0.0), Transition(0, 0, 1.0, 1, False, False),
...     Rates(0.5, 1.0, 0.0), np.random.default_rng(0))
1
>>> float(q[0, 0]), int(memory[4][0])  # as Q-learning; a greedy a' keeps the trace
(2.5, 1)
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
    best_value,
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
    """Move every traced pair toward the greedy target; draw; decay or cut the traces."""
    state, action, reward = transition.state, transition.action, transition.reward
    next_state, terminated = transition.next_state, transition.terminated
    truncated = transition.truncated
    alpha, gamma, epsilon = rates.alpha, rates.gamma, rates.epsilon
    values, states, actions, slots, count = memory[0], memory[1], memory[2], memory[3], memory[4]
    decay, kind = gamma * params[LAMBDA_AT], int(params[TRACE_AT])
    n_actions = action_count(q)
    target = reward
    if not terminated:
        target = reward + gamma * best_value(q, next_state)
    delta = target - value(q, state, action)
    give_trace(q, values, states, actions, slots, count, state, action, kind, alpha, n_actions)
    if terminated or truncated:
        apply_traces(q, values, states, actions, count, alpha, delta)
        clear_traces(states, actions, slots, count, n_actions)
        return ENDED
    # Decayed in the same pass; cleared below instead when the next action explores.
    apply_and_decay(q, values, states, actions, slots, count, alpha, delta, decay)
    next_action = behaviour_action(q, params, next_state, epsilon, rng)
    if value(q, next_state, next_action) != best_value(q, next_state):
        clear_traces(states, actions, slots, count, n_actions)
    return next_action


def memory(context: MemoryContext) -> tuple[np.ndarray, ...]:
    """No traces yet."""
    return trace_memory(context.n_states, context.n_actions)


PARAMS = (LAMBDA, TRACE)
"""the parameters, in the order the hooks get them"""
LAMBDA_AT = param_index(PARAMS, LAMBDA)
TRACE_AT = param_index(PARAMS, TRACE)


ALGORITHM = Algorithm(
    name="watkins_q_lambda",
    no_sample_average="",  # every step size reaches update and the trace functions
    description="Watkins's Q(lambda): Q-learning with traces, cut after an exploratory action",
    book="12.10",
    step=step,
    params=PARAMS,
    memory=memory,
    memory_names=("trace_values", "trace_states", "trace_actions", "trace_slots", "trace_count"),
)
