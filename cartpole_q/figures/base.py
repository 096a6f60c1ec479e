"""What every figure shares.

The data a figure carries (:class:`DataFigure`), its sizes and colours, the resolution a
long line is drawn at, and the file formats a figure is written in.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

DPI = 100


CURVE_SIZE = (8.0, 4.5)
"""inches; at 100 dpi a reward curve is 800 x 450 pixels"""


DRAWN_POINTS = 1_000
"""the most points a long line keeps along its x axis, drawn and in its data: a figure 8
inches wide at 100 dpi has 800 pixel columns, so more points draw nothing more (the full
record stays in the run or study directory; ``plot --all-points`` draws every point)"""


POLICY_SIZE = (13.5, 4.2)
"""inches; at 100 dpi a policy map is 1350 x 420 pixels"""


BOOTSTRAP_RESAMPLES = 1000


FIGURE_FORMATS = {".png": "png", ".svg": "svg", ".pdf": "pdf"}
"""the extensions ``plot --out`` writes, and matplotlib's format for each"""


DATA_COLUMNS = ("panel", "series", "x", "y", "y_low", "y_high", "value")
"""the columns of a figure's data, ``<figure>.csv``"""


Cell = float | int | str | None
"""one value of a figure's data: a number, a category (a sweep axis's value), or nothing"""


class FigureData:
    """The numbers a figure draws, in the tidy long format of ``<figure>.csv``.

    One row per plotted point, columns :data:`DATA_COLUMNS`: the ``panel`` (its title; empty
    on a one-panel figure), the ``series`` (a curve, a band, a line or a map, named as its
    legend names it), the point's ``x`` and ``y``, the interval drawn around it (``y_low``,
    ``y_high``, empty where none is drawn); a coloured cell (a heatmap, a policy map) is a
    row with ``x``, ``y`` and its ``value``. A horizontal reference line is one row with an
    empty ``x``, a vertical one a row with an empty ``y``. Numbers are written with
    ``repr``, so they read back as the very floats drawn; a value not drawn (NaN, a masked
    cell) is an empty cell. Rows keep the order the figure draws them in.

    >>> data = FigureData()
    >>> data.panel("").line("mean", [1, 2], [0.5, float("nan")], low=[0.25, None], high=[1.0, None])
    >>> data.panel("").level("threshold", 475.0)
    >>> print(data.csv_text(), end="")
    panel,series,x,y,y_low,y_high,value
    ,mean,1,0.5,0.25,1.0,
    ,mean,2,,,,
    ,threshold,,475.0,,,
    """

    def __init__(self) -> None:
        self.rows: list[tuple[str, str, Cell, Cell, Cell, Cell, Cell]] = []

    def panel(self, name: str) -> PanelData:
        """A recorder for the panel titled ``name`` (``""``: the figure's only panel)."""
        return PanelData(self, name)

    def csv_text(self) -> str:
        """The rows as CSV text (Unix line ends), the header first."""
        buffer = io.StringIO()
        writer = csv.writer(buffer, lineterminator="\n")
        writer.writerow(DATA_COLUMNS)
        labels: dict[str, str] = {}

        def cell(value: Cell) -> str:
            # The common cells first, without _data_cell's checks: a long run's curve has
            # millions (a float64 is a float: its repr is the float's).
            kind = type(value)
            if kind is float or kind is np.float64:
                return float.__repr__(value) if value == value else ""
            if isinstance(value, str):
                if value not in labels:
                    labels[value] = _data_cell(value)
                return labels[value]
            return _data_cell(value)

        writer.writerows([cell(value) for value in row] for row in self.rows)
        return buffer.getvalue()


@dataclass(frozen=True)
class PanelData:
    """What one panel of a figure draws, recorded into its :class:`FigureData`."""

    data: FigureData
    name: str

    def line(
        self,
        series: str,
        x: Iterable[Cell],
        y: Iterable[Cell],
        low: Iterable[Cell] | None = None,
        high: Iterable[Cell] | None = None,
    ) -> None:
        """Points of a curve (a band's centre with its ``low`` and ``high`` edges), in order."""
        xs, ys = list(x), list(y)
        lows = [None] * len(xs) if low is None else list(low)
        highs = [None] * len(xs) if high is None else list(high)
        rows = zip(xs, ys, lows, highs, strict=True)
        self.data.rows.extend((self.name, series, a, b, c, d, None) for a, b, c, d in rows)

    def level(self, series: str, y: float) -> None:
        """A horizontal line at ``y`` (a threshold, a reference): ``x`` stays empty."""
        self.data.rows.append((self.name, series, None, y, None, None, None))

    def mark(self, series: str, x: float) -> None:
        """A vertical line at ``x`` (a solve episode, a trained value): ``y`` stays empty."""
        self.data.rows.append((self.name, series, x, None, None, None, None))

    def cells(self, series: str, x: Sequence[Cell], y: Sequence[Cell], values: np.ndarray) -> None:
        """A map: ``values[i, j]`` coloured at ``(x[j], y[i])``, row by row; masked: empty.

        Integer values (actions, counts) stay integers.
        """
        shown = np.ma.asarray(values)
        if shown.dtype.kind == "f":
            shown = np.ma.masked_invalid(shown)
        if shown.shape != (len(y), len(x)):
            raise ValueError(f"cells: values of shape {shown.shape} for {len(y)} x {len(x)}")
        mask = np.ma.getmaskarray(shown)
        for i, row_y in enumerate(y):
            for j, column_x in enumerate(x):
                value = None if mask[i, j] else shown.data[i, j].item()
                self.data.rows.append((self.name, series, column_x, row_y, None, None, value))


def _data_cell(value: Cell) -> str:
    """A value as a CSV cell: floats round-trip (``repr``), NaN and ``None`` are empty.

    Text is written as the figure draws it (:func:`drawable`: an undecodable file name's
    bytes become U+FFFD), so the data is UTF-8 whatever the directory's name.

    >>> _data_cell(0.1), _data_cell(np.float64(2.5)), _data_cell(np.int64(3)), _data_cell(None)
    ('0.1', '2.5', '3', '')
    >>> _data_cell(float("nan")), _data_cell("0.5")
    ('', '0.5')
    """
    if value is None:
        return ""
    if isinstance(value, str):  # a label naming a directory: as the figure draws it
        return drawable(value)
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    number = float(value)
    return "" if np.isnan(number) else repr(number)


class DataFigure(Figure):
    """A matplotlib figure that carries the numbers it draws (``data``), for its ``.csv``."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.data = FigureData()


def drawn_points(count: int, log: bool = False, most: int | None = DRAWN_POINTS) -> np.ndarray:
    """The indices of a line's ``count`` points that are drawn, and written as its data.

    Every point when there are at most ``most`` (or ``most`` is ``None``); else ``most``
    evenly spaced along the axis, log-spaced on a log axis (whose x are 1, 2, ..., as
    episodes are), the first and the last always kept.

    >>> drawn_points(5).tolist(), drawn_points(10, most=4).tolist()
    ([0, 1, 2, 3, 4], [0, 3, 6, 9])
    >>> drawn_points(100_000, log=True)[:12].tolist(), int(drawn_points(100_000, log=True)[-1])
    ([0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11], 99999)
    """
    if most is None or count <= most:
        return np.arange(count)
    spaced = np.geomspace(1.0, count, most) if log else np.linspace(1.0, count, most)
    return np.unique(np.rint(spaced).astype(np.int64)) - 1


def drawable(text: str) -> str:
    r"""``text`` as a font can draw it: undecodable file-name bytes become U+FFFD.

    A directory name that is not UTF-8 (``--out $'bad\xffname'``) reaches Python as a
    string with surrogate escapes, which matplotlib cannot lay out; titles and labels
    name run directories, so every text of a figure goes through this before rendering.

    >>> drawable("bad\udcffname") == "bad\ufffdname", drawable("seed 3")
    (True, 'seed 3')
    """
    try:
        return text.encode("utf-8", "surrogateescape").decode("utf-8", "replace")
    except UnicodeEncodeError:  # a surrogate that no undecodable byte made
        return text.encode("utf-8", "replace").decode("utf-8")


def _make_drawable(figure: Figure) -> None:
    """Make every text of ``figure`` drawable (see :func:`drawable`)."""
    from matplotlib.text import Text

    for artist in figure.findobj(Text):
        assert isinstance(artist, Text)
        text = artist.get_text()
        if text != drawable(text):
            artist.set_text(drawable(text))


def figure_png(figure: Figure) -> bytes:
    """Render a figure to PNG bytes."""
    _make_drawable(figure)
    canvas = FigureCanvasAgg(figure)
    buffer = io.BytesIO()
    canvas.print_png(buffer)  # type: ignore[no-untyped-call]
    return buffer.getvalue()


def figure_bytes(figure: Figure, file_format: str) -> bytes:
    """Render a figure as ``png``, ``svg`` or ``pdf`` bytes."""
    if file_format == "png":
        return figure_png(figure)
    _make_drawable(figure)
    buffer = io.BytesIO()
    # The date would make every SVG or PDF of the same run differ.
    metadata = {"Date": None}
    figure.savefig(buffer, format=file_format, dpi=DPI, metadata=metadata)
    return buffer.getvalue()


def colour_cycle(count: int) -> list[tuple[float, ...]]:
    """``count`` colours of one qualitative cycle, in order."""
    from matplotlib import colormaps

    if count <= 10:
        palette = colormaps["tab10"]
        return [tuple(palette(i)) for i in range(count)]
    palette = colormaps["turbo"]
    return [tuple(palette(x)) for x in np.linspace(0.05, 0.95, count)]


def cell_square(row: int, column: int, colour: str) -> Any:
    """A square patch covering one grid cell, in ``colour``."""
    from matplotlib.patches import Rectangle

    return Rectangle((column - 0.5, row - 0.5), 1.0, 1.0, color=colour, zorder=2)


def text_outline() -> list[object]:
    """A dark outline that keeps white text readable on any cell colour."""
    from matplotlib import patheffects

    return [patheffects.withStroke(linewidth=2, foreground="black")]
