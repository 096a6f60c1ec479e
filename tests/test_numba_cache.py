"""The numba cache directory: keyed by the compiled source only, private, cleaned up."""

from __future__ import annotations

import os
import re
import shutil
import stat
from pathlib import Path

import pytest

from cartpole_q import numba_cache


@pytest.fixture
def package_copy(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    copy = tmp_path / "cartpole_q"
    shutil.copytree(numba_cache.PACKAGE_DIR, copy, ignore=shutil.ignore_patterns("__pycache__"))
    monkeypatch.setattr(numba_cache, "PACKAGE_DIR", copy)
    numba_cache.source_digest.cache_clear()
    yield copy
    numba_cache.source_digest.cache_clear()


def _digest_after_editing(copy: Path, name: str) -> str:
    path = copy / name
    path.write_text(path.read_text() + "\n# changed\n")
    numba_cache.source_digest.cache_clear()
    return numba_cache.source_digest()


def test_editing_an_inlined_module_changes_the_cache_key(package_copy: Path) -> None:
    before = numba_cache.source_digest()
    assert _digest_after_editing(package_copy, "rl/algorithms/sarsa.py") != before
    assert _digest_after_editing(package_copy, "rl/tabular.py") != before


def test_editing_the_command_line_keeps_the_cache(package_copy: Path) -> None:
    before = numba_cache.source_digest()
    assert _digest_after_editing(package_copy, "cli/app.py") == before


def test_every_module_with_compiled_functions_is_hashed() -> None:
    compiled = {
        path.relative_to(numba_cache.PACKAGE_DIR).as_posix()
        for path in numba_cache.PACKAGE_DIR.rglob("*.py")
        if re.search(
            r"@njit|njit\(|structref|@overload|@compilable|specialise\(",
            path.read_text(encoding="utf-8"),
        )
    }
    assert compiled - {"engines/compile.py"} <= set(numba_cache.compiled_modules())


def test_cache_lives_under_xdg_cache_home(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    chosen = numba_cache.choose_cache_dir()
    assert chosen == numba_cache.cache_dir()
    assert chosen.parent == tmp_path / "xdg" / "cartpole-q"
    assert numba_cache.is_private_directory(chosen)


def test_stale_caches_of_this_package_are_removed(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    root = tmp_path / "cartpole-q"
    stale = root / "numba-0123456789abcdef"
    stale.mkdir(parents=True, mode=0o700)
    (stale / "agent.nbi").write_bytes(b"old")
    unrelated = root / "notes"
    unrelated.mkdir()
    chosen = numba_cache.choose_cache_dir()
    assert chosen.is_dir() and not stale.exists() and unrelated.is_dir()


@pytest.mark.skipif(os.getuid() != 0, reason="making another user's directory needs root")
def test_a_directory_another_user_owns_is_never_used(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # Another local user could plant pickled "compiled code" in a shared, predictable path.
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "home-cache"))
    (tmp_path / "home-cache").write_text("not a directory")  # the home cache is unusable
    monkeypatch.setattr(numba_cache.tempfile, "tempdir", str(tmp_path / "tmp"))
    planted = tmp_path / "tmp" / f"cartpole-q-{os.getuid()}"
    planted.mkdir(parents=True)
    os.chown(planted, 12345, 12345)
    chosen = numba_cache.choose_cache_dir()
    assert planted not in chosen.parents
    assert numba_cache.is_private_directory(chosen)


def test_a_world_writable_directory_is_not_private(tmp_path: Path) -> None:
    shared = tmp_path / "shared"
    shared.mkdir()
    shared.chmod(0o777)
    assert not numba_cache.is_private_directory(shared)
    link = tmp_path / "link"
    link.symlink_to(tmp_path)
    assert not numba_cache.is_private_directory(link)
    private = tmp_path / "private"
    private.mkdir(mode=0o700)
    assert numba_cache.is_private_directory(private)
    assert not stat.S_IMODE(private.stat().st_mode) & 0o077
