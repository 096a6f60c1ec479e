"""Learning curves of any metric across seeds, and ``plot --metric``."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from matplotlib.image import imread

from cartpole_q import learning_curves
from cartpole_q.learning_curves import (
    aggregate_band,
    interquartile_mean,
    nan_percentiles,
    per_episode,
    seed_curves,
    smooth,
)
from tests.conftest import invoke


def test_per_episode_metrics_by_hand() -> None:
    returns, lengths = np.array([1.0, -2.0, 4.0]), np.array([10, 20, 5])
    assert per_episode(returns, lengths, "return").tolist() == [1.0, -2.0, 4.0]
    assert per_episode(returns, lengths, "length").tolist() == [10.0, 20.0, 5.0]
    assert per_episode(returns, lengths, "cumulative-return").tolist() == [1.0, -1.0, 3.0]
    assert per_episode(returns, lengths, "episodes").tolist() == [1.0, 2.0, 3.0]
    with pytest.raises(ValueError, match="unknown metric"):
        per_episode(returns, lengths, "reward")


def test_an_env_steps_grid_is_a_step_function_of_finished_episodes() -> None:
    # seed 0 finishes episodes at steps 10, 30, 35; seed 1 at 5, 10 and then stops
    curves = seed_curves(
        [np.array([1.0, 2.0, 3.0]), np.array([5.0, 6.0])],
        [np.array([10, 20, 5]), np.array([5, 5])],
        "cumulative-return",
        "env-steps",
    )
    assert curves.x[0] == 0.0 and curves.x[-1] == 35.0
    at = {float(x): i for i, x in enumerate(curves.x)}
    first = curves.values[0]
    assert first[0] == 0.0  # nothing finished: a running total of 0
    assert first[-1] == 6.0
    # before step 10 seed 0 has finished nothing; from 10 to 30 one episode
    for i, x in enumerate(curves.x):
        expected = 0.0 if x < 10 else 1.0 if x < 30 else 3.0 if x < 35 else 6.0
        assert first[i] == expected, x
    second = curves.values[1]
    assert np.isnan(second[curves.x > 10]).all()  # it stopped training at step 10
    assert second[at[0.0]] == 0.0
    # a per-episode metric has no value before its first episode ends
    lengths = seed_curves([np.array([1.0])], [np.array([10])], "length", "env-steps")
    assert np.isnan(lengths.values[0][lengths.x < 10]).all()
    assert (lengths.values[0][lengths.x >= 10] == 10.0).all()


def test_an_episode_grid_pads_shorter_seeds_with_nan_and_smooths_per_seed() -> None:
    curves = seed_curves(
        [np.array([2.0, 4.0, 6.0]), np.array([1.0])],
        [np.array([1, 1, 1]), np.array([1])],
        "return",
        "episode",
        window=2,
    )
    assert curves.x.tolist() == [1.0, 2.0, 3.0]
    assert curves.values[0].tolist() == [2.0, 3.0, 5.0]
    assert curves.values[1][0] == 1.0 and np.isnan(curves.values[1][1:]).all()
    assert smooth(np.array([1.0, 2.0]), 1).tolist() == [1.0, 2.0]


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(-1e6, 1e6), min_size=1, max_size=40))
def test_the_interquartile_mean_is_the_mean_of_the_middle_half(values: list[float]) -> None:
    ordered = sorted(values)
    cut = len(values) // 4
    expected = float(np.mean(ordered[cut : len(values) - cut]))
    got = interquartile_mean(np.array(values)[:, None])[0]
    assert got == pytest.approx(expected, rel=1e-12, abs=1e-9)
    # NaN (a seed without a value there) is left out, as if the seed were absent
    with_nan = np.array([*values, np.nan])[:, None]
    assert interquartile_mean(with_nan)[0] == pytest.approx(expected, rel=1e-12, abs=1e-9)


@settings(max_examples=80, deadline=None)
@given(
    st.integers(1, 30).flatmap(
        lambda rows: st.lists(
            st.lists(
                st.one_of(st.floats(-1e9, 1e9), st.sampled_from([np.nan, np.inf, -np.inf])),
                min_size=rows,
                max_size=rows,
            ),
            min_size=1,
            max_size=12,
        )
    ),
    st.lists(st.floats(0.0, 100.0), min_size=1, max_size=3),
)
def test_nan_percentiles_are_numpys_nanpercentile(
    columns: list[list[float]], percents: list[float]
) -> None:
    values = np.array(columns).T  # (rows, columns), NaN anywhere, whole columns of it too
    with warnings.catch_warnings():  # (numpy warns of a column of NaN alone)
        warnings.simplefilter("ignore", RuntimeWarning)
        expected = np.nanpercentile(values, percents, axis=0)
    got = nan_percentiles(values, percents)
    assert np.array_equal(got, expected, equal_nan=True)  # the same numbers


@pytest.mark.parametrize("aggregate", ["mean", "iqm", "mean_square"])
def test_a_long_curves_band_is_computed_in_blocks_as_at_once(
    aggregate: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    rng = np.random.default_rng(5)
    curves = rng.normal(size=(7, 1003))
    curves[2, 600:] = np.nan  # runs of different lengths
    curves[:, 990:] = np.nan  # points no seed reaches
    at_once = aggregate_band(curves, aggregate, np.random.default_rng(1), 200)
    monkeypatch.setattr(learning_curves, "BAND_BLOCK_VALUES", 200 * 64)  # blocks of >= 64 points
    in_blocks = aggregate_band(curves, aggregate, np.random.default_rng(1), 200)
    for whole, blocked in zip(at_once, in_blocks, strict=True):
        if aggregate == "iqm":  # sorted per point: the same numbers
            assert np.array_equal(whole, blocked, equal_nan=True)
        else:  # a matrix product in blocks may round the last bit otherwise
            np.testing.assert_allclose(blocked, whole, rtol=1e-12, atol=0.0)
            assert np.array_equal(np.isnan(whole), np.isnan(blocked))


@pytest.mark.parametrize("aggregate", ["mean", "iqm"])
def test_the_band_holds_the_aggregate_and_collapses_for_equal_seeds(aggregate: str) -> None:
    rng = np.random.default_rng(3)
    curves = rng.normal(size=(30, 12))
    centre, low, high = aggregate_band(curves, aggregate, np.random.default_rng(0), 200)
    assert (low <= centre + 1e-12).all() and (centre <= high + 1e-12).all()
    assert (high - low > 0).all()
    if aggregate == "mean":
        assert centre == pytest.approx(curves.mean(axis=0))
    same = np.tile(np.arange(5.0), (8, 1))
    centre, low, high = aggregate_band(same, aggregate, np.random.default_rng(0), 50)
    assert centre.tolist() == low.tolist() == high.tolist() == [0.0, 1.0, 2.0, 3.0, 4.0]
    with pytest.raises(ValueError, match="unknown aggregate"):
        aggregate_band(same, "median", np.random.default_rng(0))


def test_plot_metric_draws_seeds_against_env_steps(in_tmp: Path) -> None:
    trained = invoke(
        "train", "--seeds", "0-2", "--episodes", "30", "--workers", "1", "-q", "--out", "runs/m",
        "--set", "train.stop_when_solved=false", "--engine", "gymnasium",
    )  # fmt: skip
    assert trained.exit_code == 0, trained.output
    result = invoke("plot", "runs/m", "--metric", "length", "--x", "env-steps", "--log-y")
    assert result.exit_code == 0, result.output
    written = Path(result.output.strip())
    assert written == Path("runs/m/length_by_env-steps.png")
    assert imread(written).shape[:2] == (450, 800)
    result = invoke("plot", "runs/m", "--metric", "return", "--aggregate", "iqm", "--smooth",
                    "10", "--out", "r.svg")  # fmt: skip
    assert result.exit_code == 0 and Path("r.svg").read_text().startswith("<?xml")


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--x", "env-steps"], "apply to --metric only"),
        (["--metric", "reward"], "--metric reward: not one of return, length"),
        (["--metric", "length", "--x", "time"], "--x time: not one of episode, env-steps"),
        (["--metric", "length", "--policy"], "one of them"),
    ],
)
def test_plot_metric_refuses_bad_options_before_drawing(
    in_tmp: Path, args: list[str], message: str
) -> None:
    Path("runs").mkdir()
    result = invoke("plot", "runs", *args)
    assert result.exit_code == 2
    assert message in result.output


def _sweep_file(path: Path, figure: object) -> Path:
    from tests.conftest import write_yaml

    return write_yaml(path, {
        "name": "fig",
        "base": {
            "engine": "gymnasium",
            "train": {"episodes": 20, "stop_when_solved": False, "eval_every": 0},
        },
        "seeds": "0-2",
        "grid": {"agent.alpha": [0.1, 0.5]},
        "figure": figure,
    })  # fmt: skip


def test_a_sweep_draws_its_figure_when_it_completes(in_tmp: Path) -> None:
    figure = {
        "metric": "length", "x": "env-steps", "title": "Steps per episode", "scale": 2.0,
        "reference": 15, "reference_label": "optimum", "file": "fig.svg",
    }  # fmt: skip
    result = invoke(
        "sweep", _sweep_file(in_tmp / "s.yaml", figure), "--out", "sw", "--workers", "1"
    )
    assert result.exit_code == 0, result.output
    assert "the sweep file's figure: sw/fig.svg" in result.output
    svg = Path("sw/fig.svg").read_text()
    assert "alpha 0.1: mean of 3 seeds" in svg and "alpha 0.5: mean of 3 seeds" in svg
    assert "optimum" in svg and "Steps per episode" in svg
    # the resolved sweep.yaml keeps the section, every key filled
    import yaml

    resolved = yaml.safe_load(Path("sw/sweep.yaml").read_text())
    assert resolved["figure"]["aggregate"] == "mean" and resolved["figure"]["scale"] == 2.0


@pytest.mark.parametrize(
    ("figure", "message"),
    [
        ({"x": "episode"}, "figure.metric: is missing"),
        ({"metric": "steps"}, 'figure.metric: "steps" is not one of return, length'),
        ({"metric": "length", "colour": "red"}, "colour"),
        ({"metric": "length", "scale": "x"}, 'figure.scale: "x" is not a int or float'),
        ({"metric": "length", "smooth": 0}, "figure.smooth: must be at least 1"),
        ({"metric": "length", "file": "../f.png"}, "figure.file"),
        ({"metric": "length", "file": "points.svg"}, "would write points.csv beside it"),
        ({"metric": "length", "file": "sweep.png"}, "would write sweep.csv beside it"),
        ([1], "figure: must be a mapping"),
        ({"metric": "length", "against": "agent.gamma"}, "figure.against: 'agent.gamma' is not"),
        ({"metric": "length", "y_min": 5, "y_max": 5}, "figure.y_min: must be below figure.y_max"),
        ({"metric": "length", "against": "agent.alpha", "first": 0}, "figure.first: must be"),
        ({"metric": "length", "best": {"agent.alpha": "min"}}, "give figure.against too"),
        ({"metric": "length", "total": True}, "figure.total: works on the points drawn"),
        (
            {"metric": "length", "against": "agent.alpha", "best": {"agent.alpha": "min"}},
            "figure.best: 'agent.alpha' is not a grid axis other than figure.against",
        ),
        (
            {"metric": "length", "against": "agent.alpha", "best": {"agent.gamma": "min"}},
            "figure.best: 'agent.gamma' is not a grid axis",
        ),
    ],
)
def test_a_bad_figure_section_is_refused_before_anything_runs(
    in_tmp: Path, figure: object, message: str
) -> None:
    result = invoke("sweep", _sweep_file(in_tmp / "s.yaml", figure), "--out", "sw", "-q")
    assert result.exit_code == 2, result.output
    assert message in result.output
    assert not Path("sw").exists()


def test_x_max_ends_the_grid_where_the_book_does() -> None:
    returns, lengths = [np.array([1.0, 1.0, 1.0])], [np.array([10, 10, 10])]
    steps = seed_curves(returns, lengths, "cumulative-return", "env-steps", x_max=15)
    assert steps.x[-1] == 15.0 and steps.values[0][-1] == 1.0
    episodes = seed_curves(returns, lengths, "return", "episode", x_max=2)
    assert episodes.x.tolist() == [1.0, 2.0] and episodes.values.shape == (1, 2)
    longer = seed_curves(returns, lengths, "return", "episode", x_max=5)
    assert np.isnan(longer.values[0][3:]).all()


def test_a_figure_against_an_axis_draws_each_points_mean_over_its_first_episodes(
    in_tmp: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """S&B Fig. 12.10's shape: per point, the seeds' mean over the first episodes."""
    figure = {"metric": "length", "against": "agent.alpha", "first": 5, "file": "fig.svg"}
    result = invoke(
        "sweep", _sweep_file(in_tmp / "s.yaml", figure), "--out", "sw", "--workers", "1", "-q"
    )
    assert result.exit_code == 0, result.output
    svg = Path("sw/fig.svg").read_text()
    assert "steps per episode, mean over the first 5 episodes" in svg
    # the plotted y values are the seeds' means of their first 5 lengths
    from cartpole_q.experiments.sweep import plot_against
    from cartpole_q.experiments.sweep_spec import load_sweep

    spec = load_sweep(Path("sw/sweep.yaml"))
    points = [Path("sw/points") / spec.point_id(p.index) for p in spec.points]
    drawn = {}

    def capture(lines, *args, **kwargs):  # type: ignore[no-untyped-def]
        drawn.update({label: (list(xs), centre.tolist()) for label, xs, centre, _, _ in lines})
        from cartpole_q.figures import summary_line_figure

        return summary_line_figure(lines, *args, **kwargs)

    import cartpole_q.experiments.sweep as sweep_module

    monkeypatch.setattr(sweep_module, "summary_line_figure", capture)
    plot_against(spec, points, in_tmp / "again.png")
    curves = np.load(points[1] / "curves.npz")
    expected = np.mean([curves[f"seed-{s:03d}.lengths"][:5].mean() for s in (0, 1, 2)])
    ((xs, centre),) = drawn.values()
    assert xs == [0.1, 0.5] and centre[1] == pytest.approx(expected)


def test_y_limits_end_the_axis_where_the_book_does() -> None:
    """``figure.y_min``/``y_max``: Example 6.6's axis stops at -100 as the book's does."""
    from cartpole_q.figures import MetricBand, metric_curve_figure

    values = np.array([[-1700.0, -50.0, -25.0], [-1500.0, -40.0, -30.0]])
    band = MetricBand("a", np.arange(1.0, 4.0), values, values.mean(0), values.min(0),
                      values.max(0), "mean")  # fmt: skip
    figure = metric_curve_figure([band], "episode", "return", "t", y_limits=(-100.0, 0.0))
    assert figure.axes[0].get_ylim() == (-100.0, 0.0)
    automatic = metric_curve_figure([band], "episode", "return", "t")
    assert automatic.axes[0].get_ylim()[0] < -1500


def test_best_draws_each_value_at_its_best_point_and_total_sums(in_tmp: Path) -> None:
    """Figure 12.14's shape: against one axis, each line through the best of another axis."""
    from tests.conftest import write_yaml

    study = write_yaml(in_tmp / "s.yaml", {
        "name": "best",
        "base": {
            "env": {"id": "Taxi-v4"}, "discretization": None,
            "agent": {"epsilon": 0.1, "q_init": 0.0},
            "train": {"episodes": 6, "stop_when_solved": False, "eval_every": 0},
        },
        "seeds": "0-2",
        "grid": {"agent.gamma": [0.9, 0.99], "agent.alpha": [0.1, 0.3, 0.5]},
        "figure": {
            "metric": "length", "against": "agent.gamma", "best": {"agent.alpha": "max"},
            "total": True, "file": "fig.png",
        },
    })  # fmt: skip
    result = invoke("sweep", study, "--out", "sw", "--workers", "1", "-q")
    assert result.exit_code == 0, result.output
    from cartpole_q.experiments.sweep_spec import load_sweep

    spec = load_sweep(Path("sw/sweep.yaml"))
    totals: dict[tuple[float, float], float] = {}
    for point in spec.points:
        curves = np.load(Path("sw/points") / spec.point_id(point.index) / "curves.npz")
        per_seed = [float(curves[f"seed-{s:03d}.lengths"].sum()) for s in (0, 1, 2)]
        totals[(point.values["agent.gamma"], point.values["agent.alpha"])] = float(
            np.mean(per_seed)
        )
    rows = Path("sw/fig.csv").read_text(encoding="utf-8").splitlines()[1:]
    drawn = [row.split(",") for row in rows]
    line = {float(r[2]): float(r[3]) for r in drawn if r[1] == "best"}
    chosen = {float(r[2]): float(r[3]) for r in drawn if r[1] == "best alpha"}
    for gamma in (0.9, 0.99):
        best = max((totals[(gamma, a)], -i, a) for i, a in enumerate((0.1, 0.3, 0.5)))
        assert chosen[gamma] == best[2]
        assert line[gamma] == pytest.approx(best[0])
    assert set(chosen.values()) != {0.1}  # not merely the first alpha: the choice is real


@pytest.mark.parametrize(
    ("axes", "words"),
    [
        ({"grid": {"agent.gamma": [0.9, 0.99], "agent.trace": ["accumulating", "replacing"]}},
         "figure.best: the axis agent.trace must hold numbers"),
        ({"grid": {"agent.gamma": [0.9, 0.99]}, "zip": {"agent.alpha": [0.1, 0.2],
                                                      "agent.lambda": [0.5, 0.9]}},
         "figure.best: 'agent.alpha' is not a grid axis other than figure.against"),
    ],
)  # fmt: skip
def test_best_needs_a_grid_axis_of_numbers(in_tmp: Path, axes: dict, words: str) -> None:
    """A zip axis moves with its partner (nothing to choose); a text axis has no value to draw."""
    from tests.conftest import write_yaml

    best = "agent.trace" if "agent.trace" in axes["grid"] else "agent.alpha"
    study = write_yaml(in_tmp / "s.yaml", {
        "name": "best", "seeds": 0,
        "base": {"agent": {"algorithm": "sarsa_lambda"}, "train": {"episodes": 2}},
        **axes,
        "figure": {"metric": "length", "against": "agent.gamma", "best": {best: "min"}},
    })  # fmt: skip
    result = invoke("study", study, "--check")
    assert result.exit_code == 2, result.output
    assert words in result.output
