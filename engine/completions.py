"""Waiting for worker threads' futures in a way Ctrl+C and SIGTERM cannot wedge.

``concurrent.futures.wait`` takes every future's lock in turn; a ``KeyboardInterrupt`` (or the
CLI's SIGTERM exception) raised between two of those acquisitions leaves the rest held for ever,
so the worker that finishes such a future blocks in ``set_result`` and the pool's shutdown (and
the interpreter's exit) waits on it: the process hangs instead of ending with its exit code.
:class:`Completions` has each future put itself on a queue when it is done (one callback,
registered when the future is submitted); waiting is a ``get`` on that queue, which holds no
future's lock while it blocks.
"""

from __future__ import annotations

import queue
from concurrent.futures import Future

__all__ = ["Completions"]


class Completions:
    """The futures :meth:`watch`-ed so far that are done, as they finish."""

    def __init__(self) -> None:
        self._queue: queue.SimpleQueue = queue.SimpleQueue()
        self._finished: set[Future] = set()

    def watch(self, future: Future) -> Future:
        """Report ``future`` here when it is done (finished, failed or cancelled)."""
        future.add_done_callback(self._queue.put)
        return future

    def wait(self, futures) -> set[Future]:
        """Block until at least one of ``futures`` (all watched) is done; those that are."""
        wanted = set(futures)
        if not wanted:
            raise ValueError("nothing to wait for")
        self._take_ready()
        while not wanted & self._finished:
            self._finished.add(self._queue.get())
            self._take_ready()
        return wanted & self._finished

    def is_done(self, future: Future) -> bool:
        """Whether ``future`` has been reported done (without taking its lock)."""
        self._take_ready()
        return future in self._finished

    def _take_ready(self) -> None:
        while True:
            try:
                self._finished.add(self._queue.get_nowait())
            except queue.Empty:
                return
