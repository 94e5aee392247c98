"""Quilt Studio engine: pure numpy/scipy/scikit-image algorithms, never Qt.

Images are float32 arrays shaped (H, W) or (H, W, C) with values in [0, 1].
Long algorithms come in two faces: ``iter_x(...)`` returns a generator of
events (see :mod:`engine.events`) whose return value is the result, and
``x(...)`` drains it.
"""

from engine.cancel import Cancelled, CancelToken

__all__ = ["CancelToken", "Cancelled"]
