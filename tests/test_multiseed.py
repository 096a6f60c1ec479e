"""Many seeds in one command: each seed equals its single run; the aggregate adds up."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from PIL import Image

from cartpole_q.config import load_config
from cartpole_q.experiments.multiseed import run_seeds, seed_dir
from cartpole_q.experiments.run import prepare, start_run
from tests.conftest import invoke


@pytest.fixture(scope="module")
def seeds_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    parent = tmp_path_factory.mktemp("multi") / "seeds"
    result = invoke("train", "--seeds", "0-3", "--workers", "1", "--out", parent)
    assert result.exit_code == 0, result.output
    assert result.stdout.strip().splitlines()[-1] == str(parent)
    return parent


def test_every_seed_is_a_complete_run_equal_to_its_single_run(
    seeds_run: Path, tmp_path: Path
) -> None:
    parent_config = load_config(seeds_run / "config.yaml")
    assert parent_config.train.seeds == (0, 1, 2, 3)
    for seed in (0, 3):
        child = seed_dir(seeds_run, seed, (0, 1, 2, 3))
        assert child.name == f"seed-00{seed}"
        child_config = load_config(child / "config.yaml")
        assert child_config.seed == seed and child_config.train.seeds is None
        single = tmp_path / f"single-{seed}"
        assert invoke("train", "--seed", seed, "--out", single, "-q").exit_code == 0
        for name in ("q_table.npy", "metrics.csv", "visits.npy", "evaluations.csv"):
            assert (child / name).read_bytes() == (single / name).read_bytes(), name


def test_aggregate_summary(seeds_run: Path) -> None:
    summary = json.loads((seeds_run / "summary.json").read_text())
    children = [
        json.loads((seeds_run / f"seed-00{s}" / "summary.json").read_text()) for s in range(4)
    ]
    assert summary["seeds"] == "0-3" and summary["runs"] == summary["finished"] == 4
    assert summary["interrupted"] is False and summary["engine"] == "numba"
    successes = sum(child["eval"]["mean"] >= 475 for child in children)
    assert summary["successes"] == successes and summary["success_rate"] == successes / 4
    solved = sorted(child["solved_episode"] for child in children)
    assert summary["solved_episode"]["median"] == (solved[1] + solved[2]) / 2
    assert summary["per_seed"]["2"]["solved_episode"] == children[2]["solved_episode"]
    assert summary["per_seed"]["2"]["env_steps_to_solve"] == children[2]["env_steps_to_solve"]


def test_eval_and_plot_a_multi_seed_run(seeds_run: Path, tmp_path: Path) -> None:
    result = invoke("eval", seeds_run, "--episodes", "3", "--workers", "1", "--json")
    assert result.exit_code == 0, result.output
    report = json.loads(result.stdout)
    assert [run["run_seed"] for run in report["runs"]] == [0, 1, 2, 3]
    assert report["episodes"] == 3 and report["reward_threshold"] == 475.0
    lines = invoke("eval", seeds_run, "--episodes", "3", "--workers", "1").stdout.splitlines()
    successes = sum(run["mean"] >= 475 for run in report["runs"])
    assert lines[0].startswith("seed 0: mean ")
    assert lines[-1].startswith(
        f"{seeds_run}: {successes}/4 seeds with greedy mean >= 475 over 3 episodes"
    )
    out = tmp_path / "band.png"
    assert invoke("plot", seeds_run, "--out", out).exit_code == 0
    with Image.open(out) as image:
        assert image.size == (800, 450)
    result = invoke("eval", seeds_run, "--video", tmp_path / "v.gif")
    assert result.exit_code == 2 and "seed-*" in result.stderr


def test_interrupted_multi_seed_run_resumes_to_the_same_results(
    seeds_run: Path, tmp_path: Path
) -> None:
    prepared = prepare(load_config(overrides={"train.seeds": "0-3"}), "test")
    parent = start_run(prepared, tmp_path / "parent")
    polls = iter(range(10**9))
    summary = run_seeds(prepared, parent, workers=1, should_stop=lambda: next(polls) >= 25)
    assert summary.interrupted is True and summary.finished < 4
    result = invoke("train", "--resume", parent, "-q", "--workers", "1")
    assert result.exit_code == 0, result.output
    assert json.loads((parent / "summary.json").read_text())["finished"] == 4
    for seed in range(4):
        name = f"seed-00{seed}"
        for file in ("q_table.npy", "metrics.csv"):
            assert (parent / name / file).read_bytes() == (seeds_run / name / file).read_bytes()


@pytest.mark.slow
def test_worker_processes_give_the_same_results(seeds_run: Path, tmp_path: Path) -> None:
    parent = tmp_path / "parallel"
    result = invoke("train", "--seeds", "0-3", "--workers", "2", "--out", parent)
    assert result.exit_code == 0, result.output
    assert "seed 3: solved at episode" in result.stdout
    for seed in range(4):
        name = f"seed-00{seed}"
        for file in ("q_table.npy", "metrics.csv"):
            assert (parent / name / file).read_bytes() == (seeds_run / name / file).read_bytes()


def test_a_multi_seed_run_draws_figures_only_when_asked(seeds_run: Path, tmp_path: Path) -> None:
    """Figures would cost more than the training: none by default, all with --seed-plots."""
    assert not list(seeds_run.rglob("reward_curve.png"))
    parent = tmp_path / "plotted"
    result = invoke(
        "train", "--seeds", "0-1", "--workers", "2", "--seed-plots", "--out", parent, "-q"
    )
    assert result.exit_code == 0, result.output
    for path in (parent, parent / "seed-000", parent / "seed-001"):
        with Image.open(path / "reward_curve.png") as image:
            assert image.size[0] > 0
    for name in ("q_table.npy", "metrics.csv"):
        assert (parent / "seed-001" / name).read_bytes() == (
            seeds_run / "seed-001" / name
        ).read_bytes()
