"""Memory budget: how much memory a job may use here, and a clear refusal before it starts.

Every sub-command and every file reader estimates its peak memory from the sizes it is given
(:func:`estimate` helpers live next to the algorithms they describe, or here when shared) and
calls :func:`check_memory` before any work: an input the loader accepts must never end in a
``MemoryError`` halfway through. The message names what needs the memory, how much, the limit
and the way out.

The limit is the smallest of: the memory the system reports available (``MemAvailable``), the
address-space limit of the process (``ulimit -v``) minus what it already maps, and the cgroup
limit of a container, times :data:`USABLE_FRACTION` (the rest is the interpreter, libraries and
copies the estimates do not count). ``QUILT_MEMORY_LIMIT`` (bytes, or with a K/M/G suffix)
overrides it, e.g. to share a machine.
"""

from __future__ import annotations

import os
import re
import resource

USABLE_FRACTION = 0.8
ENV_LIMIT = "QUILT_MEMORY_LIMIT"

__all__ = [
    "ENV_LIMIT",
    "MemoryBudgetError",
    "available_memory",
    "check_memory",
    "format_bytes",
    "memory_limit",
]


class MemoryBudgetError(ValueError):
    """A job would need more memory than this machine (or this process) can give it."""


def format_bytes(n: float) -> str:
    """``1536 * 2**20`` -> ``"1.5 GiB"``."""
    for unit in ("bytes", "KiB", "MiB", "GiB", "TiB"):
        if abs(n) < 1024 or unit == "TiB":
            return f"{n:.0f} {unit}" if unit == "bytes" else f"{n:.1f} {unit}"
        n /= 1024
    return f"{n:.1f} TiB"  # pragma: no cover


def _meminfo(key: str) -> int | None:
    try:
        with open("/proc/meminfo", encoding="ascii") as f:
            for line in f:
                if line.startswith(key + ":"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return None


def _mapped_bytes() -> int:
    """The process's current virtual size (what ``RLIMIT_AS`` counts)."""
    try:
        with open("/proc/self/statm", encoding="ascii") as f:
            return int(f.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return 0


def _cgroup_free() -> int | None:
    try:
        with open("/sys/fs/cgroup/memory.max", encoding="ascii") as f:
            limit = f.read().strip()
        if limit == "max":
            return None
        with open("/sys/fs/cgroup/memory.current", encoding="ascii") as f:
            return int(limit) - int(f.read().strip())
    except (OSError, ValueError):
        return None


def available_memory() -> int:
    """Bytes this process can still allocate (see the module docstring), before the
    :data:`USABLE_FRACTION` margin."""
    candidates = []
    avail = _meminfo("MemAvailable")
    if avail is not None:
        candidates.append(avail)
    soft, _hard = resource.getrlimit(resource.RLIMIT_AS)
    if soft != resource.RLIM_INFINITY:
        candidates.append(soft - _mapped_bytes())
    cgroup = _cgroup_free()
    if cgroup is not None:
        candidates.append(cgroup)
    return max(0, min(candidates)) if candidates else 8 * 2**30


def _parse_size(text: str) -> int | None:
    m = re.fullmatch(r"\s*(\d+(?:\.\d+)?)\s*([KMGT]?)i?B?\s*", text, re.IGNORECASE)
    if not m:
        return None
    scale = {"": 1, "K": 2**10, "M": 2**20, "G": 2**30, "T": 2**40}[m.group(2).upper()]
    return int(float(m.group(1)) * scale)


def memory_limit() -> int:
    """Bytes a job may plan to use now: ``QUILT_MEMORY_LIMIT`` if set, else
    :data:`USABLE_FRACTION` of :func:`available_memory`."""
    env = os.environ.get(ENV_LIMIT)
    if env:
        parsed = _parse_size(env)
        if parsed is not None:
            return parsed
    return int(available_memory() * USABLE_FRACTION)


def check_memory(needed: int, *, what: str, way_out: str, limit: int | None = None) -> None:
    """Raise :class:`MemoryBudgetError` if ``needed`` bytes exceed ``limit`` (default
    :func:`memory_limit`): "{what} needs about X of memory, more than the Y available here;
    {way_out}"."""
    limit = memory_limit() if limit is None else limit
    if needed > limit:
        raise MemoryBudgetError(
            f"{what} needs about {format_bytes(needed)} of memory, more than the "
            f"{format_bytes(limit)} available here; {way_out}"
        )


# ---------------------------------------------------------------- estimates
# Peak bytes of the jobs whose engine does not estimate itself (quilting and transfer do:
# engine.quilting.estimate). Calibrated on peak RSS (benchmarks/memory.py) and rounded up.

FLOAT = 4  # bytes per float32 sample


def image_bytes(h: int, w: int, channels: int, itemsize: int = FLOAT) -> int:
    return int(h) * int(w) * int(channels) * itemsize


def tileset_bytes(
    source_shape, tile_hw, *, candidates: int, preview: tuple[int, int], map_channels=()
) -> int:
    """The ``tileset`` workflow: the template search over the source (about 20 float copies
    of it), every candidate per map, and the preview (float, quantized and encoded)."""
    h, w, c = source_shape
    th, tw = tile_hw
    chans = c + sum(map_channels)
    search = 20 * image_bytes(h, w, chans)
    tiles = (candidates + 2) * image_bytes(th, tw, chans) * 2
    rows, cols = preview
    shown = image_bytes(rows * th, cols * tw, chans) * 2
    return search + tiles + shown


def export_bytes(
    count: int, tile_hw, map_channels, *, atlas_hw, preview_hw=None, bit_depth: int = 16
) -> int:
    """An export bundle built in memory: the tiles quantized, one atlas per map and the
    preview, each also as encoded PNG bytes (at most its raw size)."""
    item = 2 if bit_depth == 16 else 1
    th, tw = tile_hw
    total = 0
    for c in map_channels:
        total += 2 * count * image_bytes(th, tw, c, item)
        total += 2 * image_bytes(*atlas_hw, c, item)
        if preview_hw is not None:
            total += image_bytes(*preview_hw, c, FLOAT + 2 * item)
    return total


def seam_bytes(h: int, w: int, channels: int) -> int:
    """One seam between two overlaps: both images, the error map and the solvers' float64
    cost tables, plus the optional composite and mask."""
    return 6 * image_bytes(h, w, channels) + 6 * image_bytes(h, w, 1, 8)


def heal_bytes(h: int, w: int, channels: int) -> int:
    """Healing an image: the image and its maps, and the masked search's FFT buffers (about
    24 float planes of the image's size)."""
    return 4 * image_bytes(h, w, channels) + 24 * image_bytes(h, w, 1, 8)
