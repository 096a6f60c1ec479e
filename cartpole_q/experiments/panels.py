"""A figure of several panels, each a sweep of its own: one study file, one command.

A ``kind: panels`` file names the sweep files whose figures are a book figure's panels
(Sutton & Barto Figure 12.14: Mountain Car, the random walk, the puddle world, pole
balancing, each a sweep of its own task, measure and seeds):

.. code-block:: yaml

    kind: panels
    name: fig12_14
    panels: [fig12_14_mountain_car.yaml, fig12_14_random_walk.yaml]  # beside this file
    columns: 2
    title: "Figure 12.14: ..."
    file: fig12_14.png

The directory holds ``study.yaml`` and one sweep directory per panel,
``panels/<the panel file's name>/``, each claimed when the study starts and run in the
order given, each exactly as ``cartpole-q study`` runs that file alone: its workers, its
backend, its progress, its resume. A stop ends the panel running; ``--resume`` goes on
where it stopped. When every panel is complete, their figures are drawn side by side,
``columns`` to a row, as ``file``, and their data (``<figure>.csv`` of each) follow one
another in ``<file's stem>.csv``, each row's ``panel`` the panel's name (and its own
panel's title after a colon, where it has one).
"""

from __future__ import annotations

import contextlib
import csv
import io
import math
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from cartpole_q.config import ConfigError, shown_value
from cartpole_q.errors import RunError
from cartpole_q.experiments.study import (
    KIND_KEY,
    Options,
    Outcome,
    StudyFile,
    directory_kind,
    kinds,
    read_study_file,
    register_kind,
    study_of,
)
from cartpole_q.experiments.sweep_spec import checked_name, safe_name
from cartpole_q.store import studydir

STUDY_KEYS = ("name", "panels", "columns", "title", "file")
"""the keys of a panels file (beside ``kind``)"""
PANELS_DIR = "panels"
"""the directory of the panels' own study directories"""
PANEL_KIND = "sweep"
"""the kind every panel is"""
PANEL_INCHES = (8.0, 4.5)
"""a panel's size in the composed figure"""


@dataclass(frozen=True)
class Panel:
    """One panel: its name (its file's stem), its file as read, and its sweep."""

    name: str
    study: StudyFile
    spec: Any


@dataclass(frozen=True)
class PanelsSpec:
    """A panels study as read."""

    name: str
    panels: tuple[Panel, ...]
    columns: int
    title: str
    file: str


class PanelsKind:
    """The ``panels`` kind: its panels' sweeps run in turn, their figures drawn as one."""

    name = "panels"
    figure_kinds: tuple[str, ...] = ()

    def read(self, study: StudyFile) -> PanelsSpec:
        """Check the file and each panel's sweep file (each read as ``cartpole-q study`` does).

        Raises:
            ConfigError: naming the file and the key: an unknown key, no panels, a panel
                that is not a sweep file with a figure, two panels of one name, a bad
                ``columns`` or ``file``.
        """
        body = study.body
        where = study.where
        unknown = sorted(set(body) - set(STUDY_KEYS))
        if unknown:
            raise ConfigError(
                f"{where}: {unknown[0]}: is not a key of a panels file ({', '.join(STUDY_KEYS)})."
            )
        listed = body.get("panels")
        if (
            not isinstance(listed, list)
            or not listed
            or not all(isinstance(p, str) for p in listed)
        ):
            raise ConfigError(
                f"{where}: panels: must be a non-empty list of sweep files (paths beside this "
                f"file), got {shown_value(listed)}."
            )
        panels = tuple(self._panel(study, text) for text in listed)
        names = [panel.name for panel in panels]
        twice = next((name for name in names if names.count(name) > 1), None)
        if twice is not None:
            raise ConfigError(
                f"{where}: panels: two panels are named {twice} (each is its file's name)."
            )
        columns = body.get("columns", min(2, len(panels)))
        if isinstance(columns, bool) or not isinstance(columns, int) or columns < 1:
            raise ConfigError(
                f"{where}: columns: must be a whole number of at least 1, got "
                f"{shown_value(columns)}."
            )
        name = checked_name(body, safe_name(study.stem), where)
        title = body.get("title", name)
        file = body.get("file", f"{name}.png")
        for key, value in (("title", title), ("file", file)):
            if not isinstance(value, str) or not value:
                raise ConfigError(f"{where}: {key}: must be text, got {shown_value(value)}.")
        if "/" in file or Path(file).suffix.lower() not in (".png", ".svg", ".pdf"):
            raise ConfigError(
                f"{where}: file: {file!r} must be a file name in the study directory ending "
                "in .png, .svg or .pdf."
            )
        return PanelsSpec(name, panels, min(columns, len(panels)), title, file)

    def _panel(self, study: StudyFile, text: str) -> Panel:
        """One panel's sweep file, read beside the panels file."""
        path = study.base_dir / text
        if not path.is_file():
            raise ConfigError(f"{study.where}: panels: {text}: no such file beside it ({path}).")
        panel = read_study_file(path)
        if panel.kind != PANEL_KIND:
            raise ConfigError(
                f"{study.where}: panels: {text}: is a {panel.kind} study; a panel is a sweep "
                "file with a figure."
            )
        if not isinstance(panel.raw.get("figure"), Mapping):
            raise ConfigError(
                f"{study.where}: panels: {text}: has no figure section; a panel is a sweep "
                "file with a figure."
            )
        return Panel(path.stem, panel, kinds()[PANEL_KIND].read(panel))

    def describe(self, spec: PanelsSpec) -> tuple[int, str]:
        """Every panel's runs, and what each panel is."""
        sweep = kinds()[PANEL_KIND]
        described = [sweep.describe(panel.spec) for panel in spec.panels]
        total = sum(runs for runs, _ in described)
        each = "; ".join(f"{panel.name}: {what}" for panel, (_, what) in zip(
            spec.panels, described, strict=True))  # fmt: skip
        return total, f"a panels study of {len(spec.panels)} sweeps, {total:,} runs in all ({each})"

    @contextlib.contextmanager
    def start(self, spec: PanelsSpec, study: StudyFile, out: Path | None) -> Iterator[Path]:
        """Claim the directory, write ``study.yaml`` and claim every panel's directory in it."""
        from cartpole_q.store.rundir import new_directory

        sweep = kinds()[PANEL_KIND]
        with new_directory(spec.name, out, runs_root=studydir.STUDIES_ROOT, kind="study") as claim:
            studydir.write_start(claim.path, {
                KIND_KEY: self.name, "name": spec.name, "title": spec.title,
                "columns": spec.columns, "file": spec.file,
                "panels": [panel.name for panel in spec.panels],
            })  # fmt: skip
            for panel in spec.panels:
                with sweep.start(panel.spec, panel.study, claim.path / PANELS_DIR / panel.name):
                    pass  # its start files written; it runs under this study's lock
            claim.keep()
            yield claim.path

    def is_directory(self, directory: Path) -> bool:
        """A study directory whose ``study.yaml`` names this kind (read without its lock)."""
        return directory_kind(directory) == self.name

    def load(self, directory: Path) -> PanelsSpec:
        """The study of ``directory``: its ``study.yaml`` and each panel's sweep directory.

        The caller holds the study's lock; each panel is read under its own (reading a
        sweep directory tidies its temporary files).
        """
        from cartpole_q.store.lock import directory_lock

        raw, _ = studydir.read_start(directory)
        sweep = kinds()[PANEL_KIND]
        names = raw.get("panels")
        if not isinstance(names, list) or not names:
            raise RunError(f"{directory / studydir.STUDY_FILE}: panels: lists no panel.")
        panels = []
        for name in names:
            where = directory / PANELS_DIR / str(name)
            if not sweep.is_directory(where):
                raise RunError(f"{where}: the panel {name} is no sweep directory.")
            stub = study_of({}, str(where), str(name), where, PANEL_KIND)
            with directory_lock(where, "sweep"):
                panels.append(Panel(str(name), stub, sweep.load(where)))
        return PanelsSpec(
            str(raw.get("name", directory.name)), tuple(panels), int(raw.get("columns", 2)),
            str(raw.get("title", "")), str(raw.get("file", f"{directory.name}.png")),
        )  # fmt: skip

    def run(self, spec: PanelsSpec, directory: Path, options: Options) -> Outcome:
        """Run each panel's sweep in turn; when all are complete, draw them as one figure."""
        from cartpole_q.store.lock import directory_lock

        sweep = kinds()[PANEL_KIND]
        done = 0
        outcomes = []
        for panel in spec.panels:
            where = directory / PANELS_DIR / panel.name
            if options.stop_requested():
                break
            options.note(f"panel {panel.name}:")
            with directory_lock(where, "sweep"):
                outcome = sweep.run(panel.spec, where, options)
            outcomes.append(outcome)
            if not outcome.complete:
                break
        # the panels not reached this time count what earlier sessions saved
        done = sum(outcome.done_runs for outcome in outcomes) + sum(
            _saved_runs(directory / PANELS_DIR / panel.name, panel.spec)
            for panel in spec.panels[len(outcomes) :]
        )
        runs = sum(sweep.describe(panel.spec)[0] for panel in spec.panels)
        complete = len(outcomes) == len(spec.panels) and all(o.complete for o in outcomes)
        result = Outcome(directory, runs, done, complete)
        result.saved = f"{done:,} of {runs:,} runs of the panels saved"
        if not complete:
            return result
        figures = [_panel_figure(panel, outcome) for panel, outcome in zip(
            spec.panels, outcomes, strict=True)]  # fmt: skip
        result.files = _write_composed(directory, spec, figures)
        result.lines = [
            line
            for panel, outcome in zip(spec.panels, outcomes, strict=True)
            for line in (f"panel {panel.name}:", *outcome.lines)
        ]
        result.lines.append(f"the figure of its {len(spec.panels)} panels: {result.files[0]}")
        return result


def _saved_runs(where: Path, spec: Any) -> int:
    """How many runs a panel's sweep directory holds (its ``results.csv`` rows)."""
    from cartpole_q.store import sweepdir

    return len(sweepdir.read_results(where, spec.axes))


def _panel_figure(panel: Panel, outcome: Outcome) -> Path:
    """The figure a complete panel drew (its sweep's ``figure.file``)."""
    figure = panel.spec.figure
    path: Path = outcome.directory / figure.file
    if not path.is_file():
        raise RunError(f"{path}: the panel {panel.name} drew no figure.")
    return path


def _write_composed(directory: Path, spec: PanelsSpec, figures: list[Path]) -> list[Path]:
    """Draw the panels' figures side by side and write them with their data, together."""
    import matplotlib.image as mpimg

    from cartpole_q.figures import FIGURE_FORMATS, DataFigure, figure_bytes
    from cartpole_q.store.atomic import atomic_write_together
    from cartpole_q.store.figure_file import data_path

    rows = math.ceil(len(figures) / spec.columns)
    width, height = PANEL_INCHES
    composed = DataFigure(figsize=(width * spec.columns, height * rows), layout="constrained")
    grid = composed.subplots(rows, spec.columns, squeeze=False)
    for index, axes in enumerate(grid.flat):
        axes.set_axis_off()
        if index < len(figures):
            if figures[index].suffix.lower() == ".png":
                axes.imshow(mpimg.imread(figures[index]))
            else:  # an .svg or .pdf panel: named, not drawn (matplotlib reads only images)
                axes.text(0.5, 0.5, figures[index].name, ha="center", va="center")
    composed.suptitle(spec.title)
    path = directory / spec.file
    files = [
        (path, figure_bytes(composed, FIGURE_FORMATS[path.suffix.lower()])),
        (data_path(path), _joined_data(spec, figures).encode("utf-8")),
    ]
    atomic_write_together(files)
    return [path, data_path(path)]


def _joined_data(spec: PanelsSpec, figures: list[Path]) -> str:
    r"""The panels' ``<figure>.csv`` rows one after another, each ``panel`` named by its panel.

    >>> import tempfile
    >>> folder = Path(tempfile.mkdtemp())
    >>> _ = (folder / "a.csv").write_text("panel,series,x,y\n,mean,1,0.5\nleft,mean,2,1\n")
    >>> spec = PanelsSpec("s", (Panel("one", None, None),), 1, "t", "s.png")
    >>> print(_joined_data(spec, [folder / "a.png"]), end="")
    panel,series,x,y
    one,mean,1,0.5
    one: left,mean,2,1
    """
    from cartpole_q.store.figure_file import data_path

    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    header: list[str] | None = None
    for panel, figure in zip(spec.panels, figures, strict=True):
        with data_path(figure).open(encoding="utf-8", newline="") as handle:
            reader = csv.reader(handle)
            own = next(reader)
            if header is None:
                header = own
                writer.writerow(header)
            for row in reader:
                row[0] = f"{panel.name}: {row[0]}" if row[0] else panel.name
                writer.writerow(row)
    return buffer.getvalue()


PANELS = register_kind(PanelsKind())
"""the panels kind (registered)"""
