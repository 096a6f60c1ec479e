"""Bandits (chapter 2): the testbed, its twin, both engines and the re-derivation agree exactly.

``tests/reference_bandits.py`` re-derives every rule from docs/algorithms.md ("Bandits")
without the package; each rule's rewards and optimal flags must be its floats, byte for byte,
on the numba engine (the compiled twin) and on the gymnasium engine (``gymnasium.make``).
"""

from __future__ import annotations

import csv
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np
import pytest
import yaml
from gymnasium.utils.env_checker import check_env

import cartpole_q  # noqa: F401  (registers the worlds)
from cartpole_q.engines.bandit import (
    make_env,
    play_curve,
    play_run_gymnasium,
    play_run_numba,
    run_generators,
)
from cartpole_q.families.bandit.twin import ArmedTestbed, reset_testbed, step_testbed
from cartpole_q.rl.bandits import RULES, BanditAgent
from tests.conftest import REPO, invoke, write_yaml
from tests.reference_bandits import Learner, reference_run

STEPS = 150
SEEDS = (0, 1, 7)

LEARNERS = {
    "greedy": Learner("epsilon_greedy"),
    "epsilon 0.01": Learner("epsilon_greedy", epsilon=0.01),
    "epsilon 0.1": Learner("epsilon_greedy", epsilon=0.1),
    "epsilon 1": Learner("epsilon_greedy", epsilon=1.0),
    "optimistic": Learner("epsilon_greedy", alpha=0.1, q_init=5.0),
    "epsilon 0.1 constant alpha": Learner("epsilon_greedy", epsilon=0.1, alpha=0.1),
    "ucb c 2": Learner("ucb", c=2.0),
    "ucb c 1 constant alpha": Learner("ucb", c=1.0, alpha=0.1),
    "gradient baseline": Learner("gradient", alpha=0.1, baseline=True),
    "gradient no baseline": Learner("gradient", alpha=0.4),
}
TESTBEDS = {
    "stationary": ArmedTestbed(10, 0.0, 1.0, 0.0),
    "mean 4": ArmedTestbed(10, 4.0, 1.0, 0.0),
    "walk": ArmedTestbed(10, 0.0, 0.0, 0.01),
    "5 arms": ArmedTestbed(5, 0.0, 1.0, 0.0),
}


def agent_of(learner: Learner) -> BanditAgent:
    return BanditAgent(
        RULES[learner.method], learner.epsilon, learner.c, learner.alpha, learner.q_init,
        learner.baseline,
    )  # fmt: skip


def test_the_testbed_is_registered_and_passes_check_env() -> None:
    env = gymnasium.make("cartpole_q/Bandit-v0")
    check_env(env.unwrapped)
    assert env.action_space == gymnasium.spaces.Discrete(10)
    assert env.observation_space == gymnasium.spaces.Discrete(1)
    assert env.spec is not None and env.spec.max_episode_steps == 1000  # the book's runs


def test_reset_draws_the_true_values_in_arm_order_from_the_envs_generator() -> None:
    env = gymnasium.make("cartpole_q/Bandit-v0", mean=4.0)
    _, info = env.reset(seed=12)
    expected = np.random.Generator(np.random.PCG64(np.random.SeedSequence(12))).normal(
        4.0, 1.0, size=10
    )
    assert info["q_star"].tobytes() == expected.tobytes()
    best = int(np.argmax(expected))
    assert env.step(best)[4]["optimal"] and not env.step((best + 1) % 10)[4]["optimal"]


@pytest.mark.parametrize("name", TESTBEDS)
def test_the_twin_draws_what_the_environment_draws(name: str) -> None:
    from cartpole_q.engines.compile import jit

    testbed = TESTBEDS[name]
    env = make_env(testbed)
    _, info = env.reset(seed=3)
    rng = np.random.Generator(np.random.PCG64(np.random.SeedSequence(3)))
    q_star = np.empty(testbed.k)
    jit(reset_testbed)(testbed, q_star, rng)
    assert q_star.tobytes() == info["q_star"].tobytes()
    step = jit(step_testbed)
    arms = np.random.default_rng(0).integers(0, testbed.k, size=300)
    for arm in arms:
        _, reward, terminated, truncated, info = env.step(int(arm))
        twin_reward, twin_optimal = step(testbed, q_star, int(arm), rng)
        assert (reward, info["optimal"]) == (twin_reward, twin_optimal)
        assert not terminated and not truncated
    assert q_star.tobytes() == env.unwrapped.q_star.tobytes()  # type: ignore[attr-defined]


# One worker for all: they compile the same bandit loop, once.
@pytest.mark.xdist_group("bandit-loops")
@pytest.mark.parametrize("name", LEARNERS)
def test_both_engines_equal_the_rederivation_byte_for_byte(name: str) -> None:
    learner = LEARNERS[name]
    testbed = TESTBEDS["mean 4"] if learner.method == "gradient" else TESTBEDS["stationary"]
    agent = agent_of(learner)
    for seed in SEEDS:
        rewards, optimal = reference_run(learner, seed, STEPS, *testbed)
        expected = (np.array(rewards).tobytes(), np.array(optimal).tobytes())
        for play in (play_run_numba, play_run_gymnasium):
            got_rewards, got_optimal = play(agent, testbed, seed, STEPS)
            assert (got_rewards.tobytes(), got_optimal.tobytes()) == expected, (name, play, seed)


@pytest.mark.parametrize("testbed_name", ["walk", "5 arms"])
def test_the_walk_and_other_arm_counts_equal_the_rederivation(testbed_name: str) -> None:
    testbed = TESTBEDS[testbed_name]
    for learner in (LEARNERS["epsilon 0.1 constant alpha"], LEARNERS["ucb c 2"]):
        rewards, optimal = reference_run(learner, 5, STEPS, *testbed)
        for play in (play_run_numba, play_run_gymnasium):
            got = play(agent_of(learner), testbed, 5, STEPS)
            assert got[0].tobytes() == np.array(rewards).tobytes()
            assert got[1].tobytes() == np.array(optimal).tobytes()


def test_a_run_longer_than_the_registered_time_limit_plays_on() -> None:
    agent, testbed = agent_of(LEARNERS["ucb c 2"]), TESTBEDS["walk"]
    numba_run = play_run_numba(agent, testbed, 3, 1_200)
    gymnasium_run = play_run_gymnasium(agent, testbed, 3, 1_200)
    assert numba_run[0].tobytes() == gymnasium_run[0].tobytes()
    assert numba_run[1].tobytes() == gymnasium_run[1].tobytes()


def test_bad_testbed_arguments_are_refused_by_the_environment() -> None:
    for kwargs in ({"k": 0}, {"spread": -1.0}, {"walk": float("nan")}, {"mean": "4"}):
        with pytest.raises(ValueError, match="must be"):
            gymnasium.make("cartpole_q/Bandit-v0", **kwargs)


def test_a_curve_averages_each_step_over_the_runs_in_seed_order() -> None:
    learner = LEARNERS["epsilon 0.1"]
    testbed = TESTBEDS["stationary"]
    seeds = [4, 2, 9]
    curve = play_curve(agent_of(learner), testbed, seeds, 50, keep_runs=True)
    runs = [reference_run(learner, seed, 50) for seed in seeds]
    total = [0.0] * 50
    for rewards, _ in runs:
        total = [a + b for a, b in zip(total, rewards, strict=True)]
    assert curve.average_reward.tolist() == [value / 3 for value in total]
    counts = [sum(optimal[t] for _, optimal in runs) for t in range(50)]
    assert curve.optimal_percent.tolist() == [100.0 * count / 3 for count in counts]
    gymnasium_curve = play_curve(agent_of(learner), testbed, seeds, 50, engine="gymnasium")
    assert gymnasium_curve.average_reward.tobytes() == curve.average_reward.tobytes()
    assert gymnasium_curve.optimal_percent.tobytes() == curve.optimal_percent.tobytes()


def test_run_seeds_follow_the_package_convention() -> None:
    agent_rng, env_seed = run_generators(0)
    agent_seq, env_seq = np.random.SeedSequence(0).spawn(2)
    assert agent_rng.random() == np.random.Generator(np.random.PCG64(agent_seq)).random()
    assert env_seed == int(env_seq.generate_state(1, dtype=np.uint32)[0])


# -- cartpole-q bandit --------------------------------------------------------------------------

BOOK = REPO / "examples" / "book"


def small_study(tmp_path: Path, name: str, **change: Any) -> Path:
    """A shipped study file on few runs and steps (its curves, figure and book kept)."""
    study = yaml.safe_load((BOOK / f"{name}.yaml").read_text(encoding="utf-8"))
    study.update({"seeds": "0-19", "steps": 100})
    for entry in study.get("book", []):
        entry.pop("step", None)
        entry.pop("steps", None)
    study.update(change)
    return write_yaml(tmp_path / f"{name}.yaml", study)


def test_bandit_draws_a_figure_with_its_data_and_prints_the_books_numbers(tmp_path: Path) -> None:
    out = tmp_path / "fig2_2"
    path = small_study(tmp_path, "fig2_2_epsilon_greedy")
    result = invoke("bandit", path, "--out", out)
    assert result.exit_code == 0, result.output
    assert "bandit: 60/60 runs, 3/3 learners" in result.stdout  # progress, counted in runs
    lines = [line for line in result.stdout.splitlines() if not line.startswith("bandit: ")]
    assert lines[0].startswith("fig2_2_epsilon_greedy: 20 runs x 100 steps on the 10-armed")
    assert any(line.startswith("  ε = 0.1, average reward at step 1,000: book ~1.35, ours ")
               for line in lines)  # fmt: skip
    figure = out / "fig2_2_epsilon_greedy.png"
    assert lines[-1] == str(out) and figure.read_bytes().startswith(b"\x89PNG")
    assert (out / "summary.txt").read_text(encoding="utf-8").splitlines() == lines[:-1]
    data = out / "fig2_2_epsilon_greedy.csv"
    rows = list(csv.DictReader(data.read_text(encoding="utf-8").splitlines()))
    curve = [
        row for row in rows if row["panel"] == "% Optimal action" and row["series"] == "ε = 0.1"
    ]
    assert [int(row["x"]) for row in curve] == list(range(1, 101))
    # The plotted numbers are the engines' averages, exactly (20 runs: multiples of 5%).
    expected = play_curve(agent_of(LEARNERS["epsilon 0.1"]), TESTBEDS["stationary"],
                          list(range(20)), 100)  # fmt: skip
    assert [float(row["y"]) for row in curve] == expected.optimal_percent.tolist()
    # The gymnasium engine writes the same data; `study` runs the same file the same way.
    other = tmp_path / "other"
    assert invoke("bandit", path, "--out", other, "--engine", "gymnasium").exit_code == 0
    assert (other / data.name).read_bytes() == data.read_bytes()
    assert "engine: gymnasium" in (other / "study.yaml").read_text(encoding="utf-8")
    assert invoke("study", path, "--out", tmp_path / "third", "-q").exit_code == 0
    assert (tmp_path / "third" / data.name).read_bytes() == data.read_bytes()
    again = invoke("bandit", path, "--out", out)
    assert again.exit_code == 2 and "points at a non-empty directory" in again.stderr


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"stesp": 10}, "unknown key 'stesp'; did you mean 'steps'?"),
        ({"steps": 0}, "steps: must be a whole number >= 1"),
        ({"seeds": "x"}, "seeds:"),
        ({"testbed": {"k": 0}}, "testbed: k: must be a whole number >= 1"),
        ({"testbed": {"walk": -1}}, "testbed.spread and testbed.walk must not be negative"),
        ({"curves": []}, "curves: must be a list of learners"),
        ({"curves": [{"method": "softmax"}]}, "curves[0].method: must be one of epsilon_greedy"),
        ({"curves": [{"method": "ucb", "epsilon": 0.1}]}, "curves[0].epsilon: ucb takes no"),
        ({"curves": [{"method": "gradient"}]}, "curves[0].alpha: the gradient bandit needs"),
        ({"curves": [{"method": "epsilon_greedy", "epsilon": 2}]}, "epsilon must be in [0, 1]"),
        ({"curves": [{"method": "epsilon_greedy", "alpha": 0}]}, "alpha: must be positive"),
        ({"curves": [{"method": "ucb", "vary": "c", "values": [1]}]}, "only a parameter study"),
        ({"figure": {"kind": "pie"}}, "figure.kind: must be one of curves, parameter_study"),
        ({"figure": {"kind": "curves", "metrics": ["regret"]}}, "figure.metrics: a list of"),
        (
            {"book": [{"label": "x", "value": 1, "curve": 7}]},
            "book[0].curve: a curve's index in `curves` (0 to 2), got 7",
        ),
        ({"book": [{"label": "x", "value": 1, "curve": 0, "step": 101}]}, "book[0].step: 101"),
        ({"book": [{"label": "x", "value": 1, "curve": 0, "of": "peak"}]}, "book[0].of: must be"),
        ({"book": [{"label": "x", "curve": 0, "above": 3}]}, "book[0].above: a curve's index"),
        ({"book": [{"label": "x", "curve": 0, "above": 1, "value": 2}]}, "not both"),
        ({"book": [{"label": "x", "curve": 0}]}, "book[0].value: the book's value, a number"),
    ],
)
def test_bandit_refuses_bad_study_files_with_exit_code_2(
    tmp_path: Path, change: dict[str, Any], message: str
) -> None:
    path = small_study(tmp_path, "fig2_2_epsilon_greedy", **change)
    result = invoke("bandit", path, "--out", tmp_path / "study")
    assert result.exit_code == 2, result.output
    assert message in result.stderr, result.stderr
    assert result.stderr.startswith(f"error: {path}") and "Traceback" not in result.stderr
    assert not (tmp_path / "study").exists()


def test_bandit_refuses_a_missing_file_a_bad_out_and_a_bad_engine(tmp_path: Path) -> None:
    result = invoke("bandit", tmp_path / "nope.yaml")
    assert result.exit_code == 2 and "study file not found" in result.stderr
    study = BOOK / "fig2_2_epsilon_greedy.yaml"
    (tmp_path / "f.txt").write_text("x")
    result = invoke("bandit", study, "--out", tmp_path / "f.txt")
    assert (
        result.exit_code == 2 and "--out must be a directory, but this is a file" in result.stderr
    )
    result = invoke("bandit", study, "--engine", "jax", "--out", tmp_path / "s")
    assert result.exit_code == 2 and "engine: must be one of numba, gymnasium" in result.stderr
    result = invoke("bandit", REPO / "examples" / "book" / "fig4_1_small_gridworld.yaml")
    assert result.exit_code == 2 and "is a dp study, not a bandit study" in result.stderr
    result = invoke("updates", study, "--check")  # the alias answers by the name it was called
    assert result.exit_code == 2
    assert "is a bandit study, not an updates study" in result.stderr
    assert "(`updates` runs updates studies)" in result.stderr
    assert not (tmp_path / "s").exists()


# -- the book's figures ---------------------------------------------------------------------------

BOOK_DATA = REPO / "docs" / "book"


CHAPTER_2 = sorted([*BOOK.glob("fig2_*.yaml"), *BOOK.glob("exercise2_*.yaml")])


@pytest.mark.parametrize("study", CHAPTER_2, ids=lambda path: path.stem)
def test_each_shipped_study_runs_on_few_runs(tmp_path: Path, study: Path) -> None:
    data = yaml.safe_load(study.read_text(encoding="utf-8"))
    # The book's 2,000 runs x 1,000 steps (Exercise 2.5: "longer runs, say of 10,000 steps").
    assert data["seeds"] == "0-1999"
    assert data["steps"] == (10_000 if study.stem.startswith("exercise") else 1000)
    path = small_study(tmp_path, study.stem, seeds="0-1", steps=20)
    out = tmp_path / "study"
    result = invoke("study", path, "--out", out, "--workers", 1)
    assert result.exit_code == 0, result.output
    figure = out / data["figure"]["file"]
    assert figure.is_file() and figure.with_suffix(".csv").is_file()
    assert (BOOK_DATA / data["figure"]["file"]).is_file()


def curves_of(figure: str, panel: str) -> dict[str, list[float]]:
    """The shipped data's curves of one panel, by series."""
    text = (BOOK_DATA / f"{figure}.csv").read_text(encoding="utf-8").splitlines()
    curves: dict[str, list[float]] = {}
    for row in csv.DictReader(text):
        if row["panel"] == panel:
            curves.setdefault(row["series"], []).append(float(row["y"]))
    return curves


def from_step(upper: list[float], lower: list[float]) -> int:
    """The step from which ``upper`` stays above ``lower`` to the end."""
    below = [step for step, (a, b) in enumerate(zip(upper, lower, strict=True), 1) if a <= b]
    return below[-1] + 1 if below else 1


def test_the_shipped_figures_show_what_the_book_shows() -> None:
    reward = curves_of("fig2_2_epsilon_greedy", "Average reward")
    optimal = curves_of("fig2_2_epsilon_greedy", "% Optimal action")
    assert 1.30 <= reward["ε = 0.1"][-1] <= 1.40 and 77 <= optimal["ε = 0.1"][-1] <= 83
    assert (
        0.95 <= reward["ε = 0 (greedy)"][-1] <= 1.10 and 32 <= optimal["ε = 0 (greedy)"][-1] <= 40
    )
    assert optimal["ε = 0.01"][999] > optimal["ε = 0.01"][499] > optimal["ε = 0 (greedy)"][-1]
    optimistic = curves_of("fig2_3_optimistic", "% Optimal action")
    upper, lower = optimistic.values()
    assert from_step(upper, lower) <= 200 and upper[10] > 40  # the spike at step 11
    ucb = curves_of("fig2_4_ucb", "Average reward")
    assert from_step(ucb["UCB c = 2"], ucb["ε-greedy ε = 0.1"]) <= 60
    gradient = curves_of("fig2_5_gradient", "% Optimal action")
    for alpha in ("0.1", "0.4"):
        with_baseline = gradient[f"\N{GREEK SMALL LETTER ALPHA} = {alpha}, with baseline"][499:]
        without = gradient[f"\N{GREEK SMALL LETTER ALPHA} = {alpha}, without baseline"][499:]
        assert min(a - b for a, b in zip(with_baseline, without, strict=True)) > 20


def test_the_shipped_nonstationary_study_favours_a_constant_step_size() -> None:
    optimal = curves_of("exercise2_5_nonstationary", "% Optimal action")
    constant, averages = (
        optimal["constant \N{GREEK SMALL LETTER ALPHA} = 0.1"],
        optimal["sample averages"],
    )
    assert optimal["sample averages"][0] == 100.0  # every arm starts equal: all are optimal
    assert from_step(constant, averages) <= 300 and constant[-1] - averages[-1] > 20


def test_the_shipped_parameter_study_shows_inverted_us_and_ucb_best() -> None:
    lines = curves_of("fig2_6_parameter_study", "")
    assert len(lines) == 4
    for label, points in lines.items():
        peak = points.index(max(points))
        assert 0 < peak < len(points) - 1, label  # an inverted U: the best value inside
    best = {label: max(points) for label, points in lines.items()}
    assert max(best, key=best.__getitem__).startswith("UCB") and 1.44 <= best["UCB (c)"] <= 1.52


@pytest.mark.slow
def test_ctrl_c_stops_a_study_within_seconds_with_exit_code_130(tmp_path: Path) -> None:
    import os
    import signal
    import subprocess
    import sys
    import time

    out = tmp_path / "study"
    process = subprocess.Popen(
        [sys.executable, "-m", "cartpole_q", "bandit", str(BOOK / "fig2_6_parameter_study.yaml"),
         "--out", str(out), "--engine", "gymnasium", "--workers", "1"],
        cwd=tmp_path, env={**os.environ, "PYTHONPATH": str(REPO)},
        stdout=subprocess.PIPE, stderr=subprocess.PIPE,
    )  # fmt: skip
    time.sleep(4.0)
    process.send_signal(signal.SIGINT)
    sent = time.monotonic()
    _, stderr = process.communicate(timeout=30)
    assert process.returncode == 130, stderr
    assert time.monotonic() - sent < 5.0
    assert b"stopping after the runs in flight" in stderr
    assert f"finish it with `cartpole-q bandit --resume {out}`".encode() in stderr
    assert b"Traceback" not in stderr
    assert not (out / "fig2_6_parameter_study.png").exists()


def test_a_study_reads_fractions_defaults_and_sample_averages(tmp_path: Path) -> None:
    from cartpole_q.experiments.bandits import load_study

    path = write_yaml(
        tmp_path / "study.yaml",
        {
            "seeds": "0-9",
            "curves": [
                {"method": "ucb", "vary": "c", "values": ["1/16", 0.5, "2"]},
                {"method": "epsilon_greedy", "alpha": "sample_average", "vary": "epsilon",
                 "values": ["1/128", "1e-2"]},
                {"method": "gradient", "baseline": True, "vary": "alpha", "values": [0.25]},
            ],
            "figure": {"kind": "parameter_study"},
        },
    )  # fmt: skip
    study = load_study(path)
    assert study.name == "study" and study.steps == 1000 and study.testbed == (10, 0.0, 1.0, 0.0)
    assert study.seeds == tuple(range(10)) and study.file == "study.png"
    assert [curve.values for curve in study.curves] == [
        (0.0625, 0.5, 2.0),
        (0.0078125, 0.01),
        (0.25,),
    ]
    ucb, greedy, gradient = (curve.agents() for curve in study.curves)
    assert [agent.c for agent in ucb] == [0.0625, 0.5, 2.0] and ucb[0].alpha == 0.0
    assert [agent.epsilon for agent in greedy] == [0.0078125, 0.01]
    assert gradient[0].alpha == 0.25 and gradient[0].baseline
