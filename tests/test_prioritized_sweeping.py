"""Prioritized sweeping (Sutton & Barto 8.4): what its contract implies, on the Dyna maze.

The byte-for-byte re-derivation on every world is in ``tests/test_rederivation.py``
(``reference_tabular.PrioritizedSweeping``); here, properties that follow from the box.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from cartpole_q import load_config, train
from cartpole_q.rl.algorithms.prioritized_sweeping import first_in_queue, queue

BASE: dict[str, Any] = {
    "env": {"id": "cartpole_q/DynaMaze-v0"},
    "agent": {"gamma": 0.95, "alpha": 0.1, "epsilon": 0.1, "q_init": 0.0, "tie_break": "random"},
    "train": {"episodes": 20, "stop_when_solved": False, "eval_every": 0, "checkpoint_every": 0},
    "eval": {"episodes": 1},
}


def run(seed: int, **agent: Any) -> Any:
    return train(load_config({**BASE, "agent": {**BASE["agent"], **agent}, "seed": seed}))


def test_the_queue_keeps_the_larger_priority_and_serves_the_lowest_pair_among_equals() -> None:
    priorities = np.full(4, -1.0)
    assert first_in_queue(priorities) == -1
    queue(priorities, 2, 0.5, 0.1)
    queue(priorities, 2, 0.3, 0.1)  # a smaller priority leaves it as it is
    queue(priorities, 1, 0.1, 0.1)  # not strictly above theta: not queued
    queue(priorities, 3, 0.5, 0.1)
    assert priorities.tolist() == [-1.0, -1.0, 0.5, 0.5]
    assert first_in_queue(priorities) == 2


def test_without_planning_steps_nothing_is_learned() -> None:
    result = run(0, algorithm="prioritized_sweeping", planning_steps=0)
    assert (result.q_table == 0.0).all()


def test_before_the_first_reward_it_plays_as_q_learning_and_then_learns_faster() -> None:
    # The maze pays only at the goal: nothing is queued before the first episode ends, and
    # planning draws nothing, so the first episode is Q-learning's, step for step.
    for seed in range(3):
        sweeping = run(seed, algorithm="prioritized_sweeping", planning_steps=5)
        q_learning = run(seed, algorithm="q_learning")
        assert sweeping.lengths[0] == q_learning.lengths[0]
        assert sum(sweeping.lengths[1:]) < sum(q_learning.lengths[1:])
