"""Prioritized sweeping (Sutton & Barto 8.4): what its contract implies, on the Dyna maze.

The byte-for-byte re-derivation on every world is in ``tests/test_rederivation.py``
(``reference_tabular.PrioritizedSweeping``); here, properties that follow from the box, and
the data structures that make it fast: the heap serves exactly what a scan of every
priority would, and the predecessor lists are exactly the pairs remembered as leading to
each state.
"""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from cartpole_q import load_config, train
from cartpole_q.rl.algorithm import MemoryContext
from cartpole_q.rl.algorithms import prioritized_sweeping as ps
from cartpole_q.rl.algorithms.prioritized_sweeping import (
    ABSENT,
    HEAP,
    HEAP_PLACES,
    HEAP_SIZE,
    LEADING_FIRST,
    LEADING_NEXT,
    LEADING_PREVIOUS,
    NEXT_STATES,
    OLDER_MEMORY,
    QUEUE,
    memory_from_older,
    queue,
    queue_of,
    relink,
    sweeping_memory,
    take_first,
)
from cartpole_q.rl.model import remember
from cartpole_q.rl.tabular import Rates, Transition

BASE: dict[str, Any] = {
    "env": {"id": "cartpole_q/DynaMaze-v0"},
    "agent": {"gamma": 0.95, "alpha": 0.1, "epsilon": 0.1, "q_init": 0.0, "tie_break": "random"},
    "train": {"episodes": 20, "stop_when_solved": False, "eval_every": 0, "checkpoint_every": 0},
    "eval": {"episodes": 1},
}


def run(seed: int, **agent: Any) -> Any:
    return train(load_config({**BASE, "agent": {**BASE["agent"], **agent}, "seed": seed}))


def memory_of(n_states: int, n_actions: int) -> tuple[np.ndarray, ...]:
    return sweeping_memory(MemoryContext(n_states, n_actions, 0.0, {}, 10))


def scanned_first(priorities: np.ndarray) -> int:
    """The contract's first pair, by a scan: the largest priority, the lowest pair among equals."""
    best, first = ABSENT, -1
    for flat in range(priorities.shape[0]):
        if priorities[flat] > best:
            best, first = priorities[flat], flat
    return first


def assert_heap(memory: tuple[np.ndarray, ...]) -> None:
    """The heap holds exactly the queued pairs, each at its recorded place, in heap order."""
    priorities, heap, heap_at, size = queue_of(memory)
    queued = heap[: size[0]]
    assert sorted(queued.tolist()) == np.flatnonzero(priorities != ABSENT).tolist()
    assert heap_at[queued].tolist() == list(range(size[0]))
    assert (np.delete(heap_at, queued) == -1).all()
    for at in range(1, size[0]):
        parent, child = heap[(at - 1) // 2], heap[at]
        assert ps.ahead(priorities, parent, child)


def test_the_queue_keeps_the_larger_priority_and_serves_the_lowest_pair_among_equals() -> None:
    memory = memory_of(2, 2)
    line = queue_of(memory)
    assert take_first(*line) == -1
    queue(*line, 2, 0.5, 0.1)
    queue(*line, 2, 0.3, 0.1)  # a smaller priority leaves it as it is
    queue(*line, 1, 0.1, 0.1)  # not strictly above theta: not queued
    queue(*line, 3, 0.5, 0.1)
    assert memory[QUEUE].tolist() == [-1.0, -1.0, 0.5, 0.5]
    assert scanned_first(memory[QUEUE]) == 2
    assert take_first(*line) == 2
    assert memory[QUEUE].tolist() == [-1.0, -1.0, -1.0, 0.5]
    assert take_first(*line) == 3
    assert take_first(*line) == -1


# Priorities from a few values, so that ties are common; theta 0.25 refuses some.
operations = st.lists(
    st.one_of(
        st.tuples(
            st.just("queue"), st.integers(0, 23), st.sampled_from([0.1, 0.25, 0.5, 1.0, 2.0])
        ),
        st.tuples(st.just("take"), st.just(0), st.just(0.0)),
    ),
    max_size=120,
)


@given(operations)
def test_the_heap_serves_what_a_scan_of_the_priorities_would(
    ops: list[tuple[str, int, float]],
) -> None:
    memory = memory_of(6, 4)
    line = queue_of(memory)
    scanned = np.full(24, ABSENT)  # the contract's queue, kept by hand
    for kind, flat, priority in ops:
        if kind == "queue":
            queue(*line, flat, priority, 0.25)
            if priority > 0.25 and priority > scanned[flat]:
                scanned[flat] = priority
        else:
            expected = scanned_first(scanned)
            assert take_first(*line) == expected
            if expected >= 0:
                scanned[expected] = ABSENT
        assert memory[QUEUE].tolist() == scanned.tolist()
        assert_heap(memory)
    while (expected := scanned_first(scanned)) >= 0:  # empty it: every pop in scan order
        assert take_first(*line) == expected
        scanned[expected] = ABSENT
    assert take_first(*line) == -1


@given(st.lists(st.tuples(st.integers(0, 7), st.integers(0, 2), st.integers(0, 7)), max_size=80))
def test_the_predecessor_lists_follow_every_changed_outcome(
    steps: list[tuple[int, int, int]],
) -> None:
    n_states, n_actions = 8, 3
    memory = memory_of(n_states, n_actions)
    first, following, preceding = (
        memory[LEADING_FIRST],
        memory[LEADING_NEXT],
        memory[LEADING_PREVIOUS],
    )
    for state, action, next_state in steps:
        flat = state * n_actions + action
        was = int(memory[NEXT_STATES][flat])
        remember(memory, state, action, next_state, 0.0, False, n_actions)
        relink(first, following, preceding, flat, was, next_state)
        for target in range(n_states):
            walked, before, pair = [], -1, first[target]
            while pair != -1:
                assert preceding[pair] == before  # linked both ways
                walked.append(int(pair))
                before, pair = pair, following[pair]
            assert sorted(walked) == np.flatnonzero(memory[NEXT_STATES] == target).tolist()


def played(memory: tuple[np.ndarray, ...], q: np.ndarray, seed: int, steps: int) -> None:
    """``steps`` real steps of a random walk on a 5-state chain (terminal at the right end)."""
    rng = np.random.default_rng(seed)
    params = (3.0, 0.0, 0.0)  # 3 planning steps, theta 0, lowest ties
    state = 0
    for _ in range(steps):
        action = int(rng.integers(0, 2))
        following = min(state + 1, 4) if action else max(state - 1, 0)
        if rng.random() < 0.2:  # the outcome changes now and then (a stochastic world)
            following = int(rng.integers(0, 5))
        ended = following == 4
        transition = Transition(state, action, float(ended), following, ended, False)
        ps.step(q, memory, params, transition, Rates(0.5, 0.9, 0.1), rng)
        state = 0 if ended else following


def test_a_memory_saved_before_the_heap_is_rebuilt_and_goes_on_as_the_whole_one() -> None:
    q = np.zeros((5, 2))
    memory = memory_of(5, 2)
    played(memory, q, 0, 40)
    rebuilt = memory_from_older(memory[:OLDER_MEMORY])
    assert len(rebuilt) == len(ps.ALGORITHM.memory_names)
    for index in range(OLDER_MEMORY):
        assert rebuilt[index].tobytes() == memory[index].tobytes()
        assert rebuilt[index] is not memory[index]
    assert_heap(rebuilt)
    assert sorted(rebuilt[HEAP][: rebuilt[HEAP_SIZE][0]].tolist()) == sorted(
        memory[HEAP][: memory[HEAP_SIZE][0]].tolist()
    )
    again = q.copy()
    played(memory, q, 1, 60)
    played(rebuilt, again, 1, 60)
    assert again.tobytes() == q.tobytes()
    assert rebuilt[QUEUE].tobytes() == memory[QUEUE].tobytes()
    assert (rebuilt[HEAP_PLACES] >= 0).sum() == (memory[HEAP_PLACES] >= 0).sum()


def test_a_memory_of_another_shape_is_not_taken_for_an_older_one() -> None:
    whole = memory_of(3, 2)
    copied = memory_from_older(whole)
    assert all(a.tobytes() == b.tobytes() for a, b in zip(copied, whole, strict=True))
    with pytest.raises(ValueError, match=r"9 or 15 arrays .*, not 4"):
        memory_from_older(whole[:4])


def test_the_update_counts_of_sample_averages_stay_last() -> None:
    q = np.zeros((5, 2))
    memory = memory_of(5, 2)
    played(memory, q, 0, 30)
    counts = np.arange(10.0)
    rebuilt = memory_from_older((*memory[:OLDER_MEMORY], counts))
    assert len(rebuilt) == len(memory) + 1 and rebuilt[-1].tolist() == counts.tolist()
    assert_heap(rebuilt[:-1])


def test_resuming_a_checkpoint_written_before_the_heap_continues_or_says_why_not(
    tmp_path: Path,
) -> None:
    """A checkpoint without ``memory_9`` to ``memory_14``: the run goes on as if never
    stopped, or is refused with one line that names the memory arrays."""
    from cartpole_q.store.checkpoint import CHECKPOINT_FILE, load_checkpoint, write_checkpoint

    config = load_config({
        **BASE, "engine": "numba", "seed": 3,
        "agent": {**BASE["agent"], "algorithm": "prioritized_sweeping", "planning_steps": 5},
        "train": {**BASE["train"], "checkpoint_every": 5},
    })  # fmt: skip
    whole = train(config)
    saved = 0

    def save(snapshot: Any) -> None:
        nonlocal saved
        saved += 1
        write_checkpoint(tmp_path, snapshot)

    train(config, should_stop=lambda: saved >= 2, on_checkpoint=save)
    path = tmp_path / CHECKPOINT_FILE
    with np.load(path) as archive:
        arrays = {name: archive[name] for name in archive.files}
    for index in range(OLDER_MEMORY, len(ps.ALGORITHM.memory_names)):
        del arrays[f"memory_{index}"]
    older = io.BytesIO()
    np.savez(older, allow_pickle=False, **arrays)
    path.write_bytes(older.getvalue())
    resumed = train(config, resume=load_checkpoint(tmp_path))  # rebuilt: the run goes on
    assert resumed.q_table.tobytes() == whole.q_table.tobytes()


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
