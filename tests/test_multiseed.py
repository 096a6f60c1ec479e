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


RAY_CONFIG = {
    "train": {
        "episodes": 120, "stop_when_solved": False, "checkpoint_every": 20, "eval_every": 40,
        "eval_episodes": 2,
    },
    "eval": {"episodes": 5},
}  # fmt: skip
RUN_FILES = ("q_table.npy", "visits.npy", "metrics.csv", "evaluations.csv", "config.yaml")


@pytest.mark.slow
def test_the_ray_backend_trains_and_resumes_seeds_to_the_same_bytes(tmp_path: Path) -> None:
    """Seeds trained as Ray tasks on a real local cluster equal local ones, also when the
    cluster resumes seeds that local workers left interrupted (their checkpoints travel)."""
    ray = pytest.importorskip("ray")
    from cartpole_q.experiments.run import prepare_resume
    from tests.conftest import write_yaml

    path = write_yaml(tmp_path / "ray.yaml", RAY_CONFIG)
    reference = tmp_path / "reference"
    result = invoke("train", "-c", path, "--seeds", "0-3", "--workers", "1", "--out", reference)
    assert result.exit_code == 0, result.output

    prepared = prepare(load_config(path, {"train.seeds": "0-3"}), "test")
    mixed = start_run(prepared, tmp_path / "mixed")
    polls = iter(range(10**9))
    stopped = run_seeds(prepared, mixed, workers=1, should_stop=lambda: next(polls) >= 12)
    assert stopped.interrupted and stopped.interrupted_seeds, "a seed should stop midway"
    interrupted = seed_dir(
        mixed, int(stopped.interrupted_seeds.split("-")[0].split(",")[0]), (0, 1, 2, 3)
    )
    assert (interrupted / "checkpoint.npz").is_file()

    fresh = start_run(prepared, tmp_path / "fresh")
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        resumed = run_seeds(prepare_resume(mixed), mixed, workers=2, resume=True, backend="ray")
        whole = run_seeds(prepared, fresh, workers=2, backend="ray")
    finally:
        ray.shutdown()
    assert resumed.finished == whole.finished == 4 and not whole.interrupted
    for parent in (mixed, fresh):
        for seed in range(4):
            child, expected = (
                seed_dir(parent, seed, (0, 1, 2, 3)),
                seed_dir(reference, seed, (0, 1, 2, 3)),
            )
            for name in RUN_FILES:
                assert (child / name).read_bytes() == (expected / name).read_bytes(), (child, name)
            # Reaching train.episodes keeps the checkpoint, to extend the run later.
            assert (child / "checkpoint.npz").is_file()
    summary = json.loads((fresh / "summary.json").read_text())
    assert (
        summary["statistics"] == json.loads((reference / "summary.json").read_text())["statistics"]
    )


def test_the_ray_backend_is_for_several_seeds(tmp_path: Path) -> None:
    from tests.test_cli import assert_refused

    assert_refused(
        invoke("train", "--backend", "ray", "--out", tmp_path / "one"),
        "--backend ray runs the seeds of a multi-seed run as Ray tasks: give --seeds",
    )
    assert_refused(
        invoke("train", "--address", "auto", "--seeds", "0-1"), "--address is for --backend ray."
    )
    assert not (tmp_path / "one").exists()


def test_a_ray_task_continues_from_the_checkpoint_it_is_given(tmp_path: Path) -> None:
    """The job a Ray task runs, called here: a checkpoint changed by hand changes the result,
    so the one sent along is the one continued (with the true one, the same bytes)."""
    import io

    import numpy as np

    from cartpole_q.experiments.multiseed import _train_seeds_in_memory
    from cartpole_q.experiments.workers import InProcess
    from cartpole_q.progress import NullReporter
    from cartpole_q.store.checkpoint import checkpoint_bytes
    from cartpole_q.training import train

    config = load_config({**RAY_CONFIG, "seed": 5})
    checkpoints: list[bytes] = []
    whole = train(config)

    train(
        config,
        should_stop=lambda: bool(checkpoints),
        on_checkpoint=lambda snapshot: checkpoints.append(checkpoint_bytes(snapshot)),
    )
    first = checkpoints[0]
    with np.load(io.BytesIO(first)) as data:
        arrays = {name: data[name] for name in data.files}
    arrays["q"] = np.zeros_like(arrays["q"])  # forget what was learnt
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    handle = InProcess(None, NullReporter())
    mapping = config.to_dict()
    (true,) = _train_seeds_in_memory(handle, mapping, [(5, first)])
    (changed,) = _train_seeds_in_memory(handle, mapping, [(5, buffer.getvalue())])
    assert np.array_equal(true.result["q_table"], whole.q_table)
    assert not np.array_equal(changed.result["q_table"], whole.q_table)
    assert len(true.result["metrics"].returns) == len(changed.result["metrics"].returns) == 120
