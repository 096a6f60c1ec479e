"""Where numba keeps compiled code: a private cache directory keyed by the compiled source.

numba invalidates a cached function only when the function's own file changes, not when
a function it inlines from another file does (the engines inline ``rl/``, ``envs/``). A stale
cache would silently run old code, and the two engines would no longer agree. So every
version of the compiled modules gets its own directory,
``$XDG_CACHE_HOME/cartpole-q/numba-<hash of the compiled modules>`` (``~/.cache`` by
default), unless the user chose one with ``NUMBA_CACHE_DIR``. Only the modules numba
compiles are hashed (:func:`compiled_modules`): editing the command line costs no
recompilation. Directories of older sources are removed. An algorithm registered from
outside the package is cached under a name holding a digest of its module's source.

numba's cache files are pickles, which numba loads and runs. A cache directory must
therefore belong to the current user and be writable by nobody else: when the home cache
cannot be used, a per-user directory in the temporary directory (mode 0700, owner
checked) is used, and failing that a fresh temporary directory.

Every module that defines ``cache=True`` functions calls :func:`configure` before them.
"""

from __future__ import annotations

import atexit
import hashlib
import os
import shutil
import stat
import tempfile
from functools import cache
from pathlib import Path

PACKAGE_DIR = Path(__file__).resolve().parent

COMPILED_PACKAGES = ("rl", "envs", "engines")
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


def remove_stale_caches(root: Path, keep: Path) -> None:
    """Delete the cache directories of other source versions under ``root``."""
    try:
        entries = list(root.iterdir())
    except OSError:
        return
    for entry in entries:
        if entry.name.startswith(_PREFIX) and entry != keep and is_private_directory(entry):
            shutil.rmtree(entry, ignore_errors=True)


def choose_cache_dir() -> Path:
    """The private directory numba should cache into (see the module docstring)."""
    directory = cache_dir()
    if _private_directory(directory.parent) and _private_directory(directory):
        remove_stale_caches(directory.parent, directory)
        return directory
    fallback = Path(tempfile.gettempdir()) / f"cartpole-q-{os.getuid()}" / directory.name
    if _private_directory(fallback.parent) and _private_directory(fallback):
        remove_stale_caches(fallback.parent, fallback)
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
    Used to say, before a first run compiles for seconds, that it is compiling.
    """
    configure()
    import numba

    root = Path(os.environ.get("NUMBA_CACHE_DIR") or numba.config.CACHE_DIR)  # type: ignore[attr-defined]
    try:
        return any(root.rglob(f"*.{function_name}-*.nbi"))
    except OSError:
        return False
