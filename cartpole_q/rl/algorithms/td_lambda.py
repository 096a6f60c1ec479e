"""TD(lambda) prediction (Sutton & Barto 12.2, tabular): TD(0)'s error along eligibility traces.

Per step: ``delta = y - V(s)`` with ``y = r + gamma * V(s')`` (``r`` when terminated); ``s``
gets its trace (``agent.trace``: accumulating, replacing or dutch); every state with a trace
moves by ``alpha * delta * z``; then the traces decay by ``gamma * lambda`` (and are cleared
when the episode ends). The traces are SARSA(lambda)'s with the action 0
(:mod:`cartpole_q.rl.traces`). With ``lambda = 0`` it is TD(0), byte for byte. The contract:
docs/algorithms.md, "Prediction".

>>> import numpy as np
>>> v = np.zeros((3, 1))
>>> memory = td_lambda_memory(MemoryContext(3, 2, 0.0, {"policy": "random"}, 10))
>>> rng = np.random.default_rng(0)
>>> step(v, memory, (0.0, 1.0, 0.0), Transition(0, 0, 0.0, 1, False, False),
...     Rates(0.5, 1.0, 0.0), rng) in (0, 1)
True
>>> step(v, memory, (0.0, 1.0, 0.0), Transition(1, 0, 1.0, 2, True, False),
...     Rates(0.5, 1.0, 0.0), rng)
-1
>>> float(v[0, 0]), float(v[1, 0])  # lambda 1, accumulating: both move by 0.5 * 1
(0.5, 0.5)
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
from cartpole_q.rl.tabular import ENDED, Memory, Params, Rates, Rng, Table, Transition, value
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
    """Give ``s`` its trace, move every traced state, decay the traces."""
    state, reward, next_state = transition.state, transition.reward, transition.next_state
    terminated, truncated = transition.terminated, transition.truncated
    alpha, gamma = rates.alpha, rates.gamma
    policy = memory[0]
    values, states, actions, slots, count = memory[1], memory[2], memory[3], memory[4], memory[5]
    decay, kind = gamma * params[LAMBDA_AT], int(params[TRACE_AT])
    target = reward
    if not terminated:
        target = reward + gamma * value(q, next_state, 0)
    delta = target - value(q, state, 0)
    give_trace(q, values, states, actions, slots, count, state, 0, kind, alpha, 1)
    if terminated or truncated:
        apply_traces(q, values, states, actions, count, alpha, delta)
        clear_traces(states, actions, slots, count, 1)
        return ENDED
    apply_and_decay(q, values, states, actions, slots, count, alpha, delta, decay)
    return policy_action(policy, next_state, params, rng)


def td_lambda_memory(context: MemoryContext) -> tuple[np.ndarray, ...]:
    """The policy and no traces yet (one per state)."""
    return (policy_table(context), *trace_memory(context.n_states, 1))


PARAMS = (POLICY, LAMBDA, TRACE, *POLICY_SOURCE)
"""the parameters, in the order the hooks get them"""
LAMBDA_AT = param_index(PARAMS, LAMBDA)
TRACE_AT = param_index(PARAMS, TRACE)


ALGORITHM = Algorithm(
    name="td_lambda",
    no_sample_average="",  # every step size reaches update and the trace functions
    description="TD(lambda) prediction: the state values of agent.policy with eligibility traces",
    book="12.2",
    task="prediction",
    step=step,
    start=first_policy_action,
    params=PARAMS,
    memory=td_lambda_memory,
    memory_names=(
        "policy", "trace_values", "trace_states", "trace_actions", "trace_slots", "trace_count",
    ),
)  # fmt: skip
