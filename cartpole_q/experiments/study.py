"""One way in for every study: a study file names its kind, and its kind reads, runs and draws it.

A **study file** is a YAML mapping whose ``kind`` says what it is: ``sweep`` (a grid of
configs trained on many seeds), ``bandit`` (the k-armed testbed of chapter 2), ``dp``
(dynamic programming on a world's model, chapters 3-4), ``updates`` (chapter 8's planning
studies). A file without ``kind`` is a sweep, unless its ``figure.kind`` names one of
another kind's figures (the files written before ``kind`` existed).

A **study kind** is one registered object implementing :class:`StudyKind`: it reads its
part of the file, says what it would run, claims a new directory or takes up an old one,
runs what is missing and draws the figure. ``cartpole-q study`` (and its aliases) asks
the kind and nothing else, so a new kind adds no command.

Most kinds are made of **runs** (a learner on the testbed, a maze size and seed, a
dynamic-programming solve) and share one implementation, :class:`RunsKind`: its runs go
through the worker pool (local processes or Ray), each finished run is saved within about
a second (:mod:`cartpole_q.store.studydir`), a stop or a kill loses only the runs in
flight, ``--resume`` runs the rest, and the outputs come out byte for byte as in one go.
A kind of runs gives its runs' keys, runs one (returning to Python often enough to see a
stop), and turns the finished runs into its figure and lines.
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar, Protocol, TypeVar

import numpy as np

from cartpole_q.config import ConfigError, read_yaml_mapping, shown_value
from cartpole_q.errors import RunError
from cartpole_q.experiments.workers import JobHandle, chunk_size, default_workers, execute
from cartpole_q.progress import NullSweepProgress, SweepProgress, Units
from cartpole_q.store import studydir
from cartpole_q.store.studydir import Cell, RunRecord
from cartpole_q.training import Progress

KIND_KEY = "kind"
"""the study file's key naming its kind"""
FLUSH_SECONDS = 1.0
"""finished runs are saved at most this often (a kill loses at most this much finished work)"""


# -- the study file -------------------------------------------------------------------------


@dataclass(frozen=True)
class StudyFile:
    """A study file as read: its mapping and where it came from."""

    raw: Mapping[str, Any]
    """the file's mapping, ``kind`` included when given"""
    kind: str
    """its kind (given, or inferred for files older than the key)"""
    where: str
    """how messages name it (its path)"""
    stem: str
    """the file's name without its extension (the default study name)"""
    base_dir: Path
    """its directory (paths in the file are relative to it)"""

    @property
    def body(self) -> Mapping[str, Any]:
        """The mapping without ``kind``: what the kind's reader checks."""
        return {key: value for key, value in self.raw.items() if key != KIND_KEY}


@dataclass(frozen=True)
class Options:
    """How to run a study: the command line's choices, none of which changes a result."""

    workers: int = 0
    """worker processes (or a local Ray cluster's CPUs); 0: one per core, at most one per job"""
    backend: str = "local"
    address: str | None = None
    quiet: bool = False
    should_stop: Callable[[], bool] | None = None
    """polled between runs (and inside long ones); when true the study saves and stops"""
    progress: Callable[[Units], SweepProgress] | None = None
    """makes the progress display for the kind's units (``None``: none)"""
    say: Callable[[str], None] | None = None
    """where notes go (compiling a loop first, ...)"""

    def stop_requested(self) -> bool:
        """Whether a stop was asked for."""
        return self.should_stop is not None and self.should_stop()

    def note(self, text: str) -> None:
        """Pass a note on (unless quiet)."""
        if self.say is not None and not self.quiet:
            self.say(text)


@dataclass
class Outcome:
    """How a study call ended."""

    directory: Path
    total_runs: int
    done_runs: int
    complete: bool
    lines: list[str] = field(default_factory=list)
    """what to print at the end (what ran, the key numbers, the book's beside ours)"""
    files: list[Path] = field(default_factory=list)
    """the figures and files written at the end"""
    saved: str = ""
    """what a stopped study has saved, exactly (for the interruption message)"""


class StudyInterrupted(KeyboardInterrupt):
    """A study stopped at once (a second signal), with what it had saved (``text``)."""

    def __init__(self, text: str) -> None:
        super().__init__(text)
        self.text = text


class StudyKind(Protocol):
    """A kind of study: what ``cartpole-q study`` needs of it."""

    @property
    def name(self) -> str:
        """Its ``kind`` value."""
        ...

    @property
    def figure_kinds(self) -> tuple[str, ...]:
        """The ``figure.kind`` values that mark an older file (without ``kind``) as this kind."""
        ...

    def read(self, study: StudyFile) -> Any:
        """Check the file and return the study it describes (raising ConfigError)."""
        ...

    def describe(self, spec: Any) -> tuple[int, str]:
        """How many runs the study has, and one line saying what they are."""
        ...

    def start(
        self, spec: Any, study: StudyFile, out: Path | None
    ) -> contextlib.AbstractContextManager[Path]:
        """Claim a new directory and write its start files (holding its lock inside)."""
        ...

    def is_directory(self, directory: Path) -> bool:
        """Whether ``directory`` is a study directory of this kind."""
        ...

    def load(self, directory: Path) -> Any:
        """The study of an existing directory, for ``--resume`` (the caller holds its lock)."""
        ...

    def run(self, spec: Any, directory: Path, options: Options) -> Outcome:
        """Run whatever the directory does not hold yet; when complete, draw and summarise."""
        ...


_KINDS: dict[str, StudyKind] = {}


Kind = TypeVar("Kind", bound=StudyKind)


def register_kind(kind: Kind) -> Kind:
    """Make ``kind`` known to ``cartpole-q study`` (once per name)."""
    if kind.name in _KINDS and _KINDS[kind.name] is not kind:
        raise ValueError(f"a study kind named {kind.name!r} is registered already")
    _KINDS[kind.name] = kind
    return kind


def kinds() -> dict[str, StudyKind]:
    """The registered kinds by name."""
    return dict(_KINDS)


def read_study_file(path: Path, default: str | None = None, label: str = "study file") -> StudyFile:
    """Read a study file and find its kind.

    Args:
        path: the file.
        default: the kind of a file without ``kind`` whose ``figure.kind`` names no
            kind's figure (an alias's kind, ``bandit``); ``None``: a sweep.
        label: what messages call the file.

    Raises:
        ConfigError: not a YAML mapping, or a ``kind`` no registered kind has.
    """
    raw = read_yaml_mapping(path, label)
    return study_of(raw, str(path), path.stem, path.parent, default)


def study_of(
    raw: Mapping[str, Any], where: str, stem: str, base_dir: Path, default: str | None = None
) -> StudyFile:
    """A study mapping with its kind (given, or as :func:`read_study_file` says).

    Raises:
        ConfigError: a ``kind`` no registered kind has.
    """
    known = sorted(_KINDS)
    if KIND_KEY in raw:
        kind = raw[KIND_KEY]
        if kind not in _KINDS:
            raise ConfigError(
                f"{where}: kind: must be one of {', '.join(known)}, got {shown_value(kind)}."
            )
        return StudyFile(raw, str(kind), where, stem, base_dir)
    figure = raw.get("figure")
    figure_kind = figure.get("kind") if isinstance(figure, Mapping) else None
    inferred = next(
        (name for name, kind in _KINDS.items() if figure_kind in kind.figure_kinds),
        default or "sweep",
    )
    return StudyFile(raw, inferred, where, stem, base_dir)


def directory_kind(directory: Path) -> str | None:
    """The ``kind`` a study directory's ``study.yaml`` names (``None``: none, or no such file).

    Read without the directory's lock: nothing in it is changed.
    """
    path = directory / studydir.STUDY_FILE
    if not path.is_file():
        return None
    try:
        raw = read_yaml_mapping(path, "study file")
    except ConfigError:
        return None
    kind = raw.get(KIND_KEY)
    return kind if isinstance(kind, str) else None


def kind_of_directory(directory: Path) -> StudyKind:
    """The kind whose directory ``directory`` is.

    Raises:
        RunError: it is no study directory.
    """
    for kind in _KINDS.values():
        if kind.is_directory(directory):
            return kind
    if not directory.is_dir():
        raise RunError(f"{directory}: does not exist; --resume takes a study directory.")
    raise RunError(
        f"{directory}: is not a study directory (it has neither {studydir.STUDY_FILE} nor "
        "sweep.yaml); --resume takes a directory `cartpole-q study` (or `sweep`) made."
    )


# -- kinds made of runs ---------------------------------------------------------------------


@dataclass(frozen=True)
class Finished:
    """What a kind of runs makes of its finished runs: files to write and lines to print."""

    figures: Sequence[tuple[str, Any]]
    """``(file name, DataFigure)``: each written with its data beside it"""
    texts: Sequence[tuple[str, str]] = ()
    """``(file name, text)``: further files (dynamic programming's recorded sweeps)"""
    lines: Sequence[str] = ()
    """what to print, and to keep as ``summary.txt``"""


class RunsKind:
    """The shared implementation of a kind whose study is a list of independent runs.

    A subclass gives :meth:`read`, :meth:`runs` (each run's key: a mapping of cells, the
    ``results.csv`` key columns), :meth:`run_one` (one run, in a worker) and
    :meth:`finish` (the figure and lines from every run's record, in run order), and may
    give :meth:`run_size` (the work in a run, for progress) and :meth:`before_runs` (a
    note before the first run, such as compiling).
    """

    name: ClassVar[str] = ""
    figure_kinds: ClassVar[tuple[str, ...]] = ()
    units: ClassVar[Units] = Units("study", "runs", "runs")
    """what the progress display counts: the kind's title, its items, its groups (runs)"""
    runs_per_task: ClassVar[int] = 8
    """at most this many runs per job sent to a worker"""

    # -- what a subclass gives ---------------------------------------------------------------

    def read(self, study: StudyFile) -> Any:
        """Check the file; return the study (a frozen, picklable object)."""
        raise NotImplementedError

    def runs(self, spec: Any) -> list[dict[str, Cell]]:
        """Every run's key, in run order: its ``results.csv`` key cells."""
        raise NotImplementedError

    def result_columns(self, spec: Any) -> tuple[str, ...]:
        """The ``results.csv`` columns of a run's scalar results."""
        return ()

    def run_one(self, spec: Any, key: Mapping[str, Cell], handle: RunHandle) -> RunRecord | None:
        """Run one run; ``None`` when ``handle.should_stop()`` ended it early."""
        raise NotImplementedError

    def finish(
        self, spec: Any, keys: Sequence[Mapping[str, Cell]], records: Sequence[RunRecord]
    ) -> Finished:
        """The figures, files and lines of a complete study."""
        raise NotImplementedError

    def run_size(self, spec: Any, key: Mapping[str, Cell]) -> int:
        """The work in a run, in :attr:`units`' items (1: a run is one item)."""
        return 1

    def before_runs(self, spec: Any) -> str | None:
        """A note before the runs start (the first run compiles a loop), or ``None``."""
        return None

    def describe(self, spec: Any) -> tuple[int, str]:
        """The runs and one line about them."""
        keys = self.runs(spec)
        items = sum(self.run_size(spec, key) for key in keys)
        extra = f" ({items:,} {self.units.items})" if items != len(keys) else ""
        return len(keys), f"a {self.name} study of {len(keys):,} {self.units.groups}{extra}"

    # -- the shared machinery ----------------------------------------------------------------

    def __init__(self) -> None:
        self._unkept: dict[Path, Any] = {}
        """the directories this process claimed whose first run is not saved yet"""

    def is_directory(self, directory: Path) -> bool:
        """A study directory whose ``study.yaml`` names this kind."""
        return directory_kind(directory) == self.name

    @contextlib.contextmanager
    def start(self, spec: Any, study: StudyFile, out: Path | None) -> Iterator[Path]:
        """Claim the directory and write ``study.yaml`` (``kind`` first), holding its lock.

        Until its first run is saved, a failure (bad input only a run finds, a full disk)
        removes the directory again: nothing is left that holds no result.
        """
        from cartpole_q.store.rundir import new_directory

        root = studydir.STUDIES_ROOT
        with new_directory(spec.name, out, runs_root=root, kind="study") as claim:
            # its name too: a resumed study (read from the directory) keeps the file's
            studydir.write_start(claim.path, {KIND_KEY: self.name, "name": spec.name, **study.body})
            self._unkept[claim.path] = claim
            try:
                yield claim.path
            finally:
                self._unkept.pop(claim.path, None)

    def load(self, directory: Path) -> Any:
        """The study of ``directory`` from its ``study.yaml``."""
        raw, _ = studydir.read_start(directory)
        where = str(directory / studydir.STUDY_FILE)
        return self.read(study_of(raw, where, directory.name, directory))

    def run(self, spec: Any, directory: Path, options: Options) -> Outcome:
        """Run the missing runs in batches, saving each; when all are done, finish."""
        keys = self.runs(spec)
        columns = studydir.header(list(keys[0]) if keys else [], self.result_columns(spec))
        raw, study_digest = studydir.read_start(directory)
        # Workers read the study again from its mapping (a study holds read-only mappings,
        # which do not pickle), once per process: the digest names it.
        where = getattr(spec, "where", str(directory / studydir.STUDY_FILE))  # as first read
        started = (study_digest, raw, where, directory.name)
        claim = self._unkept.get(directory)
        book = _RunBook(
            directory, columns, keys, study_digest, None if claim is None else claim.keep
        )
        missing = [index for index in range(len(keys)) if index not in book.rows]
        sizes = [self.run_size(spec, key) for key in keys]
        counted = len(keys) > 1 or sum(sizes) > 1  # one indivisible run: nothing to count
        make = options.progress if counted else None
        progress = (make or (lambda units: NullSweepProgress()))(self.units)
        if missing:
            note = self.before_runs(spec)
            if note is not None:
                options.note(note)
        done_items = sum(sizes[index] for index in book.rows)
        progress.start(sum(sizes), done_items, len(keys), len(book.rows))
        reporter = _ItemsReporter(progress, book, sizes)
        workers = options.workers or default_workers(len(missing))
        size = chunk_size(len(missing), workers, most=self.runs_per_task)
        jobs = [
            (self, started, [(index, keys[index]) for index in missing[start : start + size]])
            for start in range(0, len(missing), size)
        ]

        def on_item(job: int, item: tuple[int, RunRecord]) -> None:
            index, record = item
            book.add(index, record)
            reporter.finished(index)

        try:
            execute(
                run_task, jobs, on_item, backend=options.backend, workers=workers,
                address=options.address, should_stop=options.should_stop, reporter=reporter,
            )  # fmt: skip
        except KeyboardInterrupt:
            book.flush(force=True)
            raise StudyInterrupted(book.saved_text()) from None
        finally:
            book.flush(force=True)
            progress.close()
        outcome = Outcome(directory, len(keys), len(book.rows), len(book.rows) == len(keys))
        outcome.saved = book.saved_text()
        if not outcome.complete:
            return outcome
        records = [book.record(index) for index in range(len(keys))]
        finished = self.finish(spec, keys, records)
        outcome.files = _write_finished(directory, finished)
        outcome.lines = list(finished.lines)
        return outcome


@dataclass(frozen=True)
class RunHandle:
    """What a run sees of its process: whether to stop, and where its progress goes."""

    should_stop: Callable[[], bool]
    """polled by long runs between chunks of work; true: return ``None`` at once"""
    report: Callable[[int], None]
    """told the items (of the kind's units) the run has done so far"""


_READ: dict[tuple[str, str], Any] = {}
"""the studies this process has read, by their ``study.yaml`` digest and file"""


@dataclass(frozen=True)
class CurveFunctions:
    """What a curves kind's module does: read a file, list, run and finish the runs."""

    read: Callable[[StudyFile], Any]
    runs: Callable[[Any], list[dict[str, Cell]]]
    run_one: Callable[[Any, Mapping[str, Cell], RunHandle], RunRecord | None]
    finish: Callable[[Any, Sequence[Mapping[str, Cell]], Sequence[RunRecord]], Finished]
    columns: Callable[[Any], tuple[str, ...]]
    """a run's ``results.csv`` columns"""
    length: Callable[[Any], int]
    """a run's episodes, steps or sweeps (what the progress counts)"""
    unit: Callable[[Any], str]
    """what :attr:`length` counts (``episodes``, ``steps``)"""
    compile_notice: Callable[[], str | None]
    """a sentence when the kind's loops are not compiled yet"""


class CurvesKind(RunsKind):
    """A kind whose study is curves, each run on each seed (linear, policy gradient, average reward).

    The study (``read``'s result) has ``curves``, ``seeds`` and ``engine``; the module's
    functions (:class:`CurveFunctions`) do the work, so a kind is a name and its units.
    """

    def __init__(self, functions: CurveFunctions) -> None:
        super().__init__()
        self.functions = functions

    def read(self, study: StudyFile) -> Any:
        """Check the file."""
        return self.functions.read(study)

    def runs(self, spec: Any) -> list[dict[str, Cell]]:
        """Each curve on each seed."""
        return self.functions.runs(spec)

    def run_size(self, spec: Any, key: Mapping[str, Cell]) -> int:
        """A run's episodes, steps or sweeps."""
        return self.functions.length(spec)

    def result_columns(self, spec: Any) -> tuple[str, ...]:
        """A run's scalar results."""
        return self.functions.columns(spec)

    def before_runs(self, spec: Any) -> str | None:
        """The compile notice."""
        return self.functions.compile_notice()

    def run_one(self, spec: Any, key: Mapping[str, Cell], handle: RunHandle) -> RunRecord | None:
        """One run."""
        return self.functions.run_one(spec, key, handle)

    def finish(
        self, spec: Any, keys: Sequence[Mapping[str, Cell]], records: Sequence[RunRecord]
    ) -> Finished:
        """The figure and the summary."""
        return self.functions.finish(spec, keys, records)

    def describe(self, spec: Any) -> tuple[int, str]:
        """The runs, by curves and seeds."""
        runs = len(self.runs(spec))
        seeds, curves = len(spec.seeds), len(spec.curves)
        article = "an" if self.name[:1] in "aeiou" else "a"
        return runs, (
            f"{article} {self.name} study of {runs:,} run{'s' if runs != 1 else ''}: {curves} "
            f"curve{'s' if curves != 1 else ''} x {seeds:,} seed{'s' if seeds != 1 else ''} "
            f"({self.functions.length(spec):,} {self.functions.unit(spec)} each, the "
            f"{spec.engine} engine)"
        )


def run_task(
    handle: JobHandle,
    kind: RunsKind,
    started: tuple[str, Mapping[str, Any], str, str],
    items: Sequence[tuple[int, Mapping[str, Cell]]],
) -> Iterator[tuple[int, RunRecord]]:
    """Job: run each ``(index, key)`` in turn, yielding each record as it ends.

    ``started`` is the study as its directory holds it: ``study.yaml``'s digest, mapping,
    path and directory name. The job ends early, yielding nothing more, when its handle
    asks to stop (the run in flight returns ``None``).
    """
    digest, raw, where, stem = started
    if (digest, where) not in _READ:  # (the file too: its messages name it)
        _READ[digest, where] = kind.read(study_of(raw, where, stem, Path(where).parent))
    spec = _READ[digest, where]
    reporter = handle.reporter()
    for index, key in items:
        if handle.should_stop():
            return

        def report(done: int, index: int = index) -> None:
            reporter.update(index, Progress(done, 0, 0.0, 0.0, 0.0, 0, 0.0, None))

        record = kind.run_one(spec, key, RunHandle(handle.should_stop, report))
        if record is None:
            return
        yield index, record


class _ItemsReporter:
    """Turns the runs' reports (items done so far) into the study's progress display."""

    def __init__(self, progress: SweepProgress, book: _RunBook, sizes: Sequence[int]) -> None:
        self._progress = progress
        self._book = book
        self._sizes = sizes
        self._partial: dict[Any, int] = {}
        self._last = 0.0

    def _advance(self) -> None:
        done = sum(self._sizes[index] for index in self._book.rows) + sum(self._partial.values())
        self._progress.advance(done, len(self._book.rows))

    def finished(self, index: int) -> None:
        """A run ended (its record is saved)."""
        self._partial.pop(index, None)
        self._advance()

    def start(self, key: Any, label: str, episodes: int) -> None:
        """Runs do not announce themselves."""

    def update(self, key: Any, progress: Progress) -> None:
        """A run in flight did ``progress.episode`` items (shown at most ten times a second)."""
        self._partial[key] = progress.episode
        now = time.monotonic()
        if now - self._last >= 0.1:
            self._last = now
            self._advance()

    def finish(self, key: Any, line: str) -> None:
        """Nothing to print."""

    def close(self) -> None:
        """Nothing to close."""


class _RunBook:
    """The finished runs of a study directory, saved in batches."""

    def __init__(
        self,
        directory: Path,
        columns: Sequence[str],
        keys: Sequence[Mapping[str, Cell]],
        study_digest: str,
        on_first_save: Callable[[], None] | None = None,
    ) -> None:
        self._on_first_save = on_first_save
        self._directory = directory
        self._columns = list(columns)
        self._keys = keys
        self._digest = study_digest
        self.rows: dict[int, Mapping[str, Cell]] = {}
        results = directory / studydir.RESULTS_FILE
        for index, row_digest, cells in studydir.read_results(directory, columns):
            if row_digest != study_digest:
                raise RunError(
                    f"{directory / studydir.STUDY_FILE}: was changed after the runs in {results} "
                    "were made; --resume finishes a study exactly as it started. Put it back, "
                    "or start a new study from the edited file."
                )
            expected = keys[index] if index < len(keys) else None
            if (
                expected is None
                or index in self.rows
                or any(cells[name] != studydir.cell_text(value) for name, value in expected.items())
            ):
                raise RunError(
                    f"{results}: has a row (run {index}) that is not of this study, or twice; "
                    "the study directory was changed by hand. Start a new study."
                )
            self.rows[index] = {name: studydir.parse_cell(text) for name, text in cells.items()}
        self._saved = len(self.rows)
        self._dirty = False
        self._last_flush = -float("inf")

    def add(self, index: int, record: RunRecord) -> None:
        """Keep a finished run: its arrays now, its row at the next flush."""
        if record.arrays:
            studydir.write_arrays(self._directory, index, record.arrays)
        self.rows[index] = {**self._keys[index], **record.row}
        self._dirty = True
        self.flush()

    def flush(self, *, force: bool = False) -> None:
        """Rewrite ``results.csv`` with every finished run (at most once a second unless forced)."""
        if not self._dirty or (not force and time.monotonic() - self._last_flush < FLUSH_SECONDS):
            return
        ordered = sorted(self.rows)
        studydir.write_results(
            self._directory, self._columns, [(i, self._digest, self.rows[i]) for i in ordered]
        )
        self._saved = len(ordered)
        self._dirty = False
        self._last_flush = time.monotonic()
        if self._on_first_save is not None:
            self._on_first_save()  # the directory now holds a result: it stays, whatever comes
            self._on_first_save = None

    def saved_text(self) -> str:
        """What ``results.csv`` holds, for the message of a stopped study."""
        results = self._directory / studydir.RESULTS_FILE
        if not self._saved:
            return f"no run had finished, so nothing is saved in {results} yet"
        return f"{self._saved:,} of {len(self._keys):,} runs are saved in {results}"

    def record(self, index: int) -> RunRecord:
        """A finished run's record, read back as saved (the same whether resumed or not)."""
        cells = self.rows[index]
        row = {name: value for name, value in cells.items() if name not in self._keys[index]}
        reread = {
            name: studydir.parse_cell(studydir.cell_text(value)) for name, value in row.items()
        }
        return RunRecord(reread, studydir.read_arrays(self._directory, index))


def _write_finished(directory: Path, finished: Finished) -> list[Path]:
    """Write the figures (with their data), the further files and ``summary.txt`` together.

    Raises:
        WriteError: any cannot be written; then none is changed.
    """
    from cartpole_q.figures import FIGURE_FORMATS, figure_bytes
    from cartpole_q.store.atomic import atomic_write_together
    from cartpole_q.store.figure_file import data_path

    files: list[tuple[Path, bytes]] = []
    for name, figure in finished.figures:
        path = directory / name
        files.append((data_path(path), figure.data.csv_text().encode("utf-8")))
        files.append((path, figure_bytes(figure, FIGURE_FORMATS[path.suffix.lower()])))
    files.extend((directory / name, text.encode("utf-8")) for name, text in finished.texts)
    summary = "".join(f"{line}\n" for line in finished.lines)
    files.append((directory / studydir.SUMMARY_FILE, summary.encode("utf-8")))
    atomic_write_together(files)
    return [path for path, _ in files]


def mean_in_order(rows: Sequence[np.ndarray]) -> np.ndarray:
    """The mean of equal-length rows: summed in order from 0.0, then divided once.

    >>> mean_in_order([np.array([1.0, 2.0]), np.array([3.0, 5.0])]).tolist()
    [2.0, 3.5]
    """
    total = np.zeros(len(rows[0]))
    for row in rows:
        total = total + row
    return total / len(rows)
