"""Cooperative cancellation shared by every long engine function."""

from __future__ import annotations

import threading


class Cancelled(Exception):
    """Raised by non-anytime algorithms when their cancel token is set."""


class CancelToken:
    """A thread-safe flag checked by engine loops.

    Anytime algorithms return their best result so far when it is set;
    the others raise :class:`Cancelled`.
    """

    __slots__ = ("_event",)

    def __init__(self) -> None:
        self._event = threading.Event()

    def cancel(self) -> None:
        self._event.set()

    @property
    def cancelled(self) -> bool:
        return self._event.is_set()

    def raise_if_cancelled(self) -> None:
        if self._event.is_set():
            raise Cancelled("cancelled")


def is_cancelled(cancel: CancelToken | None) -> bool:
    """True when ``cancel`` is given and set (``None`` never cancels)."""
    return cancel is not None and cancel.cancelled


def check(cancel: CancelToken | None) -> None:
    """Raise :class:`Cancelled` when ``cancel`` is set."""
    if cancel is not None and cancel.cancelled:
        raise Cancelled("cancelled")


class AnyCancel:
    """Cancelled when any of the tokens is (duck-types :class:`CancelToken`)."""

    __slots__ = ("tokens",)

    def __init__(self, *tokens):
        self.tokens = tuple(t for t in tokens if t is not None)

    @property
    def cancelled(self) -> bool:
        return any(t.cancelled for t in self.tokens)

    def raise_if_cancelled(self) -> None:
        if self.cancelled:
            raise Cancelled("cancelled")
