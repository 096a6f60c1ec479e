"""`cartpole-q eval` and the summary's evaluations: limits, and where episodes were played."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tests.conftest import invoke
from tests.test_cli import assert_refused


@pytest.fixture(scope="module")
def quick_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("runs") / "quick"
    result = invoke("train", "--episodes", "20", "--out", out)
    assert result.exit_code == 0, result.output
    return out


@pytest.mark.parametrize("episodes", ["1000000000000", "10000001"])
def test_eval_caps_the_episode_count(quick_run: Path, episodes: str) -> None:
    # 10**12 episodes used to allocate their returns at once: a MemoryError traceback
    assert_refused(invoke("eval", quick_run, "--episodes", episodes), "--episodes", "10,000,000")


@pytest.mark.parametrize(("engine", "where"), [("numba", "twin"), ("gymnasium", "gymnasium")])
def test_summary_says_where_its_evaluations_were_played(
    tmp_path: Path, engine: str, where: str
) -> None:
    out = tmp_path / engine
    result = invoke("train", "--engine", engine, "--out", out, "--quiet")
    assert result.exit_code == 0, result.output
    summary = json.loads((out / "summary.json").read_text())
    assert summary["eval"]["played_in"] == where
    assert summary["first_greedy_success"]["played_in"] == where


# -- eval --engine numba: the compiled twin, the same returns ------------------------------


@pytest.fixture(scope="module")
def seeds_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Three seeds, half trained: their greedy returns vary from episode to episode."""
    out = tmp_path_factory.mktemp("runs") / "seeds"
    result = invoke(
        "train", "--seeds", "0-2", "--episodes", "60", "--set", "train.stop_when_solved=false",
        "--workers", "1", "--out", out, "-q",
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    return out


def _eval_json(*args: object) -> dict:
    result = invoke("eval", *args, "--json")
    assert result.exit_code == 0, result.output
    return json.loads(result.stdout)


CONDITIONS = [
    pytest.param([], id="as-trained"),
    pytest.param(["--physics", "length=0.8", "--physics", "force_mag=7"], id="physics"),
    pytest.param(["--max-steps", "120"], id="max-steps"),
    pytest.param(["--physics", "gravity=12", "--max-steps", "700"], id="both"),
]


@pytest.mark.parametrize("conditions", CONDITIONS)
def test_the_twin_plays_exactly_what_gymnasium_make_plays(
    seeds_run: Path, conditions: list[str]
) -> None:
    args = ("--episodes", 7, "--seed", 11, *conditions)
    real = _eval_json(seeds_run, *args, "--workers", 1)
    twin = _eval_json(seeds_run, *args, "--engine", "numba")
    assert real["played_in"] == "gymnasium" and twin["played_in"] == "twin"
    assert [run["played_in"] for run in twin["runs"]] == ["twin"] * 3
    for key in ("mean", "min", "successes", "reward_threshold", "conditions"):
        assert twin[key] == real[key], key
    for played, compiled in zip(real["runs"], twin["runs"], strict=True):
        for key in ("run_seed", "mean", "std", "min", "max", "episodes", "seed"):
            assert compiled[key] == played[key], key
    assert len({run["mean"] for run in real["runs"]}) > 1  # the seeds differ: a real check

    one = seeds_run / "seed-001"
    single = _eval_json(one, *args, "--engine", "numba")
    assert single == {**_eval_json(one, *args), "played_in": "twin"}


def test_the_twins_returns_are_gymnasiums_episode_by_episode(seeds_run: Path) -> None:
    from cartpole_q.evaluation import evaluate, under_conditions
    from cartpole_q.store.rundir import load_run

    run = load_run(seeds_run / "seed-002")
    for physics, max_steps in (({}, None), ({"length": 0.7}, 300)):
        config = under_conditions(run.config, physics, max_steps)
        real = evaluate(run.q_table, config, episodes=25, seed=3)
        twin = evaluate(run.q_table, config, episodes=25, seed=3, engine="numba")
        assert twin.returns == real.returns and len(set(real.returns)) > 3
        assert (real.played_in, twin.played_in) == ("gymnasium", "twin")


def test_the_text_says_where_it_played(seeds_run: Path) -> None:
    result = invoke("eval", seeds_run, "--episodes", 2, "--engine", "numba")
    assert result.exit_code == 0, result.output
    assert "over 2 episodes each on the compiled twin" in result.stdout.splitlines()[-1]
    result = invoke("eval", seeds_run / "seed-000", "--episodes", 2, "--engine", "numba")
    assert "from seed 1000000 on the compiled twin" in result.stdout


def test_the_twin_refuses_what_it_cannot_play(seeds_run: Path, tmp_path: Path) -> None:
    from tests import plugin_world

    one = seeds_run / "seed-000"
    assert_refused(
        invoke("eval", one, "--engine", "numba", "--video", tmp_path / "a.gif"),
        "--video", "--engine numba", "draws nothing",
    )  # fmt: skip
    assert_refused(invoke("eval", one, "--engine", "numba", "--render"), "--render")
    assert_refused(invoke("eval", one, "--engine", "twin"), "--engine")
    world = tmp_path / "world"
    trained = invoke(
        "train", "--set", f"env.id={plugin_world.ENV_ID}", "--episodes", 5, "--out", world, "-q"
    )
    assert trained.exit_code == 0, trained.output
    assert_refused(
        invoke("eval", world, "--engine", "numba"),
        "--engine numba", "has no compiled twin", "--engine gymnasium",
    )  # fmt: skip
