"""Dynamic programming (chapters 3-4): the algorithms, the book's worlds and numbers, ``cartpole-q dp``.

The book prints values rounded to one decimal (Figure 4.1's -1.7 for -1.75: halves
upwards); the tests compare exact values where the book's are exact, and rounded ones as
the book prints them elsewhere.
"""

from __future__ import annotations

import csv
import warnings
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from hypothesis import given
from hypothesis import strategies as st

from cartpole_q.config import load_config
from cartpole_q.envs.models import PlanningModel, planning_model
from cartpole_q.families.planning import WORLDS as PLANNING_WORLDS
from cartpole_q.figures import book_round
from cartpole_q.rl import solvers as dp
from cartpole_q.rl.mdp import FiniteMDP
from tests.conftest import REPO, invoke, write_yaml

BOOK = REPO / "examples" / "book"


def _world(env_id: str, **kwargs: Any) -> PlanningModel:
    found = planning_model(load_config({"env": {"id": env_id, "kwargs": kwargs}}).env)
    assert not isinstance(found, str), found
    return found


@pytest.fixture(scope="module")
def small_grid() -> FiniteMDP:
    return _world("cartpole_q/SmallGridworld-v0").model


@pytest.fixture(scope="module")
def grid() -> FiniteMDP:
    return _world("cartpole_q/Gridworld-v0").model


# -- Figure 4.1: the 4x4 gridworld ----------------------------------------------------------


def test_fig_4_1_first_sweeps_are_the_books_synchronous_ones(small_grid: FiniteMDP) -> None:
    sweeps = dp.evaluate_sweeps(small_grid, dp.uniform_policy(small_grid), 1.0)
    values = sweeps.values.reshape(-1, 4, 4)
    assert values[0].tolist() == np.zeros((4, 4)).tolist()
    inner = np.ones((4, 4), bool)
    inner[0, 0] = inner[3, 3] = False
    assert np.all(values[1][inner] == -1.0) and values[1][0, 0] == values[1][3, 3] == 0.0
    # k = 2: -1.75 next to a corner (the book prints -1.7), -2 elsewhere: exact in binary.
    assert values[2].tolist() == [
        [0.0, -1.75, -2.0, -2.0], [-1.75, -2.0, -2.0, -2.0],
        [-2.0, -2.0, -2.0, -1.75], [-2.0, -2.0, -1.75, 0.0],
    ]  # fmt: skip
    assert values[3][0].tolist() == [0.0, -2.4375, -2.9375, -3.0]
    rounded = [[book_round(float(v), 1) for v in row] for row in values[3]]
    assert rounded[0] == [0.0, -2.4, -2.9, -3.0] and rounded[1] == [-2.4, -2.9, -3.0, -2.9]
    ten = [[book_round(float(v), 1) for v in row] for row in values[10]]
    assert ten == [
        [0.0, -6.1, -8.4, -9.0], [-6.1, -7.7, -8.4, -8.4],
        [-8.4, -8.4, -7.7, -6.1], [-9.0, -8.4, -6.1, 0.0],
    ]  # fmt: skip


def test_in_place_sweeps_are_not_the_books_figure_4_1(small_grid: FiniteMDP) -> None:
    sweeps = dp.evaluate_sweeps(small_grid, dp.uniform_policy(small_grid), 1.0, order="in_place")
    assert sweeps.values[1][:4].tolist() == [0.0, -1.0, -1.25, -1.3125]
    assert sweeps.values[2][1] == -1.9375  # the book's synchronous -1.75 (printed -1.7)
    np.testing.assert_allclose(sweeps.values[-1][[1, 5, 2, 3]], [-14, -18, -20, -22], atol=1e-8)


def test_fig_4_1_k_infinity_is_the_books_exact_values(small_grid: FiniteMDP) -> None:
    sweeps = dp.evaluate_sweeps(small_grid, dp.uniform_policy(small_grid), 1.0, tolerance=1e-12)
    book = [[0, -14, -20, -22], [-14, -18, -20, -20], [-20, -20, -18, -14], [-22, -20, -14, 0]]
    np.testing.assert_allclose(sweeps.values[-1].reshape(4, 4), book, atol=1e-9)
    assert sweeps.changes[-1] < 1e-12 <= sweeps.changes[-2]


def test_fig_4_1_greedy_policy_at_k_1_and_the_tie_rule(small_grid: FiniteMDP) -> None:
    sweeps = dp.evaluate_sweeps(small_grid, dp.uniform_policy(small_grid), 1.0)
    tied = dp.tied_best(small_grid.backup(sweeps.values[1], 1.0), small_grid.allowed, 1e-9)
    up, down, left, right = range(4)
    assert np.flatnonzero(tied[1]).tolist() == [left]  # next to the top-left corner
    assert np.flatnonzero(tied[14]).tolist() == [right]
    assert tied[5].all()  # all four tie in the middle
    assert dp.greedy(small_grid.backup(sweeps.values[1], 1.0), small_grid.allowed)[5] == up
    assert np.flatnonzero(tied[11]).tolist() == [down]


def test_book_round_rounds_halves_upwards_as_the_book_prints() -> None:
    assert [book_round(v, 1) for v in (-1.75, 8.7893, 5.3227, -2.4375, 24.4194)] == [
        -1.7, 8.8, 5.3, -2.4, 24.4,
    ]  # fmt: skip


# -- Figures 3.2 and 3.5: the 5x5 gridworld -------------------------------------------------


def test_fig_3_2_random_policy_values(grid: FiniteMDP) -> None:
    values = dp.evaluate_sweeps(grid, dp.uniform_policy(grid), 0.9, tolerance=1e-12).values[-1]
    exact = dp.evaluate_policy(grid, dp.uniform_policy(grid), 0.9)
    np.testing.assert_allclose(values, exact, atol=1e-10)
    printed = [book_round(float(v), 1) for v in values]
    assert printed[1] == 8.8 and printed[3] == 5.3  # A and B
    assert printed[:5] == [3.3, 8.8, 4.4, 5.3, 1.5]
    assert printed[20:] == [-1.9, -1.3, -1.2, -1.4, -2.0]


def test_fig_3_5_optimal_values_and_policy(grid: FiniteMDP) -> None:
    sweeps = dp.value_iteration_sweeps(grid, 0.9, tolerance=1e-12)
    values = sweeps.values[-1]
    assert book_round(float(values[1]), 1) == 24.4  # v*(A)
    assert book_round(float(values[0]), 1) == 22.0
    assert [book_round(float(v), 1) for v in values[20:]] == [14.4, 16.0, 14.4, 13.0, 11.7]
    # v*(A) exactly: 10 + 0.9^5 v*(A) (A -> A' then four steps up back to A).
    assert values[1] == pytest.approx(10 / (1 - 0.9**5), abs=1e-9)
    tied = dp.tied_best(grid.backup(values, 0.9), grid.allowed, 1e-9)
    up, _down, left, right = range(4)
    assert np.flatnonzero(tied[0]).tolist() == [right]
    assert np.flatnonzero(tied[24]).tolist() == [up, left]
    assert tied[1].all()  # every action in A moves to A'


# -- property tests: the algorithms against the linear algebra ------------------------------


@st.composite
def small_mdps(draw: Any) -> FiniteMDP:
    states = draw(st.integers(1, 5))
    actions = draw(st.integers(1, 3))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    transition = rng.dirichlet(np.ones(states + 1), size=(states, actions))[..., :states]
    reward = rng.normal(size=(states, actions)).round(3)
    allowed = rng.random((states, actions)) < 0.7
    allowed[np.arange(states), rng.integers(actions, size=states)] = True
    return FiniteMDP.from_dense(transition, reward, allowed)


@given(small_mdps(), st.floats(0.0, 0.95))
def test_policy_evaluation_equals_the_linear_solve(model: FiniteMDP, gamma: float) -> None:
    pi = dp.uniform_policy(model)
    for order in dp.SWEEP_ORDERS:
        swept = dp.evaluate_sweeps(model, pi, gamma, tolerance=1e-12, order=order).values[-1]
        exact = dp.evaluate_policy(model, pi, gamma)
        np.testing.assert_allclose(swept, exact, atol=1e-9)


@given(small_mdps(), st.floats(0.0, 0.95))
def test_value_iteration_satisfies_the_bellman_optimality_equation(
    model: FiniteMDP, gamma: float
) -> None:
    for order in dp.SWEEP_ORDERS:
        values = dp.value_iteration_sweeps(model, gamma, tolerance=1e-13, order=order).values[-1]
        q = np.where(model.allowed, model.backup(values, gamma), -np.inf)
        np.testing.assert_allclose(values, q.max(axis=1), atol=1e-9)
        # Its greedy policy's exact values are the optimum: policy iteration agrees.
        greedy = dp.greedy(model.backup(values, gamma), model.allowed)
        assert model.allowed[np.arange(model.n_states), greedy].all()
        # (a tie within 1e-9 may cost up to 1e-9 / (1 - gamma) of value)
        np.testing.assert_allclose(dp.policy_values(model, greedy, gamma).values, values, atol=1e-7)
    start = np.argmax(model.allowed, axis=1)
    found = dp.policy_iteration(model, gamma, start)
    np.testing.assert_allclose(found.values[-1], values, atol=1e-7)


def test_policy_iteration_stops_when_the_old_action_is_still_among_the_best() -> None:
    # Two actions of equal value everywhere: the start policy (action 1) is kept.
    transition = np.zeros((2, 2, 2))
    transition[:, :, 0] = 0.5
    model = FiniteMDP.from_dense(transition, np.ones((2, 2)))
    found = dp.policy_iteration(model, 0.5, np.array([1, 1]))
    assert found.improvements == 0 and found.policies.tolist() == [[1, 1]]


def test_bad_arguments_are_refused(small_grid: FiniteMDP) -> None:
    pi = dp.uniform_policy(small_grid)
    with pytest.raises(ValueError, match="gamma"):
        dp.evaluate_sweeps(small_grid, pi, 1.5)
    with pytest.raises(ValueError, match="did not converge in 3 sweeps"):
        dp.evaluate_sweeps(small_grid, pi, 1.0, max_sweeps=3)
    with pytest.raises(ValueError, match="sweeps must be one of"):
        dp.value_iteration_sweeps(small_grid, 1.0, order="backwards")
    with pytest.raises(ValueError, match="never ends the episode"):
        dp.policy_values(small_grid, np.zeros(16, np.int64), 1.0)  # up forever in row 0


# -- the worlds -----------------------------------------------------------------------------


@pytest.mark.parametrize("world", PLANNING_WORLDS, ids=lambda world: world.id)
def test_each_planning_world_is_registered_and_passes_check_env(world: Any) -> None:
    env = gymnasium.make(world.id)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env.unwrapped)
    assert env.spec is not None and env.spec.max_episode_steps == world.max_episode_steps
    found = _world(world.id)
    # Every (state, action)'s outcomes sum to 1 (what ends the episode included).
    model = found.model
    totals = np.bincount(model.state * model.n_actions + model.action, weights=model.probability)
    np.testing.assert_allclose(totals, 1.0, atol=1e-12)


def test_the_small_gridworld_plays_its_table() -> None:
    env = gymnasium.make("cartpole_q/SmallGridworld-v0")
    state, _ = env.reset(seed=3)
    env.action_space.seed(3)
    assert state not in (0, 15)
    total, done, steps = 0.0, False, 0
    while not done:
        state, reward, terminated, truncated, _ = env.step(int(env.action_space.sample()))
        total += float(reward)
        steps += 1
        done = terminated or truncated
    assert total == -steps and state in (0, 15)


# -- cartpole-q dp ----------------------------------------------------------------------------


def test_dp_draws_fig_4_1_with_its_data_and_prints_the_books_numbers(tmp_path: Path) -> None:
    out = tmp_path / "fig4_1"
    result = invoke("dp", BOOK / "fig4_1_small_gridworld.yaml", "--out", out)
    assert result.exit_code == 0, result.output
    lines = result.stdout.splitlines()
    assert "426 synchronous sweeps" in lines[0]  # no progress line: the study is one run
    assert "  k = ∞, state (0, 3): book -22, ours -22 (-22; same)" in lines
    assert "  k = 2, next to a corner (0, 1): book -1.7, ours -1.7 (-1.75; same)" in lines
    assert "differs" not in result.stdout
    assert lines[-1] == str(out)
    assert (out / "fig4_1_small_gridworld.png").read_bytes().startswith(b"\x89PNG")
    data = (out / "fig4_1_small_gridworld.csv").read_text(encoding="utf-8").splitlines()
    assert data[0] == "panel,series,x,y,y_low,y_high,value"
    final = {
        (row["x"], row["y"]): float(row["value"])
        for row in csv.DictReader(data)
        if row["panel"] == "v_pi (k = ∞: 426 sweeps)"
    }
    assert len(final) == 16 and final["3", "0"] == pytest.approx(-22.0, abs=1e-8)
    assert '"greedy w.r.t. v_k, k = 1",greedy actions,1,0,,,left' in data
    sweeps = (out / "fig4_1_small_gridworld_sweeps.csv").read_text(encoding="utf-8")
    sweeps_lines = sweeps.splitlines()
    assert sweeps_lines[0] == "record,step,state,value"
    assert "values,2,1,-1.75" in sweeps_lines and "policy,1,1,2" in sweeps_lines  # left: 2
    assert len(sweeps_lines) == 1 + 427 * 16 * 2
    # The directory holds a study now: a second one is refused there, `study` makes the same.
    again = invoke("dp", BOOK / "fig4_1_small_gridworld.yaml", "--out", out)
    assert again.exit_code == 2 and "points at a non-empty directory" in again.stderr
    other = tmp_path / "other"
    assert invoke("study", BOOK / "fig4_1_small_gridworld.yaml", "--out", other).exit_code == 0
    assert (other / "fig4_1_small_gridworld_sweeps.csv").read_text(encoding="utf-8") == sweeps


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"algorithm": "policy_evolution"}, "algorithm: must be one of policy_evaluation"),
        ({"gama": 0.9}, "unknown key 'gama'; did you mean 'gamma'?"),
        ({"gamma": 1.5}, "gamma: must be a number in [0, 1]"),
        ({"env": {"id": "CartPole-v1"}}, "CartPole-v1"),
        ({"env": {"id": "cartpole_q/NoSuchWorld-v0"}}, "env.id"),
        ({"figure": {"kind": "pie"}}, "figure.kind: must be one of grid, gambler, car_rental"),
        ({"book": [{"label": "x", "value": 1, "state": 99}]}, "book[0].state: 99 is not a state"),
        ({"book": [{"label": "x", "value": 1, "state": 1, "sweep": 9999}]}, "made only 426"),
        ({"policy": 7}, "policy: action 7 does not exist"),
        ({"max_sweeps": 11}, "did not converge in 11 sweeps"),
        ({"max_sweeps": 5}, "figure.show: sweep 10 is beyond max_sweeps (5)"),
        (
            {"figure": {"kind": "gambler"}},
            "cartpole_q/SmallGridworld-v0 is not the gambler's problem",
        ),
        (
            {"algorithm": "value_iteration", "policy": 0},
            "policy: value iteration starts from v = 0",
        ),
        ({"tolerance": "fast"}, "tolerance: must be a number"),
        ({"tolerance": 0}, "tolerance: must be positive"),
        ({"policy": "greedy"}, "policy: must be random or an action"),
        ({"sweeps": "backwards"}, "sweeps: must be one of synchronous, in_place"),
        ({"figure": {"kind": "grid", "file": "a/b.png"}}, "figure.file: must be a file name"),
        (
            {"figure": {"kind": "gambler"}, "algorithm": "policy_iteration", "policy": 0},
            "gambler draws sweeps",
        ),
        ({"figure": {"kind": "car_rental"}}, "car_rental draws policy iteration"),
        ({"book": [{"label": "x", "value": 1, "of": "mean"}]}, "book[0].of: must be one of"),
        ({"env": {"id": "cartpole_q/Gambler-v0", "kwargs": {"p_h": 2}}}, "p_h"),
    ],
)
def test_dp_refuses_bad_study_files_with_exit_code_2(
    tmp_path: Path, change: dict[str, Any], message: str
) -> None:
    import yaml

    study = yaml.safe_load((BOOK / "fig4_1_small_gridworld.yaml").read_text(encoding="utf-8"))
    study.update(change)
    path = write_yaml(tmp_path / "study.yaml", study)
    result = invoke("dp", path, "--out", tmp_path / "out")
    assert result.exit_code == 2, result.output
    assert message in result.stderr, result.stderr
    # (what only the run finds comes after the note that the study started)
    assert result.stderr.splitlines()[-1].startswith(f"error: {path}")
    assert "Traceback" not in result.stderr
    assert not (tmp_path / "out").exists()  # also when only the run found it


def test_dp_refuses_a_missing_study_file_and_a_bad_out(tmp_path: Path) -> None:
    result = invoke("dp", tmp_path / "nope.yaml")
    assert result.exit_code == 2 and "study file not found" in result.stderr
    (tmp_path / "f.txt").write_text("x")
    result = invoke("dp", BOOK / "fig4_1_small_gridworld.yaml", "--out", tmp_path / "f.txt")
    assert (
        result.exit_code == 2 and "--out must be a directory, but this is a file" in result.stderr
    )


# -- Figure 4.3: the gambler ------------------------------------------------------------------


def test_fig_4_3_gambler_v_star_50_and_the_books_policy_shape() -> None:
    world = _world("cartpole_q/Gambler-v0")
    model = world.model
    sweeps = dp.value_iteration_sweeps(model, 1.0, tolerance=1e-9)
    values = sweeps.values[-1]
    assert sweeps.sweeps == 31
    assert values[50] == pytest.approx(0.4, abs=1e-12)  # stake everything once
    assert values[25] == pytest.approx(0.16, abs=1e-12) and values[75] == pytest.approx(
        0.64, abs=1e-12
    )
    assert values[0] == values[100] == 0.0  # the ends; +1 is the reward of reaching 100
    stakes = dp.greedy(model.backup(values, 1.0), model.allowed, 1e-9)
    # The book's figure (and Zhang's rounded argmax): spikes at 25, 50, 75; between them
    # triangles rising by one a capital from 1 to 12 and falling back to 1.
    triangle = [*range(1, 13), *range(12, 0, -1)]
    assert stakes[1:100].tolist() == [*triangle, 25, *triangle, 50, *triangle, 25, *triangle]
    # Zhang's rule, state for state.
    for capital in range(1, 100):
        returns = model.backup(values, 1.0)[capital, : min(capital, 100 - capital) + 1]
        assert stakes[capital] == np.argmax(np.round(returns[1:], 5)) + 1


def test_the_gambler_plays_its_stakes_and_ends() -> None:
    env = gymnasium.make("cartpole_q/Gambler-v0", p_h=0.5, start=10)
    state, _ = env.reset(seed=1)
    assert state == 10
    # A stake above min(s, 100 - s) plays that; stake 0 plays 1.
    state, reward, terminated, _, _ = env.step(50)
    assert state in (0, 20) and terminated == (state == 0) and reward == 0.0
    allowed = env.unwrapped.allowed_actions()
    assert allowed[10].tolist() == [False] + [True] * 10 + [False] * 40
    with pytest.raises(ValueError, match="p_h"):
        gymnasium.make("cartpole_q/Gambler-v0", p_h=1.0)


# -- Figure 4.2: Jack's car rental ------------------------------------------------------------


def test_the_car_rental_model_is_exact_and_sums_to_one() -> None:
    from cartpole_q.families.planning.car_rental import day_at_location

    following, rented = day_at_location(3.0, 3.0, 20)
    np.testing.assert_allclose(following.sum(axis=1), 1.0, atol=1e-12)
    assert rented[0] == 0.0 and rented[1] == pytest.approx(1 - np.exp(-3.0))
    assert rented[20] == pytest.approx(3.0, abs=1e-6)  # 20 cars: nearly every request met
    model = _world("cartpole_q/CarRental-v0").model
    assert not model.terminated.any()  # the days go on: every row sums to 1, none ends
    totals = np.bincount(model.state * model.n_actions + model.action, weights=model.probability)
    np.testing.assert_allclose(totals, 1.0, atol=1e-12)
    # No car, no move: nothing rented. From (20, 0), moving 5 costs $10 and leaves 15 cars
    # at the first location (3 requests a day) and 5 at the second (4 a day).
    expected_reward = model.backup(np.zeros(model.n_states), 0.0)  # sum p * r: r's expectation
    assert expected_reward[0, 5] == 0.0
    _, rented_second = day_at_location(4.0, 2.0, 20)
    expected = 10 * (rented[15] + rented_second[5]) - 10.0
    assert expected_reward[20 * 21 + 0, 10] == pytest.approx(expected, abs=1e-9)


def test_fig_4_2_policy_iteration_stops_at_pi_4() -> None:
    model = _world("cartpole_q/CarRental-v0").model
    found = dp.policy_iteration(model, 0.9, np.full(441, 5))
    assert found.improvements == 4
    moves = found.policies - 5
    assert moves[0].tolist() == [0] * 441
    assert moves[-1].max() == 5 and moves[-1].min() == -4
    assert moves[-1][20 * 21 + 0] == 5 and moves[-1][0 * 21 + 20] == -4
    assert moves[-1][10 * 21 + 10] == 0
    values = found.values[-1]
    assert 421 < values.min() < 422 and 636 < values.max() < 638
    # Each improvement improves: v_pi(i+1) >= v_pi(i) everywhere.
    assert np.all(np.diff(found.values, axis=0) >= -1e-9)
    # The last policy is greedy with respect to its own values (policy iteration's stop).
    tied = dp.tied_best(model.backup(values, 0.9), model.allowed, 1e-9)
    assert tied[np.arange(441), found.policies[-1]].all()


def test_the_car_rental_env_moves_what_it_can() -> None:
    env = gymnasium.make("cartpole_q/CarRental-v0")
    env.reset(seed=0)
    env.unwrapped.cars = (2, 7)
    _, reward, terminated, truncated, info = env.step(10)  # move 5: only 2 are there
    assert info["moved"] == 2 and not terminated and not truncated
    assert reward >= -4.0 and (reward + 4.0) % 10 == 0


DP_STUDIES = {
    "fig3_2_gridworld": set(),
    "fig3_5_gridworld_optimal": set(),
    "fig4_1_small_gridworld": set(),
    "fig4_3_gambler": {"sweeps (the book's last curve: sweep 32)"},
    "fig4_2_car_rental": {
        "lowest v_pi4 (the book's axis: 420)",
        "highest v_pi4 (the book's axis: 612)",
    },
}
"""each dynamic programming study file, and the book's numbers ours do not round to"""


@pytest.mark.parametrize("name", DP_STUDIES)
def test_each_dp_study_agrees_with_the_book_and_the_docs_data(name: str, tmp_path: Path) -> None:
    result = invoke("dp", BOOK / f"{name}.yaml", "--out", tmp_path / "out")
    assert result.exit_code == 0, result.output
    differs = {
        line.strip().partition(": book")[0]
        for line in result.stdout.splitlines()
        if line.endswith("differs)")
    }
    assert differs == DP_STUDIES[name]
    assert (tmp_path / "out" / f"{name}_sweeps.csv").is_file()
    # docs/book holds the figure's data as the command writes it; the numbers agree to 1e-9
    # (another machine's BLAS may sum in another order), the rest exactly.
    shipped = (REPO / "docs" / "book" / f"{name}.csv").read_text(encoding="utf-8")
    made = (tmp_path / "out" / f"{name}.csv").read_text(encoding="utf-8")
    rows = zip(csv.reader(made.splitlines()), csv.reader(shipped.splitlines()), strict=True)
    for ours, theirs in rows:
        assert ours[:2] == theirs[:2]
        for a, b in zip(ours[2:], theirs[2:], strict=True):
            try:
                assert float(a) == pytest.approx(float(b), rel=1e-9, abs=1e-9), ours
            except ValueError:
                assert a == b, ours


def test_the_planning_worlds_have_profiles_for_maps_and_models() -> None:
    from cartpole_q.envs.models import grid_layout
    from cartpole_q.families import profile_for

    config = load_config({"env": {"id": "cartpole_q/SmallGridworld-v0"}})
    layout = grid_layout(config.env)
    assert layout is not None and (layout.rows, layout.columns) == (4, 4)
    assert layout.cells[0] == layout.cells[15] == "E" and set(layout.cells[1:15]) == {"F"}
    assert layout.arrows() == "^v<>"
    rental = profile_for("cartpole_q/CarRental-v0")
    assert rental.policy_map == "components" and rental.state_components == (21, 21)
    assert rental.names_actions(11) == [f"move {move}" for move in range(-5, 6)]
    assert profile_for("cartpole_q/Gambler-v0").model == "transition_table"


def test_the_figures_data_is_what_they_draw(tmp_path: Path) -> None:
    from cartpole_q import figures

    drawn: list[Any] = []
    real = figures.figure_bytes

    def keep(figure: Any, file_format: str) -> bytes:
        drawn.append(figure)
        return real(figure, file_format)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(figures, "figure_bytes", keep)
        for name in ("fig4_3_gambler", "fig4_2_car_rental"):
            result = invoke("dp", BOOK / f"{name}.yaml", "--out", tmp_path / name)
            assert result.exit_code == 0, result.output
    gambler, rental = drawn
    rows = list(
        csv.DictReader((tmp_path / "fig4_3_gambler" / "fig4_3_gambler.csv").open(encoding="utf-8"))
    )
    top, bottom = gambler.axes
    for line in top.get_lines():
        series = [row for row in rows if row["series"] == line.get_label()]
        assert [float(row["y"]) for row in series] == list(line.get_ydata())
    stakes = [int(row["y"]) for row in rows if row["series"] == "stake"]
    assert stakes == list(bottom.get_lines()[0].get_ydata()) and stakes[49] == 50
    rows = list(
        csv.DictReader(
            (tmp_path / "fig4_2_car_rental" / "fig4_2_car_rental.csv").open(encoding="utf-8")
        )
    )
    last = {(int(r["y"]), int(r["x"])): int(r["value"]) for r in rows if r["panel"] == "pi_4"}
    drawn_moves = rental.axes[4].collections[0].get_array().reshape(21, 21)
    assert all(drawn_moves[key] == move for key, move in last.items()) and len(last) == 441
    assert last[20, 0] == 5 and last[0, 20] == -4
