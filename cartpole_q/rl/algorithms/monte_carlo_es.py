"""Monte Carlo control with exploring starts, Monte Carlo ES (Sutton & Barto 5.3).

Every episode's first action is drawn uniformly, whatever ``Q`` says: one
``rng.integers(0, n)``. With a world that also starts in a random state
(``cartpole_q/BlackjackES-v0``, every one of its 200 states equally likely), every
state-action pair starts episodes (the exploring starts), and the policy may then be greedy:
the later actions are epsilon-greedy on ``Q`` with the episode's epsilon, so
``agent.epsilon: 0`` is the book's algorithm (greedy after the first action). Learning is
:mod:`monte_carlo`'s, unchanged: the episode recorded, then first-visit returns backwards,
by sample averages (``agent.update: sample_average``, the book's) or by ``alpha``. The
contract: docs/algorithms.md.

>>> import numpy as np
>>> from cartpole_q.rl.algorithm import MemoryContext
>>> q = np.array([[0.0, 5.0]])  # action 1 is greedy
>>> memory = mc_memory(MemoryContext(1, 2, 0.0, {}, 5))
>>> rng, copy = np.random.default_rng(3), np.random.default_rng(3)
>>> start(q, memory, (0.0, 0.0), 0, 0.0, rng) == int(copy.integers(0, 2))  # not greedy
True
"""

from __future__ import annotations

from cartpole_q.rl.algorithm import Algorithm
from cartpole_q.rl.algorithms.monte_carlo import UPDATE, mc_memory, step
from cartpole_q.rl.tabular import Memory, Params, Rng, Table, action_count, compilable


@compilable
def start(q: Table, memory: Memory, params: Params, state: int, epsilon: float, rng: Rng) -> int:
    """The exploring start: a uniformly random first action, ``rng.integers(0, n)``."""
    return int(rng.integers(0, action_count(q)))


ALGORITHM = Algorithm(
    name="monte_carlo_es",
    no_sample_average="",  # every step size reaches update
    description="Monte Carlo ES: a uniformly random first action, then epsilon-greedy "
    "(agent.epsilon: 0 for the book's greedy policy); first-visit returns (agent.update)",
    book="5.3",
    not_on_tiles=(
        "its first-visit marks and sample averages count states, and a tiled observation is not one of a finite set of states"
    ),
    start=start,
    step=step,
    params=(UPDATE,),
    memory=mc_memory,
    memory_names=(
        "episode_states", "episode_actions", "episode_rewards", "visit_counts",
        "episode_length", "first_visits",
    ),
)  # fmt: skip
