"""Every figure goes out with its data: ``<figure>.csv`` holds the very numbers drawn."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest
from matplotlib.axes import Axes
from matplotlib.collections import PolyCollection
from matplotlib.figure import Figure

import cartpole_q.figures as figures
from cartpole_q.errors import WriteError
from cartpole_q.figures import DATA_COLUMNS, DataFigure, MapDimensions, policy_figure
from cartpole_q.store.atomic import atomic_write_together
from tests.conftest import invoke, write_yaml


@pytest.fixture
def drawn(monkeypatch: pytest.MonkeyPatch) -> list[Figure]:
    """Every figure rendered to a file during the test, in order, as drawn."""
    rendered: list[Figure] = []
    real = figures.figure_bytes

    def keep(figure: Figure, file_format: str) -> bytes:
        rendered.append(figure)
        return real(figure, file_format)

    # write_figure imports figure_bytes when it writes, so every figure file passes here.
    monkeypatch.setattr(figures, "figure_bytes", keep)
    return rendered


def read_rows(path: Path) -> list[dict[str, str]]:
    with path.open(newline="", encoding="utf-8") as file:
        reader = csv.DictReader(file)
        assert tuple(reader.fieldnames or ()) == DATA_COLUMNS
        return list(reader)


def column(rows: list[dict[str, str]], name: str) -> np.ndarray:
    """A numeric column, an empty cell as NaN (the figure draws nothing there)."""
    return np.array([float(row[name]) if row[name] else np.nan for row in rows])


def series(rows: list[dict[str, str]], panel: str = "") -> dict[str, list[dict[str, str]]]:
    """The rows of one panel by series, in the order the figure drew them."""
    found: dict[str, list[dict[str, str]]] = {}
    for row in rows:
        if row["panel"] == panel:
            found.setdefault(row["series"], []).append(row)
    return found


def assert_line(rows: list[dict[str, str]], axes: Axes, index: int) -> None:
    """The rows are exactly the x and y data of ``axes.lines[index]``."""
    line = axes.lines[index]
    xs = np.asarray(line.get_xdata(), dtype=np.float64)
    ys = np.asarray(line.get_ydata(), dtype=np.float64)
    assert np.array_equal(column(rows, "x"), xs, equal_nan=True)
    assert np.array_equal(column(rows, "y"), ys, equal_nan=True)


def assert_band(rows: list[dict[str, str]], band: PolyCollection) -> None:
    """``y_low`` and ``y_high`` are the edges of the drawn band, point by point."""
    corners = {tuple(vertex) for path in band.get_paths() for vertex in path.vertices.tolist()}
    for x, low, high in zip(
        column(rows, "x"), column(rows, "y_low"), column(rows, "y_high"), strict=True
    ):
        assert (x, low) in corners and (x, high) in corners


def test_plot_run_writes_beside_its_figure_the_numbers_on_its_axes(
    tmp_path: Path, drawn: list[Figure]
) -> None:
    run = tmp_path / "run"
    assert invoke("train", "--out", run, "-q").exit_code == 0  # solves, then stops
    trained = (run / "reward_curve.csv").read_text(encoding="utf-8")
    out = tmp_path / "curve.png"
    result = invoke("plot", run, "--out", out)
    assert result.exit_code == 0, result.output
    assert (tmp_path / "curve.csv").read_text(encoding="utf-8") == trained  # the same drawing
    figure = drawn[-1]
    assert isinstance(figure, DataFigure)
    (axes,) = figure.axes
    by_series = series(read_rows(tmp_path / "curve.csv"))
    returns = np.loadtxt(run / "metrics.csv", delimiter=",", skiprows=1, usecols=1)
    assert list(by_series) == ["run: return", "run: 100-episode average", "run: solved",
                               "reward threshold"]  # fmt: skip
    assert column(by_series["run: return"], "y").tolist() == returns.tolist()
    assert column(by_series["run: return"], "x").tolist() == list(range(1, len(returns) + 1))
    assert_line(by_series["run: return"], axes, 0)
    assert_line(by_series["run: 100-episode average"], axes, 1)
    # the vertical and horizontal lines: one row each, at the solve episode and threshold
    (solved,) = by_series["run: solved"]
    assert solved["y"] == "" and float(solved["x"]) == axes.lines[2].get_xdata()[0]
    (threshold,) = by_series["reward threshold"]
    assert threshold["x"] == "" and float(threshold["y"]) == axes.lines[3].get_ydata()[0] == 475.0


def test_a_sweep_writes_the_numbers_of_its_figure_and_of_sweep_png(
    in_tmp: Path, drawn: list[Figure]
) -> None:
    sweep = write_yaml(in_tmp / "s.yaml", {
        "name": "small",
        "base": {"train": {"episodes": 30, "eval_every": 0}, "eval": {"episodes": 2}},
        "seeds": "0-2",
        "grid": {"agent.alpha": [0.1, 0.5]},
        "figure": {"metric": "return", "reference": 500, "reference_label": "the most",
                   "file": "curves.png"},
    })  # fmt: skip
    result = invoke("sweep", sweep, "--out", "sw", "--workers", 1, "-q")
    assert result.exit_code == 0, result.output
    sweep_png, study_figure = drawn[-2:]
    # The study figure: each seed faint, the mean with its band, the reference line.
    (axes,) = study_figure.axes
    by_series = series(read_rows(Path("sw/curves.csv")))
    names = [
        f"alpha {a}: {s}" for a in ("0.1", "0.5") for s in ("seed 0", "seed 1", "seed 2", "mean")
    ]
    assert list(by_series) == [*names, "the most"]
    for index, name in enumerate(names):
        assert_line(by_series[name], axes, index)
    bands = [c for c in axes.collections if isinstance(c, PolyCollection)]
    assert_band(by_series["alpha 0.1: mean"], bands[0])
    assert_band(by_series["alpha 0.5: mean"], bands[1])
    seeds = np.stack([column(by_series[f"alpha 0.5: seed {s}"], "y") for s in range(3)])
    assert column(by_series["alpha 0.5: mean"], "y") == pytest.approx(seeds.mean(axis=0), rel=1e-12)
    assert by_series["the most"] == [{"panel": "", "series": "the most", "x": "", "y": "500.0",
                                     "y_low": "", "y_high": "", "value": ""}]  # fmt: skip
    # sweep.png: the points' statistics as points.csv has them, and the profiles as drawn.
    rows = read_rows(Path("sw/sweep.csv"))
    with Path("sw/points.csv").open(newline="") as file:
        points = list(csv.DictReader(file))
    rate = series(rows, "success rate")["success rate"]
    assert [row["x"] for row in rate] == ["0.1", "0.5"]
    for row, point in zip(rate, points, strict=True):
        assert (row["y"], row["y_low"], row["y_high"]) == (
            point["success_rate"],
            point["success_rate_low"],
            point["success_rate_high"],
        )
    rate_axes, _, profile_axes = sweep_png.axes[:3]
    data_line = rate_axes.containers[0].lines[0]
    assert column(rate, "y").tolist() == np.asarray(data_line.get_ydata()).tolist() == [0.0, 0.0]
    assert float(rate[0]["y_high"]) > 0.0  # three seeds, none a success: Wilson's upper end
    profiles = series(rows, "performance profiles")
    assert [name for name in profiles if name != "threshold"] == ["point 000", "point 001"]
    for index, name in enumerate(("point 000", "point 001")):
        assert_line(profiles[name], profile_axes, index)


def test_a_figure_or_its_data_is_not_replaced_without_force(tmp_path: Path) -> None:
    run = tmp_path / "run"
    assert invoke("train", "--out", run, "--episodes", 20, "-q").exit_code == 0
    (tmp_path / "mine.csv").write_text("keep me\n", encoding="utf-8")
    result = invoke("plot", run, "--out", tmp_path / "mine.png")
    assert result.exit_code == 2 and "mine.csv: already exists" in result.stderr
    assert not (tmp_path / "mine.png").exists()
    assert (tmp_path / "mine.csv").read_text(encoding="utf-8") == "keep me\n"
    assert invoke("plot", run, "--out", tmp_path / "mine.svg").exit_code == 2
    assert invoke("plot", run, "--out", tmp_path / "mine.png", "--force").exit_code == 0
    assert read_rows(tmp_path / "mine.csv")[0]["series"] == "run: return"


def test_a_policy_map_writes_each_cell_at_its_centre() -> None:
    q = np.zeros((1, 1, 2, 3, 2))
    q[0, 0, 0] = [[1.0, 0.0], [0.0, 2.0], [5.0, 4.0]]
    q[0, 0, 1] = [[0.0, 3.0], [7.0, 1.0], [0.5, 0.6]]
    visits = np.ones_like(q, dtype=np.int64)
    visits[0, 0, 1, 2] = 0  # never visited: blank on the map, empty in the data
    figure = policy_figure(
        q, visits, MapDimensions((2, 3), [-2.4, -3, -0.2, -2], [2.4, 3, 0.2, 2], list("abcd")), "t"
    )
    rows = list(csv.DictReader(figure.data.csv_text().splitlines()))
    actions = series(rows, "greedy action")["action"]
    # row by row from the first bin of dimension 2 (y), across dimension 3 (x): bin centres
    assert column(actions, "x") == pytest.approx([-4 / 3, 0.0, 4 / 3] * 2)
    assert column(actions, "y") == pytest.approx([-0.1] * 3 + [0.1] * 3)
    assert [row["value"] for row in actions] == ["0", "1", "0", "1", "0", ""]
    values = series(rows, "state value max_a Q")["value"]
    shown = np.ma.filled(figure.axes[1].images[0].get_array(), np.nan).ravel()
    assert np.array_equal(column(values, "value"), shown, equal_nan=True)
    assert column(values, "value")[:5].tolist() == [1.0, 2.0, 5.0, 3.0, 7.0]
    visits_rows = series(rows, "training visits (log scale)")["visits"]
    assert [row["value"] for row in visits_rows] == ["2", "2", "2", "2", "2", ""]
    # a table without visit counts (tiles) draws a blank visits panel: no rows for it
    blank = policy_figure(q, None, MapDimensions((2, 3), [0] * 4, [1] * 4, list("abcd")), "t")
    panels = {row["panel"] for row in csv.DictReader(blank.data.csv_text().splitlines())}
    assert panels == {"greedy action", "state value max_a Q"}


def test_a_figure_that_cannot_be_written_leaves_its_old_data(tmp_path: Path) -> None:
    data = tmp_path / "figure.csv"
    data.write_text("old\n", encoding="utf-8")
    unwritable = tmp_path / "missing" / "figure.png"
    with pytest.raises(WriteError, match=r"missing/figure\.png: cannot be written"):
        atomic_write_together([(data, b"new\n"), (unwritable, b"\x89PNG")])
    assert data.read_text(encoding="utf-8") == "old\n"
    assert sorted(path.name for path in tmp_path.iterdir()) == ["figure.csv"]  # no temporaries


@pytest.mark.parametrize(("episodes", "stride"), [(20_000, 1), (20_001, 2), (100_000, 5)])
def test_a_long_runs_reward_curve_draws_every_kth_episode(episodes: int, stride: int) -> None:
    """At most CURVE_POINTS points per line; the moving average is of every episode."""
    returns = np.arange(episodes, dtype=np.float64) % 7.0
    drawn = figures.reward_curve_figure([figures.Curve("run", returns)], None)
    rows = list(csv.DictReader(drawn.data.csv_text().splitlines()))
    raw = [row for row in rows if row["series"] == "run: return"]
    average = [row for row in rows if row["series"] == "run: 100-episode average"]
    assert len(raw) == len(average) == len(range(0, episodes, stride)) <= figures.CURVE_POINTS
    assert [float(row["x"]) for row in raw[:2]] == [1.0, 1.0 + stride]
    last = (len(raw) - 1) * stride  # the last drawn episode, 0-based
    assert float(raw[-1]["y"]) == returns[last]
    assert float(average[-1]["y"]) == pytest.approx(returns[last - 99 : last + 1].mean())


# -- a figure's data is what it draws, at the resolution drawn (issue 47: 89 MB of docs/book) --


BOOK_DATA = Path(__file__).resolve().parents[1] / "docs" / "book"


def test_the_books_figure_data_stays_small() -> None:
    files = sorted(BOOK_DATA.iterdir())
    assert files, "docs/book holds the book's figures"
    for path in files:
        assert path.stat().st_size <= 2**20, f"{path.name}: more than 1 MiB"
    assert sum(path.stat().st_size for path in files) <= 15 * 2**20


@pytest.mark.parametrize("log_x", [False, True])
def test_a_long_curve_is_drawn_and_written_at_the_resolution_drawn(log_x: bool) -> None:
    from cartpole_q.figures import DRAWN_POINTS, MetricBand, metric_curve_figure

    count = 100_000
    x = np.arange(1, count + 1, dtype=float)
    per_seed = np.vstack([np.sin(x / 1000.0), np.cos(x / 1000.0)])
    centre = per_seed.mean(axis=0)
    band = MetricBand("b", x, per_seed, centre, centre - 1, centre + 1, "mean", (0, 1))
    figure = metric_curve_figure([band], "episode", "y", "t", log_x=log_x)
    lines = figure.axes[0].get_lines()
    table = list(csv.reader(figure.data.csv_text().splitlines()))[1:]
    rows = [row for row in table if row[1] == "b: mean"]
    drawn_x = lines[-1].get_xdata()
    assert len(drawn_x) <= DRAWN_POINTS and drawn_x[0] == 1 and drawn_x[-1] == count
    assert [float(row[2]) for row in rows] == list(drawn_x)  # the data is what is drawn
    kept = np.asarray(drawn_x, dtype=np.int64) - 1
    assert [float(row[3]) for row in rows] == centre[kept].tolist()  # exact, not resampled
    gaps = np.diff(drawn_x)
    if log_x:  # every early episode, ever wider steps later
        assert list(drawn_x[:10]) == list(range(1, 11)) and gaps[-1] > 100 * gaps[0]
    else:
        assert gaps.max() - gaps.min() <= 1
    whole = metric_curve_figure([band], "episode", "y", "t", log_x=log_x, most=None)
    assert len(whole.axes[0].get_lines()[-1].get_xdata()) == count
