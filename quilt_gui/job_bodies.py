"""The bodies of the pipeline's jobs that run in workers: the preview, quilting and texture
transfer, and the wrappers that make the excluded-pixel mask and the flattened source there
(:mod:`quilt_gui.pipeline` starts them)."""

from __future__ import annotations

import numpy as np

from engine.seams import SeamSpec
from quilt_gui import params
from quilt_gui.imaging import prepare_display


def make_preview(tiles, source, *, rows, cols, seed, no_equal_neighbours, weights, cancel=None):
    """(layout, image, grid score) of the picked tiles (runs in a worker)."""
    from engine.metrics import grid_score
    from engine.tiles import assemble, random_layout

    n = len(tiles)
    if n < 2 or sum(w > 0 for w in weights) < 2:
        no_equal_neighbours = False
    layout = random_layout(
        n, rows, cols, rng=seed, no_equal_neighbours=no_equal_neighbours, weights=weights
    )
    image = assemble(tiles, layout)
    th, tw = tiles[0].shape[:2]
    score = None
    if rows * cols > 1:
        score = float(grid_score(image, (th, tw), source=source))
    return layout, image, score


def quilt_options(p: dict) -> dict:
    """Keyword options of :func:`engine.quilting.iter_quilt` from the parameters."""
    return dict(
        block=p["block"],
        overlap=p["q_overlap"] or None,
        select=p["select"],
        tolerance=p["tolerance"],
        candidates=p["q_candidates"] or None,
        seam=SeamSpec(
            p["q_method"],
            params.seam_options(p, p["q_method"]),
            metric=p["q_metric"],
            blend=p["q_blend"],
            width=p["q_width"],
            rho=p["q_rho"],
        ),
        tileable=p["tileable"],
        adaptive_threshold=p["adaptive_threshold"] or None,
        min_block=p["min_block"] or None,
        mode=p["q_mode"],
        rng=p["q_seed"],
    )


def excluded_mask(sample: np.ndarray, color: str, tolerance: float, painted=None):
    """Sample pixels within ``tolerance`` of ``color`` (per channel) or painted; None if none."""
    from engine.exclusion import colour_range_around, exclusion_mask

    color_range = colour_range_around(color, tolerance)
    if color_range is None and (painted is None or not painted.any()):
        return None
    return exclusion_mask(sample, color_range=color_range, painted=painted)


def _job_mask(sample, exclusion):
    mask = excluded_mask(sample, *exclusion)
    if mask is not None and mask.all():
        raise ValueError("the excluded colour range and painted mask cover the whole source")
    return mask


def excluding(fn):
    """``fn(source, *args, excluded=mask, **options)`` as a job body taking ``exclusion``
    (:meth:`Pipeline.exclusion`) and ``flatten`` (:meth:`Pipeline.flatten_scale`): the mask
    (from the source's own colours) and the flattened source are made in the worker."""

    def job(source, *args, exclusion, flatten=None, **options):
        mask = _job_mask(source, exclusion)
        return fn(_flattened(source, flatten), *args, excluded=mask, **options)

    job.__name__ = job.__qualname__ = f"excluding_{fn.__name__}"
    return job


def flattening(fn):
    """``fn(source, ...)`` as a job body taking ``flatten`` (:meth:`Pipeline.flatten_scale`):
    the source's lighting is flattened in the worker first when it is a scale."""

    def job(source, *args, flatten=None, **options):
        return fn(_flattened(source, flatten), *args, **options)

    job.__name__ = job.__qualname__ = f"flattening_{fn.__name__}"
    return job


def _flattened(source, scale):
    if scale is None:
        return source
    from engine.tone import flatten_lighting

    return flatten_lighting(source, scale=scale)


def quilt_job(sample, out_shape, *, exclusion, cancel=None, **options):
    """Worker body of a quilting run: exclusion mask, then the engine's event generator."""
    from engine.quilting import iter_quilt

    mask = _job_mask(sample, exclusion)
    gen = iter_quilt(sample, out_shape, excluded=mask, cancel=cancel, threads=2, **options)
    return _with_display_copy(gen)


def transfer_job(sample, target, *, exclusion, cancel=None, **options):
    """Worker body of a texture transfer: exclusion mask, then the engine's generator."""
    from engine.transfer import iter_transfer

    mask = _job_mask(sample, exclusion)
    gen = iter_transfer(sample, target, excluded=mask, cancel=cancel, threads=2, **options)
    return _with_display_copy(gen)


def _with_display_copy(gen):
    """The engine's events unchanged; the final image's 8-bit display copy is made here in
    the worker, so the GUI thread only wraps it (a 1536 px output took 0.1-0.2 s there)."""
    result = yield from gen
    prepare_display(result.image)
    return result
