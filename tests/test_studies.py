"""Studies that never lie, tried as a new user would: comparisons, run sets, messages, guards.

Each test here failed on the code before issue 19: a comparison of different tasks that
printed P = 1.000, a sweep point that "did not finish", a traceback from a bad
``env.kwargs``, a message that blamed the wrong source, a guard that was missing.
"""

from __future__ import annotations

import csv
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import invoke, write_yaml
from tests.test_cli import assert_refused

QUICK = ("--workers", "1", "-q")


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Small runs of three environments, a multi-seed run and a sweep with two points."""
    root = tmp_path_factory.mktemp("studies")
    made = {
        "cartpole": ("--seeds", "0-3", "--episodes", "150"),
        "short": ("--seeds", "0-3", "--episodes", "20"),
        "one": ("--seed", "5", "--episodes", "150"),
        "frozenlake": ("-c", "frozenlake", "--seeds", "0-2", "--episodes", "300"),
        "mountaincar": ("-c", "mountaincar", "--seeds", "0-1", "--episodes", "20"),
        "threshold": ("--seeds", "0-1", "--episodes", "20", "--set", "train.reward_threshold=400"),
    }
    paths = {}
    for name, args in made.items():
        paths[name] = root / name
        result = invoke("train", *args, "--out", paths[name], *QUICK)
        assert result.exit_code == 0, result.output
    sweep = write_yaml(
        root / "s.yaml",
        {"base": {"train": {"episodes": 150}}, "seeds": "0-3",
         "grid": {"agent.alpha": [0.1, 0.3]}},
    )  # fmt: skip
    result = invoke("sweep", sweep, "--out", root / "sweep", *QUICK)
    assert result.exit_code == 0, result.output
    paths["point"] = root / "sweep" / "points" / "001"
    return paths


# -- compare -------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("other", "differs"),
    [
        ("frozenlake", 'env.id: A ({a}) has "CartPole-v1", B ({b}) has "FrozenLake-v1"'),
        ("mountaincar", 'env.id: A ({a}) has "CartPole-v1", B ({b}) has "MountainCar-v0"'),
        ("threshold", "reward threshold: A ({a}) has 475.0, B ({b}) has 400.0"),
    ],
)
def test_compare_refuses_runs_of_different_tasks_unless_forced(
    runs: dict[str, Path], other: str, differs: str
) -> None:
    a, b = runs["cartpole"], runs[other]
    result = invoke("compare", a, b)
    assert_refused(result, "not comparable", differs.format(a=a, b=b), "--force")
    forced = invoke("compare", a, b, "--force", "--json")
    assert forced.exit_code == 0, forced.output
    assert "compared although" in forced.stderr
    assert json.loads(forced.stdout)["notes"]


def test_compare_takes_n_runs_and_sweep_points_and_draws_the_aggregate(
    runs: dict[str, Path], tmp_path: Path
) -> None:
    paths = [runs["cartpole"], runs["short"], runs["point"], runs["one"]]
    out = tmp_path / "compare.png"
    result = invoke("compare", *paths, "--json", "--out", out)
    assert result.exit_code == 0, result.output
    figures = json.loads(result.stdout.splitlines()[0])
    assert [run["seeds"] for run in figures["runs"]] == [4, 4, 4, 1]
    pairs = {(p["a"], p["b"]): p["probability_of_improvement"] for p in figures["pairs"]}
    assert len(pairs) == 4 * 3
    for (a, b), probability in pairs.items():  # P(A > B) + P(B > A) = 1
        assert probability + pairs[(b, a)] == pytest.approx(1.0)
    # the 150-episode runs beat the 20-episode ones on every seed
    assert pairs[("A", "B")] == 1.0 and pairs[("C", "B")] == 1.0
    gap = figures["runs"][1]
    assert gap["optimality_gap"] > 0 and gap["optimality_gap_low"] <= gap["optimality_gap"]
    assert out.is_file() and out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    text = invoke("compare", *paths).stdout
    assert "P(row better than column)" in text and "optimality gap" in text


def test_compare_of_a_point_that_is_not_in_the_sweep_says_so(runs: dict[str, Path]) -> None:
    sweep = runs["point"].parent
    result = invoke("compare", runs["cartpole"], sweep / "042")
    assert_refused(result, "is not a point of the sweep", "its points are 000 to 001")


# -- sweep points and multi-seed runs behave like runs ------------------------------------------


def test_eval_and_plot_take_a_sweep_point(runs: dict[str, Path], tmp_path: Path) -> None:
    point = runs["point"]
    result = invoke("eval", point, "--episodes", 2, "--workers", 1, "--json")
    assert result.exit_code == 0, result.output
    report = json.loads(result.stdout)
    assert [run["run_seed"] for run in report["runs"]] == [0, 1, 2, 3]
    with (point.parent.parent / "results.csv").open(newline="") as file:
        rows = [row for row in csv.DictReader(file) if row["point"] == "001"]
    # each seed's kept table, played again: the sweep's own eval means
    full = json.loads(invoke("eval", point, "--workers", 1, "--json").stdout)
    assert [run["mean"] for run in full["runs"]] == [float(row["eval_mean"]) for row in rows]
    result = invoke("plot", point, "--out", tmp_path / "curves.png")
    assert result.exit_code == 0, result.output
    with np.load(point / "curves.npz") as curves:
        assert curves["seed-000.returns"].size == int(rows[0]["episodes"])
    assert invoke("plot", point, "--policy", "--out", tmp_path / "p.png").exit_code == 0


def test_plot_policy_of_several_seeds_draws_their_agreement_or_one_seed(
    runs: dict[str, Path], tmp_path: Path
) -> None:
    multi = runs["cartpole"]
    result = invoke("plot", multi, "--policy", "--out", tmp_path / "all.png")
    assert result.exit_code == 0, result.output
    result = invoke("plot", multi, "--policy", "--seed", 2, "--out", tmp_path / "two.png")
    assert result.exit_code == 0, result.output
    assert_refused(
        invoke("plot", multi, "--policy", "--seed", 9, "--out", tmp_path / "x.png"),
        "--seed 9: it has no finished seed 9",
    )


def test_the_agreement_table_counts_votes_for_the_lowest_greedy_action() -> None:
    from types import SimpleNamespace

    from cartpole_q.experiments.plots import agreement_table

    tables = [np.array([[1.0, 1.0, 0.0]]), np.array([[0.0, 2.0, 0.0]])]
    visits = [np.array([[1, 0, 0]]), np.array([[0, 2, 0]])]
    votes, summed = agreement_table(
        [SimpleNamespace(q_table=q, visits=v) for q, v in zip(tables, visits, strict=True)]
    )
    assert votes.tolist() == [[0.5, 0.5, 0.0]]  # ties go to the lowest action
    assert summed is not None and summed.tolist() == [[1, 2, 0]]


def test_an_interrupted_run_is_used_with_a_notice(runs: dict[str, Path], tmp_path: Path) -> None:
    import shutil

    run = tmp_path / "run"
    shutil.copytree(runs["one"], run)
    summary = json.loads((run / "summary.json").read_text())
    summary["interrupted"] = True
    (run / "summary.json").write_text(json.dumps(summary))
    for args in (("eval", run, "--episodes", 2), ("compare", run, runs["cartpole"])):
        result = invoke(*args)
        assert result.exit_code == 0, result.output
        assert "note: " in result.stderr and "training was interrupted" in result.stderr


def test_eval_echoes_the_conditions_it_played_under(runs: dict[str, Path]) -> None:
    args = ("eval", runs["one"], "--episodes", 2, "--physics", "length=0.75", "--max-steps", 300)
    report = json.loads(invoke(*args, "--json").stdout)
    assert report["conditions"] == {"physics": {"length": 0.75}, "max_steps": 300}
    assert "under physics length=0.75, time limit 300" in invoke(*args).stdout
    multi = invoke("eval", runs["cartpole"], "--episodes", 2, "--physics", "length=0.75",
                   "--workers", 1)  # fmt: skip
    assert "under physics length=0.75" in multi.stdout


def test_frozenlake_headlines_count_seeds_within_the_optimum(runs: dict[str, Path]) -> None:
    result = invoke("eval", runs["frozenlake"], "--episodes", 5, "--workers", 1)
    assert result.exit_code == 0, result.output
    headline = result.stdout.splitlines()[-2]
    assert "seeds within 0.01 of the optimum 0.7442 (exact)" in headline
    assert "greedy mean >= 1" not in result.stdout


def test_robustness_names_seeds_rounds_values_and_guards_its_size(
    runs: dict[str, Path], tmp_path: Path
) -> None:
    out = tmp_path / "r.png"
    result = invoke(
        "robustness", runs["cartpole"], "--vary", "length=0.1:0.5:5", "--episodes", 2,
        "--out", out,
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    assert result.stdout.splitlines() == [str(tmp_path / "r_seeds.csv"), str(out)]
    with (tmp_path / "r_seeds.csv").open(newline="") as file:
        rows = list(csv.DictReader(file))
    assert {row["seed"] for row in rows} == {"0", "1", "2", "3"}
    assert sorted({row["length"] for row in rows}) == ["0.1", "0.2", "0.3", "0.4", "0.5"]
    # the figure's data beside it: at each length the seeds' median and interquartile range
    with out.with_suffix(".csv").open(newline="") as file:
        drawn = [row for row in csv.DictReader(file) if row["series"] == "median across seeds"]
    for row in drawn:
        means = [float(r["mean"]) for r in rows if r["length"] == row["x"]]
        assert len(means) == 4
        assert float(row["y"]) == np.median(means)
        assert [float(row["y_low"]), float(row["y_high"])] == np.percentile(
            means, [25, 75]
        ).tolist()
    assert [row["x"] for row in drawn] == ["0.1", "0.2", "0.3", "0.4", "0.5"]
    big = ("robustness", runs["cartpole"], "--vary", "length=0.1:0.5:1000", "--vary",
           "force_mag=5:15:1000", "--episodes", 10, "--out", tmp_path / "big.png")  # fmt: skip
    assert_refused(invoke(*big), "40,000,000 greedy episodes", "--yes")
    assert not (tmp_path / "big.png").exists()


# -- bad input: a config error naming the key, never a traceback ---------------------------------


@pytest.mark.parametrize(
    ("settings", "named"),
    [
        (("env.kwargs.map_name=9x9",), "command line: env.kwargs.map_name: 'FrozenLake-v1'"),
        (("env.kwargs.desc=5",), "command line: env.kwargs.desc:"),
        (("env.kwargs.max_episode_steps=0",), "env.kwargs.max_episode_steps: the time limit"),
        (("env.kwargs.max_episode_steps=-1",), "env.kwargs.max_episode_steps: the time limit"),
    ],
)
def test_bad_env_kwargs_are_config_errors_naming_the_key(
    in_tmp: Path, settings: tuple[str, ...], named: str
) -> None:
    sets = [arg for setting in settings for arg in ("--set", setting)]
    result = invoke("train", "--set", "env.id=FrozenLake-v1", *sets, "--episodes", 2)
    assert_refused(result, named)
    assert not (in_tmp / "runs").exists()


@pytest.mark.parametrize(
    ("args", "named"),
    [
        (("train", "--set", "env.physics.gravity=-9.8"), "env.physics.gravity: must be in [0, 1000]"),
        (("train", "--set", "env.physics.force_mag=1e308"), "env.physics.force_mag: must be in (0, 10000]"),
        (("train", "--set", "seed=1e30"), "seed: must be an integer no larger than 4294967295"),
        (("train", "--seed", "99999999999"), "--seed"),
        (("train", "--set", "env.id=CartPol-v1"), "command line: env.id: 'CartPol-v1' is not a registered Gymnasium environment; did you mean 'CartPole-v1'?"),
        (("train", "--bogus"), "No such option: --bogus"),
        (("optimum", "FrozenLake-v1", "--gamma", "1"), "--gamma 1: the discounted optimum needs"),
        (("sweep", "nonexist.yaml"), "nonexist.yaml: sweep file not found"),
        (("tune", "nonexist.yaml"), "nonexist.yaml: tune file not found"),
    ],
)  # fmt: skip
def test_messages_name_the_right_source(in_tmp: Path, args: tuple[str, ...], named: str) -> None:
    result = invoke(*args)
    assert_refused(result, named)
    assert "shipped config" not in result.stderr or args[0] == "train"


def test_eval_physics_errors_blame_physics(runs: dict[str, Path]) -> None:
    assert_refused(invoke("eval", runs["one"], "--physics", "length"), "--physics 'length'")
    assert_refused(
        invoke("eval", runs["one"], "--physics", "gravity=-1"),
        "--physics: env.physics.gravity: must be in [0, 1000]",
    )
    assert_refused(
        invoke("robustness", runs["one"], "--vary", "gravity=-10:10:3", "--episodes", 1),
        "--vary: env.physics.gravity: must be in [0, 1000]",
    )


def test_sweep_file_mistakes_are_refused_and_blamed_on_the_point(in_tmp: Path) -> None:
    empty = in_tmp / "empty.yaml"
    empty.write_text("# nothing\n")
    assert_refused(invoke("sweep", empty), "empty.yaml: is empty")
    twice = write_yaml(in_tmp / "twice.yaml", {"grid": {"agent.alpha": [0.1, 0.1]}})
    assert_refused(invoke("sweep", twice), "grid.agent.alpha: has the value 0.1 twice")
    bins = write_yaml(in_tmp / "bins.yaml", {"grid": {"discretization.bins": [[1, 1, 2]]}})
    result = invoke("sweep", bins)
    assert_refused(result, "point 000 (discretization.bins=[1, 1, 2]): discretization.low")
    assert ": base:" not in result.stderr
    (in_tmp / "full").mkdir()
    (in_tmp / "full" / "x").write_text("x")
    plain = write_yaml(in_tmp / "plain.yaml", {"grid": {"agent.alpha": [0.1]}})
    result = invoke("sweep", plain, "--out", in_tmp / "full")
    assert_refused(result, "never writes a new sweep into one", "under sweeps/")
    assert not (in_tmp / "sweeps").exists()


def test_a_sweep_without_axes_says_it_is_one_point(in_tmp: Path) -> None:
    path = write_yaml(in_tmp / "one.yaml", {"base": {"train": {"episodes": 5}}, "seeds": "0-1"})
    result = invoke("sweep", path, "--out", in_tmp / "out", *QUICK)
    assert result.exit_code == 0, result.output
    assert (
        "1 point x 2 seeds = 2 runs (no grid or zip axes: every seed runs the base config)"
        in result.stderr
    )


def test_usage_errors_are_one_line_with_exit_2() -> None:
    for args in (("train", "--bogus"), ("nope",), ("eval",), ("train", "--engine", "x")):
        result = invoke(*args)
        assert_refused(result, "see `cartpole-q")
        assert "╭" not in result.stderr


def test_a_first_run_says_it_is_compiling(in_tmp: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import cartpole_q.numba_cache

    monkeypatch.setattr(cartpole_q.numba_cache, "is_cached", lambda name: False)
    result = invoke("train", "--episodes", 5, "--out", in_tmp / "run")
    assert result.exit_code == 0, result.output
    assert "compiling the training loop for q_learning on CartPole-v1" in result.stderr
    monkeypatch.setattr(cartpole_q.numba_cache, "is_cached", lambda name: True)
    result = invoke("train", "--episodes", 5, "--out", in_tmp / "again")
    assert "compiling" not in result.stderr


def test_is_cached_finds_the_compiled_loop() -> None:
    from cartpole_q.config import load_config
    from cartpole_q.envs.registry import twin_for
    from cartpole_q.numba_cache import is_cached
    from cartpole_q.rl.algorithms import get
    from cartpole_q.training import train

    train(load_config(overrides={"train.episodes": 1}))  # compiles or loads it
    twin = twin_for("CartPole-v1")
    assert twin is not None
    # one exploring episode: the exploring loop (engines.kernel: one loop per kind of episode)
    assert is_cached(f"train_exploring__{get('q_learning').key}__{twin.key}")
    assert not is_cached("no_such_function_anywhere")


@pytest.mark.slow
def test_an_unreachable_ray_address_fails_within_seconds(tmp_path: Path) -> None:
    pytest.importorskip("ray")
    sweep = write_yaml(tmp_path / "s.yaml", {"grid": {"agent.alpha": [0.1]}})
    started = time.monotonic()
    done = subprocess.run(
        [sys.executable, "-m", "cartpole_q", "sweep", str(sweep), "--backend", "ray",
         "--address", "127.0.0.1:1", "--out", str(tmp_path / "out")],
        capture_output=True, text=True, timeout=60, cwd=tmp_path,
        env={**os.environ},
    )  # fmt: skip
    assert done.returncode == 2, done.stderr
    assert time.monotonic() - started < 20
    assert "--address 127.0.0.1:1: no Ray cluster answers there" in done.stderr
    assert "Traceback" not in done.stderr
    assert not (tmp_path / "out").exists()


# -- figures -----------------------------------------------------------------------------------


def test_profiles_are_visible_when_every_seed_scores_the_same() -> None:
    from cartpole_q.figures import profile_thresholds

    taus = profile_thresholds([np.full(10, 500.0)], 475.0)
    assert taus[0] < 475.0 < 500.0 < taus[-1]


def test_sweep_figures_join_neighbours_along_one_axis_only() -> None:
    from cartpole_q.figures import SweepAxis, sweep_figure

    stats = [{"success_rate": 0.5, "success_rate_low": 0.2, "success_rate_high": 0.8,
              "median_solved_episode": 100.0, "median_solved_episode_low": 90.0,
              "median_solved_episode_high": 110.0, "iqm_eval_return": 400.0}] * 8  # fmt: skip
    means = [np.full(3, 400.0)] * 8
    three = [SweepAxis(name, ["1", "2"]) for name in ("a", "b", "c")]
    figure = sweep_figure("s", three, [f"{i:03d}" for i in range(8)], stats, means, 475.0)
    assert figure.axes[0].lines[0].get_linestyle() == "None"
    one = sweep_figure(
        "s", [SweepAxis("a", ["1", "2"])], ["000", "001"], stats[:2], means[:2], None
    )
    assert one.axes[0].lines[0].get_linestyle() == "-"


def test_taxi_policy_maps_put_row_0_at_the_top(tmp_path: Path) -> None:
    result = invoke("train", "-c", "taxi", "--episodes", 50, "--out", tmp_path / "taxi", *QUICK)
    assert result.exit_code == 0, result.output
    import matplotlib.figure

    from cartpole_q.experiments.plots import plot_policy

    drawn: list[matplotlib.figure.Figure] = []
    import cartpole_q.experiments.plots as plots

    real = plots.policy_figure

    def keep(*args: object, **kwargs: object) -> matplotlib.figure.Figure:
        figure = real(*args, **kwargs)  # type: ignore[arg-type]
        drawn.append(figure)
        return figure

    plots.policy_figure = keep  # type: ignore[assignment]
    try:
        plot_policy(tmp_path / "taxi", tmp_path / "p.png", None)
    finally:
        plots.policy_figure = real  # type: ignore[assignment]
    assert drawn[0].axes[0].yaxis_inverted()


def test_exact_gaps_hide_rounding_noise() -> None:
    from cartpole_q.cli.exact_text import exact_lines

    lines = exact_lines({
        "optimum": {"return": 0.5, "discounted": 0.4, "gamma": 0.99}, "note": "n",
        "greedy": {"return": 0.5, "discounted": 0.4 + 1.641e-11},
        "gap": {"return": 0.0, "discounted": -1.641e-11},
    })  # fmt: skip
    assert lines[1].endswith("gap 0")


def test_the_readme_names_every_shipped_config() -> None:
    from cartpole_q.config import shipped_configs
    from tests.conftest import REPO

    text = (REPO / "docs" / "reference" / "configuration.md").read_text()
    section = text[text.index("Shipped configs (installed") :].split("\n\n")[0]
    missing = [name for name in shipped_configs() if f"`{name}`" not in section]
    assert not missing, f"the configuration reference's list of shipped configs misses {missing}"


def test_compile_fills_the_cache_for_a_config(in_tmp: Path) -> None:
    from cartpole_q.config import load_config
    from cartpole_q.envs.registry import twin_for
    from cartpole_q.numba_cache import is_cached
    from cartpole_q.rl.algorithms import get

    result = invoke("compile", "--workers", 1)
    assert result.exit_code == 0, result.output
    assert "compiled q_learning on CartPole-v1 (numba engine)" in result.stdout
    assert "2 compiled or loaded, 0 skipped, in " in result.stdout
    twin = twin_for(load_config().env.id)
    assert twin is not None
    # the default's epsilon reaches 0 at episode 90: both loops
    for kind in ("exploring", "greedy"):
        assert is_cached(f"train_{kind}__{get('q_learning').key}__{twin.key}")
    assert is_cached(f"next_step__{get('q_learning').key}__values")
    assert_refused(invoke("compile", "-c", "default", "--all"), "not both")


def test_compile_names_what_it_skipped_and_counts_it_apart(in_tmp: Path) -> None:
    # the twins report no step info: the numba engine cannot record train.info_metric
    config = write_yaml(in_tmp / "lake.yaml", {
        "env": {"id": "FrozenLake-v1"}, "train": {"info_metric": "prob"},
    })  # fmt: skip
    result = invoke("compile", "-c", config, "--workers", 1)
    assert result.exit_code == 0, result.output
    lines = result.stdout.splitlines()
    assert "compiled q_learning on FrozenLake-v1 (gymnasium engine)" in lines
    skipped = [line for line in lines if line.startswith("skipped ")]
    assert len(skipped) == 1 and "q_learning on FrozenLake-v1 (numba engine): " in skipped[0]
    assert "train.info_metric" in skipped[0]
    assert lines[-1].startswith("1 compiled or loaded, 1 skipped, in ")


def _shipped_study(tmp_path: Path, name: str) -> Path:
    """Run ``examples/book/<name>.yaml`` as a reader would; its study directory."""
    out = tmp_path / name
    study = Path(__file__).resolve().parents[1] / "examples" / "book" / f"{name}.yaml"
    result = invoke("study", study, "--out", out, "-q")
    assert result.exit_code == 0, result.output
    return out


def _grid_arrows(figure_data: Path) -> dict[str, dict[tuple[int, int], int]]:
    """A grid-arrows figure's greedy actions by panel, as ``{(row, column): action}``."""
    rows = figure_data.read_text(encoding="utf-8").splitlines()[1:]
    arrows: dict[str, dict[tuple[int, int], int]] = {}
    for row in rows:
        panel, series, x, y, _, _, value = row.rsplit(",", 6)
        if series == "greedy action (empty: all values equal)" and value:
            arrows.setdefault(panel.strip('"'), {})[(int(y), int(x))] = int(value)
    return arrows


def test_figure_7_4_sets_one_arrow_for_one_step_sarsa_and_the_last_ten_steps_for_ten(
    tmp_path: Path,
) -> None:
    """The shipped study: one episode on the Dyna maze, the same path for both n."""
    out = _shipped_study(tmp_path, "fig7_4_n_step_sarsa_path")
    arrows = _grid_arrows(out / "fig7_4_n_step_sarsa_path.csv")
    # one-step SARSA: only the last action, up from (1, 8) into the goal at (0, 8)
    assert arrows["n 1, seed 4"] == {(1, 8): 0}
    # the path: both points take the same 72 steps through the same 25 cells, shaded
    for point in ("000", "001"):
        visits = np.load(out / "points" / point / "visits.npz")["seed-004"]
        assert visits.shape == (54, 4) and visits.sum() == 72
        assert (visits.sum(axis=1) > 0).sum() == 25
    # 10-step: the last ten actions, from six cells up the right-hand column (up 0, down 1,
    # right 3: in (1, 8) the bumps to the right, each strengthened, outweigh the last step)
    assert arrows["n 10, seed 4"] == {
        (4, 7): 3, (3, 7): 1, (4, 8): 0, (3, 8): 0, (2, 8): 0, (1, 8): 3,
    }  # fmt: skip


def test_figure_6_1_moves_every_prediction_as_monte_carlo_and_td_recommend(
    tmp_path: Path,
) -> None:
    """The shipped study: one drive from Example 6.1's predictions, alpha 1, arrows drawn."""
    out = _shipped_study(tmp_path, "fig6_1_driving_home")
    rows = list(csv.DictReader((out / "fig6_1_driving_home.csv").open(encoding="utf-8")))
    drawn: dict[tuple[str, str], list[float]] = {}
    for row in rows:
        drawn.setdefault((row["panel"], row["series"]), []).append(float(row["y"]))
    for algorithm in ("mc_prediction", "td"):
        assert drawn[(f"algorithm {algorithm}", "before the run")] == [30, 35, 15, 10, 3]
        assert drawn[(f"algorithm {algorithm}", "true values")] == [43, 38, 23, 13, 3]
    assert drawn[("algorithm mc_prediction", "after the run")] == [43, 38, 23, 13, 3]
    assert drawn[("algorithm td", "after the run")] == [40, 30, 20, 13, 3]


def test_figure_8_3_dyna_q_stops_halfway_through_its_second_episode(tmp_path: Path) -> None:
    """The shipped study: n 0 has set one arrow, n 50 a policy over most of the maze."""
    out = _shipped_study(tmp_path, "fig8_3_dyna_policies")
    # the first episode whole, the second cut at half its length (104 and 38 uncut)
    lengths = {
        point: np.load(out / "points" / point / "curves.npz")["seed-000.lengths"].tolist()
        for point in ("000", "001")
    }
    assert lengths == {"000": [108, 52], "001": [294, 19]}
    for point, steps in (("000", 160), ("001", 313)):  # the path of each: every step taken
        visits = np.load(out / "points" / point / "visits.npz")["seed-000"]
        assert visits.sum() == steps
    arrows = {
        panel: len(cells) for panel, cells in _grid_arrows(out / "fig8_3_dyna_policies.csv").items()
    }
    assert arrows == {
        "planning_steps 0, max_env_steps 160, seed 0": 1,
        "planning_steps 50, max_env_steps 313, seed 0": 23,
    }
