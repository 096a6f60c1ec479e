"""Off-policy Monte Carlo control with weighted importance sampling (Sutton & Barto 5.7).

Behaviour: epsilon-greedy on ``Q``; target: greedy. The episode is recorded with each
action's behaviour probability; when it ends, backwards: ``G = gamma * G + R``,
``C(s, a) += W`` (``sample_average``; ``constant_alpha``: ``C = (1 - alpha) C + W``, older
returns' weights fading), ``Q(s, a) += (W / C) (G - Q)``; the loop stops at the first action
the greedy policy would not take, else ``W = W / b``. After a time limit the tail is
bootstrapped with the greedy policy's value ``max_b Q(s', b)``. The contract:
docs/algorithms.md.

>>> import numpy as np
>>> q = np.zeros((2, 2))
>>> memory = off_policy_memory(MemoryContext(2, 2, 0.0, {}, 5))
>>> rng = np.random.default_rng(0)
>>> step(q, memory, (0.0, 0.0), Transition(0, 0, 1.0, 1, False, False), Rates(0.5, 1.0, 0.0), rng)
0
>>> step(q, memory, (0.0, 0.0), Transition(1, 0, 2.0, 0, True, False), Rates(0.5, 1.0, 0.0), rng)
-1
>>> float(q[0, 0]), float(q[1, 0])  # greedy all along: W stays 1
(3.0, 2.0)
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
    behaviour_probability,
    best_action,
    best_value,
    shift,
    value,
)

UPDATES = ("sample_average", "constant_alpha")
"""``agent.update`` values, in the order of their codes"""


def step(
    q: Table, memory: Memory, params: Params, transition: Transition, rates: Rates, rng: Rng
) -> int:
    """Record the step and its behaviour probability; at the end, learn backwards."""
    state, action, reward = transition.state, transition.action, transition.reward
    next_state, terminated = transition.next_state, transition.terminated
    truncated = transition.truncated
    alpha, gamma, epsilon = rates.alpha, rates.gamma, rates.epsilon
    states, actions, rewards, weights, length = (
        memory[0],
        memory[1],
        memory[2],
        memory[3],
        memory[4],
    )
    behaviour = memory[5]
    n_actions = action_count(q)
    t = length[0]
    states[t], actions[t], rewards[t] = state, action, reward
    behaviour[t] = behaviour_probability(q, params, state, action, epsilon)
    length[0] = t + 1
    if not (terminated or truncated or length[0] == states.shape[0]):
        return behaviour_action(q, params, next_state, epsilon, rng)
    averaging = params[UPDATE_AT] == 0.0
    target = 0.0
    if not terminated:  # cut by a time limit: the tail's value under the greedy target
        target = best_value(q, next_state)
    weight = 1.0
    for t in range(length[0] - 1, -1, -1):
        target = gamma * target + rewards[t]
        s, a = states[t], actions[t]
        flat = s * n_actions + a
        if averaging:
            weights[flat] = weights[flat] + weight
        else:
            weights[flat] = (1.0 - alpha) * weights[flat] + weight
        shift(q, s, a, (weight / weights[flat]) * (target - value(q, s, a)))
        if a != best_action(q, s):
            break
        weight = weight / behaviour[t]
    length[0] = 0
    return ENDED


def off_policy_memory(context: MemoryContext) -> tuple[np.ndarray, ...]:
    """An empty episode record, cumulative weights, and the behaviour probabilities."""
    pairs = context.n_states * context.n_actions
    return (
        np.zeros(context.max_steps, dtype=np.int64),
        np.zeros(context.max_steps, dtype=np.int64),
        np.zeros(context.max_steps, dtype=np.float64),
        np.zeros(pairs, dtype=np.float64),
        np.zeros(1, dtype=np.int64),
        np.zeros(context.max_steps, dtype=np.float64),
    )


UPDATE = Param(
    "update", "sample_average",
    "how C weighs returns: all alike (weighted importance sampling), or older ones fading by alpha",
    kind="choice", choices=UPDATES,
)  # fmt: skip

PARAMS = (UPDATE,)
"""the parameters, in the order the hooks get them"""
UPDATE_AT = param_index(PARAMS, UPDATE)


ALGORITHM = Algorithm(
    name="off_policy_monte_carlo",
    no_sample_average="it averages returns by their importance-sampling weights already (agent.update: sample_average), and alpha is only its constant_alpha's recency",
    description="Off-policy Monte Carlo control: weighted importance sampling, greedy target",
    book="5.7",
    not_on_tiles=(
        "its importance-sampling weights are summed per state, and a tiled observation is not one of a finite set of states"
    ),
    step=step,
    params=PARAMS,
    # W / b_t: an exploratory action's b_t = epsilon / n must not round to 0 in float64
    # (docs/algorithms.md, "No division by zero").
    epsilon_floor=1e-300,
    memory=off_policy_memory,
    memory_names=(
        "episode_states", "episode_actions", "episode_rewards", "cumulative_weights",
        "episode_length", "behaviour_probabilities",
    ),
)  # fmt: skip
