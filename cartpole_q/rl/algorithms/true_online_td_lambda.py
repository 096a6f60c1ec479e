"""True online TD(lambda) (van Seijen et al. 2016; Sutton & Barto 12.5, tabular features).

Per step: ``delta = r + gamma * V(s') - V(s)`` (``V(s') = 0`` after a terminal state); dutch
traces: every trace decays by ``gamma * lambda``, then ``s``'s grows by ``1 - alpha * gamma *
lambda * z_old(s)``; every traced state moves by ``alpha * (delta + V(s) - v_old) * z`` and
``s`` back by ``alpha * (V(s) - v_old)``; ``v_old = V(s')``. It is true online SARSA(lambda)
with the action 0. The contract: docs/algorithms.md, "Prediction".

>>> import numpy as np
>>> v = np.array([[0.0], [4.0], [0.0]])
>>> memory = true_online_memory(MemoryContext(3, 2, 0.0, {"policy": "random"}, 10))
>>> step(v, memory, (0.0, 0.5), Transition(0, 0, 1.0, 1, False, False),
...     Rates(0.5, 1.0, 0.0), np.random.default_rng(0)) in (0, 1)
True
>>> float(v[0, 0]), float(memory[6][0])  # 0.5 * 5 * 1 - 0.5 * 0; v_old = V(s') = 4
(2.5, 4.0)
"""

from __future__ import annotations

import numpy as np

from cartpole_q.rl.algorithm import Algorithm, MemoryContext, param_index
from cartpole_q.rl.prediction import (
    POLICY,
    POLICY_SOURCE,
    first_policy_action,
    policy_action,
    policy_table,
)
from cartpole_q.rl.tabular import (
    ENDED,
    Memory,
    Params,
    Rates,
    Rng,
    Table,
    Transition,
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
    """The true online update with dutch traces and the ``v_old`` correction."""
    state, reward, next_state = transition.state, transition.reward, transition.next_state
    terminated, truncated = transition.terminated, transition.truncated
    alpha, gamma = rates.alpha, rates.gamma
    policy = memory[0]
    values, states, actions, slots, count = memory[1], memory[2], memory[3], memory[4], memory[5]
    v_old_cell = memory[6]
    lam = params[LAMBDA_AT]
    v_next = 0.0
    if not terminated:
        v_next = value(q, next_state, 0)
    v_s = value(q, state, 0)
    v_old = v_old_cell[0]
    delta = reward + gamma * v_next - v_s
    z_s = trace_dot(q, slots, values, state, 0)
    decay_traces(values, states, actions, slots, count, gamma * lam, 1)
    grow = 1.0 - feature_alpha(q, alpha) * gamma * lam * z_s
    grow_trace(q, values, states, actions, slots, count, state, 0, grow, 1)
    apply_traces(q, values, states, actions, count, alpha, delta + v_s - v_old)
    shift(q, state, 0, -(alpha * (v_s - v_old)))
    v_old_cell[0] = v_next
    if terminated or truncated:
        clear_traces(states, actions, slots, count, 1)
        v_old_cell[0] = 0.0
        return ENDED
    return policy_action(policy, next_state, params, rng)


def true_online_memory(context: MemoryContext) -> tuple[np.ndarray, ...]:
    """The policy, no traces yet, and ``v_old = 0``."""
    return (
        policy_table(context),
        *trace_memory(context.n_states, 1),
        np.zeros(1, dtype=np.float64),
    )


PARAMS = (POLICY, LAMBDA, *POLICY_SOURCE)
"""the parameters, in the order the hooks get them"""
LAMBDA_AT = param_index(PARAMS, LAMBDA)


ALGORITHM = Algorithm(
    name="true_online_td_lambda",
    no_sample_average=TRUE_ONLINE_NOT_AVERAGED,
    description="True online TD(lambda): dutch traces with the exact online lambda-return",
    book="12.5",
    task="prediction",
    step=step,
    start=first_policy_action,
    params=PARAMS,
    memory=true_online_memory,
    memory_names=(
        "policy", "trace_values", "trace_states", "trace_actions", "trace_slots", "trace_count",
        "v_old",
    ),
)  # fmt: skip
