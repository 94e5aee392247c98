"""The quilting benchmark's jobs A and B and its sample crops, shared by
:mod:`benchmarks.quilting` and :mod:`benchmarks.fft_backends` (which the former runs: the jobs
lived in it, an import circle between the two)."""

from __future__ import annotations

import numpy as np

from engine.io import load_image
from resources import sample_path

JOBS = {
    "A": dict(crop=128, out=(512, 512), block=32, overlap=6),
    "B": dict(crop=256, out=(1024, 1024), block=48, overlap=8),
}


def load_sample(name: str, crop: int) -> np.ndarray:
    return np.ascontiguousarray(load_image(sample_path(name)).rgb[:crop, :crop])
