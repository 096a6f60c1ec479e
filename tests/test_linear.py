"""Linear function approximation (issue 49): feature layers, the ten methods, their errors.

Byte for byte: both engines against the plain re-derivation of docs/algorithms.md
(``tests/reference_linear.py``) on Baird's counterexample (every continuing algorithm) and
the 1000-state walk (every episodic one, every dense and tiled layer). Exact where the answer
is known: hand-computed features, semi-gradient DP on Baird's against its matrix form,
expected TDC's limit (√PBE 0, √VE near 2), each layer's TD fixed point against LSTD's.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cartpole_q.experiments import linear as study_kind
from cartpole_q.experiments.study import RunHandle, study_of
from cartpole_q.families.book_mdps.baird import baird_features
from cartpole_q.rl import features as layers
from tests import reference_linear as reference
from tests.conftest import REPO, invoke, write_yaml
from tests.test_cli import assert_refused

BAIRD = "cartpole_q/Baird-v0"
WALK = "cartpole_q/RandomWalk1000-v0"
W0 = [1, 1, 1, 1, 1, 1, 10, 1]
BAIRD_STUDY = {
    "kind": "linear", "world": {"id": BAIRD}, "gamma": 0.99, "target": [0, 1],
    "behaviour": ["6/7", "1/7"], "errors": ["ve", "pbe"],
}  # fmt: skip
WALK_STUDY = {
    "kind": "linear", "world": {"id": WALK, "kwargs": {"position": True}}, "gamma": 1.0,
    "errors": ["ve", "pbe"],
}  # fmt: skip
TILES = {"kind": "tiles", "bins": [5], "low": [1], "high": [1001], "tilings": 4}


def read(raw: Mapping[str, Any]) -> study_kind.Study:
    """A linear study from its mapping."""
    return study_kind.read_study(study_of(raw, "t.yaml", "t", Path(".")))


def run(raw: Mapping[str, Any], seed: int = 0) -> dict[str, np.ndarray]:
    """The first curve's run on ``seed``: its arrays."""
    record = study_kind.run_one(
        read(raw), {"curve": 0, "seed": seed}, RunHandle(lambda: False, lambda n: None)
    )
    assert record is not None
    return {name: np.asarray(value) for name, value in record.arrays.items()}


def assert_same(ours: Mapping[str, np.ndarray], theirs: Mapping[str, np.ndarray]) -> None:
    for name in ("at", "weights", "ve", "pbe"):
        assert ours[name].dtype == theirs[name].dtype, name
        assert ours[name].tobytes() == theirs[name].tobytes(), name


BAIRD_CASES = [
    ("off_policy_td", {"alpha": 0.01}),
    ("tdc", {"alpha": 0.005, "beta": 0.05}),
    ("gtd2", {"alpha": 0.005, "beta": 0.05}),
    ("emphatic_td", {"alpha": 0.03}),
    ("semi_gradient_dp", {"alpha": 0.01}),
    ("expected_tdc", {"alpha": 0.005, "beta": 0.05}),
    ("expected_emphatic_td", {"alpha": 0.03}),
]


@pytest.mark.parametrize("engine", ["numba", "gymnasium"])
@pytest.mark.parametrize(("algorithm", "params"), BAIRD_CASES, ids=[c[0] for c in BAIRD_CASES])
def test_every_continuing_algorithm_equals_the_re_derivation_byte_for_byte(
    engine: str, algorithm: str, params: dict[str, float]
) -> None:
    curve = {"algorithm": algorithm, "features": {"kind": "declared"}, "w0": W0, **params}
    raw = {**BAIRD_STUDY, "engine": engine, "seeds": 3, "steps": 60, "record_every": 7,
           "curves": [curve]}  # fmt: skip
    theirs = reference.run_linear(
        BAIRD, {}, {"kind": "declared"}, algorithm, gamma=0.99, seed=3, steps=60, w0=W0,
        target=[0.0, 1.0], behaviour=[6 / 7, 1 / 7], record_every=7, errors=("ve", "pbe"),
        **params,
    )  # fmt: skip
    assert_same(run(raw, seed=3), theirs)


WALK_CASES = [
    ("gradient_mc", {"kind": "fourier", "order": 3}, {"alpha": 5e-5}),
    ("semi_gradient_td", {"kind": "polynomial", "order": 3}, {"alpha": 1e-4}),
    ("lstd", {"kind": "fourier", "order": 2}, {"epsilon": 0.5}),
    ("gradient_mc", TILES, {"alpha": 1e-4}),
]


@pytest.mark.parametrize("engine", ["numba", "gymnasium"])
@pytest.mark.parametrize(
    ("algorithm", "layer", "params"), WALK_CASES,
    ids=[f"{c[0]}-{c[1]['kind']}" for c in WALK_CASES],
)  # fmt: skip
def test_every_episodic_algorithm_and_layer_equals_the_re_derivation_byte_for_byte(
    engine: str, algorithm: str, layer: dict[str, Any], params: dict[str, float]
) -> None:
    raw = {**WALK_STUDY, "engine": engine, "seeds": 5, "episodes": 6, "record_every": 4,
           "curves": [{"algorithm": algorithm, "features": layer, **params}]}  # fmt: skip
    theirs = reference.run_linear(
        WALK, {"position": True}, layer, algorithm, gamma=1.0, seed=5, episodes=6,
        record_every=4, errors=("ve", "pbe"), **params,
    )  # fmt: skip
    assert_same(run(raw, seed=5), theirs)


def test_state_aggregation_on_the_table_layer_equals_the_re_derivation() -> None:
    raw = {**WALK_STUDY, "world": {"id": WALK, "kwargs": {"groups": 10}}, "seeds": 2,
           "episodes": 5, "curves": [{"algorithm": "semi_gradient_td", "alpha": 0.01,
                                      "features": {"kind": "table"}}]}  # fmt: skip
    theirs = reference.run_linear(
        WALK, {"groups": 10}, {"kind": "table"}, "semi_gradient_td", gamma=1.0, seed=2,
        episodes=5, alpha=0.01, errors=("ve", "pbe"),
    )  # fmt: skip
    assert_same(run(raw, seed=2), theirs)


# -- the features, by hand --------------------------------------------------------------------


def test_polynomial_and_fourier_features_at_hand_computed_states() -> None:
    scaled = np.array([[0.0], [0.25], [1.0]])
    polynomial = layers.polynomial_rows(scaled, order=3).value
    assert polynomial.tolist() == [
        [1.0, 0.0, 0.0, 0.0], [1.0, 0.25, 0.0625, 0.015625], [1.0, 1.0, 1.0, 1.0],
    ]  # fmt: skip
    fourier = layers.fourier_rows(scaled, order=2).value
    assert fourier[0].tolist() == [1.0, 1.0, 1.0]  # cos(0) for every c
    assert fourier[1].tolist() == [1.0, math.cos(math.pi / 4), math.cos(math.pi / 2)]
    assert fourier[2].tolist() == [1.0, -1.0, 1.0]  # cos(pi c)
    two = layers.fourier_rows(np.array([[0.5, 0.25]]), order=1).value
    # c in C order: (0,0), (0,1), (1,0), (1,1): cos(pi (c . u))
    assert two.tolist() == [[1.0, math.cos(math.pi * 0.25), math.cos(math.pi * 0.5),
                             math.cos(math.pi * 0.75)]]  # fmt: skip


def test_the_walks_points_are_scaled_by_its_observation_bounds() -> None:
    facts = study_kind.world_facts(WALK, (("position", True),), "t.yaml")
    rows = study_kind.feature_rows(study_kind.FeatureSpec("polynomial", order=1), facts)
    assert rows.value[[0, 500, 1001], 1].tolist() == [0.0, 500 / 1001, 1.0]


@settings(max_examples=30, deadline=None)
@given(order=st.integers(1, 6), points=st.lists(st.floats(0.0, 1.0), min_size=1, max_size=6))
def test_one_dimensional_layers_are_the_books_formulas(order: int, points: list[float]) -> None:
    scaled = np.array(points).reshape(-1, 1)
    fourier = layers.fourier_rows(scaled, order)
    polynomial = layers.polynomial_rows(scaled, order)
    for rows in (fourier, polynomial):
        assert rows.index.tolist() == [list(range(order + 1))] * len(points)
    for state, u in enumerate(points):
        assert fourier.value[state].tolist() == [
            math.cos(math.pi * (0.0 + float(c) * u)) for c in range(order + 1)
        ]
        assert polynomial.value[state].tolist() == [
            math.prod([u] * c, start=1.0) for c in range(order + 1)
        ]


@pytest.mark.parametrize(
    "layer", [{"kind": "fourier", "order": 4}, {"kind": "polynomial", "order": 2}, TILES]
)
def test_feature_rows_equal_the_re_derivation(layer: dict[str, Any]) -> None:
    facts = study_kind.world_facts(WALK, (("position", True),), "t.yaml")
    spec = read({**WALK_STUDY, "episodes": 1, "curves": [
        {"algorithm": "gradient_mc", "alpha": 0.1, "features": layer}]}).curves[0].features  # fmt: skip
    ours = study_kind.feature_rows(spec, facts)
    index, value, d = reference.feature_rows(WALK, {"position": True}, layer)
    assert (ours.index.tolist(), ours.value.tobytes(), ours.weights) == (
        index.tolist(), value.tobytes(), d,
    )  # fmt: skip


def test_bairds_declared_features_are_the_books() -> None:
    expected = np.zeros((7, 8))
    for i in range(6):
        expected[i, i], expected[i, 7] = 2.0, 1.0
    expected[6, 6], expected[6, 7] = 1.0, 2.0
    assert np.array_equal(baird_features(), expected)


# -- exact checks -------------------------------------------------------------------------------


def test_semi_gradient_dp_on_baird_after_1000_sweeps_is_the_synchronous_update() -> None:
    raw = {**BAIRD_STUDY, "steps": 1000, "record_every": 1000, "curves": [
        {"algorithm": "semi_gradient_dp", "alpha": 0.01, "features": {"kind": "declared"}, "w0": W0}]}  # fmt: skip
    ours = run(raw)["weights"][-1]
    # The book's update in matrix form, w += alpha/|S| X^T (gamma X[lower] w - X w): every
    # state's expected next state is the lower one (the target is solid), every reward 0.
    x = baird_features()
    w = np.array(W0, dtype=np.float64)
    for _ in range(1000):
        bellman = 0.99 * (x[6] @ w) - x @ w
        w = w + 0.01 / 7 * (x.T @ bellman)
    np.testing.assert_allclose(ours, w, rtol=1e-9)
    assert np.all(np.abs(w) > 5.0) and w[7] > 300.0  # every component has left its start
    theirs = reference.run_linear(
        BAIRD, {}, {"kind": "declared"}, "semi_gradient_dp", gamma=0.99, seed=0, steps=1000,
        alpha=0.01, w0=W0, target=[0.0, 1.0], behaviour=[6 / 7, 1 / 7], record_every=1000,
    )  # fmt: skip
    assert ours.tobytes() == theirs["weights"][-1].tobytes()


def test_expected_tdc_drives_the_pbe_to_zero_and_not_the_ve() -> None:
    raw = {**BAIRD_STUDY, "steps": 4000, "record_every": 1000, "curves": [
        {"algorithm": "expected_tdc", "alpha": 0.005, "beta": 0.05,
         "features": {"kind": "declared"}, "w0": W0}]}  # fmt: skip
    arrays = run(raw)
    assert arrays["pbe"][0] > 8.0 and arrays["pbe"][-1] < 0.01
    assert np.all(np.diff(arrays["pbe"]) < 0)
    assert np.all((arrays["ve"][1:] > 1.9) & (arrays["ve"][1:] < 2.0))  # the book: near 2
    # Its exact limit: expected TDC is a linear map of (w, v) (every reward 0; every state's
    # expected next features the lower state's x_L). Its limit, the map to the power 2^40:
    x, mu, gamma, alpha, beta = baird_features(), np.full(7, 1 / 7), 0.99, 0.005, 0.05
    lower, d = x[6], np.diag(mu)
    bellman = x.T @ d @ (gamma * np.outer(np.ones(7), lower) - x)
    step = np.block([
        [np.eye(8) + alpha * bellman, -alpha * gamma * np.outer(lower, x.T @ mu)],
        [beta * bellman, np.eye(8) - beta * x.T @ d @ x],
    ])  # fmt: skip
    power = step.copy()
    for _ in range(40):
        power = power @ power
    limit = (power @ np.concatenate([W0, np.zeros(8)]))[:8]
    # There √VE is 0 as well (every value 0, as Baird's seven values can be) ...
    assert math.sqrt(mu @ (x @ limit) ** 2) < 1e-6
    # ... but the slowest mode shrinks by about 1.2e-7 a sweep: millions of sweeps away,
    # while √PBE is near 0 within a thousand.
    slowest = sorted(abs(np.linalg.eigvals(step)))[-3]
    assert 1 - 2e-7 < slowest < 1 - 1e-7
    assert np.max(np.abs(arrays["weights"][-1] - limit)) > 0.5


@pytest.mark.parametrize(
    ("kwargs", "layer"),
    [
        ({"groups": 10}, {"kind": "table"}),
        ({"position": True}, {"kind": "fourier", "order": 3}),
        ({"position": True}, {"kind": "polynomial", "order": 2}),
        ({"position": True}, TILES),
    ],
    ids=["aggregation", "fourier", "polynomial", "tiles"],
)
def test_each_layers_td_fixed_point_is_where_lstd_goes(
    kwargs: dict[str, Any], layer: dict[str, Any]
) -> None:
    raw = {**WALK_STUDY, "world": {"id": WALK, "kwargs": kwargs}, "errors": ["ve"],
           "episodes": 3000, "record_every": 3000, "seeds": 0,
           "curves": [{"algorithm": "lstd", "features": layer}]}  # fmt: skip
    study = read(raw)
    fixed = study_kind.curve_setup(study, 0).fixed_point
    assert fixed is not None
    independent = reference.td_fixed_point(WALK, kwargs, layer, gamma=1.0)
    np.testing.assert_allclose(fixed, independent, rtol=1e-9, atol=1e-9)
    rows = study_kind.curve_setup(study, 0).rows.dense()[1:1001]
    learned = run(raw)["weights"][-1]
    # LSTD's estimate from 3,000 episodes: within a few hundredths of the fixed point's values
    assert np.max(np.abs(rows @ learned - rows @ fixed)) < 0.05


def test_gradient_mc_fixed_point_is_the_least_ve() -> None:
    raw = {**WALK_STUDY, "episodes": 1, "curves": [
        {"algorithm": "gradient_mc", "alpha": 1e-4, "features": TILES}]}  # fmt: skip
    fixed = study_kind.curve_setup(read(raw), 0).fixed_point
    independent = reference.mc_fixed_point(WALK, {"position": True}, TILES, gamma=1.0)
    assert fixed is not None
    np.testing.assert_allclose(fixed, independent, rtol=1e-9, atol=1e-12)


# -- the study: resume, the command, bad input ----------------------------------------------------


def test_a_linear_study_runs_by_one_command_with_its_figure_and_data(tmp_path: Path) -> None:
    out = tmp_path / "out"
    path = write_yaml(tmp_path / "s.yaml", {**BAIRD_STUDY, "name": "b", "seeds": "0-1",
                      "steps": 100, "curves": [
                          {"label": "TDC", "algorithm": "tdc", "alpha": 0.005, "beta": 0.05,
                           "features": {"kind": "declared"}, "w0": W0},
                          {"label": "DP", "algorithm": "semi_gradient_dp", "alpha": 0.01,
                           "features": {"kind": "declared"}, "w0": W0}],
                      "figure": {"kind": "weights", "file": "b.png"}})  # fmt: skip
    result = invoke("study", path, "--out", out, "--workers", 1)
    assert result.exit_code == 0, result.output
    assert "a linear study of 3 runs: 2 curves x 2 seeds" in result.stderr
    assert (out / "b.png").is_file() and (out / "b.csv").is_file()
    summary = (out / "summary.txt").read_text(encoding="utf-8")
    assert "TDC (tdc, declared features, alpha 0.005): after 100 steps:" in summary
    assert "mean of 2 runs" in summary and "DP (semi_gradient_dp" in summary
    data = (out / "b.csv").read_text(encoding="utf-8").splitlines()
    assert data[0] == "panel,series,x,y,y_low,y_high,value"
    assert any(line.startswith("DP,w8,100,") for line in data)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"curves": [{"algorithm": "gradient_mc", "alpha": 0.1, "features": {"kind": "fourier", "order": 0}}]},
         "curves[0].features.order: must be a whole number from 1 to 1000, got 0"),
        ({"curves": [{"algorithm": "gradient_mc", "alpha": 0.1, "features": {"kind": "fourier", "order": 1000}}],
          "episodes": 10_000_000},
         "curves[0].features: Fourier order 1000 on 1,002 states, 1 run of 10,000,002 records would take"),
        ({"curves": [{"algorithm": "gradient_mc", "alpha": 0.1, "features": {"kind": "declared"}}]},
         "curves[0].features: cartpole_q/RandomWalk1000-v0 declares no feature matrix"),
        ({"curves": [{"algorithm": "gradient_mc", "alpha": 0.1, "features": {"kind": "fourier", "order": 2}}],
          "world": {"id": WALK}},
         "curves[0].features: fourier features need the world's states as points"),
        ({"curves": [{"algorithm": "tdc", "alpha": 0.1, "beta": 0.1, "features": {"kind": "table"}}]},
         "curves[0].algorithm: tdc is for continuing worlds"),
        ({"curves": [{"algorithm": "gradient_mc", "features": {"kind": "table"}}]},
         "curves[0].alpha: is missing; give a number."),
        ({"steps": 10}, "steps: cartpole_q/RandomWalk1000-v0 is episodic; give `episodes` instead."),
    ],
)  # fmt: skip
def test_bad_input_is_refused_naming_the_file_and_key(
    tmp_path: Path, change: dict[str, Any], message: str
) -> None:
    raw = {**WALK_STUDY, "episodes": 10, "curves": [
        {"algorithm": "gradient_mc", "alpha": 0.1, "features": {"kind": "table"}}], **change}  # fmt: skip
    path = write_yaml(tmp_path / "s.yaml", raw)
    assert_refused(invoke("study", path, "--check"), f"{path}: {message}")


def test_a_continuing_world_asked_for_episodes_is_refused(tmp_path: Path) -> None:
    path = write_yaml(tmp_path / "s.yaml", {**BAIRD_STUDY, "episodes": 10, "curves": [
        {"algorithm": "tdc", "alpha": 0.1, "beta": 0.1, "features": {"kind": "declared"}}]})  # fmt: skip
    assert_refused(
        invoke("study", path, "--check"),
        f"{path}: episodes: cartpole_q/Baird-v0 is continuing: nothing ever ends; give `steps` instead.",
    )


def test_the_shipped_linear_studies_are_the_books_figures() -> None:
    for name, figure in (
        ("fig9_5_polynomial_fourier", "Figure 9.5"), ("fig9_10_tile_coding", "Figure 9.10"),
        ("fig11_2_baird", "Figure 11.2"), ("fig11_5_tdc", "Figure 11.5"),
        ("fig11_6_emphatic_td", "Figure 11.6"),
    ):  # fmt: skip
        text = (REPO / "examples" / "book" / f"{name}.yaml").read_text(encoding="utf-8")
        assert f"Sutton & Barto {figure})" in text and "kind: linear" in text


def test_a_long_stretch_between_records_still_returns_to_python_and_stops() -> None:
    study = read({**BAIRD_STUDY, "steps": 250_000, "record_every": 250_000, "curves": [
        {"algorithm": "tdc", "alpha": 0.005, "beta": 0.05, "features": {"kind": "declared"}}]})  # fmt: skip
    reported: list[int] = []
    record = study_kind.run_one(
        study, {"curve": 0, "seed": 0}, RunHandle(lambda: False, reported.append)
    )
    assert reported == [100_000, 200_000, 250_000]
    assert record is not None and record.arrays["at"].tolist() == [0, 250_000]
    seen: list[int] = []
    stopped = study_kind.run_one(
        study, {"curve": 0, "seed": 0}, RunHandle(lambda: bool(seen), seen.append)
    )
    assert stopped is None and seen == [100_000]  # asked after every compiled call


@pytest.mark.parametrize("engine", ["numba", "gymnasium"])
def test_long_episodes_return_to_python_every_hundred_thousand_steps(engine: str) -> None:
    """Episodes of 10,000 steps (the short corridor, almost always left): 10 per call."""
    raw = {
        "kind": "linear", "world": {"id": "cartpole_q/ShortCorridor-v0"}, "gamma": 1.0,
        "target": [0.9999, 0.0001], "episodes": 12, "record_every": 12, "engine": engine,
        "curves": [{"algorithm": "gradient_mc", "features": {"kind": "table"}, "alpha": 1e-6}],
    }  # fmt: skip
    reports: list[int] = []
    record = study_kind.run_one(
        read(raw), {"curve": 0, "seed": 0}, RunHandle(lambda: False, reports.append)
    )
    assert record is not None
    assert reports == [10, 12]
    assert np.asarray(record.arrays["at"]).tolist() == [0, 12]
