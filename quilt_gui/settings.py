"""Typed, persisted user settings (mnelab style): one table of defaults, typed reads.

Every key has a default in :data:`DEFAULTS`; reading or writing an unknown key raises
``KeyError`` so a typo cannot silently create a new setting. Values are stored with
``QSettings`` (under the organisation and application names set by :func:`set_names`), so
tests can redirect them to a temporary folder with ``QSettings.setPath``.
"""

from __future__ import annotations

import json
from typing import Any

from PySide6.QtCore import QByteArray, QCoreApplication, QSettings

APP_NAME = "Quilt Studio"
ORG_NAME = "QuiltStudio"
MAX_RECENT = 10

DEFAULTS: dict[str, Any] = {
    "theme": "dark",  # "dark" or "light"
    "recent_files": [],
    "last_open_dir": "",
    "last_project_dir": "",
    "last_export_dir": "",
    "last_library_dir": "",
    "window_geometry": QByteArray(),
    "window_state": QByteArray(),
    "autosave_seconds": 60,
    "tile_repeats": 3,
    "tile_grid_lines": True,
    "heat_overlay": True,
    "preview_grid": False,
    "wang_grid": False,  # the Wang tab's Grid box (tile borders over its layout)
    "wang_seams": True,  # the Wang tab's Seams box (the tiles' cuts)
    "thumbnail_size": 112,
    "params_view": "Basic",  # the parameters panel's view: "Basic" or "Advanced"
    "parameters": {},  # the last used tile-set / quilting parameters (JSON-able dict)
}


def set_names() -> None:
    """Organisation and application names (they locate the QSettings file)."""
    QCoreApplication.setOrganizationName(ORG_NAME)
    QCoreApplication.setApplicationName(APP_NAME)


def _store() -> QSettings:
    return QSettings()


def get(key: str) -> Any:
    """The stored value of ``key``, converted to the type of its default."""
    default = DEFAULTS[key]
    s = _store()
    if not s.contains(key):
        return _copy(default)
    raw = s.value(key)
    try:
        return _convert(raw, default)
    except (TypeError, ValueError):
        return _copy(default)


def set(key: str, value: Any) -> None:  # noqa: A001 - mirrors QSettings.setValue
    """Store ``value`` under ``key`` (must be a known key)."""
    default = DEFAULTS[key]
    value = _convert(value, default)
    if isinstance(default, dict):
        value = json.dumps(value)
    _store().setValue(key, value)


def reset() -> None:
    """Forget every stored value (defaults apply again)."""
    s = _store()
    for key in DEFAULTS:
        s.remove(key)


def add_recent_file(path: str) -> list[str]:
    """Put ``path`` first in the recent-files list (no duplicates, at most MAX_RECENT)."""
    files = [f for f in get("recent_files") if f != path]
    files.insert(0, path)
    files = files[:MAX_RECENT]
    set("recent_files", files)
    return files


def remove_recent_file(path: str) -> list[str]:
    files = [f for f in get("recent_files") if f != path]
    set("recent_files", files)
    return files


def _copy(v: Any) -> Any:
    if isinstance(v, (list, dict)):
        return type(v)(v)
    if isinstance(v, QByteArray):
        return QByteArray(v)
    return v


def _convert(raw: Any, default: Any) -> Any:
    """Coerce a value read from (or written to) QSettings to the default's type.

    INI files give strings back; lists of one element come back as a string;
    ``None`` stands for an empty list.
    """
    if isinstance(default, bool):
        if isinstance(raw, str):
            return raw.strip().lower() in ("1", "true", "yes", "on")
        return bool(raw)
    if isinstance(default, int):
        return int(raw)
    if isinstance(default, float):
        return float(raw)
    if isinstance(default, str):
        return "" if raw is None else str(raw)
    if isinstance(default, list):
        if raw is None:
            return []
        if isinstance(raw, str):
            return [raw]
        return [str(v) for v in raw]
    if isinstance(default, dict):
        if raw is None or raw == "":
            return {}
        if isinstance(raw, str):
            v = json.loads(raw)
            if not isinstance(v, dict):
                raise ValueError("not a dict")
            return v
        return dict(raw)
    if isinstance(default, QByteArray):
        return QByteArray(raw) if raw is not None else QByteArray()
    return raw
