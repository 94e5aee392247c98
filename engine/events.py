"""Event base classes streamed by ``iter_*`` engine generators.

Two kinds matter to a consumer:

* :class:`Snapshot` — the latest wins; a GUI may drop older ones and redraw
  at most ~30 Hz (an improved seam, the best template so far, a placed block).
* :class:`Item` — each must arrive (a finished candidate tile).

:class:`Progress` reports how far a job is. Concrete events are frozen,
slotted dataclasses defined next to the algorithm that yields them; arrays in
them are read-only copies (see :func:`frozen_array`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


class Event:
    """Base of every engine event."""

    __slots__ = ()


class Snapshot(Event):
    """An intermediate state; a newer snapshot of the same type and :attr:`slot` supersedes it."""

    __slots__ = ()

    @property
    def slot(self):
        """Which of several parallel states this is (e.g. one per overlap); None: one per type."""
        return None


class Item(Event):
    """A finished piece of the result; consumers must keep every one."""

    __slots__ = ()


@dataclass(frozen=True, slots=True)
class Progress(Event):
    """``done`` of ``total`` steps finished; ``message`` says of what."""

    done: int
    total: int
    message: str = ""

    @property
    def fraction(self) -> float:
        return 1.0 if self.total <= 0 else min(1.0, self.done / self.total)


def frozen_array(a: np.ndarray) -> np.ndarray:
    """A read-only copy of ``a``, safe to hand to another thread."""
    out = np.array(a, copy=True)
    out.setflags(write=False)
    return out


def drain(gen, on_event=None):
    """Run an event generator to its end and return its return value; ``on_event``, if
    given, is called with every event on the way."""
    while True:
        try:
            event = next(gen)
        except StopIteration as stop:
            return stop.value
        if on_event is not None:
            on_event(event)
