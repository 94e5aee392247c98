"""A warm command line for the signal tests: one process imports the engine once, then forks
a child per command, so a case pays for its job, not for a fresh interpreter's imports.

Each child is what ``quilt-studio ARGS`` is after its imports: it runs
``quilt_gui.__main__.main(ARGS)`` in its own session with the default signal handlers, stdin and
stdout on /dev/null and stderr in a file, and exits with its exit code. :class:`Child` has the
parts of :class:`subprocess.Popen` the signal tests use (``pid``, ``stderr.readline/read/close``,
``poll``, ``wait``), so :func:`tests.engine.hostile.wait_for_line` and ``signal_and_wait`` work
on it unchanged. What only a fresh process shows (the interpreter's start, the imports, the exit
through ``sys.exit``) is checked by the real-process cases next to them.
"""

from __future__ import annotations

import json
import os
import select
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from tests.engine.hostile import REPO

_SERVER = r"""
import json, os, pkgutil, signal, sys, importlib
import engine
from quilt_gui.__main__ import main
for m in pkgutil.walk_packages(engine.__path__, "engine."):
    if not m.name.startswith("engine.batch") and not m.name.endswith("__main__"):
        importlib.import_module(m.name)
engine._jit.load()  # numba too: the engine imports it at its first kernel call
print("ready", flush=True)
for line in sys.stdin:
    request = json.loads(line)
    sys.stderr.flush()
    pid = os.fork()
    if pid == 0:
        code = 70
        try:
            os.setsid()
            signal.signal(signal.SIGINT, signal.default_int_handler)
            signal.signal(signal.SIGTERM, signal.SIG_DFL)
            null = os.open(os.devnull, os.O_RDWR)
            os.dup2(null, 0)
            os.dup2(null, 1)
            err = os.open(request["stderr"], os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
            os.dup2(err, 2)
            os.chdir(request["cwd"])
            code = main(request["argv"])
        except SystemExit as exc:
            code = exc.code if isinstance(exc.code, int) else 2
        except BaseException:
            import traceback
            traceback.print_exc()
        finally:
            sys.stderr.flush()
            os._exit(code)
    print(pid, flush=True)
    print(os.waitstatus_to_exitcode(os.waitpid(pid, 0)[1]), flush=True)
"""


class _Tail:
    """The child's stderr file read as it grows (like a pipe: EOF once the child has ended)."""

    def __init__(self, path: Path, child: Child):
        self._file = open(path, encoding="utf-8", errors="replace")  # noqa: SIM115
        self._child = child

    def readline(self) -> str:
        line = ""
        while True:
            line += self._file.readline()
            if line.endswith("\n"):
                return line
            if self._child.poll() is not None:
                return line + self._file.read()
            time.sleep(0.005)

    def read(self) -> str:
        self._child.wait()
        return self._file.read()

    def close(self) -> None:
        self._file.close()

    def __del__(self) -> None:
        # closed when dropped: an unclosed file's ResourceWarning would surface wherever the
        # collector happens to run (in another test's captured stderr)
        self._file.close()


class Child:
    def __init__(self, server: WarmCli, pid: int, stderr: Path):
        self._server = server
        self.pid = pid
        self.returncode: int | None = None
        self.stderr = _Tail(stderr, self)

    def poll(self) -> int | None:
        if self.returncode is None:
            line = self._server._line(timeout=0)
            if line is not None:
                self.returncode = int(line)
        return self.returncode

    def wait(self, timeout: float | None = None) -> int:
        if self.returncode is None:
            line = self._server._line(timeout=timeout)
            if line is None:
                raise subprocess.TimeoutExpired("warm quilt-studio", timeout)
            self.returncode = int(line)
        return self.returncode


class WarmCli:
    """``start(*args)`` forks a warm ``quilt-studio ARGS``; one child at a time."""

    def __init__(self):
        self._dir = tempfile.TemporaryDirectory(prefix="warm-cli-")
        self._proc = subprocess.Popen(
            [sys.executable, "-u", "-c", _SERVER],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            cwd=REPO,
            env={**os.environ, "PYTHONUNBUFFERED": "1"},
        )
        self._buffer = b""
        self._count = 0
        self._child: Child | None = None
        assert self._line(timeout=300) == "ready", "the warm CLI did not start"

    def _line(self, timeout: float | None) -> str | None:
        """The server's next stdout line, or None when none came within ``timeout``."""
        end = None if timeout is None else time.monotonic() + timeout
        fd = self._proc.stdout.fileno()
        while b"\n" not in self._buffer:
            left = None if end is None else max(0.0, end - time.monotonic())
            if not select.select([fd], [], [], left)[0]:
                return None
            chunk = os.read(fd, 4096)
            assert chunk, "the warm CLI server ended"
            self._buffer += chunk
        line, self._buffer = self._buffer.split(b"\n", 1)
        return line.decode()

    def _end_child(self) -> None:
        """kill -9 a child still running (a failed test's) and collect its exit."""
        if self._child is not None and self._child.poll() is None:
            os.kill(self._child.pid, signal.SIGKILL)
            self._child.wait()

    def start(self, *args, cwd=None) -> Child:
        self._end_child()
        self._count += 1
        stderr = Path(self._dir.name) / f"stderr-{self._count}.txt"
        stderr.touch()
        request = {"argv": list(map(str, args)), "stderr": str(stderr), "cwd": str(cwd or REPO)}
        self._proc.stdin.write(json.dumps(request).encode() + b"\n")
        self._proc.stdin.flush()
        self._child = Child(self, int(self._line(timeout=60)), stderr)
        return self._child

    def close(self) -> None:
        self._end_child()
        self._proc.stdin.close()
        self._proc.wait(timeout=60)
        self._proc.stdout.close()
        self._dir.cleanup()
