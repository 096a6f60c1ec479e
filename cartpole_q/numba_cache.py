"""Where numba keeps compiled code: a private cache directory keyed by the compiled source.

numba invalidates a cached function only when the function's own file changes, not when
a function it inlines from another file does (the engines inline ``rl/``, ``envs/``). A stale
cache would silently run old code, and the two engines would no longer agree. So every
version of the compiled modules gets its own directory,
``$XDG_CACHE_HOME/cartpole-q/numba-<hash of the compiled modules>`` (``~/.cache`` by
default), unless the user chose one with ``NUMBA_CACHE_DIR``. Only the modules numba
compiles are hashed (:func:`compiled_modules`): editing the command line costs no
recompilation. An algorithm registered from outside the package is cached under a name
holding a digest of its module's source.

Several versions share the cache root (a release and a clone, two virtual environments, CI
beside a working copy), so a directory of another version may be in use right now, and
removing it under a running process loses its compiled code (or fails it). Every process
marks the directory it uses: it touches the stamp file ``last-used`` in it at start and
holds a shared ``flock`` on its ``in-use.lock`` until it exits (the kernel releases it,
however the process ends; forked workers share it). The directory of another version is
removed only when **no process holds it** and either it has been **unused for
30 days** (:data:`UNUSED_DAYS`) or all the versions' caches together exceed **1 GiB**
(:data:`MAX_TOTAL_BYTES`; the least recently used go first, never the current one). A
process looks at other versions at most **once a day** (:data:`PRUNE_INTERVAL_SECONDS`,
the root's ``last-pruned`` stamp), under an exclusive lock on the root's ``prune.lock``
that starting processes take shared while they create and mark their directory; a
directory is removed only under an exclusive lock on its ``in-use.lock``, which a live
user's shared lock refuses. Removing never fails the process, follows no symbolic link
and touches only directories that are private to the user.

numba's cache files are pickles, which numba loads and runs. A cache directory must
therefore belong to the current user and be writable by nobody else: when the home cache
cannot be used, a per-user directory in the temporary directory (mode 0700, owner
checked) is used, and failing that a fresh temporary directory.

Every module that defines ``cache=True`` functions calls :func:`configure` before them.
"""

from __future__ import annotations

import atexit
import contextlib
import hashlib
import os
import shutil
import stat
import tempfile
import time
from collections.abc import Iterator
from functools import cache
from pathlib import Path

PACKAGE_DIR = Path(__file__).resolve().parent

COMPILED_PACKAGES = ("rl", "families", "envs", "engines")
"""the subpackages whose functions numba compiles, or whose constants and functions the
compiled code inlines: every module in them is hashed (and ``config/schema.py``)"""


def compiled_modules() -> tuple[str, ...]:
    """The modules, relative to the package, whose sources key the cache directory."""
    found = ["config/schema.py"]
    for package in COMPILED_PACKAGES:
        found.extend(
            str(path.relative_to(PACKAGE_DIR))
            for path in sorted((PACKAGE_DIR / package).rglob("*.py"))
        )
    return tuple(found)


_PREFIX = "numba-"

UNUSED_DAYS = 30
"""a cache directory of another source version that no process has used for this many
days is removed"""

MAX_TOTAL_BYTES = 1 << 30
"""when the cache directories of all versions together hold more bytes than this, other
versions' directories are removed, the least recently used first (the default config's
compiled code takes under 1 MB)"""

PRUNE_INTERVAL_SECONDS = 24 * 3600
"""the most often a process looks for other versions' directories to remove"""

LAST_USED_FILE = "last-used"
"""the stamp file in a cache directory: its modification time is the directory's last use"""

IN_USE_LOCK_FILE = "in-use.lock"
"""the file in a cache directory that every process using it holds a shared ``flock`` on"""

_PRUNE_LOCK_FILE = "prune.lock"
"""in the cache root: pruners hold it exclusively, starting processes shared"""

_LAST_PRUNED_FILE = "last-pruned"
"""in the cache root: its modification time is the last look at other versions"""

_START_PATIENCE_SECONDS = 10.0
"""how long a starting process waits for a pruner to finish before going on unprotected"""


@cache
def source_digest() -> str:
    """A short hash of the modules numba compiles."""
    digest = hashlib.sha256()
    for name in compiled_modules():
        digest.update(name.encode())
        digest.update((PACKAGE_DIR / name).read_bytes())
    return digest.hexdigest()[:16]


def cache_root() -> Path:
    """The directory that holds this package's numba caches (one per source version)."""
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "cartpole-q"


def cache_dir() -> Path:
    """The numba cache directory for this source."""
    return cache_root() / f"{_PREFIX}{source_digest()}"


def is_private_directory(path: Path) -> bool:
    """Whether ``path`` is a real directory owned by this user that nobody else may write.

    Symbolic links are refused: another user could point one at their own directory.
    """
    try:
        info = path.lstat()
    except OSError:
        return False
    return (
        stat.S_ISDIR(info.st_mode)
        and info.st_uid == os.getuid()
        and not info.st_mode & (stat.S_IWGRP | stat.S_IWOTH)
    )


def _private_directory(path: Path) -> Path | None:
    """Create ``path`` (mode 0700) if needed; return it if it is private, else ``None``."""
    try:
        path.mkdir(mode=0o700, parents=True, exist_ok=True)
    except OSError:
        return None
    return path if is_private_directory(path) and os.access(path, os.W_OK) else None


def _fresh_temporary_directory() -> Path:
    """A new private directory, removed when the process exits."""
    path = Path(tempfile.mkdtemp(prefix="cartpole-q-numba-"))
    atexit.register(shutil.rmtree, path, ignore_errors=True)
    return path


def _open_lock_file(path: Path) -> int | None:
    """A descriptor of the lock file ``path`` (created if needed), or ``None``.

    A symbolic link is refused (``O_NOFOLLOW``), and exec'd children do not inherit it.
    """
    try:
        return os.open(path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_CLOEXEC, 0o600)
    except OSError:
        return None


def _try_lock(descriptor: int, *, exclusive: bool) -> bool:
    """Take ``flock`` on ``descriptor`` without waiting; whether it was taken."""
    import fcntl  # POSIX only, like os.getuid above

    operation = fcntl.LOCK_EX if exclusive else fcntl.LOCK_SH
    try:
        fcntl.flock(descriptor, operation | fcntl.LOCK_NB)
    except OSError:
        return False
    return True


_held: dict[Path, int] = {}
"""the ``in-use.lock`` descriptors this process holds shared, open until it exits"""


def mark_in_use(directory: Path) -> None:
    """Stamp ``directory`` as used now and hold its shared lock until this process exits.

    While the lock is held, no process removes the directory (:func:`remove_stale_caches`).
    Never raises: an unmarked directory is still kept for :data:`UNUSED_DAYS` after its
    last stamp.
    """
    with contextlib.suppress(OSError):
        (directory / LAST_USED_FILE).touch(mode=0o600)
    if directory in _held:
        return
    descriptor = _open_lock_file(directory / IN_USE_LOCK_FILE)
    if descriptor is None:
        return
    if _try_lock(descriptor, exclusive=False):
        _held[directory] = descriptor  # never closed: the kernel releases it at exit
    else:
        os.close(descriptor)


@contextlib.contextmanager
def _starting(root: Path) -> Iterator[None]:
    """No pruner runs under ``root`` inside the block (waiting a little for one to end).

    A process creates and marks its directory inside, so that a pruner cannot remove it
    between the two. A pruner that does not end within ``_START_PATIENCE_SECONDS`` (a
    hung file system) is not waited for further: starting matters more.
    """
    descriptor = _open_lock_file(root / _PRUNE_LOCK_FILE)
    deadline = time.monotonic() + _START_PATIENCE_SECONDS
    while descriptor is not None and not _try_lock(descriptor, exclusive=False):
        if time.monotonic() >= deadline:
            break
        time.sleep(0.02)
    try:
        yield
    finally:
        if descriptor is not None:
            os.close(descriptor)


def _modified(path: Path) -> float | None:
    """The modification time of ``path`` (not following a link), or ``None``."""
    try:
        return path.lstat().st_mtime
    except OSError:
        return None


def _last_used(directory: Path) -> float:
    """When ``directory`` was last used: its stamp's time, else (older releases) its own."""
    for path in (directory / LAST_USED_FILE, directory):
        moment = _modified(path)
        if moment is not None:
            return moment
    return 0.0


def _size(directory: Path) -> int:
    """The bytes of the files under ``directory`` (links are not followed)."""
    total = 0
    for parent, _, files in os.walk(directory):
        for name in files:
            with contextlib.suppress(OSError):
                total += os.lstat(os.path.join(parent, name)).st_size
    return total


def _remove_if_unused(directory: Path) -> bool:
    """Remove ``directory`` unless a live process holds its lock; whether it is gone."""
    descriptor = _open_lock_file(directory / IN_USE_LOCK_FILE)
    if descriptor is None:
        return False
    try:
        if not _try_lock(descriptor, exclusive=True):
            return False  # a live process uses it
        shutil.rmtree(directory, ignore_errors=True)  # refuses a link; never follows one
    finally:
        os.close(descriptor)
    return not directory.exists()


def remove_stale_caches(root: Path, keep: Path) -> list[Path]:
    """Remove the cache directories of other source versions under ``root`` nobody uses.

    The policy is the module docstring's: a directory no process holds is removed when it
    has been unused for :data:`UNUSED_DAYS`, or, the least recently used first, while all
    the caches under ``root`` exceed :data:`MAX_TOTAL_BYTES`. ``keep`` (the current
    version's) is never removed, nor anything but private directories named ``numba-*``.
    When another process is pruning or starting, nothing is done (a later start will).

    Args:
        root: the cache root (holding one ``numba-<digest>`` directory per version).
        keep: the current version's directory.

    Returns:
        The directories removed.
    """
    lock = _open_lock_file(root / _PRUNE_LOCK_FILE)
    if lock is None:
        return []
    try:
        if not _try_lock(lock, exclusive=True):
            return []
        with contextlib.suppress(OSError):
            (root / _LAST_PRUNED_FILE).touch(mode=0o600)
        return _prune(root, keep)
    finally:
        os.close(lock)


def _prune(root: Path, keep: Path) -> list[Path]:
    """:func:`remove_stale_caches`' work, under the root's exclusive lock."""
    try:
        entries = sorted(root.iterdir())
    except OSError:
        return []
    others = {
        entry: _last_used(entry)
        for entry in entries
        if entry.name.startswith(_PREFIX) and entry != keep and is_private_directory(entry)
    }
    unused_since = time.time() - UNUSED_DAYS * 24 * 3600
    removed = [
        entry for entry, used in others.items() if used < unused_since and _remove_if_unused(entry)
    ]
    remaining = {entry: used for entry, used in others.items() if entry not in removed}
    sizes = {entry: _size(entry) for entry in remaining}
    total = _size(keep) + sum(sizes.values())
    for entry in sorted(remaining, key=remaining.__getitem__):
        if total <= MAX_TOTAL_BYTES:
            break
        if _remove_if_unused(entry):
            removed.append(entry)
            total -= sizes[entry]
    return removed


def _prune_if_due(root: Path, keep: Path) -> None:
    """:func:`remove_stale_caches`, if the last look is older than the interval."""
    last = _modified(root / _LAST_PRUNED_FILE)
    if last is None or time.time() - last >= PRUNE_INTERVAL_SECONDS:
        remove_stale_caches(root, keep)


def _use(directory: Path) -> bool:
    """Create (if needed), mark and hold ``directory``; whether it is usable and private."""
    root = directory.parent
    if not _private_directory(root):
        return False
    with _starting(root):
        if not _private_directory(directory):
            return False
        mark_in_use(directory)
    _prune_if_due(root, directory)
    return True


def choose_cache_dir() -> Path:
    """The private directory numba should cache into (see the module docstring)."""
    directory = cache_dir()
    if _use(directory):
        return directory
    fallback = Path(tempfile.gettempdir()) / f"cartpole-q-{os.getuid()}" / directory.name
    if _use(fallback):
        return fallback
    return _fresh_temporary_directory()


@cache
def configure() -> None:
    """Point numba's cache at :func:`choose_cache_dir` (unless ``NUMBA_CACHE_DIR`` is set)."""
    import warnings

    import numba
    from numba.core.errors import NumbaIRAssumptionWarning

    # numba's own "pedantic check" warns about the functions that overloads inline (see
    # rl.algorithms and envs.registry); the compiled code is correct (the golden-hash and
    # cross-engine tests check it), and users cannot act on the warning.
    warnings.filterwarnings("ignore", category=NumbaIRAssumptionWarning)
    if os.environ.get("NUMBA_CACHE_DIR"):
        return
    numba.config.CACHE_DIR = str(choose_cache_dir())  # type: ignore[attr-defined]


def is_cached(function_name: str) -> bool:
    """Whether numba's cache holds compiled code of a function named ``function_name``.

    numba names a cached function's index ``<module>.<name>-<line>.py<version>.nbi``.
    Used to say, before a first run compiles for seconds, that it is compiling. A name once
    found is remembered for the process (a sweep's worker asks before each of its runs, and
    the directory this process uses is never pruned while it runs).
    """
    if function_name in _found:
        return True
    configure()
    import numba

    root = Path(os.environ.get("NUMBA_CACHE_DIR") or numba.config.CACHE_DIR)  # type: ignore[attr-defined]
    try:
        found = any(root.rglob(f"*.{function_name}-*.nbi"))
    except OSError:
        return False
    if found:
        _found.add(function_name)
    return found


_found: set[str] = set()
"""the names :func:`is_cached` has found in this process"""
