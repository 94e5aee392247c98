"""How a sub-command ends: its exit code and one clear line on stderr for every error,
signal and warning, never a traceback.

Exit codes: 0 done, 1 refused or failed (the line says why: bad input, bad option, an output
that cannot be written, not enough memory), 2 bad command line (argparse), 130 interrupted
(Ctrl+C, SIGINT), 143 terminated (SIGTERM). Every output is written atomically, so an error or
a signal never leaves a half-written file or folder behind.
"""

from __future__ import annotations

import signal
import sys
import threading
import warnings
from contextlib import contextmanager

__all__ = ["Terminated", "run_command", "stopped_early"]


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised in the main thread like Ctrl+C so every job cancels and cleans up."""


def _on_sigterm(signum, frame):
    raise Terminated


@contextmanager
def _sigterm_as_interrupt():
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, _on_sigterm)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


@contextmanager
def _warnings_as_lines(name: str):
    """Every warning (ours, numpy's, a library's) as one ``name: warning: text`` line, once."""
    seen: set[str] = set()

    def show(message, category, filename, lineno, file=None, line=None):
        text = str(message)
        if text not in seen:
            seen.add(text)
            print(f"{name}: warning: {text}", file=sys.stderr, flush=True)

    with warnings.catch_warnings():
        warnings.simplefilter("always")
        warnings.showwarning = show
        yield


@contextmanager
def stopped_early():
    """Around the set-up before :func:`run_command` (imports, parsing): SIGTERM or Ctrl+C
    there ends the process with its exit code and one line instead of a traceback; the
    yielded list receives that code."""
    code: list[int] = []
    try:
        with _sigterm_as_interrupt():
            yield code
    except Terminated:
        print("quilt-studio: terminated (SIGTERM) before it started", file=sys.stderr)
        code.append(143)
    except KeyboardInterrupt:
        print("quilt-studio: interrupted before it started", file=sys.stderr)
        code.append(130)


def run_command(args) -> int:
    """Run ``args.func(args)``; the exit code (see the module docstring)."""
    from engine.io import ImageError

    name = f"quilt-studio {args.command}"
    kept = "no output was left half-written"
    try:
        with _sigterm_as_interrupt(), _warnings_as_lines(name):
            return int(args.func(args) or 0)
    except (ImageError, ValueError, TypeError, OSError) as exc:  # engine validation errors
        print(f"{name}: error: {exc}", file=sys.stderr)
        return 1
    except MemoryError:
        print(
            f"{name}: error: out of memory ({kept}); use smaller inputs or sizes, or free memory",
            file=sys.stderr,
        )
        return 1
    except Terminated:
        print(f"{name}: terminated (SIGTERM); {kept}", file=sys.stderr)
        return 143
    except KeyboardInterrupt:
        print(f"{name}: interrupted; {kept}", file=sys.stderr)
        return 130
