"""JSON in and out for project files and manifests: numpy values written as plain JSON, and
untrusted JSON read within bounds.

:func:`loads_bounded` counts the values a document holds *before* Python builds them (a
72 KB compressed document can otherwise expand into lists of tens of millions of items), refuses
``NaN`` / ``Infinity`` (not JSON) and deep nesting, and reports every problem as one
:class:`JSONDataError`.
"""

from __future__ import annotations

import json
import re

import numpy as np

MAX_VALUES = 2_000_000
"""Most values (numbers, strings, lists, objects) one document may hold: a project with 1 000
candidates and a 1 000 x 1 000 layout needs about 1.1 million; the parsed document stays under
about 200 MB."""
MAX_DEPTH = 64

_STRING = re.compile(rb'"(?:[^"\\]|\\.)*"', re.DOTALL)

__all__ = ["JSONDataError", "MAX_VALUES", "json_default", "loads_bounded"]


class JSONDataError(ValueError):
    """The bytes are not JSON within the bounds; the message says why."""


def json_default(o):
    """``json.dumps(default=...)``: numpy scalars and arrays, tuples and sets as JSON."""
    if isinstance(o, np.integer):
        return int(o)
    if isinstance(o, np.floating):
        return float(o)
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, (tuple, set, frozenset)):
        return list(o)
    raise TypeError(f"{type(o).__name__} is not JSON-serialisable")


def _blank_strings(raw: bytes) -> bytes:
    return _STRING.sub(b'""', raw)


def loads_bounded(raw: bytes, *, max_values: int = MAX_VALUES, max_depth: int = MAX_DEPTH):
    """Parse UTF-8 JSON ``raw`` if it holds at most ``max_values`` values nested at most
    ``max_depth`` deep; raises :class:`JSONDataError`.

    Both are measured on the text before parsing: with strings blanked, every value but the
    first follows a ``,``, ``[``, ``{`` or ``:`` (an upper bound), and the depth is the running
    count of opening minus closing brackets."""
    bare = _blank_strings(raw)
    count = 1 + sum(bare.count(c) for c in (b",", b"[", b"{", b":"))
    if count > max_values:
        raise JSONDataError(
            f"it holds about {count:,} values, over the limit of {max_values:,}; refused"
        )
    a = np.frombuffer(bare, np.uint8)
    step = (a == ord("[")).astype(np.int8) + (a == ord("{")) - (a == ord("]")) - (a == ord("}"))
    depth = int(np.cumsum(step, dtype=np.int32).max(initial=0))
    if depth > max_depth:
        raise JSONDataError(
            f"it is nested too deeply ({depth} levels, over the limit of {max_depth}); refused"
        )
    try:
        return json.loads(raw.decode("utf-8"), parse_constant=_no_constant)
    except UnicodeDecodeError as exc:
        raise JSONDataError(f"it is not UTF-8 text ({exc})") from None
    except json.JSONDecodeError as exc:
        raise JSONDataError(f"it is not valid JSON ({exc})") from None
    except RecursionError:
        raise JSONDataError("it is nested too deeply") from None


def _no_constant(name: str):
    """NaN / Infinity / -Infinity: Python's extension, not JSON (and nothing we write)."""
    raise JSONDataError(f"it is not valid JSON ({name} is not a JSON number)")
