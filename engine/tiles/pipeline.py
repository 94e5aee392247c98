"""The whole tile-set workflow in one call: template, seamless tile, candidates, preview layout.

:func:`iter_tileset` runs the steps of Somol & Haindl's method with one
:class:`~engine.settings.TilesetSettings` (re-exported here), streaming every step's events,
and returns a
:class:`TilesetResult`; ``quilt-studio tileset`` writes that result to files. (The editor runs
the same steps one by one, as the person edits.)
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from engine.events import Progress
from engine.seams.spec import POISSON
from engine.settings import TilesetSettings
from engine.tiles.candidates import (
    MARGIN,
    CandidatesNotice,
    CandidateTile,
    default_patch_overlap,
    iter_candidates,
)
from engine.tiles.layout import assemble_maps, random_layout
from engine.tiles.scale import Scale
from engine.tiles.seamless import MAIN, SeamlessTile, iter_make_seamless
from engine.tiles.template import default_overlap, iter_find_template, template_cost

__all__ = [
    "TilesetResult",
    "TilesetSettings",
    "auto_tone",
    "flatten_scale_for",
    "iter_tileset",
    "resolve",
    "tileset",
    "working_source",
]


@dataclass(frozen=True)
class TilesetResult:
    """Everything one run made.

    ``settings`` are the run's settings with every "from the source" value filled in
    (:func:`resolve`); ``rect``/``overlap``/``cost`` the template rectangle
    (x, y, w, h), w_T and its search criterion; ``picks`` the candidate indices the preview
    uses, ``layout`` its index matrix over ``picks`` (``cells``: the same over candidate
    indices) and ``preview`` the assembled image per map (``"main"``: the source's);
    ``scale`` the texture's structure scale the template search measured (None: a fixed
    ``rect`` or ``whole_structures`` off).
    """

    settings: TilesetSettings
    rect: tuple[int, int, int, int]
    overlap: int
    cost: float
    seamless: SeamlessTile
    candidates: list[CandidateTile]
    picks: list[int]
    layout: np.ndarray
    preview: dict[str, np.ndarray]
    warnings: tuple[str, ...] = field(default=())
    scale: Scale | None = None

    @property
    def cells(self) -> np.ndarray:
        """The layout as candidate indices (``tile_NNN`` of the files)."""
        return np.asarray(self.picks, dtype=np.int64)[self.layout]


def resolve(settings: TilesetSettings, shape, *, overlap: int | None = None) -> TilesetSettings:
    """``settings`` with every "from the source" value filled in for a source of ``shape``
    (H, W); ``overlap`` is the template's w_T when it is known."""
    lo, hi = settings.tile_range(shape)
    w_t = overlap or settings.overlap or default_overlap(lo, hi)
    ring = settings.patch_overlap or default_patch_overlap(w_t)
    return settings.replace(
        tile_min=lo,
        tile_max=hi,
        overlap=w_t,
        patch_overlap=ring,
        margin=min(MARGIN, ring - 1) if settings.margin is None else settings.margin,
        layout_seed=settings.seed if settings.layout_seed is None else settings.layout_seed,
        template_blend=settings.template_seam.blend,
    )


def iter_tileset(
    source,
    settings: TilesetSettings | None = None,
    *,
    rect=None,
    maps=None,
    weights=None,
    excluded=None,
    picks=None,
    workers: int = 2,
    cancel=None,
):
    """Run the workflow; a generator of the steps' events whose value is a TilesetResult.

    Parameters
    ----------
    source : (H, W[, C]) array
    settings : TilesetSettings, optional
        Every option (default ``TilesetSettings()``).
    rect : (x, y, w, h), optional
        A fixed tile rectangle instead of the template search.
    maps, weights
        Material maps (they get every cut) and the seam error weights per map.
    excluded : (H, W) bool, optional
        Source pixels no tile or patch may contain.
    picks : list of int, optional
        Candidates the preview uses (default: all of them).
    workers : int
        Threads of the candidate run.
    cancel : CancelToken, optional
    """
    s = settings if settings is not None else TilesetSettings()
    if not isinstance(s, TilesetSettings):
        raise TypeError(f"settings must be a TilesetSettings, got {type(s).__name__}")
    if picks is not None and (not picks or max(picks) >= s.candidates or min(picks) < 0):
        raise ValueError(f"picks {list(picks)} out of range: there are {s.candidates} candidates")
    return _iter_tileset(source, s, rect, maps, weights, excluded, picks, workers, cancel)


def auto_tone(settings: TilesetSettings, source) -> tuple[TilesetSettings, str | None]:
    """``settings`` with Flatten lighting decided when it is "from the source" (``flatten``
    None), and a sentence saying what was switched on (None: nothing).

    When the stationarity check (:mod:`engine.tiles.stationarity`) finds the lighting uneven
    (past ``LIGHTING_LIMIT``) on a photo whose detail is otherwise even (not past
    ``DETAIL_LIMIT``: on a page with margins or a half-blurred photo the "lighting" figure is
    the content's), the source is flattened and — unless other blendings than the defaults
    were asked for — every cut is blended in the gradient domain (``poisson``): the flattening
    removes the light trend, the blend the tone steps the trend left between patches and ring
    (measured on the public evaluation set: README, "Tone"). Only the source, the albedo, is
    ever flattened; material maps (normals, heights) are not. Wang sets are left alone."""
    if settings.flatten is not None:
        return settings, None
    if settings.wang is not None:
        return settings.replace(flatten=False), None
    from engine.tiles.stationarity import DETAIL_LIMIT, LIGHTING_LIMIT, check_stationarity

    st = check_stationarity(source)
    if not (st.lighting > LIGHTING_LIMIT and st.detail <= DETAIL_LIMIT):
        return settings.replace(flatten=False), None
    default = TilesetSettings()
    blend = settings.seam.blend == default.seam.blend
    blend = blend and settings.template_blend in (default.template_blend, None)  # None: as seam
    changes = {"flatten": True}
    if blend:
        changes.update(seam=settings.seam.replace(blend=POISSON), template_blend=None)
    what = "Flatten lighting and the gradient-domain blend are" if blend else "Flatten lighting is"
    return settings.replace(**changes), (
        f"the lighting varies across the photo (a smooth trend of about ±{50 * st.lighting:.0f} % "
        f"in brightness): {what} on (automatic; --no-flatten, or Flatten lighting: Off in "
        "the editor, keeps the photo's lighting and the blending)"
    )


def flatten_scale_for(settings: TilesetSettings, shape) -> int | None:
    """The scale (px) :func:`engine.tone.flatten_lighting` flattens at for a source of
    ``shape`` (from the largest tile side), None without ``settings.flatten``."""
    if not settings.flatten:
        return None
    from engine.tone import flatten_scale

    return flatten_scale(settings.tile_range(shape)[1])


def working_source(source, settings: TilesetSettings):
    """The image the tiles are taken from: ``source``, or with ``settings.flatten`` the source
    with its large-scale lighting flattened (:mod:`engine.tone`; the albedo only: material
    maps are never relit)."""
    scale = flatten_scale_for(settings, np.shape(source)[:2])
    if scale is None:
        return source
    from engine.tone import flatten_lighting

    return flatten_lighting(source, scale=scale)


def _iter_tileset(source, s, rect, maps, weights, excluded, picks, workers, cancel):
    H, W = np.shape(source)[:2]
    notes: list[str] = []
    scale = None
    s, tone = auto_tone(s, source)
    if tone:
        import warnings

        warnings.warn(tone, stacklevel=2)
        notes.append(tone)
    source = working_source(source, s)
    if rect is not None:
        overlap = s.overlap or default_overlap((rect[3], rect[2]))
        cost = template_cost(
            source,
            rect,
            overlap=overlap,
            excluded=excluded,
            joint_weight=s.joint_weight,
            detail_weight=s.detail_weight,
        )[0]
    else:
        lo, hi = s.tile_range((H, W))
        found = yield from iter_find_template(
            source,
            tile_min=lo,
            tile_max=hi,
            overlap=s.overlap,
            excluded=excluded,
            joint_weight=s.joint_weight,
            detail_weight=s.detail_weight,
            whole_structures=s.whole_structures,
            cancel=cancel,
        )
        rect, overlap, cost, scale = found.rect, found.overlap, found.cost, found.scale
        notes += list(found.warnings)
    resolved = resolve(s, (H, W), overlap=overlap)
    seamless = yield from iter_make_seamless(
        source,
        rect,
        overlap=overlap,
        seam=resolved.template_seam,
        maps=maps,
        weights=weights,
        cancel=cancel,
    )
    notes += [w for w in seamless.warnings if w not in notes]
    cands = yield from _noting(
        iter_candidates(
            source,
            seamless,
            resolved.candidates,
            patch_size=resolved.patch_size,
            patch_overlap=resolved.patch_overlap,
            margin=resolved.margin,
            patch_search=resolved.patch_search,
            neighbourhood=resolved.neighbourhood,
            min_distance=resolved.min_distance,
            seam=resolved.seam,
            excluded=excluded,
            maps=maps,
            weights=weights,
            rng=resolved.seed,
            scale=scale,
            workers=workers,
            cancel=cancel,
        ),
        notes,
    )
    if not cands:
        why = [n for n in notes if n.startswith("made 0")]
        raise ValueError(why[0] if why else "no candidate was made")
    chosen = list(picks) if picks is not None else [c.index for c in cands]
    made = {c.index for c in cands}
    missing = [k for k in chosen if k not in made]
    if missing:  # cancelled before they were made
        raise ValueError(f"picks {missing} were not made: {len(cands)} candidates finished")
    by_index = {c.index: c for c in cands}
    rows, cols = resolved.preview
    ids = random_layout(
        len(chosen),
        rows,
        cols,
        rng=resolved.layout_seed,
        no_equal_neighbours=resolved.no_equal_neighbours and len(chosen) > 1,
    )
    tiles = [by_index[k] for k in chosen]
    preview = assemble_maps(tiles, ids, [MAIN, *seamless.maps])
    yield Progress(1, 1, "tile set: done")
    return TilesetResult(
        settings=resolved,
        rect=tuple(int(v) for v in rect),
        overlap=int(overlap),
        cost=float(cost),
        seamless=seamless,
        candidates=cands,
        picks=chosen,
        layout=ids,
        preview=preview,
        warnings=tuple(notes),
        scale=scale,
    )


def _noting(gen, notes: list):
    """Re-yield ``gen``'s events, adding every :class:`CandidatesNotice` to ``notes``."""
    while True:
        try:
            ev = next(gen)
        except StopIteration as stop:
            return stop.value
        if isinstance(ev, CandidatesNotice) and ev.message not in notes:
            notes.append(ev.message)
        yield ev


def tileset(source, settings: TilesetSettings | None = None, **options) -> TilesetResult:
    """Drain :func:`iter_tileset` and return its :class:`TilesetResult`."""
    from engine.events import drain

    return drain(iter_tileset(source, settings, **options))
