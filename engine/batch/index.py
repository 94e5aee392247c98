"""``LIB/index.csv`` and ``LIB/index.html``, written from the library's entries."""

from __future__ import annotations

import csv
import io
from pathlib import Path

from engine._fs import write_bytes_atomically
from engine.batch.contact_sheet import contact_sheet
from engine.batch.library import COLUMNS, INDEX_CSV, read_library

INDEX_HTML = "index.html"


def index_csv(entries) -> str:
    """The CSV index: one row per photo, the columns of :data:`COLUMNS` as raw values, plus
    warnings / error (joined by " | "), the folder and the project (relative paths)."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(
        ["photo", *(k for k, _, _ in COLUMNS), "warnings", "error", "folder", "project", "source"]
    )
    for e in entries:
        project = e.files.get("project")
        w.writerow(
            [
                e.name,
                *("" if e.values.get(k) is None else e.values[k] for k, _, _ in COLUMNS),
                " | ".join(e.warnings),
                e.error,
                e.key,
                f"{e.key}/{project}" if project else "",
                e.source,
            ]
        )
    return buf.getvalue()


def write_index(library, entries=None) -> list[Path]:
    """Write ``index.csv`` and ``index.html`` of ``library`` (atomically); returns their paths."""
    lib = Path(library)
    entries = read_library(lib) if entries is None else list(entries)
    csv_path, html_path = lib / INDEX_CSV, lib / INDEX_HTML
    write_bytes_atomically(csv_path, index_csv(entries).encode("utf-8"))
    write_bytes_atomically(html_path, contact_sheet(entries, title=lib.name).encode("utf-8"))
    return [csv_path, html_path]
