"""The Makefile's quickstart: `make train` installs the package alone, and says so first.

A fresh clone's `make train` used to install the whole dev extra (Ray, Optuna, TensorBoard,
mypy) in silence (`pip --quiet`) for almost four minutes, to train one config. ``make -n``
prints what each target would run, in a copy of the Makefile with no ``.venv`` yet.
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

from tests.conftest import REPO

pytestmark = pytest.mark.skipif(shutil.which("make") is None, reason="needs make")


def _would_run(tmp_path: Path, target: str) -> str:
    """What ``make TARGET`` would run from a fresh clone (nothing is run)."""
    for name in ("Makefile", "pyproject.toml"):
        shutil.copy(REPO / name, tmp_path / name)
    return subprocess.run(
        # (--no-print-directory: under `make test` this make is a sub-make, which names its
        # directory otherwise)
        ["make", "--no-print-directory", "-n", target],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        check=True,
    ).stdout


def test_make_train_installs_the_package_alone_and_says_so_first(tmp_path: Path) -> None:
    commands = _would_run(tmp_path, "train")
    installs = [line for line in commands.splitlines() if "pip install" in line]
    assert installs == [".venv/bin/python -m pip install -e ."], commands
    assert commands.index("installing cartpole-q and its dependencies") < commands.index(
        "venv .venv"
    )
    assert "--quiet" not in commands and "[dev" not in commands
    assert commands.strip().endswith(".venv/bin/cartpole-q train")


@pytest.mark.parametrize(("target", "extra"), [("test", "dev"), ("lint", "dev"), ("docs", "docs")])
def test_the_other_targets_add_the_extra_they_need(tmp_path: Path, target: str, extra: str) -> None:
    commands = _would_run(tmp_path, target)
    installs = [line for line in commands.splitlines() if "pip install" in line]
    assert installs == [
        ".venv/bin/python -m pip install -e .",
        f'.venv/bin/python -m pip install -e ".[{extra}]"',
    ], commands
    assert "--quiet" not in commands
