"""The numba cache directory: keyed by the compiled source only, private, and shared
with other versions (kept while in use, removed when long unused)."""

from __future__ import annotations

import fcntl
import hashlib
import os
import re
import shutil
import stat
import subprocess
import sys
import time
from pathlib import Path

import pytest

from cartpole_q import numba_cache
from tests.conftest import REPO, write_yaml


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


# -- other versions' caches: kept while used, removed when long unused --------------------

DAY = 24 * 3600


def _version_cache(root: Path, digest: str, unused_days: float, size: int = 0) -> Path:
    """A private cache directory of another version, last used ``unused_days`` ago."""
    directory = root / f"numba-{digest}"
    directory.mkdir(parents=True, mode=0o700)
    (directory / "agent.nbi").write_bytes(b"x" * size)
    (directory / numba_cache.LAST_USED_FILE).touch()
    moment = time.time() - unused_days * DAY
    for path in (directory / numba_cache.LAST_USED_FILE, directory):
        os.utime(path, (moment, moment))
    return directory


@pytest.fixture
def root(tmp_path: Path) -> Path:
    """A cache root holding the current version's directory, ``numba-current``."""
    (tmp_path / "cartpole-q" / "numba-current").mkdir(parents=True, mode=0o700)
    return tmp_path / "cartpole-q"


def test_a_long_unused_cache_of_another_version_is_removed_a_recent_one_kept(root: Path) -> None:
    old = _version_cache(root, "old", unused_days=numba_cache.UNUSED_DAYS + 1)
    recent = _version_cache(root, "recent", unused_days=numba_cache.UNUSED_DAYS - 1)
    before_stamps = _version_cache(root, "unstamped", unused_days=numba_cache.UNUSED_DAYS + 1)
    (before_stamps / numba_cache.LAST_USED_FILE).unlink()  # made by a release without them
    os.utime(before_stamps, (time.time() - 40 * DAY,) * 2)
    removed = numba_cache.remove_stale_caches(root, root / "numba-current")
    assert sorted(removed) == [old, before_stamps]
    assert recent.is_dir() and (root / "numba-current").is_dir()


_HOLDER = """
import sys
from pathlib import Path
from cartpole_q.numba_cache import mark_in_use
mark_in_use(Path(sys.argv[1]))
print("held", flush=True)
sys.stdin.read()
"""


def test_a_cache_a_live_process_uses_is_kept_however_old(root: Path) -> None:
    other = _version_cache(root, "other", unused_days=365)
    holder = subprocess.Popen(
        [sys.executable, "-c", _HOLDER, str(other)], stdin=subprocess.PIPE,
        stdout=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        assert holder.stdout is not None and holder.stdout.readline() == "held\n"
        os.utime(other / numba_cache.LAST_USED_FILE, (time.time() - 365 * DAY,) * 2)
        assert numba_cache.remove_stale_caches(root, root / "numba-current") == []
        assert (other / "agent.nbi").is_file()
    finally:
        holder.communicate("")  # it exits; the kernel releases its lock
    assert numba_cache.remove_stale_caches(root, root / "numba-current") == [other]


def test_over_the_size_bound_the_least_recently_used_go_first(
    root: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(numba_cache, "MAX_TOTAL_BYTES", 2500)
    current = root / "numba-current"
    (current / "agent.nbi").write_bytes(b"x" * 1000)
    os.utime(current / "agent.nbi", (time.time() - 365 * DAY,) * 2)
    oldest = _version_cache(root, "oldest", unused_days=3, size=1000)
    older = _version_cache(root, "older", unused_days=2, size=1000)
    newest = _version_cache(root, "newest", unused_days=1, size=1000)
    assert numba_cache.remove_stale_caches(root, current) == [oldest, older]
    assert newest.is_dir() and current.is_dir()


def test_the_current_version_is_never_removed(root: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(numba_cache, "MAX_TOTAL_BYTES", 0)
    current = root / "numba-current"
    (current / "agent.nbi").write_bytes(b"x" * 1000)
    os.utime(current, (time.time() - 365 * DAY,) * 2)
    assert numba_cache.remove_stale_caches(root, current) == []
    assert (current / "agent.nbi").is_file()


def test_links_shared_and_unrelated_directories_are_never_removed(
    root: Path, tmp_path: Path
) -> None:
    target = _version_cache(tmp_path / "elsewhere", "target", unused_days=365)
    link = root / "numba-link"
    link.symlink_to(target)
    os.utime(link, (time.time() - 365 * DAY,) * 2, follow_symlinks=False)
    shared = _version_cache(root, "shared", unused_days=365)
    shared.chmod(0o777)
    unrelated = root / "notes"
    unrelated.mkdir()
    os.utime(unrelated, (time.time() - 365 * DAY,) * 2)
    assert numba_cache.remove_stale_caches(root, root / "numba-current") == []
    assert link.is_symlink() and (target / "agent.nbi").is_file()
    assert (shared / "agent.nbi").is_file() and unrelated.is_dir()


@pytest.mark.skipif(os.getuid() != 0, reason="making another user's directory needs root")
def test_another_users_directory_is_never_removed(root: Path) -> None:
    theirs = _version_cache(root, "theirs", unused_days=365)
    os.chown(theirs, 12345, 12345)
    assert numba_cache.remove_stale_caches(root, root / "numba-current") == []
    assert (theirs / "agent.nbi").is_file()


def test_other_versions_are_looked_at_once_a_day(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    root = tmp_path / "cartpole-q"
    first = _version_cache(root, "first", unused_days=365)
    chosen = numba_cache.choose_cache_dir()
    assert chosen.is_dir() and not first.exists()
    assert (chosen / numba_cache.LAST_USED_FILE).is_file()
    second = _version_cache(root, "second", unused_days=365)
    assert numba_cache.choose_cache_dir() == chosen and second.is_dir()  # looked today
    os.utime(root / "last-pruned", (time.time() - DAY - 60,) * 2)
    assert numba_cache.choose_cache_dir() == chosen and not second.exists()


def test_two_pruners_never_race(root: Path) -> None:
    old = _version_cache(root, "old", unused_days=365)
    other_pruner = os.open(root / "prune.lock", os.O_RDWR | os.O_CREAT)
    try:
        fcntl.flock(other_pruner, fcntl.LOCK_EX)
        assert numba_cache.remove_stale_caches(root, root / "numba-current") == []
        assert old.is_dir()
    finally:
        os.close(other_pruner)
    assert numba_cache.remove_stale_caches(root, root / "numba-current") == [old]


def test_the_documented_policy_is_the_code_s() -> None:
    gib = numba_cache.MAX_TOTAL_BYTES / (1 << 30)
    assert numba_cache.PRUNE_INTERVAL_SECONDS == DAY
    for text in (numba_cache.__doc__ or "", (REPO / "docs" / "how-it-works.md").read_text()):
        words = " ".join(text.replace("**", "").split())
        assert f"unused for {numba_cache.UNUSED_DAYS} days" in words
        assert f"exceed {gib:g} GiB" in words and "once a day" in words


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


# -- two source versions side by side, in real processes ------------------------------------


def _version_copy(tmp_path: Path, name: str, edit: str | None) -> tuple[Path, str]:
    """A copy of the package under ``tmp_path/name`` (``rl/tabular.py`` edited if ``edit``).

    Returns the directory to put on ``PYTHONPATH`` and the copy's cache directory name.
    """
    copy = tmp_path / name / "cartpole_q"
    shutil.copytree(numba_cache.PACKAGE_DIR, copy, ignore=shutil.ignore_patterns("__pycache__"))
    if edit is not None:
        tabular = copy / "rl" / "tabular.py"
        tabular.write_text(tabular.read_text() + f"\n# {edit}\n")
    digest = hashlib.sha256()
    for module in numba_cache.compiled_modules():
        digest.update(module.encode())
        digest.update((copy / module).read_bytes())
    return copy.parent, f"numba-{digest.hexdigest()[:16]}"


def _wait_for_compiled_code(directory: Path, process: subprocess.Popen[str]) -> set[Path]:
    """The compiled functions saved in ``directory``, once ``process`` has saved one."""
    deadline = time.monotonic() + 120
    while not (saved := set(directory.rglob("*.nbi"))):
        if process.poll() is not None:
            pytest.fail(
                f"the process ended before saving into {directory}: {process.communicate()[1]}"
            )
        assert time.monotonic() < deadline, f"nothing was saved into {directory}"
        time.sleep(0.02)
    return saved


@pytest.mark.slow
def test_two_versions_side_by_side_keep_each_others_cache(tmp_path: Path) -> None:
    """A release and a clone on one machine: each starts while the other trains (issue 29)."""
    xdg = tmp_path / "xdg"
    environment = {key: value for key, value in os.environ.items() if key != "NUMBA_CACHE_DIR"}
    environment["XDG_CACHE_HOME"] = str(xdg)
    # The gymnasium engine compiles a few small functions: seconds, not the whole loop.
    config = write_yaml(tmp_path / "quick.yaml", {"name": "quick", "engine": "gymnasium"})

    def train(version: Path, out: str) -> subprocess.Popen[str]:
        command = ["train", "-c", config, "--episodes", "30", "-q", "--out", tmp_path / out]
        return subprocess.Popen(
            [sys.executable, "-m", "cartpole_q", *map(str, command)],
            cwd=version,  # not this checkout: ``-m`` puts the working directory first
            env={**environment, "PYTHONPATH": str(version)}, text=True,
            stdout=subprocess.PIPE, stderr=subprocess.PIPE,
        )  # fmt: skip

    release, release_cache = _version_copy(tmp_path, "release", edit=None)
    clone, clone_cache = _version_copy(tmp_path, "clone", edit="an edited clone")
    root = xdg / "cartpole-q"
    assert release_cache != clone_cache
    # The clone starts once the release has saved compiled code and while it goes on
    # compiling and training (the old code deleted the release's directory there); then the
    # release starts again while the clone trains.
    processes = [train(release, "run-release")]
    saved = _wait_for_compiled_code(root / release_cache, processes[0])
    processes.append(train(clone, "run-clone"))
    saved |= _wait_for_compiled_code(root / clone_cache, processes[1])
    processes.append(train(release, "run-release-again"))
    for process in processes:
        _, stderr = process.communicate(timeout=300)
        assert process.returncode == 0, stderr
    assert (root / release_cache).is_dir() and (root / clone_cache).is_dir()
    assert {path for path in saved if not path.exists()} == set()
