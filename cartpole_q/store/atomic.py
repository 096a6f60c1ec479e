"""Atomic files: a file is absent, old, or complete, never half written.

Every file is written to a temporary file in the same directory and moved into place with
``os.replace``, so a reader (or a process killed at any instant) never sees half a file.
A write that fails (a full disk, no permission, a read-only file system) raises
:class:`~cartpole_q.errors.WriteError` naming the file, and leaves nothing behind.
"""

from __future__ import annotations

import contextlib
import errno
import io
import json
import os
import secrets
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from cartpole_q.errors import WriteError


def atomic_write_bytes(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` so that ``path`` is either absent, old, or complete.

    The temporary file is created with ``open(..., "xb")`` rather than ``mkstemp`` so
    that it gets the user's usual permissions (umask), not mkstemp's owner-only 0600.

    Raises:
        WriteError: the file cannot be written (``ENOSPC``, ``EACCES``, ``EROFS``,
            ``ENOTDIR``, ...); the temporary file is gone and ``path`` is untouched.
    """
    atomic_write_together([(path, data)])


def atomic_write_together(files: Sequence[tuple[Path, bytes]]) -> None:
    """Write several files (a figure and its data) so that a failure changes none of them.

    Every file is first written whole to its temporary file; only then are they moved into
    place, in the order given. A full disk or a refused write therefore leaves every one
    of them absent or old; only a failing ``os.replace`` (not a matter of space) could
    leave the first ones new and the rest old.

    Raises:
        WriteError: naming the first file that cannot be written; no temporary file is
            left and no file is changed.
    """
    pending: list[tuple[Path, Path]] = []
    path = files[0][0] if files else Path()
    try:
        for path, data in files:
            temporary = path.parent / f".{path.name}.{secrets.token_hex(6)}.tmp"
            with open(temporary, "xb") as stream:
                pending.append((temporary, path))
                stream.write(data)
        for temporary, path in pending:
            os.replace(temporary, path)
    except BaseException as error:
        for temporary, _ in pending:
            with contextlib.suppress(OSError):
                temporary.unlink(missing_ok=True)
        if isinstance(error, OSError):
            raise WriteError(f"{path}: cannot be written: {write_failure(path, error)}.") from None
        raise


def write_failure(path: Path, error: OSError) -> str:
    """Say in words why writing ``path`` failed.

    >>> write_failure(Path("/x/y.png"), OSError(errno.ENOSPC, "No space left on device"))
    'no space is left on the device that holds /x'
    """
    directory = path.parent
    reasons = {
        errno.ENOSPC: f"no space is left on the device that holds {directory}",
        errno.EDQUOT: f"the disk quota of {directory} is used up",
        errno.EACCES: f"permission to write in {directory} is denied",
        errno.EPERM: f"permission to write in {directory} is denied",
        errno.EROFS: f"{directory} is on a read-only file system",
        errno.ENOTDIR: f"{_first_non_directory(directory)} is not a directory",
        errno.EISDIR: "it is a directory",
        errno.ENAMETOOLONG: "the file name is too long",
    }
    if error.errno == errno.ENOENT:
        if directory.is_dir():
            return f"files cannot be created in {directory}"
        return f"the directory {directory} does not exist"
    return reasons.get(error.errno or 0, error.strerror or str(error))


def _first_non_directory(directory: Path) -> Path:
    """The first existing ancestor of ``directory`` (or itself) that is not a directory."""
    for candidate in (*reversed(directory.parents), directory):
        if candidate.exists() and not candidate.is_dir():
            return candidate
    return directory


def check_output_file(path: Path, option: str, suffixes: tuple[str, ...], force: bool) -> str:
    """Check, before any expensive work, that ``path`` can be written as asked.

    Args:
        path: the file a command will write.
        option: the option that named it (for messages), e.g. ``--out``.
        suffixes: the extensions that can be written, lower case with the dot.
        force: whether an existing file may be replaced.

    Returns:
        The file's extension, lower case, one of ``suffixes``.

    Raises:
        WriteError: the extension is not supported, the path is a directory, the file
            exists and ``force`` is not set, or no file can be created in its directory
            (it does not exist, is not a directory, is read-only, ...).
    """
    supported = ", ".join(suffixes)
    suffix = path.suffix.lower()
    if path.is_dir():
        raise WriteError(
            f"{path}: {option} is a directory; give a file name such as {path / ('out' + suffixes[0])}."
        )
    if suffix not in suffixes:
        raise WriteError(
            f"{path}: {option} cannot write {'files ending in ' + suffix if suffix else 'a file without an extension'}; "
            f"give a file name ending in one of {supported}."
        )
    if (path.exists() or path.is_symlink()) and not force:  # a dangling link too
        what = "is a symbolic link" if path.is_symlink() else "already exists"
        raise WriteError(f"{path}: {what}; pass --force to replace it, or choose another name.")
    probe = path.parent / f".{path.name}.{secrets.token_hex(6)}.tmp"
    try:
        with open(probe, "xb"):
            pass
    except OSError as error:
        raise WriteError(f"{path}: cannot be written: {write_failure(path, error)}.") from None
    with contextlib.suppress(OSError):
        probe.unlink()
    return suffix


def make_directory(path: Path) -> None:
    """Create the directory ``path`` (and its parents) unless it exists.

    Raises:
        WriteError: it cannot be created (a full disk, no permission, a file in the way),
            naming it.
    """
    try:
        path.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise WriteError(f"{path}: cannot be created: a file is in the way.") from None
    except OSError as error:
        raise WriteError(f"{path}: cannot be created: {write_failure(path, error)}.") from None


def remove_stale_temporaries(run_dir: Path) -> None:
    """Delete temporary files a killed process left behind (never a finished file)."""
    for temporary in run_dir.glob(".*.tmp"):
        temporary.unlink(missing_ok=True)


def atomic_write_text(path: Path, text: str) -> None:
    """Write UTF-8 text atomically.

    Raises:
        WriteError: the file cannot be written, or ``text`` cannot be UTF-8 (it holds
            an undecodable file name's surrogate escapes).
    """
    try:
        data = text.encode("utf-8")
    except UnicodeEncodeError as error:
        raise WriteError(
            f"{os.fsencode(path).decode('utf-8', 'replace')}: cannot be written: its text "
            f"would hold {error.object[error.start : error.end]!a}, which is not UTF-8 (a "
            "file name that is not UTF-8 text?)."
        ) from None
    atomic_write_bytes(path, data)


def atomic_save_npy(path: Path, array: np.ndarray) -> None:
    """Save one array as ``.npy`` atomically."""
    buffer = io.BytesIO()
    np.save(buffer, array, allow_pickle=False)
    atomic_write_bytes(path, buffer.getvalue())


def write_json(path: Path, data: dict[str, Any]) -> None:
    """Write JSON atomically (indented, ending with a newline)."""
    atomic_write_text(path, json.dumps(data, indent=2) + "\n")
