"""Hostile and mistaken input is refused in one paragraph, quickly, before anything is spent.

Issue 29, "What a new user met": files that make readers recurse or allocate without
bound, configs that expand without bound, a multi-seed directory holding another world's
seed, a render mode no display can show, an ``env.id`` that imports modules, a robustness
grid checked only as it is played, and messages that blamed the wrong cause.
"""

from __future__ import annotations

import io
import json
import shutil
import sys
import time
import zipfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from cartpole_q.config import ConfigError, load_config, shown_value
from cartpole_q.errors import RunError
from cartpole_q.store import sweepdir
from tests.conftest import invoke, write_yaml
from tests.test_cli import assert_refused

SMALL = {"train": {"episodes": 30, "eval_every": 0}, "eval": {"episodes": 2}}
QUICK = 10.0
"""seconds within which every refusal here comes (the old code took minutes for some)"""


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """A CartPole run, a two-seed CartPole run and a FrozenLake run, small."""
    base = tmp_path_factory.mktemp("hostile")
    found = {}
    for name, extra in (
        ("one", []),
        ("seeds", ["--seeds", "0-1"]),
        ("lake", ["--set", "env.id=FrozenLake-v1"]),
    ):
        config = write_yaml(base / f"{name}.yaml", SMALL)
        result = invoke("train", "-c", config, *extra, "--out", base / name, "-q")
        assert result.exit_code == 0, result.output
        found[name] = base / name
    return found


def _copy(run: Path, tmp_path: Path, name: str = "copy") -> Path:
    copy = tmp_path / name
    shutil.copytree(run, copy)
    return copy


def _refused_quickly(*args: object, named: tuple[str, ...] = ()) -> str:
    start = time.perf_counter()
    result = invoke(*args)
    assert time.perf_counter() - start < QUICK
    assert_refused(result, *named)
    assert len(result.stderr) < 1500, f"a {len(result.stderr):,}-character message"
    return result.stderr


# -- item 5: files whose reading recursed or allocated without bound ----------------------------


def test_a_deeply_nested_summary_is_refused_by_every_reader(
    runs: dict[str, Path], tmp_path: Path
) -> None:
    run = _copy(runs["one"], tmp_path)
    (run / "summary.json").write_text("[" * 100_000 + "]" * 100_000)
    named = ("summary.json: nests arrays and objects more than 64 levels deep",)
    _refused_quickly("eval", run, "--episodes", 1, named=named)
    _refused_quickly("plot", run, "--out", tmp_path / "p.png", named=named)
    _refused_quickly("compare", run, runs["one"], named=named)
    from cartpole_q import load_run

    with pytest.raises(RunError, match="nests arrays and objects"):
        load_run(run)
    assert not (tmp_path / "p.png").exists()


def _npy_header(shape: tuple[int, ...], descr: str = "<f8") -> bytes:
    """An ``.npy`` header declaring ``shape``, without the data it promises."""
    buffer = io.BytesIO()
    np.lib.format.write_array_header_1_0(
        buffer, {"descr": descr, "fortran_order": False, "shape": shape}
    )
    return buffer.getvalue()


HUGE = (1, 1, 2, 10, 2**40)
"""the default grid's states with 2^40 actions: 160 TiB of float64 the header declares"""


@pytest.mark.parametrize(("file", "descr"), [("q_table.npy", "<f8"), ("visits.npy", "<i8")])
def test_an_array_header_declaring_a_huge_shape_is_refused_before_allocating(
    runs: dict[str, Path], tmp_path: Path, file: str, descr: str
) -> None:
    run = _copy(runs["one"], tmp_path)
    (run / file).write_bytes(_npy_header(HUGE, descr))
    _refused_quickly("eval", run, "--episodes", 1, named=(file,))
    _refused_quickly("plot", run, "--policy", named=(file,))


def test_an_array_whose_shape_does_not_fit_its_config_is_refused_from_its_header(
    runs: dict[str, Path], tmp_path: Path
) -> None:
    run = _copy(runs["one"], tmp_path)
    (run / "q_table.npy").write_bytes(_npy_header((2**20, 2**20, 2)))
    _refused_quickly("eval", run, named=("q_table.npy: has shape (1048576, 1048576, 2)",))


def test_a_sweep_points_table_declaring_a_huge_shape_is_refused(tmp_path: Path) -> None:
    sweep = write_yaml(tmp_path / "s.yaml", {"name": "s", "base": SMALL, "seeds": "0"})
    out = tmp_path / "sweep"
    assert invoke("sweep", sweep, "--out", out, "--workers", 1, "-q").exit_code == 0
    tables = sweepdir.tables_path(out, "000")
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w") as archive:
        archive.writestr("seed-000.npy", _npy_header(HUGE))
    tables.write_bytes(buffer.getvalue())
    _refused_quickly("eval", out / "points" / "000", named=("q_tables.npz: seed-000",))
    _refused_quickly("plot", out / "points" / "000", "--policy", named=("q_tables.npz",))


def test_a_compressed_member_claiming_more_than_it_can_expand_to_is_refused(
    tmp_path: Path,
) -> None:
    path = tmp_path / "a.npz"
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as archive:
        archive.writestr("x.npy", _npy_header((4,)) + bytes(32))
    data = bytearray(buffer.getvalue())
    # Lie in both directories: 2^40 bytes uncompressed.
    for signature, offset in ((b"PK\x03\x04", 22), (b"PK\x01\x02", 24)):
        at = data.find(signature)
        data[at + offset : at + offset + 4] = (2**32 - 2).to_bytes(4, "little")
    path.write_bytes(bytes(data))
    from cartpole_q.store.reading import load_npz

    with pytest.raises(RunError, match=r"a\.npz: x: declares 4,294,967,294 bytes"):
        load_npz(path, str(path))
    np.savez_compressed(path, x=np.arange(4.0))
    assert load_npz(path, str(path))["x"].tolist() == [0.0, 1.0, 2.0, 3.0]


def test_plot_policy_of_a_run_whose_config_is_another_worlds(
    runs: dict[str, Path], tmp_path: Path
) -> None:
    run = _copy(runs["one"], tmp_path)
    shutil.copy(runs["lake"] / "config.yaml", run / "config.yaml")
    named = ("q_table.npy: has shape (1, 1, 2, 10, 2)", "expected (*bins, n_actions) = (16, 4)")
    _refused_quickly("plot", run, "--policy", named=named)
    _refused_quickly("eval", run, "--episodes", 1, named=named)
    assert not (run / "policy_map.png").exists()


def test_compare_refuses_a_summary_holding_nan(runs: dict[str, Path], tmp_path: Path) -> None:
    run = _copy(runs["one"], tmp_path)
    summary = json.loads((run / "summary.json").read_text())
    summary["eval"]["mean"] = float("nan")
    (run / "summary.json").write_text(json.dumps(summary))  # json writes NaN
    _refused_quickly(
        "compare", run, runs["one"], named=("summary.json: eval: mean: must be a finite number",)
    )


@pytest.mark.parametrize("cell", ["nan", "inf", "-Infinity"])
def test_a_results_row_holding_nan_is_damaged(cell: str) -> None:
    row = {
        "point": "000", "seed": "0", "episodes": "10", "env_steps": "100",
        "solved_episode": "", "env_steps_to_solve": "", "first_greedy_success_env_steps": "",
        "eval_mean": cell, "success": "false", "train_seconds": "0.1",
    }  # fmt: skip
    with pytest.raises(RunError, match=r"results\.csv: has a damaged row"):
        sweepdir.parse_row(row, [], Path("results.csv"))
    with pytest.raises(RunError, match=r"results\.csv: has a damaged row"):
        sweepdir.parse_row(
            {**row, "eval_mean": "1.0", "solved_episode": cell}, [], Path("results.csv")
        )


def test_tune_refuses_a_storage_file_that_is_not_a_journal(in_tmp: Path) -> None:
    pytest.importorskip("optuna")
    spec = write_yaml(in_tmp / "t.yaml", {
        "name": "t", "base": SMALL, "seeds": "0", "trials": 1,
        "space": {"agent.alpha": {"low": 0.1, "high": 0.5}},
    })  # fmt: skip
    # (a line like the beginning of a record, cut short, with no record before it)
    for junk in ("junk\n", '{"op_code": 99}\n', "precious, no newline", '{"op'):
        journal = in_tmp / "junk.journal"
        journal.write_text(junk)
        _refused_quickly(
            "tune", spec, "--storage", journal, "--out", in_tmp / "study",
            named=("--storage", "junk.journal: is not an Optuna journal file"),
        )  # fmt: skip
        assert journal.read_text() == junk, "nothing written to it, nothing cut from it"
        assert not (in_tmp / "study").exists()


# -- item 6: configs without bounds ---------------------------------------------------------------

BOMB = """env:
  kwargs:
    a: &a ["lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol"]
    b: &b [*a, *a, *a, *a, *a, *a, *a, *a, *a]
    c: &c [*b, *b, *b, *b, *b, *b, *b, *b, *b]
    d: &d [*c, *c, *c, *c, *c, *c, *c, *c, *c]
    e: &e [*d, *d, *d, *d, *d, *d, *d, *d, *d]
    f: &f [*e, *e, *e, *e, *e, *e, *e, *e, *e]
"""


@pytest.mark.parametrize(
    ("text", "named"),
    [
        (BOMB, "holds more than 100,000 values once its aliases (*name) are expanded"),
        (
            "env:\n  kwargs:\n    x: " + "[" * 200 + "]" * 200 + "\n",
            "nests lists and mappings more than 64 levels deep",
        ),
        ("a: &a [1, *a]\n", "has an alias inside the value it names"),
        ("seed: 0\n" + "# padding\n" * (256 * 1024 // 10), "is larger than 256 KiB"),
        ("env:\n  kwargs:\n    x: [" + "1, " * 120_000 + "1]\n", "is larger than 256 KiB"),
        ("env:\n  kwargs:\n    x: [" + "1," * 110_000 + "1]\n", "holds more than 100,000 values"),
    ],
)
def test_a_config_beyond_the_bounds_is_refused_quickly_and_briefly(
    in_tmp: Path, text: str, named: str
) -> None:
    path = in_tmp / "c.yaml"
    path.write_text(text)
    _refused_quickly("train", "-c", path, named=(f"{path}: {named}",))
    assert not (in_tmp / "runs").exists()
    with pytest.raises(ConfigError, match=r"c\.yaml: "):
        load_config(path)


def test_aliases_within_the_bounds_still_work(tmp_path: Path) -> None:
    path = tmp_path / "c.yaml"
    path.write_text("agent:\n  alpha: &rate {type: exponential, start: 0.5, decay: 0.99, end: 0.1}\n"
                    "  epsilon: *rate\n")  # fmt: skip
    config = load_config(path)
    assert config.agent.alpha == config.agent.epsilon


def test_an_alias_bomb_on_the_command_line_is_refused(in_tmp: Path) -> None:
    bomb = "[&a [1,2,3,4,5,6,7,8,9,10], &b [*a,*a,*a,*a,*a,*a,*a,*a,*a,*a], " \
        "&c [*b,*b,*b,*b,*b,*b,*b,*b,*b,*b], &d [*c,*c,*c,*c,*c,*c,*c,*c,*c,*c], " \
        "[*d,*d,*d,*d,*d,*d,*d,*d,*d,*d]]"  # fmt: skip
    _refused_quickly("train", "--set", f"env.kwargs.x={bomb}", named=("--set", "100,000 values"))


def test_a_large_value_is_quoted_briefly(in_tmp: Path) -> None:
    big = write_yaml(in_tmp / "c.yaml", {"env": {"kwargs": {"foo": list(range(20_000))}}})
    message = _refused_quickly("train", "-c", big, named=("env.kwargs.foo", "foo=[0, 1, 2"))
    assert len(message) < 600, message
    from cartpole_q.config import shown

    assert len(shown(list(range(10**6)))) <= 80
    assert len(shown("x" * 10**6)) <= 80 and len(shown_value({"k": ["x" * 10**6]})) <= 80


# -- item 7: a multi-seed directory holding a seed of another world ---------------------------


def test_a_seed_of_another_world_in_a_multi_seed_run_is_refused(
    runs: dict[str, Path], tmp_path: Path
) -> None:
    parent = _copy(runs["seeds"], tmp_path)
    shutil.rmtree(parent / "seed-001")
    shutil.copytree(runs["lake"], parent / "seed-001")
    named = (
        "seed-001: is not a seed of the multi-seed run",
        'env.id is "FrozenLake-v1" in seed-001 but "CartPole-v1" in',
    )
    _refused_quickly("eval", parent, "--episodes", 1, named=named)
    _refused_quickly("compare", parent, runs["seeds"], named=named)
    _refused_quickly("plot", parent, "--out", tmp_path / "p.png", named=named)


def test_a_seed_directory_holding_another_seed_is_refused(
    runs: dict[str, Path], tmp_path: Path
) -> None:
    parent = _copy(runs["seeds"], tmp_path)
    shutil.rmtree(parent / "seed-001")
    shutil.copytree(runs["seeds"] / "seed-000", parent / "seed-001")
    _refused_quickly("eval", parent, "--episodes", 1, named=("seed-001", "seed is 0 in seed-001"))


def test_a_seed_extended_on_its_own_still_belongs(runs: dict[str, Path], tmp_path: Path) -> None:
    parent = _copy(runs["seeds"], tmp_path)
    config = parent / "seed-001" / "config.yaml"
    config.write_text(config.read_text().replace("episodes: 30", "episodes: 40", 1))
    result = invoke("eval", parent, "--episodes", 1)
    assert result.exit_code == 0, result.output


# -- item 9: an env.id that imports modules ----------------------------------------------------------

PROBE = "hostile_probe_29"


@pytest.fixture
def probe(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    """A module on the path that leaves a mark when imported."""
    mark = tmp_path / "imported"
    (tmp_path / f"{PROBE}.py").write_text(f"open({str(mark)!r}, 'w').close()\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    sys.modules.pop(PROBE, None)
    yield mark
    sys.modules.pop(PROBE, None)


def test_a_run_directory_cannot_make_cartpole_q_import_a_module(
    runs: dict[str, Path], tmp_path: Path, probe: Path
) -> None:
    run = _copy(runs["one"], tmp_path, "run")
    config = run / "config.yaml"
    config.write_text(config.read_text().replace("id: CartPole-v1", f"id: {PROBE}:Foo-v0"))
    named = ("config.yaml: env.id:", f"would import the module '{PROBE}'")
    for args in (("eval", run), ("plot", run, "--policy"), ("compare", run, runs["one"])):
        _refused_quickly(*args, named=named)
    _refused_quickly("robustness", run, "--vary", "length=0.5:1:2", named=named)
    assert not probe.exists() and PROBE not in sys.modules


@pytest.mark.parametrize(
    ("env_id", "named"),
    [
        ("no_such_module_29:Foo-v0", "the module 'no_such_module_29' cannot be imported"),
        ("CartPol-v1", "did you mean 'CartPole-v1'?"),
        ("a:b:c", "is not an environment id"),
        ("not-a-module:Foo-v0", "'not-a-module' before ':' is not a module name"),
    ],
)
def test_an_env_id_is_checked_before_anything_is_imported(
    in_tmp: Path, env_id: str, named: str
) -> None:
    _refused_quickly("train", "--set", f"env.id={env_id}", named=(f"env.id: {env_id!r}", named))
    assert not (in_tmp / "runs").exists()


def test_a_module_in_the_users_own_config_is_imported_by_design(in_tmp: Path, probe: Path) -> None:
    _refused_quickly(
        "train", "--set", f"env.id={PROBE}:Foo-v0",
        named=(f"importing '{PROBE}' registered no environment 'Foo-v0'",),
    )  # fmt: skip
    assert probe.exists()


# -- item 10: a robustness grid is checked before it is played ----------------------------------


def test_robustness_checks_every_value_before_playing_any(
    runs: dict[str, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from cartpole_q.experiments import robustness

    def never(*args: Any, **kwargs: Any) -> None:
        raise AssertionError("a grid point was played before the grid was checked")

    monkeypatch.setattr(robustness, "make_engine", never)
    out = tmp_path / "r.png"
    _refused_quickly(
        "robustness", runs["one"], "--vary", "length=1:0:5", "--out", out,
        named=("--vary: env.physics.length: must be in (0, 100], got 0.0",),
    )  # fmt: skip
    assert not out.exists() and not out.with_suffix(".csv").exists()


# -- item 11: messages that named the wrong cause ----------------------------------------------------


def test_an_unversioned_id_is_blamed_not_the_default_grid(in_tmp: Path) -> None:
    message = _refused_quickly(
        "train", "--set", "env.id=CartPole",
        named=("command line: env.id: 'CartPole' gives no version; write 'CartPole-v1'",),
    )  # fmt: skip
    assert "discretization" not in message


@pytest.mark.parametrize(
    ("value", "expected"),
    [(10, 10), (10.0, 10), ("1e3", 1000), ("10.0", 10), (1e3, 1000)],
)
def test_an_integer_may_be_written_as_a_whole_float(value: object, expected: int) -> None:
    assert load_config(overrides={"train.episodes": value}).train.episodes == expected


@pytest.mark.parametrize(
    ("key", "value", "named"),
    [
        ("train.episodes", 1e30, "train.episodes: must be an integer no larger than 10000000"),
        ("train.episodes", "1e30", "train.episodes: must be an integer no larger than 10000000"),
        ("train.episodes", 10**30, "train.episodes: must be an integer no larger than 10000000"),
        (
            "train.episodes",
            20_000_000.0,
            "train.episodes: must be an integer no larger than 10000000",
        ),
        ("seed", 1e30, "seed: must be an integer no larger than 4294967295"),
        (
            "train.checkpoint_every",
            1e30,
            "train.checkpoint_every: must be an integer no larger than 9007199254740991",
        ),
        ("train.episodes", 2.5, "train.episodes: must be an integer, got 2.5"),
    ],
)
def test_an_integer_too_large_is_refused_alike_however_written(
    key: str, value: object, named: str
) -> None:
    with pytest.raises(ConfigError, match=f"^overrides: {named}"):
        load_config(overrides={key: value})
