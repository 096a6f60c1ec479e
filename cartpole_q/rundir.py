"""The run directory: what training leaves behind, written atomically, read back strictly.

| file | content |
| --- | --- |
| ``config.yaml`` | the resolved config; ``train --config`` on it reproduces the run |
| ``q_table.npy`` | float64, shape ``(*bins, n_actions)``; greedy action = argmax of last axis |
| ``visits.npy`` | int64, same shape: how often training took each (state, action) |
| ``metrics.csv`` | ``episode,return,length,epsilon,alpha``, one row per training episode |
| ``evaluations.csv`` | periodic greedy evaluations: ``episode,env_steps,mean,std,min,max`` |
| ``reward_curve.png`` | returns, their 100-episode moving average, the threshold |
| ``summary.json`` | figures of the run; written last, so its presence means complete |
| ``checkpoint.npz`` | what ``--resume`` needs, with the config it was trained with: kept while a run is unfinished or interrupted, and after a run that reached ``train.episodes`` (to extend it) |

Every file is written to a temporary file in the same directory and moved into place with
``os.replace``, so a reader (or a process killed at any instant) never sees half a file.
Arrays are read with ``allow_pickle=False`` only.
"""

from __future__ import annotations

import contextlib
import csv
import errno
import io
import json
import os
import platform
import secrets
import time
import zipfile
from dataclasses import dataclass
from importlib import metadata
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from cartpole_q.config import Config, ConfigError, load_config
from cartpole_q.errors import UserError

CONFIG_FILE = "config.yaml"
Q_TABLE_FILE = "q_table.npy"
VISITS_FILE = "visits.npy"
METRICS_FILE = "metrics.csv"
EVALUATIONS_FILE = "evaluations.csv"
CURVE_FILE = "reward_curve.png"
SUMMARY_FILE = "summary.json"
CHECKPOINT_FILE = "checkpoint.npz"
METRICS_HEADER = ("episode", "return", "length", "epsilon", "alpha")
EVALUATIONS_HEADER = ("episode", "env_steps", "mean", "std", "min", "max")
NPY_MAGIC = b"\x93NUMPY"
"""the first bytes of every ``.npy`` file"""


class RunError(UserError):
    """A run directory, or a file in it, that cannot be used; the message names it."""


# -- atomic writes --------------------------------------------------------------------


class WriteError(RunError):
    """A file that cannot be written (full disk, no permission, ...); the message names it."""


def atomic_write_bytes(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` so that ``path`` is either absent, old, or complete.

    The temporary file is created with ``open(..., "xb")`` rather than ``mkstemp`` so
    that it gets the user's usual permissions (umask), not mkstemp's owner-only 0600.

    Raises:
        WriteError: the file cannot be written (``ENOSPC``, ``EACCES``, ``EROFS``,
            ``ENOTDIR``, ...); the temporary file is gone and ``path`` is untouched.
    """
    temporary = path.parent / f".{path.name}.{secrets.token_hex(6)}.tmp"
    try:
        with open(temporary, "xb") as stream:
            stream.write(data)
        os.replace(temporary, path)
    except BaseException as error:
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
    if path.exists() and not force:
        raise WriteError(
            f"{path}: already exists; pass --force to replace it, or choose another name."
        )
    probe = path.parent / f".{path.name}.{secrets.token_hex(6)}.tmp"
    try:
        with open(probe, "xb"):
            pass
    except OSError as error:
        raise WriteError(f"{path}: cannot be written: {write_failure(path, error)}.") from None
    with contextlib.suppress(OSError):
        probe.unlink()
    return suffix


def remove_stale_temporaries(run_dir: Path) -> None:
    """Delete temporary files a killed process left behind (never a finished file)."""
    for temporary in run_dir.glob(".*.tmp"):
        temporary.unlink(missing_ok=True)


def atomic_write_text(path: Path, text: str) -> None:
    """Write UTF-8 text atomically."""
    atomic_write_bytes(path, text.encode("utf-8"))


def atomic_save_npy(path: Path, array: np.ndarray) -> None:
    """Save one array as ``.npy`` atomically."""
    buffer = io.BytesIO()
    np.save(buffer, array, allow_pickle=False)
    atomic_write_bytes(path, buffer.getvalue())


# -- creating a run directory ---------------------------------------------------------


def create_run_dir(name: str, out: Path | None, runs_root: Path = Path("runs")) -> Path:
    """Create the directory a new run writes to, never reusing a non-empty one.

    Args:
        name: the config's run-name prefix.
        out: the directory asked for with ``--out``; it must not exist, or be empty.
        runs_root: where ``<name>-<YYYYmmdd-HHMMSS>`` goes when ``out`` is ``None``.

    Raises:
        RunError: ``out`` is a file or a non-empty directory.
    """
    try:
        if out is not None:
            check_output_dir(out)
            out.mkdir(parents=True, exist_ok=True)
            return out
        stamp = time.strftime("%Y%m%d-%H%M%S")
        runs_root.mkdir(parents=True, exist_ok=True)
        for attempt in range(1000):
            path = runs_root / (f"{name}-{stamp}" if attempt == 0 else f"{name}-{stamp}-{attempt}")
            try:
                path.mkdir()
            except FileExistsError:
                continue
            return path
    except OSError as error:
        where = out if out is not None else runs_root
        raise RunError(f"{where}: cannot create the run directory ({error.strerror}).") from None
    raise RunError(f"{runs_root}: could not find a free run directory name for {name!r}.")


def check_output_dir(out: Path) -> None:
    """Refuse an output path that is a file or a non-empty directory.

    Raises:
        RunError: naming the path and what is wrong with it.
    """
    if out.exists() and not out.is_dir():
        raise RunError(f"{out}: --out must be a directory, but this is a file.")
    if out.is_dir() and any(out.iterdir()):
        raise RunError(
            f"{out}: --out points at a non-empty directory; cartpole-q never overwrites a "
            "run. Choose a new directory (or leave --out out for a fresh one under runs/)."
        )


def write_config(run_dir: Path, config: Config) -> None:
    """Write the resolved config (every key) as ``config.yaml``."""
    header = (
        "# Resolved config of this run: every key, defaults filled in.\n"
        "# `cartpole-q train --resume` continues the run only while nothing here changes\n"
        "# but train.episodes (which may grow, to extend the run).\n"
    )
    atomic_write_text(run_dir / CONFIG_FILE, header + config.to_yaml())


# -- checkpoints ----------------------------------------------------------------------


def write_checkpoint(run_dir: Path, checkpoint: Any) -> None:
    """Save a :class:`~cartpole_q.training.Checkpoint` as one atomic ``checkpoint.npz``."""
    meta = {
        "engine": checkpoint.engine,
        "episode": checkpoint.episode,
        "env_steps": checkpoint.env_steps,
        "agent_rng_state": checkpoint.agent_rng_state,
        "env_rng_state": checkpoint.env_rng_state,
        "solved_episode": checkpoint.solved_episode,
        "evaluations": checkpoint.evaluations,
        "train_seconds": checkpoint.train_seconds,
        "wall_seconds": checkpoint.wall_seconds,
        "config": None if checkpoint.config is None else checkpoint.config.to_yaml(),
    }
    arrays = {
        "q": checkpoint.q,
        "visits": checkpoint.visits,
        "returns": checkpoint.returns,
        "lengths": checkpoint.lengths,
        "epsilons": checkpoint.epsilons,
        "alphas": checkpoint.alphas,
        "meta": np.array(json.dumps(meta)),
    }
    if checkpoint.solved_q is not None:
        arrays["solved_q"] = checkpoint.solved_q
    buffer = io.BytesIO()
    np.savez(buffer, allow_pickle=False, **arrays)
    atomic_write_bytes(run_dir / CHECKPOINT_FILE, buffer.getvalue())


def load_checkpoint(run_dir: Path) -> Any:
    """Read ``checkpoint.npz`` back as a :class:`~cartpole_q.training.Checkpoint`.

    Raises:
        RunError: the checkpoint is missing or damaged.
    """
    from cartpole_q.training import Checkpoint

    path = run_dir / CHECKPOINT_FILE
    if not path.is_file():
        raise RunError(f"{path}: no checkpoint; there is nothing to resume in {run_dir}.")
    try:
        with np.load(path, allow_pickle=False) as data:
            meta = json.loads(str(data["meta"]))
            return Checkpoint(
                engine=meta["engine"],
                episode=int(meta["episode"]),
                env_steps=int(meta["env_steps"]),
                q=data["q"],
                visits=data["visits"],
                returns=data["returns"],
                lengths=data["lengths"],
                epsilons=data["epsilons"],
                alphas=data["alphas"],
                agent_rng_state=meta["agent_rng_state"],
                env_rng_state=meta["env_rng_state"],
                solved_episode=meta["solved_episode"],
                solved_q=data["solved_q"] if "solved_q" in data.files else None,
                evaluations=meta["evaluations"],
                train_seconds=float(meta["train_seconds"]),
                wall_seconds=float(meta["wall_seconds"]),
                config=_checkpoint_config(meta.get("config")),
            )
    except (
        OSError, ValueError, KeyError, TypeError, EOFError, zipfile.BadZipFile, ConfigError
    ) as error:  # fmt: skip
        raise RunError(
            f"{path}: the checkpoint is damaged and cannot be resumed ({error})."
        ) from None


def _checkpoint_config(text: Any) -> Config | None:
    """The config a checkpoint recorded (``None`` for checkpoints older than that)."""
    if text is None:
        return None
    data = yaml.safe_load(text)
    if not isinstance(data, dict):
        raise ValueError("its recorded config is not a mapping")
    return load_config(data)


def read_checkpoint_meta(run_dir: Path) -> dict[str, Any] | None:
    """The small part of ``checkpoint.npz`` (episode, engine, ...), without its arrays.

    Returns:
        ``None`` when there is no checkpoint.

    Raises:
        RunError: the checkpoint is damaged.
    """
    path = run_dir / CHECKPOINT_FILE
    if not path.is_file():
        return None
    try:
        with np.load(path, allow_pickle=False) as data:
            meta = json.loads(str(data["meta"]))
        if not isinstance(meta, dict):
            raise ValueError("its meta is not a JSON object")
        return meta
    except (OSError, ValueError, KeyError, TypeError, EOFError, zipfile.BadZipFile) as error:
        raise RunError(
            f"{path}: the checkpoint is damaged and cannot be resumed ({error})."
        ) from None


# -- writing a finished (or interrupted) run ------------------------------------------


def versions() -> dict[str, str]:
    """The versions of Python and the packages that produce a run."""
    found = {"python": platform.python_version()}
    for package in ("numpy", "gymnasium", "numba", "cartpole-q"):
        try:
            found[package.replace("-", "_")] = metadata.version(package)
        except metadata.PackageNotFoundError:
            found[package.replace("-", "_")] = "unknown"
    return found


def summarize(result: Any) -> dict[str, Any]:
    """The ``summary.json`` content of a :class:`~cartpole_q.training.TrainResult`."""
    played_in = "twin" if result.engine == "numba" else "gymnasium"
    greedy = result.first_greedy_success()
    return {
        "episodes": result.episodes,
        "env_steps": result.env_steps,
        "wall_seconds": round(result.wall_seconds, 6),
        "train_seconds": round(result.train_seconds, 6),
        "steps_per_second": round(result.steps_per_second, 1),
        "solved_episode": result.solved_episode,
        "env_steps_to_solve": (
            None
            if result.solved_episode is None
            else int(result.lengths[: result.solved_episode].sum())
        ),
        "reward_threshold": result.reward_threshold,
        "q_table": {
            "episode": result.kept_episode,
            "source": "solve point" if result.solved_episode is not None else "last episode",
        },
        # The numba engine plays its evaluations on the compiled twin (bit-identical to
        # Gymnasium's environment); `cartpole-q eval` always plays in gymnasium.make.
        "eval": None if result.eval is None else {**result.eval.to_dict(), "played_in": played_in},
        "first_greedy_success": (None if greedy is None else {**greedy, "played_in": played_in}),
        "engine": result.engine,
        "seed": result.config.seed,
        "interrupted": result.interrupted,
        "versions": versions(),
        "finished_at": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
    }


def metrics_csv(result: Any) -> str:
    """Per-episode metrics as CSV; floats written with ``repr`` so they round-trip exactly."""
    lines = [",".join(METRICS_HEADER)]
    lines.extend(
        f"{i + 1},{float(r)!r},{int(n)},{float(e)!r},{float(a)!r}"
        for i, (r, n, e, a) in enumerate(
            zip(result.returns, result.lengths, result.epsilons, result.alphas, strict=True)
        )
    )
    return "\n".join(lines) + "\n"


def evaluations_csv(evaluations: list[dict[str, Any]]) -> str:
    """Periodic evaluations as CSV."""
    lines = [",".join(EVALUATIONS_HEADER)]
    lines.extend(
        ",".join(repr(record[key]) for key in EVALUATIONS_HEADER) for record in evaluations
    )
    return "\n".join(lines) + "\n"


def write_run(
    run_dir: str | Path, result: Any, *, plot: bool = True, overwrite: bool = False
) -> dict[str, Any]:
    """Write a :class:`~cartpole_q.training.TrainResult` into ``run_dir``.

    Files go in the contract's order: data first, ``summary.json`` last. An interrupted
    result keeps its ``checkpoint.npz`` for ``--resume``, and so does one that reached
    ``train.episodes`` (so that it can be extended); a run stopped at its solve point
    removes it.

    Args:
        run_dir: the directory to write; it must not exist or be empty.
        result: the training result.
        plot: draw ``reward_curve.png``.
        overwrite: write into a non-empty ``run_dir``, replacing its run files (the
            command line does this in the directory it created, and on ``--resume``).

    Returns:
        The summary that was written.

    Raises:
        RunError: ``run_dir`` is a file, or a non-empty directory and not ``overwrite``.
    """
    run_dir = Path(run_dir)
    if run_dir.exists() and not run_dir.is_dir():
        raise RunError(f"{run_dir}: is a file; a run directory must be a new or empty directory.")
    if not overwrite and run_dir.is_dir() and any(run_dir.iterdir()):
        raise RunError(
            f"{run_dir}: is not empty; write_run never overwrites a run. Choose a new "
            "directory, or pass overwrite=True to replace this run's files."
        )
    run_dir.mkdir(parents=True, exist_ok=True)
    write_config(run_dir, result.config)
    atomic_save_npy(run_dir / Q_TABLE_FILE, result.q_table)
    atomic_save_npy(run_dir / VISITS_FILE, result.visits)
    atomic_write_text(run_dir / METRICS_FILE, metrics_csv(result))
    atomic_write_text(run_dir / EVALUATIONS_FILE, evaluations_csv(result.evaluations))
    if plot:
        from cartpole_q.plotting import Curve, figure_png, reward_curve_figure

        curve = Curve(
            run_dir.name, result.returns, result.solved_episode, interrupted=result.interrupted
        )
        title = f"Training reward: {run_dir.name}" + (
            " (interrupted)" if result.interrupted else ""
        )
        figure = reward_curve_figure([curve], result.reward_threshold, title=title)
        atomic_write_bytes(run_dir / CURVE_FILE, figure_png(figure))
    summary = summarize(result)
    write_json(run_dir / SUMMARY_FILE, summary)
    if not result.interrupted and not result.extendable:
        (run_dir / CHECKPOINT_FILE).unlink(missing_ok=True)
    return summary


def write_json(path: Path, data: dict[str, Any]) -> None:
    """Write JSON atomically (indented, ending with a newline)."""
    atomic_write_text(path, json.dumps(data, indent=2) + "\n")


# -- reading a run back ---------------------------------------------------------------


@dataclass(frozen=True)
class Metrics:
    """The columns of ``metrics.csv``."""

    episode: np.ndarray
    returns: np.ndarray
    lengths: np.ndarray
    epsilons: np.ndarray
    alphas: np.ndarray


@dataclass(frozen=True)
class Run:
    """A complete run directory, loaded and checked."""

    path: Path
    config: Config
    q_table: np.ndarray
    visits: np.ndarray | None
    metrics: Metrics
    summary: dict[str, Any]

    @property
    def name(self) -> str:
        """The directory's name."""
        return self.path.name


def is_multi_seed(path: Path) -> bool:
    """Whether ``path`` is the parent directory of a multi-seed run."""
    return (path / CONFIG_FILE).is_file() and _config_of(path).train.seeds is not None


def load_run(path: str | Path) -> Run:
    """Load a single run directory, checking every file it needs.

    Raises:
        RunError: the directory is not a complete run, or a file is missing, truncated,
            of the wrong shape or dtype, or holds NaN values; the message names the file.
    """
    path = Path(path)
    if not path.exists():
        raise RunError(
            f"{path}: does not exist (expected a run directory from `cartpole-q train`)."
        )
    if not path.is_dir():
        raise RunError(
            f"{path}: is not a directory (expected a run directory from `cartpole-q train`)."
        )
    if not (path / CONFIG_FILE).is_file():
        raise RunError(f"{path}: is not a run directory (it has no {CONFIG_FILE}).")
    config = _config_of(path)
    if config.train.seeds is not None:
        raise RunError(
            f"{path}: is a multi-seed run; its runs are the seed-* directories inside it."
        )
    if not (path / SUMMARY_FILE).is_file():
        hint = (
            f"; resume it with `cartpole-q train --resume {path}`"
            if (path / CHECKPOINT_FILE).is_file()
            else ""
        )
        raise RunError(f"{path}: training did not finish (no {SUMMARY_FILE}){hint}.")
    summary = _read_summary(path / SUMMARY_FILE)
    q_table = load_array(path / Q_TABLE_FILE, np.float64)
    check_q_table(q_table, config.discretization.bins, None, str(path / Q_TABLE_FILE))
    visits = None
    if (path / VISITS_FILE).is_file():
        visits = load_array(path / VISITS_FILE, np.int64)
        if visits.shape != q_table.shape:
            raise RunError(
                f"{path / VISITS_FILE}: has shape {visits.shape}, but the Q-table's is {q_table.shape}."
            )
    metrics = read_metrics(path / METRICS_FILE)
    return Run(
        path=path, config=config, q_table=q_table, visits=visits, metrics=metrics, summary=summary
    )


def load_array(path: Path, dtype: type) -> np.ndarray:
    """Load an ``.npy`` file without pickle and check its dtype.

    Raises:
        RunError: the file is missing, truncated, an object array, or of another dtype.
    """
    if not path.is_file():
        raise RunError(f"{path}: is missing.")
    try:
        with open(path, "rb") as stream:
            magic = stream.read(len(NPY_MAGIC))
    except OSError as error:
        raise RunError(f"{path}: cannot be read ({error.strerror}).") from None
    if magic != NPY_MAGIC:
        raise RunError(
            f"{path}: is not a NumPy array file (.npy); it was not written by cartpole-q."
        )
    try:
        array = np.load(path, allow_pickle=False)
    except ValueError as error:
        if "allow_pickle" in str(error):
            raise RunError(
                f"{path}: holds Python objects; only numeric arrays are accepted."
            ) from None
        raise RunError(f"{path}: is not a valid .npy array ({error}).") from None
    except (OSError, EOFError) as error:
        raise RunError(f"{path}: cannot be read as a .npy array ({error}).") from None
    if not isinstance(array, np.ndarray) or array.dtype != np.dtype(dtype):
        found = getattr(array, "dtype", type(array).__name__)
        raise RunError(f"{path}: must hold {np.dtype(dtype).name} values, found {found}.")
    return array


def check_q_table(
    q_table: np.ndarray, bins: tuple[int, ...], n_actions: int | None, source: str
) -> None:
    """Check a Q-table against its config's grid (and the environment's actions).

    Raises:
        RunError: wrong dtype or shape, or a non-finite value.
    """
    if q_table.dtype != np.float64:
        raise RunError(f"{source}: must hold float64 values, found {q_table.dtype}.")
    expected = f"(*bins, n_actions) = ({', '.join(map(str, bins))}, {n_actions or 'n_actions'})"
    if q_table.ndim != len(bins) + 1 or tuple(q_table.shape[:-1]) != tuple(bins):
        raise RunError(
            f"{source}: has shape {q_table.shape}, which does not match its config: expected {expected}."
        )
    if n_actions is not None and q_table.shape[-1] != n_actions:
        raise RunError(
            f"{source}: has {q_table.shape[-1]} actions per state but the environment has "
            f"{n_actions}: expected {expected}."
        )
    if not np.isfinite(q_table).all():
        raise RunError(f"{source}: holds NaN or infinite values.")


def read_metrics(path: Path) -> Metrics:
    """Read ``metrics.csv``.

    Raises:
        RunError: the file is missing, has another header, or a row is not numeric.
    """
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise RunError(f"{path}: is missing.") from None
    except (OSError, UnicodeDecodeError) as error:
        raise RunError(f"{path}: cannot be read ({error}).") from None
    rows = list(csv.reader(io.StringIO(text)))
    if not rows or tuple(rows[0]) != METRICS_HEADER:
        raise RunError(f"{path}: must start with the header {','.join(METRICS_HEADER)}.")
    try:
        columns = np.array([[float(value) for value in row] for row in rows[1:]], dtype=np.float64)
    except ValueError:
        raise RunError(f"{path}: has a row that is not five numbers.") from None
    if columns.size and (columns.ndim != 2 or columns.shape[1] != len(METRICS_HEADER)):
        raise RunError(f"{path}: every row must have {len(METRICS_HEADER)} values.")
    columns = columns.reshape(-1, len(METRICS_HEADER))
    return Metrics(
        episode=columns[:, 0].astype(np.int64),
        returns=columns[:, 1],
        lengths=columns[:, 2].astype(np.int64),
        epsilons=columns[:, 3],
        alphas=columns[:, 4],
    )


def _read_summary(path: Path) -> dict[str, Any]:
    try:
        summary = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as error:
        raise RunError(f"{path}: is not valid JSON ({error}).") from None
    if not isinstance(summary, dict):
        raise RunError(f"{path}: must hold a JSON object.")
    return summary


def _config_of(path: Path) -> Config:
    try:
        return load_config(path / CONFIG_FILE)
    except ConfigError as error:
        raise RunError(f"{path}: its {CONFIG_FILE} is not a valid config. {error}") from None
