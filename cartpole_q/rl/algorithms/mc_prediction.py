"""Monte Carlo prediction (Sutton & Barto 5.1, 6.1): state values from whole episodes' returns.

The episode is recorded; ``V`` does not change during it. When it ends, its returns are
computed backwards, ``G = gamma * G + R``, and ``V(S_t)`` moves toward ``G`` at every visit
(``agent.visits: every``) or at each state's first visit (``first``): by ``alpha``
(``agent.update: constant_alpha``, the book's constant-alpha MC, eq. 6.1) or by the sample
average (``sample_average``, a count per state: first-visit MC prediction, 5.1). After a time
limit the tail is bootstrapped from ``V(s')``. The contract: docs/algorithms.md, "Prediction".

>>> import numpy as np
>>> v = np.zeros((3, 1))
>>> memory = mc_prediction_memory(MemoryContext(3, 2, 0.0, {"policy": "random"}, 5))
>>> rng = np.random.default_rng(0)
>>> step(v, memory, (0.0, 0.0, 0.0), Transition(0, 1, 1.0, 1, False, False),
...     Rates(0.5, 0.5, 0.0), rng) in (0, 1)
True
>>> step(v, memory, (0.0, 0.0, 0.0), Transition(1, 0, 2.0, 2, True, False),
...     Rates(0.5, 0.5, 0.0), rng)
-1
>>> float(v[0, 0]), float(v[1, 0])  # returns 1 + 0.5 * 2 and 2, alpha 0.5 from 0
(1.0, 1.0)
"""

from __future__ import annotations

import numpy as np

from cartpole_q.rl.algorithm import Algorithm, MemoryContext, Param, param_index
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
    shift,
    update,
    value,
)

UPDATES = ("constant_alpha", "sample_average")
"""``agent.update`` values, in the order of their codes"""
VISITS = ("every", "first")
"""``agent.visits`` values, in the order of their codes"""


def step(
    q: Table, memory: Memory, params: Params, transition: Transition, rates: Rates, rng: Rng
) -> int:
    """Record the step; at the episode's end, learn from its returns backwards."""
    state, reward, next_state = transition.state, transition.reward, transition.next_state
    terminated, truncated = transition.terminated, transition.truncated
    alpha, gamma = rates.alpha, rates.gamma
    policy, states, rewards, counts = memory[0], memory[1], memory[2], memory[3]
    first_visit, length = memory[4], memory[5]
    t = length[0]
    states[t], rewards[t] = state, reward
    if first_visit[state] < 0:
        first_visit[state] = t
    length[0] = t + 1
    if not (terminated or truncated or length[0] == states.shape[0]):
        return policy_action(policy, next_state, params, rng)
    averaging, every_visit = params[UPDATE_AT] == 1.0, params[VISIT_AT] == 0.0
    target = 0.0
    if not terminated:  # cut by a time limit: the tail's value
        target = value(q, next_state, 0)
    for t in range(length[0] - 1, -1, -1):
        target = gamma * target + rewards[t]
        s = states[t]
        if every_visit or first_visit[s] == t:
            if averaging:
                counts[s] = counts[s] + 1.0
                shift(q, s, 0, (target - value(q, s, 0)) / counts[s])
            else:
                update(q, s, 0, target, alpha)
    for t in range(length[0]):
        first_visit[states[t]] = -1
    length[0] = 0
    return ENDED


def mc_prediction_memory(context: MemoryContext) -> tuple[np.ndarray, ...]:
    """The policy, an empty episode record, the counts and the first visits."""
    return (
        policy_table(context),
        np.zeros(context.max_steps, dtype=np.int64),
        np.zeros(context.max_steps, dtype=np.float64),
        np.zeros(context.n_states, dtype=np.float64),
        np.full(context.n_states, -1, dtype=np.int64),
        np.zeros(1, dtype=np.int64),
    )


UPDATE = Param(
    "update", "constant_alpha",
    "how V moves toward a return: by alpha (constant-alpha MC), or by the sample average",
    kind="choice", choices=UPDATES,
)  # fmt: skip
VISIT = Param(
    "visits", "every", "which visits of a state learn from their return: every one, or the first",
    kind="choice", choices=VISITS,
)  # fmt: skip

PARAMS = (POLICY, UPDATE, VISIT, *POLICY_SOURCE)
"""the parameters, in the order the hooks get them"""
UPDATE_AT = param_index(PARAMS, UPDATE)
VISIT_AT = param_index(PARAMS, VISIT)


ALGORITHM = Algorithm(
    name="mc_prediction",
    no_sample_average="",  # every step size reaches update
    description="Monte Carlo prediction: the state values of agent.policy from episodes' returns",
    book="5.1, 6.1",
    task="prediction",
    not_on_tiles="its counts and first visits are kept per state",
    step=step,
    start=first_policy_action,
    params=PARAMS,
    memory=mc_prediction_memory,
    memory_names=(
        "policy", "episode_states", "episode_rewards", "visit_counts", "first_visits",
        "episode_length",
    ),
)  # fmt: skip
