"""Monte Carlo ES on Blackjack started in a random state (Sutton & Barto 5.3, Figure 5.2).

The byte-for-byte comparison with the plain re-derivation, on both engines, is in
tests/test_rederivation.py (``test_exploring_starts``); the world's twin, step by step, in
tests/test_twins_tabular.py.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from cartpole_q import load_config, train

ES = {
    "seed": 3,
    "env": {"id": "cartpole_q/BlackjackES-v0"},
    "agent": {"algorithm": "monte_carlo_es", "gamma": 1.0, "epsilon": 0.0, "q_init": 0.0},
    "train": {"episodes": 400, "stop_when_solved": False, "eval_every": 0, "checkpoint_every": 50},
    "eval": {"episodes": 1},
}


@pytest.mark.parametrize("engine", ["numba", "gymnasium"])
def test_an_interrupted_es_run_resumes_byte_identically(engine: str, tmp_path: Path) -> None:
    from cartpole_q.store.checkpoint import load_checkpoint, write_checkpoint

    config = load_config({**ES, "engine": engine})
    whole = train(config)
    checkpoints = 0

    def save(snapshot: Any) -> None:
        nonlocal checkpoints
        checkpoints += 1
        write_checkpoint(tmp_path, snapshot)

    stopped = train(config, should_stop=lambda: checkpoints >= 3, on_checkpoint=save)
    assert stopped.interrupted and 0 < stopped.episodes < 400
    resumed = train(config, resume=load_checkpoint(tmp_path))
    assert resumed.engine == engine
    assert resumed.q_table.tobytes() == whole.q_table.tobytes()
    assert resumed.visits.tobytes() == whole.visits.tobytes()
    assert np.array_equal(resumed.returns, whole.returns)


def test_the_first_action_is_uniform_and_the_rest_greedy() -> None:
    """With epsilon 0 the only draws of the agent are the first actions: one per episode."""
    config = load_config({**ES, "engine": "gymnasium", "train": {**ES["train"], "episodes": 50}})
    result = train(config)
    agent_seq = np.random.SeedSequence(3).spawn(3)[0]
    rng = np.random.Generator(np.random.PCG64(agent_seq))
    firsts = [int(rng.integers(0, 2)) for _ in range(50)]
    # an episode that sticks first has length 1; a first hit is followed by greedy play
    sticks = [length == 1 for length in result.lengths.tolist()]
    assert all(stick for stick, first in zip(sticks, firsts, strict=True) if first == 0)
    assert 10 < sum(firsts) < 40
    assert int(result.visits[..., 1].sum()) >= sum(firsts)  # every drawn hit was played
