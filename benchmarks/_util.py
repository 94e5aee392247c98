"""Shared helpers for the benchmarks: robust timing and plain-text tables."""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence


def median_time(
    fn: Callable[[], object],
    *,
    min_time: float = 0.2,
    min_repeats: int = 3,
    max_repeats: int = 50,
    max_time: float = 20.0,
) -> tuple[float, object]:
    """Median wall time of ``fn()`` in seconds over repeats, and the last result.

    Repeats until ``min_time`` seconds were spent and at least ``min_repeats`` runs were made,
    but at most ``max_repeats`` runs and no new run once ``max_time`` seconds were spent.
    """
    times = []
    result = None
    spent = 0.0
    while (
        len(times) < max_repeats
        and (len(times) < min_repeats or spent < min_time)
        and (not times or spent < max_time)
    ):
        t0 = time.perf_counter()
        result = fn()
        dt = time.perf_counter() - t0
        times.append(dt)
        spent += dt
    times.sort()
    n = len(times)
    median = times[n // 2] if n % 2 else 0.5 * (times[n // 2 - 1] + times[n // 2])
    return median, result


def format_table(headers: Sequence[str], rows: Sequence[Sequence[object]]) -> str:
    """Rows as a Markdown-compatible table with right-aligned columns."""
    cells = [[str(h) for h in headers]] + [[str(c) for c in r] for r in rows]
    widths = [max(len(r[i]) for r in cells) for i in range(len(headers))]
    lines = []
    for k, r in enumerate(cells):
        lines.append("| " + " | ".join(c.rjust(wd) for c, wd in zip(r, widths, strict=True)) + " |")
        if k == 0:
            lines.append("|" + "|".join("-" * (wd + 1) + ":" for wd in widths) + "|")
    return "\n".join(lines)


def provenance() -> str:
    """Date, commit and machine load, for the first line of the results file."""
    import datetime
    import os
    import subprocess

    try:
        commit = subprocess.run(
            ["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True, check=True
        ).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        commit = "unknown"
    load = ", ".join(f"{v:.1f}" for v in os.getloadavg())
    return (
        f"# measured {datetime.date.today()} on this {os.cpu_count()}-core machine at commit "
        f"{commit}; load average {load}"
    )


class Tee:
    """Write to several streams (the terminal and a results file's buffer)."""

    def __init__(self, *streams):
        self.streams = streams

    def write(self, text: str) -> None:
        for s in self.streams:
            s.write(text)

    def flush(self) -> None:
        for s in self.streams:
            s.flush()


def editor_tile_size(S, rule: str) -> int | None:
    """The editor's default tile size (Tile size: Auto) for source ``S`` (H, W[, C]):
    ``"auto"`` its rule (:func:`quilt_gui.params.auto_tile_size` with the source's structure
    scale: a power of two about half the shorter side, kept to whole periods), ``"pow2"`` the
    power of two alone (the editor's Auto before session 11)."""
    from engine.tiles.scale import structure_scale
    from quilt_gui.params import auto_tile_size

    return auto_tile_size(S.shape[:2], structure_scale(S) if rule == "auto" else None)


def scale_text(scale) -> str:
    """A structure scale as 'h x w' with P marking a period (an autocorrelation peak)."""
    if scale is None:
        return "-"
    mark = ["P" if p else "" for p in scale.periodic]
    return f"{scale.height:.0f}{mark[0]} x {scale.width:.0f}{mark[1]}"
