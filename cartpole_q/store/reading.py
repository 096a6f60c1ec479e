"""Reading files back, bounded: JSON, ``.npy`` arrays and ``.npz`` archives.

A file read back (a run's ``summary.json`` or ``q_table.npy``, a sweep point's
``q_tables.npz``, a checkpoint) may have been edited by hand or come from someone else.
Its reader trusts nothing the file says about itself beyond what it holds:

- JSON: at most :data:`MAX_JSON_BYTES`, nested at most :data:`MAX_JSON_DEPTH` deep (a
  file of ten thousand ``[`` would exhaust Python's stack in any reader);
- ``.npy``: the header is read first, and the array is allocated only once its dtype is
  a plain one (no Python objects), its shape passes the caller's check (the shape the
  config implies), and the bytes it declares are the bytes the file holds, so a header
  that declares a shape of a hundred terabytes is refused, not allocated;
- ``.npz``: each member as an ``.npy``, and a compressed member may not declare more
  bytes than its compressed size can expand to (:data:`MAX_DEFLATE_RATIO`).

Every refusal is a :class:`~cartpole_q.errors.RunError` naming the file.
"""

from __future__ import annotations

import io
import json
import math
import os
import zipfile
from collections.abc import Callable
from pathlib import Path
from typing import IO, Any

import numpy as np

from cartpole_q.config import shorten
from cartpole_q.errors import RunError

MAX_JSON_BYTES = 64 * 2**20
"""the largest JSON file read (a summary of 10,000 seeds is a few megabytes)"""
MAX_JSON_DEPTH = 64
"""the deepest a JSON file may nest arrays and objects (a summary nests four levels)"""
MAX_DEFLATE_RATIO = 1032
"""the most deflate can expand its input (zlib's technical details); a member claiming
more than this times its compressed size claims bytes it cannot hold"""
NPY_MAGIC = b"\x93NUMPY"
"""the first bytes of every ``.npy`` file"""

ShapeCheck = Callable[[str, np.dtype[Any], tuple[int, ...]], None]
"""``check(where, dtype, shape)``: raise :class:`RunError` for an array that cannot be
the one expected, before it is allocated (``where`` names the file or member)"""


# -- JSON -------------------------------------------------------------------------------


def read_json(path: Path) -> object:
    """A JSON file's value, bounded in size and depth.

    Returns:
        The value, or ``None`` when the file does not exist.

    Raises:
        RunError: the file is larger than :data:`MAX_JSON_BYTES`, not UTF-8, not JSON, or
            nested deeper than :data:`MAX_JSON_DEPTH`.
    """
    try:
        with path.open("rb") as stream:
            content = stream.read(MAX_JSON_BYTES + 1)
    except FileNotFoundError:
        return None
    except NotADirectoryError:
        raise RunError(
            f"{path.parent}: is a file, but a run directory was expected here."
        ) from None
    except IsADirectoryError:
        raise RunError(f"{path}: is a directory, not a JSON file.") from None
    except OSError as error:
        raise RunError(f"{path}: cannot be read ({error.strerror}).") from None
    if len(content) > MAX_JSON_BYTES:
        raise RunError(
            f"{path}: is larger than {MAX_JSON_BYTES // 2**20} MiB, more than cartpole-q "
            "ever writes there; it is not one of its files."
        )
    try:
        value = json.loads(content.decode("utf-8"))
    except RecursionError:
        raise _too_deep(path) from None
    except (UnicodeDecodeError, json.JSONDecodeError) as error:
        raise RunError(f"{path}: is not valid JSON ({shorten(str(error))}).") from None
    if _depth(value) > MAX_JSON_DEPTH:
        raise _too_deep(path)
    return value


def _too_deep(path: Path) -> RunError:
    return RunError(
        f"{path}: nests arrays and objects more than {MAX_JSON_DEPTH} levels deep; it is "
        "not a file cartpole-q wrote."
    )


def _depth(value: object) -> int:
    """How deep arrays and objects nest in a JSON value (a scalar is 0), iteratively."""
    deepest = 0
    stack: list[tuple[object, int]] = [(value, 0)]
    while stack:
        item, depth = stack.pop()
        if isinstance(item, dict):
            item = list(item.values())
        if isinstance(item, list):
            deepest = max(deepest, depth + 1)
            if deepest > MAX_JSON_DEPTH:
                return deepest  # no need to walk the rest
            stack.extend((child, depth + 1) for child in item)
    return deepest


# -- .npy and .npz ------------------------------------------------------------------------


def load_npy(path: Path, dtype: type | None = None, check: ShapeCheck | None = None) -> np.ndarray:
    """Load an ``.npy`` file without pickle, its header checked before anything is allocated.

    Args:
        path: the file.
        dtype: the dtype the array must have (``None``: any plain dtype).
        check: called with the header's dtype and shape before the array is allocated.

    Raises:
        RunError: the file is missing or unreadable, not an ``.npy`` file, an array of
            Python objects or of another dtype, refused by ``check``, or its header
            declares more or fewer bytes than the file holds.
    """
    if not path.exists():
        raise RunError(f"{path}: is missing.")
    if not path.is_file():
        kind = "a directory" if path.is_dir() else "not a regular file"
        raise RunError(f"{path}: is {kind}, but a .npy array file is expected here.")
    try:
        with path.open("rb") as stream:
            size = os.fstat(stream.fileno()).st_size
            return _read_npy(stream, size, str(path), dtype, check)
    except OSError as error:
        raise RunError(f"{path}: cannot be read ({error.strerror or error}).") from None


def load_npz(
    source: Path | bytes,
    where: str,
    dtype: type | None = None,
    check: ShapeCheck | None = None,
) -> dict[str, np.ndarray]:
    """Every array of an ``.npz`` archive by name, each member read as :func:`load_npy` does.

    Args:
        source: the archive's file, or its bytes (a checkpoint a worker sent back).
        where: how errors name the archive.
        dtype: the dtype every member must have (``None``: any plain dtype).
        check: called for each member (``where`` then names the archive and the member).

    Raises:
        RunError: the archive is not a zip file, or a member cannot be read as an array
            as :func:`load_npy` says, or claims more bytes than its compressed size holds.
    """
    try:
        size = len(source) if isinstance(source, bytes) else source.stat().st_size
        opened = io.BytesIO(source) if isinstance(source, bytes) else source.open("rb")
        with opened as stream, zipfile.ZipFile(stream) as archive:
            arrays = {}
            for info in archive.infolist():
                name = info.filename.removesuffix(".npy")
                member = f"{where}: {shorten(name)}"
                _check_member_size(info, size, member)
                with archive.open(info) as data:
                    arrays[name] = _read_npy(data, info.file_size, member, dtype, check)
            return arrays
    except RunError:
        raise
    except (OSError, EOFError, zipfile.BadZipFile, NotImplementedError, ValueError) as error:
        # ValueError: zipfile's for a damaged directory; NotImplementedError: a compression
        # method zipfile lacks.
        raise RunError(
            f"{where}: is not a readable .npz archive ({shorten(str(error))})."
        ) from None


def _check_member_size(info: zipfile.ZipInfo, archive_size: int, where: str) -> None:
    """Refuse a member whose declared sizes its archive's bytes cannot hold."""
    stored = info.compress_type == zipfile.ZIP_STORED
    most = info.compress_size if stored else info.compress_size * MAX_DEFLATE_RATIO
    if info.compress_size > archive_size or info.file_size > most:
        raise RunError(
            f"{where}: declares {info.file_size:,} bytes, more than the archive's "
            f"{archive_size:,} bytes can hold; the file is damaged or not cartpole-q's."
        )


def _read_npy(
    stream: IO[bytes], size: int, where: str, dtype: type | None, check: ShapeCheck | None
) -> np.ndarray:
    """The array of an ``.npy`` stream of ``size`` bytes, its header checked first."""
    if stream.read(len(NPY_MAGIC)) != NPY_MAGIC:
        raise RunError(
            f"{where}: is not a NumPy array file (.npy); it was not written by cartpole-q."
        )
    try:
        version = (stream.read(1)[0], stream.read(1)[0])
        if version == (1, 0):
            shape, fortran_order, found = np.lib.format.read_array_header_1_0(stream)
        elif version == (2, 0):
            shape, fortran_order, found = np.lib.format.read_array_header_2_0(stream)
        else:
            raise ValueError(
                f"format version {version[0]}.{version[1]} is not one np.save writes for numbers"
            )
    except (ValueError, IndexError, SyntaxError) as error:
        raise RunError(f"{where}: is not a valid .npy array ({shorten(str(error))}).") from None
    if found.hasobject:
        raise RunError(f"{where}: holds Python objects; only numeric arrays are accepted.")
    if dtype is not None and found != np.dtype(dtype):
        raise RunError(f"{where}: must hold {np.dtype(dtype).name} values, found {found}.")
    if check is not None:
        check(where, found, shape)
    count = math.prod(shape)
    declared = count * found.itemsize
    held = size - stream.tell()
    if declared != held:
        raise RunError(
            f"{where}: its header declares shape {shape} ({declared:,} bytes of data), but "
            f"it holds {held:,} bytes; the file is truncated or damaged."
        )
    array = np.empty(count, dtype=found)
    buffer = array.view(np.uint8).data
    done = 0
    while done < declared:
        got = stream.readinto(buffer[done:])  # type: ignore[attr-defined]
        if not got:
            raise RunError(f"{where}: ends before its {declared:,} bytes of data; it is truncated.")
        done += got
    if fortran_order:
        return array.reshape(shape[::-1]).transpose()
    return array.reshape(shape)
