"""``bearingsim`` command lines for the tests, each in a process forked from one that has the package
imported.

The suite runs a few hundred command lines. Started as ``python -m bearingsim``, each pays a fresh
interpreter's start before its command begins: ~0.6 s of imports (numpy, pydantic, h5py) for a
refusal, ~1.5 s for a command that runs a model (numba and its first-use set-up of the CPU target,
which imports scipy's BLAS). Here one server process per test worker, started on first use, imports the
package and sets numba's CPU target up once; each command line is a fork of it, with its own pid,
standard streams, working directory and exit status, that runs ``bearingsim/__main__.py`` as
``python -m bearingsim`` does (``runpy``) and ends as the interpreter ends: an uncaught exception is
printed by ``sys.excepthook`` (exit status 1), ``SystemExit`` gives its code, the ``atexit``
functions run, and standard output and error are flushed (a failed flush is reported as the
interpreter reports it, exit status 120).

What a fork does not repeat is the interpreter's start: the imports, and the hash seed of ``str``
(every fork of one server has the server's). The tests that need those start fresh interpreters of
their own: ``tests/test_startup_imports.py`` (what a command imports), the signal, terminal,
broken-pipe and locale tests (``conftest.started`` and ``subprocess``), and the reruns compared for
identical bytes, whose second run is a fresh interpreter (``fresh_interpreter=True``).
``tests/test_forked_cli.py`` runs command lines both ways and compares their exit status, standard
output and standard error byte for byte. ``BEARINGSIM_TEST_FORK=0`` runs every command line in a
fresh interpreter.
"""
from __future__ import annotations

import contextlib
import json
import os
import signal
import socket
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FORK = os.environ.get("BEARINGSIM_TEST_FORK", "1") != "0"
#: ``args[0]`` of a forked command line's ``CompletedProcess`` (a fresh interpreter's is ``sys.executable``)
FORKED = "<fork of the tests' bearingsim server>"


def pythonpath() -> str:
    """A child interpreter's PYTHONPATH: this checkout first, then the test process's own (where an install
    by ``pip --target``, Nix or an HPC module puts the dependencies)."""
    return str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", "")


def environment() -> dict:
    """The environment of a command line: the test process's as it is now, with this checkout first on
    the path."""
    return {**os.environ, "PYTHONPATH": pythonpath()}


def _translate(data: bytes) -> str:
    """``subprocess.run(..., text=True)``'s decoding: the locale's encoding, universal newlines."""
    import locale

    return data.decode(locale.getpreferredencoding(False)).replace("\r\n", "\n").replace("\r", "\n")


def fresh(args, cwd=None, timeout=600) -> subprocess.CompletedProcess:
    """``python -m bearingsim ARGS`` in a fresh interpreter."""
    return subprocess.run([sys.executable, "-m", "bearingsim", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, timeout=timeout, env=environment())


class _Server:
    """The server process and this side of its socket."""

    def __init__(self):
        self.env = environment()
        mine, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_STREAM)
        self.proc = subprocess.Popen([sys.executable, "-c", f"from tests.forked_cli import serve; serve({theirs.fileno()})"],
                                     pass_fds=[theirs.fileno()], stdin=subprocess.DEVNULL,
                                     stdout=subprocess.DEVNULL, stderr=None, env=self.env, cwd=ROOT)
        theirs.close()
        self.sock = mine
        self.file = mine.makefile("r", encoding="utf-8")
        ready = self.file.readline()
        if ready.strip() != "ready":
            raise RuntimeError(f"the command-line server of the tests did not start ({ready!r})")

    def close(self) -> None:
        """End the server (closing twice does nothing)."""
        self.file.close()
        self.sock.close()
        if self.proc.poll() is None:
            self.proc.kill()
        self.proc.wait()

    def run(self, args, cwd, timeout) -> subprocess.CompletedProcess:
        import tempfile

        with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
            request = json.dumps({"args": [str(a) for a in args], "cwd": str(cwd or os.getcwd())}).encode()
            socket.send_fds(self.sock, [request + b"\n"], [0, out.fileno(), err.fileno()])
            pid = int(self.file.readline())
            self.sock.settimeout(timeout)
            try:
                line = self.file.readline()
            except TimeoutError:  # as subprocess.run: the command killed; the server too (its socket timed out)
                os.kill(pid, signal.SIGKILL)
                self.close()
                raise subprocess.TimeoutExpired(["bearingsim", *map(str, args)], timeout) from None
            self.sock.settimeout(None)
            status = int(line)
            out.seek(0)
            err.seek(0)
            return subprocess.CompletedProcess([FORKED, *map(str, args)], status,
                                               _translate(out.read()), _translate(err.read()))


_server: _Server | None = None


def _changed(before: dict, now: dict) -> bool:
    """Whether the environment changed, but pytest's name of the running test (no command reads it)."""
    ignored = {"PYTEST_CURRENT_TEST"}
    return {k: v for k, v in before.items() if k not in ignored} != {k: v for k, v in now.items() if k not in ignored}


def run(args, cwd=None, timeout=600, fresh_interpreter=False) -> subprocess.CompletedProcess:
    """``bearingsim ARGS`` run to its end, as ``subprocess.run([python, -m, bearingsim, *ARGS],
    capture_output=True, text=True)`` returns it: in a fork of the server, or with
    ``fresh_interpreter`` (or ``BEARINGSIM_TEST_FORK=0``) in a fresh interpreter. The server runs in
    the environment of the test process: when that changed since the server started (a test's
    ``monkeypatch.setenv``; a dask cluster sets ``PYTHONHASHSEED`` and the thread counts for good), a
    new server starts in the new one."""
    global _server
    if fresh_interpreter or not FORK or (cwd is not None and not Path(cwd).is_dir()):
        return fresh(args, cwd, timeout)  # (a missing folder: subprocess's own error)
    if _server is not None and (_server.proc.poll() is not None or _changed(_server.env, environment())):
        _server.close()
        _server = None
    if _server is None:
        import atexit

        _server = _Server()
        atexit.register(_server.close)  # at the worker's exit: no server left running, no socket left open
    return _server.run(args, cwd, timeout)


# --- the server side ------------------------------------------------------------------------------------
def _preload() -> None:
    """Import what the commands import, and set numba's CPU target up (its first use imports the
    extensions it registers, scipy's BLAS among them)."""
    import pkgutil

    import bearingsim

    for mod in pkgutil.walk_packages(bearingsim.__path__, "bearingsim."):
        if mod.name != "bearingsim.__main__":
            __import__(mod.name)
    from numba.core.registry import cpu_target

    cpu_target.target_context.refresh()


def _exit_status(code) -> int:
    """The exit status of ``SystemExit(code)`` as the interpreter gives it."""
    if code is None:
        return 0
    if isinstance(code, int):
        return code & 0xFF
    print(code, file=sys.stderr)
    return 1


def _child(request: dict, fds: list[int]) -> None:  # pragma: no cover - runs in the forked process
    for target, fd in enumerate(fds):
        os.dup2(fd, target)
        os.close(fd)
    os.chdir(request["cwd"])
    status = 0
    interrupted = False
    try:
        import runpy

        sys.argv = ["bearingsim", *request["args"]]
        runpy.run_module("bearingsim", run_name="__main__", alter_sys=True)
    except SystemExit as exc:
        status = _exit_status(exc.code)
    except KeyboardInterrupt:
        sys.excepthook(*sys.exc_info())
        interrupted = True
    except BaseException:
        sys.excepthook(*sys.exc_info())
        status = 1
    import atexit
    import threading

    threading._shutdown()  # the interpreter's own end: wait for the threads a command left running
    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except Exception as exc:  # as the interpreter's last flush reports it
            import traceback

            with contextlib.suppress(Exception):
                os.write(2, (f"Exception ignored in: {stream!r}\n"
                             + "".join(traceback.format_exception_only(exc))).encode("utf-8", "backslashreplace"))
            status = 120
    if interrupted:
        signal.signal(signal.SIGINT, signal.SIG_DFL)
        os.kill(os.getpid(), signal.SIGINT)
    os._exit(status)


def serve(fd: int) -> None:  # pragma: no cover - the server process
    sock = socket.socket(fileno=fd)
    _preload()
    sock.sendall(b"ready\n")
    while True:
        buffered, fds = b"", []
        while not buffered.endswith(b"\n"):
            data, got, _, _ = socket.recv_fds(sock, 65536, 3)
            if not data:
                return
            buffered += data
            fds += got
        request = json.loads(buffered)
        sys.stdout.flush()
        sys.stderr.flush()
        pid = os.fork()
        if pid == 0:
            try:
                sock.close()
                _child(request, fds)
            finally:  # never back into this loop
                os._exit(1)
        for fd_ in fds:
            os.close(fd_)
        sock.sendall(f"{pid}\n".encode())
        _, wait_status = os.waitpid(pid, 0)
        sock.sendall(f"{os.waitstatus_to_exitcode(wait_status)}\n".encode())
