"""``index.html``: a static contact sheet of a library, one row per photo.

Self-contained: inline CSS and a few lines of inline script (click a header to sort), images
and project links relative to the library folder; no external resource, so it works offline
and when the library is moved or copied.
"""

from __future__ import annotations

from html import escape
from urllib.parse import quote

from engine.batch.library import COLUMNS
from engine.batch.quality import past_limit

_CSS = """
body{font:13px/1.35 system-ui,sans-serif;margin:12px;background:#fafafa;color:#222}
h1{font-size:20px;margin:0 0 4px}
p.sum{margin:0 0 12px;color:#555}
table{border-collapse:collapse;background:#fff}
th,td{border:1px solid #ddd;padding:4px 6px;vertical-align:top}
th{background:#eee;cursor:pointer;position:sticky;top:0}
th.num{max-width:80px}
td.num{text-align:right;font-variant-numeric:tabular-nums;white-space:nowrap}
td.bad{background:#fde2d6;color:#8a2500;font-weight:600}
tr.failed td{background:#fbeaea}
td.img img{display:block;max-width:128px;max-height:128px}
td.tile img{max-width:96px;max-height:96px;image-rendering:auto}
.name{font-weight:600}
td.photo{min-width:130px;max-width:180px}
td.notes{min-width:220px;max-width:300px}
.src{color:#777;font-size:12px;word-break:break-all}
ul.warn{margin:0;padding-left:16px;color:#8a4b00}
.err{color:#a00;font-weight:600}
.ok{color:#2a7a2a}
"""

_SCRIPT = """
document.querySelectorAll('th[data-k]').forEach(function(th, i){
  th.addEventListener('click', function(){
    var body = th.closest('table').tBodies[0];
    var rows = Array.prototype.slice.call(body.rows);
    var dir = th.dataset.dir === 'asc' ? -1 : 1;
    th.dataset.dir = dir === 1 ? 'asc' : 'desc';
    var col = th.cellIndex;
    rows.sort(function(a, b){
      var x = a.cells[col].dataset.v, y = b.cells[col].dataset.v;
      var nx = parseFloat(x), ny = parseFloat(y);
      if (!isNaN(nx) && !isNaN(ny)) return dir * (nx - ny);
      return dir * String(x).localeCompare(String(y));
    });
    rows.forEach(function(r){ body.appendChild(r); });
  });
});
"""


SHEET_COLUMNS = tuple(c for c in COLUMNS if c[0] != "warning_count")
"""The library's columns on the sheet: the warning count is left out (the warnings column
lists them and sorts by their number), so a row fits a 1400 px wide window."""


_NUM = ' class="num"'


def _href(key: str, name: str) -> str:
    return escape(f"{quote(key)}/{quote(name)}")


def _row(e) -> str:
    cls = ' class="failed"' if e.failed else ""
    cells = []
    thumb, tile, project = (e.files.get(k) for k in ("thumbnail", "tile", "project"))
    preview = e.files.get("preview") or thumb
    if thumb:
        img = f'<img src="{_href(e.key, thumb)}" alt="8x8 preview of {escape(e.name)}">'
        cells.append(f'<td class="img"><a href="{_href(e.key, preview)}">{img}</a></td>')
    else:
        cells.append("<td></td>")
    cells.append(
        f'<td class="img tile"><img src="{_href(e.key, tile)}" alt="seamless tile"></td>'
        if tile
        else "<td></td>"
    )
    link = f'<br><a href="{_href(e.key, project)}">open project</a>' if project else ""
    cells.append(
        f'<td class="photo" data-v="{escape(e.name.lower())}">'
        f'<span class="name">{escape(e.name)}</span>'
        f'<div class="src">{escape(e.source)}</div>{link}</td>'
    )
    notes = [f'<div class="err">{escape(e.error)}</div>'] if e.error else []
    if e.warnings:
        items = "".join(f"<li>{escape(w)}</li>" for w in e.warnings)
        notes.append(f'<ul class="warn">{items}</ul>')
    cells.append(f'<td class="notes" data-v="{len(e.warnings)}">{"".join(notes)}</td>')
    for key, _, fmt in SHEET_COLUMNS:
        v = e.values.get(key)
        text = escape(e.text(key))
        sort_v = escape(str(v)) if v is not None else ""
        klass = "num" if fmt else ""
        if past_limit(key, v):
            klass += " bad"
        if key == "status":
            text = f'<span class="{"err" if e.failed else "ok"}">{text}</span>'
        cells.append(f'<td class="{klass.strip()}" data-v="{sort_v}">{text}</td>')
    return f"<tr{cls}>{''.join(cells)}</tr>"


def contact_sheet(entries, *, title: str = "library") -> str:
    """The HTML page of ``entries`` (already in the order to show)."""
    entries = list(entries)
    failed = sum(e.failed for e in entries)
    warned = sum(bool(e.warnings) and not e.failed for e in entries)
    heads = ["8x8 preview", "Tile", "Photo", "Warnings / error", *(h for _, h, _ in SHEET_COLUMNS)]
    keys = ["", "", "photo", "notes", *(k for k, _, _ in SHEET_COLUMNS)]
    numeric = {k for k, _, fmt in SHEET_COLUMNS if fmt}
    th = "".join(
        f'<th data-k="{k}"{_NUM if k in numeric else ""} title="click to sort">{escape(h)}</th>'
        if k
        else f"<th>{h}</th>"
        for k, h in zip(keys, heads, strict=True)
    )
    rows = "\n".join(_row(e) for e in entries)
    return (
        '<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
        f"<title>Quilt Studio library: {escape(title)}</title><style>{_CSS}</style></head>\n"
        f"<body><h1>Quilt Studio library: {escape(title)}</h1>\n"
        f'<p class="sum">{len(entries)} photos: {len(entries) - failed} done '
        f"({warned} with warnings), {failed} failed. Failed and warned photos first; click a "
        "header to sort; a preview opens at full size, a project opens in Quilt Studio.</p>\n"
        f"<table><thead><tr>{th}</tr></thead><tbody>\n{rows}\n</tbody></table>\n"
        f"<script>{_SCRIPT}</script></body></html>\n"
    )
