"""How a sub-command ends: its exit code and one clear line on stderr for every error,
signal and warning, never a traceback.

Exit codes: 0 done, 1 refused or failed (the line says why: bad input, bad option, an output
that cannot be written, not enough memory; or a bug, reported as an internal error — set
``QUILT_DEBUG=1`` for its traceback), 2 bad command line (argparse), 130 interrupted
(Ctrl+C, SIGINT), 143 terminated (SIGTERM). Every output is written atomically, so an error or
a signal never leaves a half-written file or folder behind.
"""

from __future__ import annotations

import gc
import os
import signal
import sys
import threading
import warnings
from contextlib import contextmanager

__all__ = ["Terminated", "run_command", "stopped_early"]


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised in the main thread like Ctrl+C so every job cancels and cleans up."""


_received: list[int] = []
"""Signals received by the handlers below (one may be swallowed where it is raised, e.g. in
the middle of an extension module's import: the command then still ends with its code)."""


RAISE_AGAIN = 5
"""Times a dropped signal is raised again (each lands somewhere new: one more drop is rare)."""


def _on_signal(signum, frame):
    _received.append(signum)
    raise Terminated if signum == signal.SIGTERM else KeyboardInterrupt


@contextmanager
def _sigterm_as_interrupt():
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {s: signal.signal(s, _on_signal) for s in (signal.SIGTERM, signal.SIGINT)}
    hook = sys.unraisablehook
    active = [True]

    def again(signum):
        if active[0]:
            signal.raise_signal(signum)

    def swallowed_signal_again(unraisable):
        """The signal's exception raised where Python cannot pass it on — a ctypes callback of
        numba's compiler, a destructor, an at-fork hook (seen: logging's, at the quilting
        workers' fork) — is dropped: print nothing and raise the signal again a moment later,
        once that code has returned, so the job still stops."""
        if not (_received and isinstance(unraisable.exc_value, KeyboardInterrupt)):
            hook(unraisable)
        elif len(_received) <= RAISE_AGAIN:
            threading.Timer(0.05, again, (_received[-1],)).start()

    sys.unraisablehook = swallowed_signal_again
    try:
        yield
    finally:
        active[0] = False
        sys.unraisablehook = hook
        for s, handler in previous.items():
            signal.signal(s, handler)


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


def _drop_interrupted(exc: BaseException) -> None:
    """Free what the stopped job held, ignoring errors of destructors: a signal that cuts
    numba's compiler mid-way leaves llvmlite objects whose ``__del__`` fails ("Exception
    ignored in ... ObjectRef.__del__", seen once in ~14 runs of the signal tests) and would print
    a traceback after the one-line outcome."""
    import traceback

    traceback.clear_frames(exc.__traceback__)
    hook = sys.unraisablehook
    sys.unraisablehook = lambda _unraisable: None
    try:
        gc.collect()
    finally:
        sys.unraisablehook = hook


def run_command(args) -> int:
    """Run ``args.func(args)``; the exit code (see the module docstring)."""
    from engine.io import ImageError

    name = f"quilt-studio {args.command}"
    kept = "no output was left half-written"
    _received.clear()
    try:
        with _sigterm_as_interrupt(), _warnings_as_lines(name):
            code = int(args.func(args) or 0)
        term = bool(_received) and _received[0] == signal.SIGTERM
        if _received and code != (143 if term else 130):
            # a signal came but was swallowed where it was raised: the work is done (a command
            # that stops on it itself, the batch, returns its code and has said so)
            what = "terminated (SIGTERM)" if term else "interrupted"
            print(f"{name}: {what} as it finished; its outputs are complete", file=sys.stderr)
            return 143 if term else 130
        return code
    except (ImageError, ValueError, TypeError, OSError) as exc:  # engine validation errors
        print(f"{name}: error: {exc or type(exc).__name__}", file=sys.stderr)
        return 1
    except MemoryError:
        print(
            f"{name}: error: out of memory ({kept}); use smaller inputs or sizes, or free memory",
            file=sys.stderr,
        )
        return 1
    except Terminated as exc:
        _drop_interrupted(exc)
        print(f"{name}: terminated (SIGTERM); {kept}", file=sys.stderr)
        return 143
    except KeyboardInterrupt as exc:
        _drop_interrupted(exc)
        print(f"{name}: interrupted; {kept}", file=sys.stderr)
        return 130
    except Exception as exc:  # noqa: BLE001 - a bug: one line (QUILT_DEBUG=1 shows where)
        if os.environ.get("QUILT_DEBUG"):
            raise
        if _received:  # the signal, swallowed where it was raised, broke the job on its way out
            # (numba's compiler cut mid-way: "no compiled object yet for <Library ...>")
            _drop_interrupted(exc)
            term = _received[0] == signal.SIGTERM
            what = "terminated (SIGTERM)" if term else "interrupted"
            print(f"{name}: {what}; {kept}", file=sys.stderr)
            return 143 if term else 130
        print(
            f"{name}: internal error, please report it: {type(exc).__name__}: {exc} "
            f"({kept}; QUILT_DEBUG=1 shows the traceback)",
            file=sys.stderr,
        )
        return 1
