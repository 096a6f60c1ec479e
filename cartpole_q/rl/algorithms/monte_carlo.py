"""On-policy first-visit Monte Carlo control, epsilon-soft (Sutton & Barto 5.4).

The episode is recorded; ``Q`` does not change during it. When it ends, its returns are
computed backwards, ``G = gamma * G + R``, and each pair's first visit moves ``Q`` toward its
return: by the sample average (``agent.update: sample_average``, a count per pair) or by
``alpha`` (``constant_alpha``). After a time limit the return does not stop: the tail is
bootstrapped from ``Q`` with the epsilon-greedy policy's value of the last state,
``E(s')`` (the episode was cut, not ended). The contract: docs/algorithms.md.

>>> import numpy as np
>>> q = np.zeros((2, 2))
>>> memory = mc_memory(MemoryContext(2, 2, 0.0, {}, 5))
>>> rng = np.random.default_rng(0)
>>> step(q, memory, (0.0, 0.0), Transition(0, 1, 1.0, 1, False, False), Rates(0.5, 0.5, 0.0), rng)
0
>>> step(q, memory, (0.0, 0.0), Transition(1, 0, 2.0, 0, True, False), Rates(0.5, 0.5, 0.0), rng)
-1
>>> float(q[0, 1]), float(q[1, 0])  # returns 1 + 0.5 * 2 and 2, first visits, averaged
(2.0, 2.0)
"""

from __future__ import annotations

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
    behaviour_action,
    expected_value,
    shift,
    update,
    value,
)

UPDATES = ("sample_average", "constant_alpha")
"""``agent.update`` values, in the order of their codes"""


def step(
    q: Table, memory: Memory, params: Params, transition: Transition, rates: Rates, rng: Rng
) -> int:
    """Record the step; at the episode's end, learn from its first visits backwards."""
    state, action, reward = transition.state, transition.action, transition.reward
    next_state, terminated = transition.next_state, transition.terminated
    truncated = transition.truncated
    alpha, gamma, epsilon = rates.alpha, rates.gamma, rates.epsilon
    states, actions, rewards, counts, length = memory[0], memory[1], memory[2], memory[3], memory[4]
    first_visit = memory[5]
    n_actions = action_count(q)
    t = length[0]
    states[t], actions[t], rewards[t] = state, action, reward
    flat = state * n_actions + action
    if first_visit[flat] < 0:
        first_visit[flat] = t
    length[0] = t + 1
    if not (terminated or truncated or length[0] == states.shape[0]):
        return behaviour_action(q, params, next_state, epsilon, rng)
    averaging = params[UPDATE_AT] == 0.0
    target = 0.0
    if not terminated:  # cut by a time limit: the tail's value under the policy
        target = expected_value(q, next_state, epsilon)
    for t in range(length[0] - 1, -1, -1):
        target = gamma * target + rewards[t]
        flat = states[t] * n_actions + actions[t]
        if first_visit[flat] == t:
            if averaging:
                counts[flat] = counts[flat] + 1.0
                error = target - value(q, states[t], actions[t])
                shift(q, states[t], actions[t], error / counts[flat])
            else:
                update(q, states[t], actions[t], target, alpha)
    for t in range(length[0]):
        first_visit[states[t] * n_actions + actions[t]] = -1
    length[0] = 0
    return ENDED


def mc_memory(context: MemoryContext) -> tuple[np.ndarray, ...]:
    """An empty episode record (as long as the longest episode), counts and first visits."""
    pairs = context.n_states * context.n_actions
    return (
        np.zeros(context.max_steps, dtype=np.int64),
        np.zeros(context.max_steps, dtype=np.int64),
        np.zeros(context.max_steps, dtype=np.float64),
        np.zeros(pairs, dtype=np.float64),
        np.zeros(1, dtype=np.int64),
        np.full(pairs, -1, dtype=np.int64),
    )


UPDATE = Param(
    "update", "sample_average",
    "how a return moves Q: the average of all returns, or by alpha (recent ones count more)",
    kind="choice", choices=UPDATES,
)  # fmt: skip

PARAMS = (UPDATE,)
"""the parameters, in the order the hooks get them"""
UPDATE_AT = param_index(PARAMS, UPDATE)


ALGORITHM = Algorithm(
    name="monte_carlo",
    no_sample_average="",  # every step size reaches update
    description="Monte Carlo control: on-policy, first-visit, epsilon-soft (agent.update)",
    book="5.4",
    not_on_tiles=(
        "its first-visit marks and sample averages count states, and a tiled observation is not one of a finite set of states"
    ),
    step=step,
    params=PARAMS,
    memory=mc_memory,
    memory_names=(
        "episode_states", "episode_actions", "episode_rewards", "visit_counts",
        "episode_length", "first_visits",
    ),
)  # fmt: skip
