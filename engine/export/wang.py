"""Wang sets for map editors: Tiled's edge Wang set and Godot 4's "match sides" terrain set.

A Wang tile set (:mod:`engine.tiles.wang`) gives every tile four edge colours (N, E, S, W):
K colours for the north/south edges and K for the east/west edges. Both map editors compare
only facing edges (a top edge with the bottom edge above it, a left with the right beside it),
so colour c of either direction can be the same colour c there: K colours, every tile's
signature among the K⁴ combinations.

* Tiled (``<wangsets><wangset type="edge">``, Tiled ≥ 1.5): ``wangcolor`` c + 1 for colour c
  (0 means "no colour"); each tile's ``wangid`` lists top, top-right, right, bottom-right,
  bottom, bottom-left, left, top-left: ``n+1,0,e+1,0,s+1,0,w+1,0``.
* Godot 4: a terrain set in mode 2 ("Match sides") with terrains 0..K-1, and per tile
  ``terrain_set = 0`` and the four ``terrains_peering_bit/{top,right,bottom,left}_side``. The
  centre terrain stays unset (-1): a Wang tile has none, the sides decide the match.

``wang`` is plain data: ``{"colours": K, "tiles": [{"n": c, "e": c, "s": c, "w": c}, ...]}``
(one signature per exported tile, in tile-id order), as the bundle manifest lists it.
"""

from __future__ import annotations

import numbers
from collections.abc import Mapping
from xml.sax.saxutils import quoteattr

import numpy as np

__all__ = [
    "check_signatures",
    "check_wang",
    "godot_terrain_lines",
    "godot_tile_terrain",
    "layout_mismatches",
    "tiled_wangset_lines",
]

SIDES = ("n", "e", "s", "w")
GODOT_MATCH_SIDES = 2  # TileSet.TERRAIN_MODE_MATCH_SIDES
_GODOT_BITS = {"n": "top_side", "e": "right_side", "s": "bottom_side", "w": "left_side"}
#: editor colours of the Wang colours (cycled)
PALETTE = ("#e8563f", "#3f8fe8", "#4fc25a", "#f0b92c", "#a45ee5", "#2cc4c0", "#e85fa8", "#9c9c9c")


def check_wang(wang, count: int) -> dict:
    """``wang`` validated for ``count`` tiles: ``{"colours": K, "tiles": [signature...]}``."""
    if not isinstance(wang, Mapping):
        raise TypeError(f"wang must be a mapping {{'colours': K, 'tiles': [...]}}, got {wang!r}")
    k = wang.get("colours")
    if isinstance(k, bool) or not isinstance(k, numbers.Integral) or not 1 <= k <= 254:
        raise ValueError(f"wang['colours'] must be an integer in 1..254, got {k!r}")
    tiles = wang.get("tiles")
    if not isinstance(tiles, (list, tuple)) or len(tiles) != count:
        raise ValueError(f"wang['tiles'] must list one signature per tile ({count})")
    out = []
    for i, sig in enumerate(tiles):
        if not isinstance(sig, Mapping) or set(sig) != set(SIDES):
            raise ValueError(f"wang['tiles'][{i}] must be {{'n', 'e', 's', 'w'}}, got {sig!r}")
        for side in SIDES:
            c = sig[side]
            if isinstance(c, bool) or not isinstance(c, numbers.Integral) or not 0 <= c < k:
                raise ValueError(f"wang['tiles'][{i}][{side!r}] must be a colour 0..{k - 1}")
        out.append({side: int(sig[side]) for side in SIDES})
    return {"colours": int(k), "tiles": out}


def colour_name(c: int) -> str:
    return f"edge {c + 1}"


def tiled_wangset_lines(wang: dict, *, name: str) -> list[str]:
    """The ``<wangsets>`` element of a tileset (checked ``wang``), one line per element."""
    lines = [" <wangsets>", f'  <wangset name={quoteattr(name)} type="edge" tile="-1">']
    for c in range(wang["colours"]):
        lines.append(
            f"   <wangcolor name={quoteattr(colour_name(c))} color="
            f'"{PALETTE[c % len(PALETTE)]}" tile="-1" probability="1"/>'
        )
    for i, sig in enumerate(wang["tiles"]):
        wid = ",".join(f"{sig[s] + 1},0" for s in SIDES)
        lines.append(f'   <wangtile tileid="{i}" wangid="{wid}"/>')
    lines += ["  </wangset>", " </wangsets>"]
    return lines


def godot_tile_terrain(sig: Mapping, cell: str) -> list[str]:
    """The terrain lines of one atlas tile (``cell`` = ``"x:y/0"``): its terrain set first
    (Godot sets peering bits only on a tile that has one)."""
    lines = [f"{cell}/terrain_set = 0"]
    for side in SIDES:
        lines.append(f"{cell}/terrains_peering_bit/{_GODOT_BITS[side]} = {int(sig[side])}")
    return lines


def godot_terrain_lines(wang: dict) -> list[str]:
    """The TileSet resource's terrain set: "Match sides", one terrain per colour."""
    lines = [f"terrain_set_0/mode = {GODOT_MATCH_SIDES}"]
    for c in range(wang["colours"]):
        h = PALETTE[c % len(PALETTE)]
        r, g, b = (int(h[i : i + 2], 16) / 255 for i in (1, 3, 5))
        lines.append(f'terrain_set_0/terrain_{c}/name = "{colour_name(c)}"')
        lines.append(f"terrain_set_0/terrain_{c}/color = Color({r:.6g}, {g:.6g}, {b:.6g}, 1)")
    return lines


def check_signatures(signatures) -> np.ndarray:
    """(n, 4) int64 array of (N, E, S, W) colours, validated."""
    s = np.asarray(signatures)
    if s.ndim != 2 or s.shape[1] != 4 or s.shape[0] < 1:
        raise ValueError(
            f"signatures must be a non-empty list of (n, e, s, w), got shape {s.shape}"
        )
    if not np.issubdtype(s.dtype, np.integer) or (s < 0).any():
        raise ValueError("signatures must hold colour indices >= 0")
    return s.astype(np.int64)


def layout_mismatches(signatures, layout, *, wrap: bool = False) -> int:
    """Number of neighbouring cell pairs whose touching edge colours differ (0 = valid);
    -1 cells (empty) are skipped."""
    sig = check_signatures(signatures)
    m = np.asarray(layout, dtype=np.int64)
    if m.ndim != 2 or m.size == 0 or m.max() >= sig.shape[0] or m.min() < -1:
        raise ValueError("layout must be a 2-D matrix of tile indices (or -1)")
    bad = 0
    a, b = m[:, :-1], m[:, 1:]
    if wrap:
        a, b = np.hstack([a, m[:, -1:]]), np.hstack([b, m[:, :1]])
    both = (a >= 0) & (b >= 0)
    bad += int(np.count_nonzero(sig[a[both], 1] != sig[b[both], 3]))
    a, b = m[:-1], m[1:]
    if wrap:
        a, b = np.vstack([a, m[-1:]]), np.vstack([b, m[:1]])
    both = (a >= 0) & (b >= 0)
    bad += int(np.count_nonzero(sig[a[both], 2] != sig[b[both], 0]))
    return bad
