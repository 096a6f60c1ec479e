"""What every command shares: the Typer app, exit codes, the stop routine, the backend.

Exit codes: 0 success; 2 bad usage or bad input (one paragraph on stderr naming the file
or field, never a traceback); 1 unexpected failure; 130 interrupted.

Heavy modules (numpy, numba, gymnasium, matplotlib) are imported inside the commands, so
``cartpole-q --help`` starts in a fraction of a second.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from enum import StrEnum
from typing import TYPE_CHECKING, Annotated, Any, NoReturn

import typer
from typer.core import TyperCommand, TyperGroup

from cartpole_q.errors import UserError, WriteError

if TYPE_CHECKING:
    from cartpole_q.engines.plan import Plan
    from cartpole_q.experiments.run import StopRequest

EXIT_BAD_INPUT = 2
EXIT_INTERRUPTED = 130


class _App(TyperGroup):
    """The root command: a usage error is one line on stderr and exit code 2, as ours are.

    Typer would draw a box around it; a user reads the same one-paragraph form as every
    other bad input (``error: ...``), with where to find the command's options.
    """

    def main(  # type: ignore[override]
        self,
        args: Any = None,
        prog_name: str | None = None,
        complete_var: str | None = None,
        standalone_mode: bool = True,
        **extra: Any,
    ) -> Any:
        """Run the command line; usage errors become one line and exit code 2."""
        import sys

        _print_file_names_as_given(sys.stdout)
        _skip_the_last_collection()
        if not standalone_mode:
            return super().main(args, prog_name, complete_var, standalone_mode, **extra)
        try:
            code = super().main(args, prog_name, complete_var, False, **extra)
        except typer.Abort:
            typer.echo("interrupted", err=True)
            sys.exit(EXIT_INTERRUPTED)
        except typer.TyperException as error:  # Typer's (click's) usage errors
            exit_code = getattr(error, "exit_code", EXIT_BAD_INPUT)
            context = getattr(error, "ctx", None)
            where = f" (see `{context.command_path} --help`)" if context is not None else ""
            message = error.format_message() if hasattr(error, "format_message") else str(error)
            typer.echo(f"error: {message}{where}", err=True)
            sys.exit(exit_code)
        sys.exit(code if isinstance(code, int) else 0)


@functools.cache
def _skip_the_last_collection() -> None:
    """Spare the interpreter's exit its garbage collection of everything still alive.

    At exit Python collects the objects left, numba's and LLVM's hundreds of thousands
    among them: about half a second of a warm ``train``, a quarter of it. A command has
    closed every file it wrote by then (each is written in a ``with`` block), so nothing
    waits on that collection: once the exit handlers registered from here on have run,
    the objects left are frozen out of its reach. Registered once per process (tests run
    many commands in one), and only at exit: a process that goes on collects as before.
    """
    import atexit
    import gc

    atexit.register(gc.freeze)


def _print_file_names_as_given(stream: Any) -> None:
    r"""Print a path that is not UTF-8 as its own bytes instead of failing.

    Such a name (``--out $'bad\xffname'``) reaches Python with surrogate escapes, which a
    UTF-8 stdout refuses under most locales: the command would fail at its last line, the
    run directory's path, which scripts read back (and need byte for byte).
    """
    reconfigure = getattr(stream, "reconfigure", None)
    if reconfigure is not None and getattr(stream, "encoding", "").lower() in ("utf-8", "utf8"):
        reconfigure(errors="surrogateescape")


app = typer.Typer(
    cls=_App,
    name="cartpole-q",
    help="Tabular reinforcement learning on Gymnasium: train, evaluate, plot, sweep, tune.",
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    context_settings={"help_option_names": ["-h", "--help"]},
)


class Command(TyperCommand):
    """A command whose usage line reads like the README: ``eval [OPTIONS] RUN_DIR``.

    Typer writes required arguments as ``{run_dir}``; this writes each argument's metavar
    as given (``[RUN_DIR]`` when optional, ``RUN_DIR...`` when repeatable).
    """

    def format_help(self, ctx: Any, formatter: Any) -> None:
        """Help without Typer's type column for arguments (``<list[Path]>``): the name says it."""
        for param in self.params:
            if param.param_type_name == "argument":
                param.display_type_rich = lambda ctx: None  # type: ignore[attr-defined]
        super().format_help(ctx, formatter)

    def collect_usage_pieces(self, ctx: Any) -> list[str]:
        """The usage line after the command's name."""
        pieces = [self.options_metavar] if self.options_metavar else []
        for param in self.get_params(ctx):
            if param.param_type_name != "argument":
                continue
            name = param.metavar or (param.name or "").upper()
            name = f"{name}..." if param.nargs != 1 else name
            pieces.append(name if param.required else f"[{name}]")
        return pieces


def _print_version(value: bool) -> None:
    if value:
        from cartpole_q import __version__

        typer.echo(f"cartpole-q {__version__}")
        raise typer.Exit()


@app.callback()
def _main(
    version: Annotated[
        bool,
        typer.Option(
            "--version", callback=_print_version, is_eager=True, help="Print the version and exit."
        ),
    ] = False,
) -> None:
    """Tabular reinforcement learning on Gymnasium: train, evaluate, plot, sweep, tune."""


class EngineChoice(StrEnum):
    """The ``--engine`` values."""

    auto = "auto"
    numba = "numba"
    gymnasium = "gymnasium"


class PlayChoice(StrEnum):
    """The ``eval --engine`` values: where the greedy episodes are played."""

    gymnasium = "gymnasium"
    numba = "numba"


class BackendChoice(StrEnum):
    """The ``--backend`` values."""

    local = "local"
    ray = "ray"


@contextmanager
def exit_codes() -> Iterator[None]:
    """Turn bad input into exit code 2 and an interruption into 130, without tracebacks.

    SIGTERM interrupts like Ctrl-C (a command may handle both itself inside, with
    :func:`stoppable`); once interrupted, further signals are ignored while it exits.
    """
    import signal
    import threading

    def interrupt(signum: int, frame: object) -> None:
        raise KeyboardInterrupt

    main = threading.current_thread() is threading.main_thread()
    previous = {signum: signal.getsignal(signum) for signum in (signal.SIGINT, signal.SIGTERM)}
    interrupted = False
    if main:
        signal.signal(signal.SIGTERM, interrupt)
    # One planning scope per command: a config is planned, its environment inspected, once.
    from cartpole_q.engines.plan import planning

    try:
        with planning():
            yield
    except UserError as error:
        typer.echo(f"error: {error}", err=True)
        raise typer.Exit(EXIT_BAD_INPUT) from None
    except KeyboardInterrupt:
        interrupted = True
        if main:
            for signum in previous:
                signal.signal(signum, signal.SIG_IGN)
        typer.echo("interrupted", err=True)
        raise typer.Exit(EXIT_INTERRUPTED) from None
    except typer.Exit as exit_:
        interrupted = exit_.exit_code == EXIT_INTERRUPTED
        raise
    finally:
        # After an interruption, signals stay ignored until the process has exited.
        if main and not interrupted:
            for signum, handler in previous.items():
                if handler is not None:  # None: installed outside Python, cannot be restored
                    signal.signal(signum, handler)


@contextmanager
def stoppable(
    hint: str | Callable[[], str], stop_point: str = "the current episode"
) -> Iterator[StopRequest]:
    """The one stop routine of every command that can stop cleanly.

    A first SIGINT or SIGTERM asks the work to stop at its next safe point, ``stop_point``
    (the request is yielded: pass ``stop.is_set`` down); a second stops at once, and the
    command says so with ``hint`` (how to go on) and exits with 130.

    An exception with a ``text`` attribute (a sweep's, saying exactly what was saved) puts
    it before the hint (a callable hint is asked then, for what is known only later).
    After the block, :func:`exit_if_stopped` ends a stopped command.
    """
    from cartpole_q.experiments.run import StopRequest

    announce = lambda message: typer.echo(message, err=True)  # noqa: E731
    with StopRequest(announce, stop_point) as stop:
        try:
            yield stop
        except KeyboardInterrupt as error:
            saved = getattr(error, "text", None)
            how = hint() if callable(hint) else hint
            exit_interrupted(f"interrupted at once: {f'{saved}; ' if saved else ''}{how}")


@contextmanager
def kept_on_write_error(kept: str, how: str) -> Iterator[None]:
    """Once a directory holds what ``--resume`` needs, a failed write says it is kept.

    A full disk in the middle of a run or study is bad input of a kind (exit code 2), not
    a bug: the message names the file, then says what is kept and how to go on.

    Args:
        kept: what stays, e.g. ``The run directory runs/x is kept as far as it got``.
        how: how to go on, e.g. ``resume it with `cartpole-q train --resume runs/x```.
    """
    try:
        yield
    except WriteError as error:
        raise WriteError(
            f"{error} {kept}; make room (or fix what refused the write), then {how}."
        ) from None


def exit_if_stopped(stopped: bool, hint: str) -> None:
    """End a command that was asked to stop: ``interrupted: HINT`` and exit code 130."""
    if stopped:
        exit_interrupted(f"interrupted: {hint}")


def exit_interrupted(message: str) -> NoReturn:
    """Say how the command was interrupted, and exit with 130."""
    typer.echo(message, err=True)
    raise typer.Exit(EXIT_INTERRUPTED)


def note(text: str) -> None:
    """A note on stderr (what a command left out, or assumed)."""
    typer.echo(f"note: {text}", err=True)


@contextmanager
def backend_connection(
    backend: BackendChoice, workers: int | None, address: str | None
) -> Iterator[None]:
    """With ``--backend ray``, stay connected to Ray (a local cluster without ``--address``).

    Raises:
        UserError: ``--address`` without ``--backend ray``.
    """
    if address is not None and backend is not BackendChoice.ray:
        raise UserError("--address is for --backend ray.")
    if backend is not BackendChoice.ray:
        yield
        return
    import os

    from cartpole_q.experiments.workers import ray_connection

    with ray_connection(workers or os.cpu_count() or 1, address):
        yield


def say_if_compiling(config: Any, plan: Plan | None = None) -> None:
    """Tell the user when the first run will compile the training loop (seconds, once).

    ``plan`` is the run's plan when the command has one (nothing is checked again).
    """
    from cartpole_q.engines import compile_notice
    from cartpole_q.engines.plan import planned

    plan = plan or planned(config)
    notice = compile_notice(plan.config, plan.env_info, plan.engine, plan.twin)
    if notice is not None:
        typer.echo(notice, err=True)
