"""A library folder read back: one entry per photo folder and the index's columns.

The editor's library browser (File ▸ Open library…) shows the same :data:`COLUMNS` in the same
order (:func:`read_library`: failed photos first, then by number of warnings, then by name) as
the contact sheet and the CSV (:mod:`engine.batch.index`), so they agree by construction.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from pathlib import Path

from engine.batch.task import MANIFEST

INDEX_CSV = "index.csv"

#: (key, header, number format or None) of every index column after the photo's name.
COLUMNS = (
    ("status", "Status", None),
    ("warning_count", "Warnings", "{:d}"),
    ("tile_size", "Tile size", None),
    ("tiles", "Tiles", "{:d}"),
    ("wrap", "Wrap", "{:.2f}"),
    ("detail", "Detail", "{:.2f}"),
    ("frame", "Frame", "{:.2f}"),
    ("ring_tone", "Ring tone", "{:.2f}"),
    ("lattice", "Lattice dB", "{:+.1f}"),
    ("duplicates", "Duplicates", "{:d}"),
    ("template_share", "Template share", "{:.0%}"),
    ("spread", "Detail spread", "{:.1f}"),
    ("seconds", "Time s", "{:.1f}"),
)


@dataclass(frozen=True, slots=True)
class Entry:
    """One photo folder of a library."""

    key: str
    folder: Path
    name: str
    status: str  # "done" | "failed"
    error: str = ""
    source: str = ""
    warnings: tuple[str, ...] = ()
    values: dict = field(default_factory=dict)  # column key -> number or text
    files: dict = field(default_factory=dict)  # "tile", "thumbnail", "project", "preview"

    @property
    def failed(self) -> bool:
        return self.status != "done"

    def file(self, which: str) -> Path | None:
        """Absolute path of ``which`` ("project", "thumbnail", "tile", "preview"), if any."""
        name = self.files.get(which)
        return self.folder / name if name else None

    def text(self, key: str) -> str:
        """Column ``key``'s value as the index shows it ("" when absent)."""
        v = self.values.get(key)
        if v is None:
            return ""
        fmt = next((f for k, _, f in COLUMNS if k == key), None)
        try:
            return fmt.format(v) if fmt else str(v)
        except (ValueError, TypeError):
            return str(v)


def sort_key(e: Entry):
    """Failed photos first, then the most warnings, then by name."""
    return (not e.failed, -len(e.warnings), e.name.lower(), e.key)


def read_entry(folder) -> Entry | None:
    """The entry of one photo folder, or None when it holds no batch manifest."""
    folder = Path(folder)
    try:
        doc = json.loads((folder / MANIFEST).read_text(encoding="utf-8"))
        b = doc["batch"]
        photo = b["photo"]
    except (OSError, ValueError, KeyError, TypeError):
        return None
    m = dict(b.get("metrics") or {})
    tmpl = doc.get("template", {}).get("rect")
    warnings = tuple(b.get("warnings") or ())
    values = {
        "status": b.get("status", "?"),
        "warning_count": len(warnings),
        "tile_size": f"{tmpl[2]}x{tmpl[3]}" if tmpl else None,
        "seconds": b.get("seconds"),
        **{k: m.get(k) for k, _, _ in COLUMNS if k in m},
    }
    return Entry(
        key=folder.name,
        folder=folder,
        name=photo.get("name") or folder.name,
        status=b.get("status", "?"),
        error=b.get("error", ""),
        source=photo.get("path", ""),
        warnings=warnings,
        values=values,
        files={k: v for k, v in (b.get("files") or {}).items() if v},
    )


def read_library(library) -> list[Entry]:
    """Every photo folder of ``library``, sorted by :func:`sort_key`."""
    lib = Path(library)
    entries = []
    for d in sorted(os.scandir(lib), key=lambda d: d.name):
        if d.is_dir() and not d.name.startswith("."):
            e = read_entry(d.path)
            if e is not None:
                entries.append(e)
    return sorted(entries, key=sort_key)


def is_library(folder) -> bool:
    """True when ``folder`` has an index or at least one photo folder."""
    p = Path(folder)
    if not p.is_dir():
        return False
    return (p / INDEX_CSV).is_file() or bool(read_library(p))
