"""Gradient-domain blending along a cut (issue 10, item 4b; Pérez et al. 2003) [REC].

A hard cut keeps every pixel of both sides but leaves the low-frequency tone step between them
(a patch from a brighter part of the photo stays brighter than the ring around it). Blending
in the gradient domain solves instead for the image ``f`` whose gradients are those of the
composite everywhere except on the edges that cross the cut, where they are the *natural*
gradients — the mean of what each side's own image has across that edge:

    minimise  Σ_edges (f_q − f_p − v_pq)²,   v_pq = ∇c on uncut edges, natural across the cut

so the step along the cut is spread smoothly over both sides (a membrane, harmonic away from
the cut) and detail is never blurred: every uncut edge keeps its gradient exactly. The
correction ``δ = f − c`` solves ``L δ = div w`` where ``L`` is the 5-point Laplacian and
``w = v − ∇c`` is non-zero only on the cut's edges. Two domains:

* :func:`poisson_window` — a patch window (candidates): the outer ``fixed`` pixels keep the
  target exactly (Dirichlet; the tiles stay connectable), the rest is solved at once with a
  type-I discrete sine transform, O(n log n);
* :func:`poisson_torus` — a seamless tile, which wraps: the composite's pixels are traced to
  their source positions, an edge is cut where its two pixels are not neighbours in the
  source, and the torus is solved with an FFT (the mean is kept).

Values are clipped to [0, 1] afterwards. Material maps are solved with the same cut;
normal maps as vectors, renormalised (:func:`solve_maps`).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from scipy import fft

from engine._validate import as_image, positive_int
from engine.materials import decode_normals, encode_normals, resolve_kinds

__all__ = ["cut_divergence", "poisson_torus", "poisson_window", "solve_maps", "solve_torus_maps"]


def _as_planes(x: np.ndarray) -> np.ndarray:
    return np.asarray(x, dtype=np.float64)


def cut_divergence(wx: np.ndarray, wy: np.ndarray, *, wrap: bool) -> np.ndarray:
    """``div w``: per pixel, what the edge mismatches flow in minus what they flow out.

    ``wx[y, x]`` belongs to the edge (y, x) -> (y, x + 1) and ``wy[y, x]`` to (y, x) ->
    (y + 1, x) (..., C trailing); with ``wrap`` the last column's and row's edges lead
    around the torus, otherwise they are absent (must be 0)."""
    b = -wx - wy
    if wrap:
        b += np.roll(wx, 1, axis=1) + np.roll(wy, 1, axis=0)
    else:
        b[:, 1:] += wx[:, :-1]
        b[1:] += wy[:-1]
    return b


def _laplacian_eigenvalues(n: int, kind: str) -> np.ndarray:
    """Eigenvalues of the 1-D second difference (−1, 2, −1): Dirichlet (DST-I) or periodic."""
    k = np.arange(n)
    if kind == "dirichlet":
        return 2.0 - 2.0 * np.cos(np.pi * (k + 1) / (n + 1))
    return 2.0 - 2.0 * np.cos(2.0 * np.pi * k / n)


def _solve_dirichlet(b: np.ndarray, screen: float = 0.0) -> np.ndarray:
    """δ with ``(L + screen) δ = b`` on a rectangle whose outside is 0 (b: (h, w[, C]))."""
    h, w = b.shape[:2]
    lam = _laplacian_eigenvalues(h, "dirichlet")[:, None] + _laplacian_eigenvalues(w, "dirichlet")
    lam = lam + screen
    B = fft.dstn(b, type=1, axes=(0, 1), norm="ortho")
    B /= lam if b.ndim == 2 else lam[..., None]
    return fft.idstn(B, type=1, axes=(0, 1), norm="ortho")


def _solve_periodic(b: np.ndarray) -> np.ndarray:
    """δ with ``L δ = b`` on a torus, mean 0 (b must sum to 0 per channel)."""
    h, w = b.shape[:2]
    lam = _laplacian_eigenvalues(h, "periodic")[:, None] + _laplacian_eigenvalues(w, "periodic")
    lam[0, 0] = 1.0
    B = fft.fftn(b, axes=(0, 1))
    B /= lam if b.ndim == 2 else lam[..., None]
    B[0, 0] = 0.0
    return fft.ifftn(B, axes=(0, 1)).real


def poisson_window(q, u, mask, *, fixed: int = 1, reach: float | None = None) -> np.ndarray:
    """``q`` over ``u`` where ``mask``, blended in the gradient domain (float64, (h, w, C)).

    Guidance: ``q``'s gradients between two mask pixels, ``u``'s between two others, and the
    mean of both across the cut. The outer ``fixed`` (>= 1) pixels keep ``u`` exactly; the mask
    must not reach them. ``reach`` (px, None = unlimited): the correction is *screened*,
    ``(L + 1/reach²) δ = div w``, so it fades about ``reach`` px away from the cut and the
    patch keeps its own tone further in (an unscreened solve gives every patch the low
    frequencies of the ring it sits in — the same in every tile). Not clipped (see
    :func:`solve_maps`).
    """
    Q = _as_planes(q)
    U = _as_planes(u)
    if Q.shape != U.shape:
        raise ValueError(f"q and u must have the same shape, got {Q.shape} and {U.shape}")
    m = np.asarray(mask, dtype=bool)
    h, w = Q.shape[:2]
    if m.shape != (h, w):
        raise ValueError(f"mask must be shaped {(h, w)}, got {m.shape}")
    k = positive_int(fixed, "fixed", minimum=1)
    if 2 * k >= min(h, w):
        raise ValueError(f"fixed {k} leaves nothing to solve in a {w}x{h} window")
    if m[:k].any() or m[-k:].any() or m[:, :k].any() or m[:, -k:].any():
        raise ValueError(f"the mask reaches the outer {k} fixed pixels")
    c = np.where(m[..., None] if Q.ndim == 3 else m, Q, U)
    if not m.any():
        return c
    D = Q - U
    ex = m[:, 1:] != m[:, :-1]  # edges crossing the cut; sign: + from inside to outside
    ey = m[1:] != m[:-1]
    sx = np.where(m[:, :-1], 1.0, -1.0) * ex
    sy = np.where(m[:-1], 1.0, -1.0) * ey
    if Q.ndim == 3:
        sx, sy = sx[..., None], sy[..., None]
    wx = np.zeros_like(Q)
    wy = np.zeros_like(Q)
    wx[:, :-1] = sx * 0.5 * (D[:, :-1] + D[:, 1:])
    wy[:-1] = sy * 0.5 * (D[:-1] + D[1:])
    b = cut_divergence(wx, wy, wrap=False)
    inner = (slice(k, h - k), slice(k, w - k))
    out = c.copy()
    screen = 0.0 if reach is None else 1.0 / float(reach) ** 2
    out[inner] += _solve_dirichlet(b[inner], screen)
    return out


def poisson_torus(tile, coords, source) -> np.ndarray:
    """A hard-cut seamless ``tile`` (h, w, C) blended in the gradient domain on the torus.

    ``coords`` (h, w, 2) gives each tile pixel's (row, col) in ``source`` (H, W, C); an edge
    is cut when its two pixels are not the same neighbours in the source, and its guidance is
    then the mean of the source's gradients from either pixel in that direction (clamped at
    the source's border). The mean value is kept. Not clipped (see :func:`solve_maps`).
    """
    T = _as_planes(tile)
    S = np.asarray(source)
    yx = np.asarray(coords, dtype=np.int64)
    h, w = T.shape[:2]
    if yx.shape != (h, w, 2):
        raise ValueError(f"coords must be shaped {(h, w, 2)}, got {yx.shape}")
    H, W = S.shape[:2]

    def at(y, x):
        return _as_planes(S[np.clip(y, 0, H - 1), np.clip(x, 0, W - 1)])

    ws = []
    for axis, step in ((1, (0, 1)), (0, (1, 0))):
        nb = np.roll(yx, -1, axis=axis)  # q = p + e on the torus
        cut = np.any(nb - yx != step, axis=2)
        wv = np.zeros_like(T)
        if cut.any():
            p, qn = yx[cut], nb[cut]
            dy, dx = step
            # w = v − (c_q − c_p), v the mean natural gradient: ½ (S[p+e] + S[p] − S[q] − S[q−e])
            wv[cut] = 0.5 * (
                at(p[:, 0] + dy, p[:, 1] + dx)
                + at(p[:, 0], p[:, 1])
                - at(qn[:, 0], qn[:, 1])
                - at(qn[:, 0] - dy, qn[:, 1] - dx)
            )
        ws.append(wv)
    b = cut_divergence(ws[0], ws[1], wrap=True)
    if not b.any():
        return T
    return T + _solve_periodic(b)


def _each_map(maps_a: Mapping, kinds: Mapping | None, solve, hard) -> dict[str, np.ndarray]:
    """Every map solved (float32, clipped to [0, 1]): ``solve(name, planes)`` returns the
    solution of the channels ``planes(image)`` picks; normal maps are solved as vectors and
    renormalised, maps of kind ``mask`` and alpha channels stay ``hard(name)``."""
    resolved = resolve_kinds(maps_a, kinds)
    out = {}
    for name in maps_a:
        base = hard(name)
        kind = resolved[name]
        res = np.array(base, dtype=np.float64)
        if kind == "normal":
            v = solve(name, decode_normals)
            v /= np.maximum(np.linalg.norm(v, axis=2, keepdims=True), 1e-12)
            res[..., :3] = encode_normals(v)
        elif kind != "mask":
            colour = res.shape[2] - (1 if res.shape[2] in (2, 4) else 0)
            res[..., :colour] = solve(name, lambda x, c=colour: _as_planes(x)[..., :c])
        out[name] = np.clip(res, 0.0, 1.0).astype(np.float32)
    return out


def solve_maps(
    maps_q: Mapping,
    maps_u: Mapping,
    mask,
    *,
    fixed: int = 1,
    reach: float | None = None,
    kinds: Mapping | None = None,
) -> dict[str, np.ndarray]:
    """:func:`poisson_window` for every map of a material (float32, clipped to [0, 1]):
    normal maps as vectors (renormalised, re-encoded); alpha channels (the 2nd of 2, the 4th
    of 4 and a normal map's 4th) and maps of kind ``mask`` are cut hard. The outer ``fixed``
    pixels keep ``maps_u`` bit for bit."""
    m = np.asarray(mask, dtype=bool)
    q = {k: as_image(v, f"maps_q[{k!r}]") for k, v in maps_q.items()}
    u = {k: as_image(v, f"maps_u[{k!r}]") for k, v in maps_u.items()}
    k = positive_int(fixed, "fixed", minimum=1)
    inner = (slice(k, -k), slice(k, -k))

    def solve(name, planes):
        return poisson_window(planes(q[name]), planes(u[name]), m, fixed=k, reach=reach)

    out = _each_map(q, kinds, solve, lambda n: np.where(m[..., None], q[n], u[n]))
    ring = np.ones(m.shape, dtype=bool)
    ring[inner] = False
    for name in out:  # the fixed ring bit for bit (a renormalised normal could drift)
        out[name][ring] = u[name][ring]
    return out


def solve_torus_maps(
    tiles: Mapping, coords, sources: Mapping, *, kinds: Mapping | None = None
) -> dict[str, np.ndarray]:
    """:func:`poisson_torus` for every map of a hard-cut seamless tile (``tiles`` and their
    ``sources`` by map name), as :func:`solve_maps` treats normals, alpha and masks."""
    t = {k: as_image(v, f"tiles[{k!r}]") for k, v in tiles.items()}
    s = {k: as_image(v, f"sources[{k!r}]") for k, v in sources.items()}

    def solve(name, planes):
        return poisson_torus(planes(t[name]), coords, planes(s[name]))

    return _each_map(t, kinds, solve, lambda n: t[n])
