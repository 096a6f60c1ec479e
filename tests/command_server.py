"""Run many ``cartpole-q`` commands without importing the package again for each one.

A tutorial runs dozens of commands, each a new interpreter that imports numpy, numba,
Gymnasium, matplotlib and the package before it does anything (about 0.7 s of a command
that then trains for one or two), and numba loads its typing and lowering registries at
the first compiled call (about 0.4 s more). :func:`command_server` starts one process that
imports them (and every module of the package) once, loads numba's registries, and puts a
``cartpole-q`` first on ``PATH`` whose every call is served by a process forked from it:
the command's own arguments, working directory, environment, standard streams and exit
code, and ``cartpole_q.cli.main`` run as the console script runs it, in a process of its
own that exits as that one would (its ``atexit`` handlers included). Nothing is compiled
or run in the server itself, so no command sees another's state. The console script's own
start-up is tested where it matters (``tests/test_cli.py``, ``tests/test_makefile.py``).
"""

from __future__ import annotations

import contextlib
import os
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path

SERVER = r"""
import json, os, socket, sys

import importlib, pkgutil
import numpy, numba, gymnasium  # noqa: F401
import matplotlib.figure, matplotlib.backends.backend_agg  # noqa: F401
import typer._adapters  # noqa: F401  (what typer imports to convert a command's options)
import cartpole_q
from cartpole_q.cli import main  # the console script's entry point
from numba.core.registry import cpu_target

# Every module a command may import, and numba's typing and lowering registries, which
# numba loads in each process at its first compiled call (about 0.4 s): once here.
for module in pkgutil.walk_packages(cartpole_q.__path__, "cartpole_q."):
    if module.name != "cartpole_q.__main__":
        importlib.import_module(module.name)
cpu_target.target_context.refresh()

listener = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
listener.bind(sys.argv[1])
listener.listen()
print("ready", flush=True)
while True:
    connection, _ = listener.accept()
    message, fds, _, _ = socket.recv_fds(connection, 1 << 22, 3)
    while not message.endswith(b"\n"):
        message += connection.recv(1 << 22)
    request = json.loads(message)
    pid = os.fork()
    if pid == 0:  # the command: its streams, directory and environment; exits as it would
        listener.close()
        connection.close()
        for number, fd in enumerate(fds):
            os.dup2(fd, number)
            os.close(fd)
        os.chdir(request["cwd"])
        os.environ.clear()
        os.environ.update(request["env"])
        sys.argv = request["argv"]
        main()
        sys.exit(0)
    for fd in fds:
        os.close(fd)
    _, status = os.waitpid(pid, 0)
    code = os.waitstatus_to_exitcode(status)
    connection.sendall(str(code if code >= 0 else 128 - code).encode())
    connection.close()
"""

CLIENT = r"""
import json, os, socket, sys

connection = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
connection.connect(os.environ["CARTPOLE_Q_COMMAND_SERVER"])
request = {"argv": ["cartpole-q", *sys.argv[1:]], "cwd": os.getcwd(), "env": dict(os.environ)}
socket.send_fds(connection, [json.dumps(request).encode() + b"\n"], [0, 1, 2])
sys.exit(int(connection.recv(16) or b"1"))
"""


@contextlib.contextmanager
def command_server(env: dict[str, str]) -> Iterator[dict[str, str]]:
    """Serve ``cartpole-q`` for commands run with the environment this yields.

    Args:
        env: the commands' environment (the server imports with it).

    Yields:
        ``env`` with the client first on ``PATH``.
    """
    # (a directory of its own, short: a socket's path may not be longer than 107 bytes)
    directory = Path(tempfile.mkdtemp(prefix="cartpole-q-commands-"))
    socket_path = directory / "server.sock"
    client = directory / "cartpole-q"
    client.write_text(f"#!{sys.executable} -S\n{CLIENT}", encoding="utf-8")
    client.chmod(0o755)
    server = subprocess.Popen(
        [sys.executable, "-c", SERVER, str(socket_path)], env=env, stdout=subprocess.PIPE,
        text=True,
    )  # fmt: skip
    try:
        assert server.stdout is not None and server.stdout.readline() == "ready\n"
        yield {
            **env,
            "PATH": f"{directory}{os.pathsep}{env.get('PATH', '')}",
            "CARTPOLE_Q_COMMAND_SERVER": str(socket_path),
        }
    finally:
        server.kill()
        server.wait()
        shutil.rmtree(directory, ignore_errors=True)
