"""Display conversions: large arrays are converted once (ahead, in a worker), metrics cached."""

from __future__ import annotations

import threading

import numpy as np

from engine.metrics import detail_ratio, laplacian_variance
from quilt_gui import imaging
from quilt_gui.widgets import tile_view


def test_large_array_display_copy_is_prepared_once_and_forgotten_with_the_array():
    a = np.random.default_rng(0).random((1100, 1000, 3)).astype(np.float32)
    t = threading.Thread(target=imaging.prepare_display, args=(a,))
    t.start()
    t.join()
    first = imaging.display_uint8(a)
    assert imaging.display_uint8(a) is first  # the GUI thread reuses the worker's copy
    assert np.array_equal(first, imaging.to_uint8(a))
    assert imaging.to_pixmap(a).width() == 1000
    key = id(a)
    del a
    assert key not in imaging._cache
    small = np.zeros((8, 8, 3), np.float32)
    assert imaging.display_uint8(small) is not imaging.display_uint8(small)  # not cached


def test_tile_metrics_match_the_engine_and_reuse_the_source_figure(monkeypatch):
    """The detail ratio is the engine's, the source's Laplacian variance is cached."""
    rng = np.random.default_rng(1)
    for channels in (1, 3):
        source = rng.random((120, 140, channels)).astype(np.float32)
        tile = source[10:70, 20:90]
        m = tile_view.tile_metrics(tile, source)
        assert abs(m["detail"] - detail_ratio(tile, source)) < 1e-9
    calls = []
    real = laplacian_variance

    def counting(a):
        calls.append(a is source)
        return real(a)

    monkeypatch.setattr("engine.metrics.laplacian_variance", counting)
    for k in range(3):
        tile_view.tile_metrics(source[k : k + 50, :50], source)
    assert len(calls) == 3 and not any(calls)  # the source's figure was computed once, above
