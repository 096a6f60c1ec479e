"""A figure file and its data: ``<stem>.png`` (or ``.svg``, ``.pdf``) and ``<stem>.csv``.

Every figure the tool writes (a run's ``reward_curve.png``, ``plot``'s figures, a sweep's
``sweep.png`` and its study figure, ``robustness``, ``compare --out``, a tune's
``history.png`` and ``importance.png``) is written by :func:`write_figure`, which writes
the numbers the figure draws beside it as ``<stem>.csv``: one row per plotted point,
columns ``panel,series,x,y,y_low,y_high,value`` (see
:class:`cartpole_q.figures.FigureData`). The two are written together: each whole to a
temporary file first, then both moved into place, so a failed write (a full disk) changes
neither, and a figure on disk has its data beside it.

matplotlib is imported only when a figure is written, not with this module.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from cartpole_q.store.atomic import atomic_write_together, check_output_file

if TYPE_CHECKING:
    from cartpole_q.figures import DataFigure

DATA_SUFFIX = ".csv"


def data_path(figure_path: Path) -> Path:
    """Where a figure's data goes: beside it, as ``<stem>.csv``.

    >>> data_path(Path("runs/a/reward_curve.png")).as_posix()
    'runs/a/reward_curve.csv'
    """
    return figure_path.with_suffix(DATA_SUFFIX)


def check_figure_file(path: Path, option: str, force: bool) -> str:
    """Check, before anything is drawn, that a figure and its data can be written.

    Args:
        path: the figure file (``.png``, ``.svg`` or ``.pdf``).
        option: the option that named it, for messages (``--out``).
        force: whether existing files may be replaced.

    Returns:
        The figure's extension, lower case.

    Raises:
        WriteError: as :func:`~cartpole_q.store.atomic.check_output_file`, for the figure
            or for its ``.csv``.
    """
    from cartpole_q.figures import FIGURE_FORMATS

    suffix = check_output_file(path, option, tuple(FIGURE_FORMATS), force)
    check_output_file(data_path(path), f"{option} (its {DATA_SUFFIX})", (DATA_SUFFIX,), force)
    return suffix


def write_figure(path: Path, figure: DataFigure) -> Path:
    """Write ``figure`` as ``path`` (its format from its extension) and its data beside it.

    Returns:
        ``path``.

    Raises:
        WriteError: either file cannot be written; then neither is changed.
    """
    from cartpole_q.figures import FIGURE_FORMATS, figure_bytes

    image = figure_bytes(figure, FIGURE_FORMATS[path.suffix.lower()])
    # The data's text is UTF-8 whatever the directory's name: its labels are drawn ones.
    data = figure.data.csv_text().encode("utf-8")
    atomic_write_together([(data_path(path), data), (path, image)])
    return path
