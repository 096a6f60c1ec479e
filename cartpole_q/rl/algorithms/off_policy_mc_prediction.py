"""Off-policy Monte Carlo prediction (Sutton & Barto 5.5-5.6): V of a target policy from a random one's play.

The behaviour policy ``b`` is uniform over the ``n`` actions; the target ``pi`` is
``agent.policy`` (a rule the world declares, or ``random``). The episode is recorded; ``V``
does not change during it. When it ends, its returns are computed backwards with the
importance-sampling ratio of the steps after each visit, ``W = prod pi(A_k | S_k) / b(A_k |
S_k)`` over ``k = t .. T-1``, and ``V(S_t)`` moves toward the weighted return at every visit
(``agent.visits: every``) or each state's first: by ``W * G``'s sample average (``agent.sampling:
ordinary``, eq. 5.5) or by ``G`` weighted by ``W`` (``weighted``, eq. 5.6, incrementally as
the book's box in 5.6). The contract: docs/algorithms.md, "Prediction".

>>> import numpy as np
>>> v = np.zeros((3, 1))
>>> context = MemoryContext(3, 2, 0.0, {"policy": "stick_20"}, 5, policy=[0, 0, 0])
>>> memory = off_policy_memory(context)
>>> rng = np.random.default_rng(0)
>>> params = (1.0, 0.0, 0.0)  # a rule, ordinary sampling, every visit
>>> step(v, memory, params, Transition(0, 0, 0.0, 1, False, False),
...     Rates(0.5, 1.0, 0.0), rng) in (0, 1)
True
>>> step(v, memory, params, Transition(1, 0, 1.0, 2, True, False), Rates(0.5, 1.0, 0.0), rng)
-1
>>> float(v[1, 0]), float(v[0, 0])  # both took pi's action: W = 2, then 4; returns 1 and 1
(2.0, 4.0)
"""

from __future__ import annotations

import numpy as np

from cartpole_q.rl.algorithm import Algorithm, MemoryContext, Param, param_index
from cartpole_q.rl.algorithms.mc_prediction import VISIT
from cartpole_q.rl.prediction import POLICY, POLICY_SOURCE, policy_table
from cartpole_q.rl.tabular import ENDED, Memory, Params, Rates, Rng, Table, Transition, shift, value

SAMPLINGS = ("ordinary", "weighted")
"""``agent.sampling`` values, in the order of their codes"""


def behaviour_action(
    q: Table, memory: Memory, params: Params, state: int, epsilon: float, rng: Rng
) -> int:
    """The behaviour policy's action: uniform, one ``rng.integers(0, n)``."""
    return int(rng.integers(0, memory[0].shape[1]))


def step(
    q: Table, memory: Memory, params: Params, transition: Transition, rates: Rates, rng: Rng
) -> int:
    """Record the step; at the episode's end, learn from its weighted returns backwards."""
    state, action, reward = transition.state, transition.action, transition.reward
    next_state, terminated = transition.next_state, transition.terminated
    truncated = transition.truncated
    gamma = rates.gamma
    pi, states, actions, rewards = memory[0], memory[1], memory[2], memory[3]
    weights, first_visit, length = memory[4], memory[5], memory[6]
    t = length[0]
    states[t], actions[t], rewards[t] = state, action, reward
    if first_visit[state] < 0:
        first_visit[state] = t
    length[0] = t + 1
    if not (terminated or truncated or length[0] == states.shape[0]):
        return int(rng.integers(0, pi.shape[1]))
    ordinary, every_visit = params[SAMPLING_AT] == 0.0, params[VISIT_AT] == 0.0
    b = 1.0 / pi.shape[1]
    target = 0.0
    if not terminated:  # cut by a time limit: the tail's value
        target = value(q, next_state, 0)
    ratio = 1.0
    for t in range(length[0] - 1, -1, -1):
        target = gamma * target + rewards[t]
        s = states[t]
        ratio = ratio * (pi[s, actions[t]] / b)
        if every_visit or first_visit[s] == t:
            if ordinary:
                weights[s] = weights[s] + 1.0
                shift(q, s, 0, (ratio * target - value(q, s, 0)) / weights[s])
            else:
                weights[s] = weights[s] + ratio
                if weights[s] > 0.0:
                    shift(q, s, 0, (ratio / weights[s]) * (target - value(q, s, 0)))
    for t in range(length[0]):
        first_visit[states[t]] = -1
    length[0] = 0
    return ENDED


def off_policy_memory(context: MemoryContext) -> tuple[np.ndarray, ...]:
    """The target policy, an empty episode record, the sums of weights and first visits."""
    return (
        policy_table(context),
        np.zeros(context.max_steps, dtype=np.int64),
        np.zeros(context.max_steps, dtype=np.int64),
        np.zeros(context.max_steps, dtype=np.float64),
        np.zeros(context.n_states, dtype=np.float64),
        np.full(context.n_states, -1, dtype=np.int64),
        np.zeros(1, dtype=np.int64),
    )


SAMPLING = Param(
    "sampling", "weighted",
    "importance sampling: ordinary (the average of W * G) or weighted (G weighted by W)",
    kind="choice", choices=SAMPLINGS,
)  # fmt: skip

PARAMS = (POLICY, SAMPLING, VISIT, *POLICY_SOURCE)
"""the parameters, in the order the hooks get them"""
SAMPLING_AT = param_index(PARAMS, SAMPLING)
VISIT_AT = param_index(PARAMS, VISIT)


ALGORITHM = Algorithm(
    name="off_policy_mc_prediction",
    no_sample_average="it averages returns by their importance-sampling weights (agent.sampling) and takes no alpha",
    description="off-policy Monte Carlo prediction: V of agent.policy from a uniform policy's play",
    book="5.5, 5.6",
    task="prediction",
    not_on_tiles="its sums of weights and first visits are kept per state",
    step=step,
    start=behaviour_action,
    params=PARAMS,
    memory=off_policy_memory,
    memory_names=(
        "policy", "episode_states", "episode_actions", "episode_rewards", "weight_sums",
        "first_visits", "episode_length",
    ),
)  # fmt: skip
