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


# Sutton & Barto's Figure 5.2, the optimal policy: "S" stick, "H" hit, dealer A, 2, ..., 10.
BOOK_POLICY = {
    1: {21: "SSSSSSSSSS", 20: "SSSSSSSSSS", 19: "SSSSSSSSSS", 18: "HSSSSSSSHH",
        **{total: "HHHHHHHHHH" for total in range(12, 18)}},
    0: {**{total: "SSSSSSSSSS" for total in range(17, 22)},
        **{total: "HSSSSSHHHH" for total in range(13, 17)}, 12: "HHHSSSHHHH"},
}  # fmt: skip


def test_the_exact_optimum_is_the_books_policy() -> None:
    """Value iteration on the rules gives Figure 5.2's policy, no state indifferent."""
    from cartpole_q.experiments.sweep import blackjack_optimum, policy_match

    config = load_config({"env": {"id": "cartpole_q/BlackjackES-v0"}})
    q_star, optimal, v_star = blackjack_optimum(config)
    for usable, rows in BOOK_POLICY.items():
        for total, actions in rows.items():
            drawn = "".join("SH"[int(optimal[total, card, usable])] for card in range(1, 11))
            assert drawn == actions, (total, usable)
    exact = policy_match(q_star, q_star)
    assert (exact.matching, exact.indifferent, exact.differing) == (200, 0, ())
    gaps = np.abs(q_star[12:22, 1:11, :, 0] - q_star[12:22, 1:11, :, 1])
    assert round(float(gaps.min()), 6) == 0.002473  # 12 against a 4, no usable ace
    assert np.array_equal(v_star, q_star.max(axis=-1))
    flipped = q_star.copy()
    flipped[12, 4, 0] = flipped[12, 4, 0, ::-1]
    assert policy_match(flipped, q_star).differing == ((12, 4, 0),)


def test_the_es_world_s_optimum_starts_uniformly_on_its_200_states() -> None:
    from cartpole_q.envs.models import env_model

    config = load_config({"env": {"id": "cartpole_q/BlackjackES-v0"}})
    model = env_model(config.env)
    assert not isinstance(model, str)
    assert np.count_nonzero(model.model.initial) == 200
    assert set(model.model.initial[model.model.initial > 0]) == {1 / 200}


def test_the_policy_figure_draws_the_greedy_policy_beside_the_optimum(tmp_path: Path) -> None:
    from tests.conftest import invoke, write_yaml

    study = write_yaml(
        tmp_path / "es.yaml",
        {
            "name": "es",
            "base": {**{k: v for k, v in ES.items() if k != "seed"},
                     "train": {"episodes": 3000, "eval_every": 0, "checkpoint_every": 0}},
            "seeds": "0",
            "figure": {"metric": "policy", "file": "p.png"},
        },
    )  # fmt: skip
    done = invoke("sweep", study, "--out", tmp_path / "sweep", "-q")
    assert done.exit_code == 0, done.output
    rows = (tmp_path / "sweep" / "p.csv").read_text().splitlines()[1:]
    panels = {row.rsplit('",', 1)[0].lstrip('"') for row in rows}
    assert len(rows) == 8 * 100 and len(panels) == 8
    exact = [row for row in rows if row.startswith('"exact optimum (the rules), policy, no')]
    assert [[*row.rsplit(",", 5)[1:3], row.rsplit(",", 1)[1]] for row in exact[:4]] == [
        ["1", "12", "1"], ["2", "12", "1"], ["3", "12", "1"], ["4", "12", "0"]
    ]  # fmt: skip
    assert any(" of 200 optimal, policy, usable ace" in panel for panel in panels)


@pytest.mark.parametrize(
    ("change", "words"),
    [
        ({"agent": {"algorithm": "mc_prediction"}}, "figure.metric: policy draws a control"),
        (
            {"env": {"id": "Taxi-v4"}},
            "needs a Blackjack world (Blackjack-v1, cartpole_q/BlackjackES-v0) or a grid world",
        ),
        ({"agent": {"gamma": 0.9}}, "compares with Blackjack's undiscounted optimum"),
    ],
)
def test_the_policy_figure_refuses_prediction_and_other_worlds(
    tmp_path: Path, change: dict[str, Any], words: str
) -> None:
    from tests.conftest import invoke, write_yaml

    base = {"env": ES["env"], "agent": dict(ES["agent"]), "train": {"episodes": 5}}
    for key, value in change.items():
        base[key] = {**base[key], **value}  # type: ignore[dict-item]
    study = {"name": "es", "base": base, "seeds": "0", "figure": {"metric": "policy"}}
    refused = invoke("sweep", write_yaml(tmp_path / "es.yaml", study), "--out", tmp_path / "s")
    assert refused.exit_code == 2, refused.output
    assert words in refused.stderr and "Traceback" not in refused.output
