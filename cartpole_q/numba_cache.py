"""Where numba keeps compiled code: a cache directory keyed by this package's source.

numba invalidates a cached function only when the function's own file changes, not when
a function it inlines from another file does (the engines inline ``agent.py``). A stale
cache would silently run old code, and the two engines would no longer agree. So every
version of the package's source gets its own directory,
``$XDG_CACHE_HOME/cartpole-q/numba-<hash of the source files>`` (``~/.cache`` by default),
unless the user chose one with ``NUMBA_CACHE_DIR``.

Every module that defines ``cache=True`` functions calls :func:`configure` before them.
"""

from __future__ import annotations

import hashlib
import os
import tempfile
from functools import cache
from pathlib import Path

PACKAGE_DIR = Path(__file__).resolve().parent


@cache
def source_digest() -> str:
    """A short hash of every Python file of the package."""
    digest = hashlib.sha256()
    for path in sorted(PACKAGE_DIR.rglob("*.py")):
        digest.update(path.relative_to(PACKAGE_DIR).as_posix().encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()[:16]


def cache_dir() -> Path:
    """The numba cache directory for this source."""
    root = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return root / "cartpole-q" / f"numba-{source_digest()}"


@cache
def configure() -> None:
    """Point numba's cache at :func:`cache_dir` (unless ``NUMBA_CACHE_DIR`` is set)."""
    import numba

    if os.environ.get("NUMBA_CACHE_DIR"):
        return
    directory = cache_dir()
    try:
        directory.mkdir(parents=True, exist_ok=True)
    except OSError:  # no writable home (some CI and container set-ups): a temporary one
        directory = Path(tempfile.gettempdir()) / "cartpole-q" / directory.name
    numba.config.CACHE_DIR = str(directory)  # type: ignore[attr-defined]
