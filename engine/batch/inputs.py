"""The photos of a batch: INPUTS (files, folders, globs) expanded, named and fingerprinted.

Each photo is identified by its *content*: its library folder is ``<name>-<8 hex of the
SHA-256 of its bytes>`` and its seed is derived from the same digest, so a photo gets the same
folder and the same tiles whatever its path, the order of the inputs, the number of workers or
the order in which workers finish.
"""

from __future__ import annotations

import glob
import hashlib
import os
import re
from dataclasses import dataclass
from pathlib import Path

#: File suffixes a folder or glob contributes (a file named explicitly is taken whatever its
#: suffix: a wrong one is reported by the photo's task).
PHOTO_SUFFIXES = (".png", ".jpg", ".jpeg", ".tif", ".tiff", ".bmp", ".webp")
_GLOB_CHARS = re.compile(r"[*?\[]")
_CHUNK = 1 << 20


@dataclass(frozen=True, slots=True)
class Photo:
    """One input photo.

    ``path`` absolute; ``digest`` the SHA-256 of its bytes (hex), or "" when it could not be
    read (``error`` says why); ``key`` its library folder name.
    """

    path: str
    key: str
    digest: str
    size: int = 0
    error: str = ""

    @property
    def name(self) -> str:
        return os.path.basename(self.path)


def slug(text: str, limit: int = 40) -> str:
    """A file-name-safe form of ``text``: letters, digits, ``-`` and ``_`` (others -> ``_``)."""
    s = re.sub(r"[^A-Za-z0-9_-]+", "_", text).strip("_") or "photo"
    return s[:limit]


def file_digest(path) -> str:
    """SHA-256 (hex) of a file's bytes, read in chunks."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        while chunk := f.read(_CHUNK):
            h.update(chunk)
    return h.hexdigest()


def photo_seed(digest: str, seed: int = 0) -> int:
    """The seed of a photo's tile set: from its content digest and the batch ``seed``."""
    d = hashlib.sha256(f"{int(seed)}:{digest}".encode()).digest()
    return int.from_bytes(d[:4], "big")


def make_photo(path) -> Photo:
    """Fingerprint one file (an unreadable one gets ``error`` and a key from its path)."""
    p = os.path.abspath(os.fspath(path))
    stem = slug(Path(p).stem)
    try:
        size = os.path.getsize(p)
        digest = file_digest(p)
    except OSError as exc:
        why = exc.strerror or str(exc)
        tag = hashlib.sha256(p.encode()).hexdigest()[:8]
        return Photo(p, f"{stem}-{tag}", "", 0, f"cannot be read ({why})")
    return Photo(p, f"{stem}-{digest[:8]}", digest, size)


def _folder_files(folder: Path, skip: Path | None) -> list[Path]:
    out = []
    for root, dirs, files in os.walk(folder):
        r = Path(root)
        dirs[:] = sorted(
            d for d in dirs if not d.startswith(".") and (skip is None or (r / d) != skip)
        )
        out += [
            r / f
            for f in sorted(files)
            if not f.startswith(".") and f.lower().endswith(PHOTO_SUFFIXES)
        ]
    return out


def expand_inputs(inputs, *, skip=None) -> tuple[list[Path], list[str]]:
    """Files named by ``inputs`` (files, folders searched recursively, globs) in input order,
    each once, and the inputs that named nothing. ``skip`` (the library) is never searched."""
    skip_p = Path(os.path.abspath(skip)) if skip is not None else None
    seen: set[str] = set()
    files: list[Path] = []
    unmatched: list[str] = []
    for text in inputs:
        p = Path(text)
        if p.is_dir():
            found = _folder_files(p, skip_p)
        elif p.exists() or p.is_symlink():
            found = [p]
        elif _GLOB_CHARS.search(text):
            found = []
            for m in sorted(glob.glob(text, recursive=True)):
                mp = Path(m)
                if mp.is_dir():
                    found += _folder_files(mp, skip_p)
                elif m.lower().endswith(PHOTO_SUFFIXES):
                    found.append(mp)
        else:
            found = []  # no such file
        if not found:
            unmatched.append(text)
        for f in found:
            a = os.path.abspath(f)
            if skip_p is not None and Path(a).is_relative_to(skip_p):
                continue
            if a not in seen:
                seen.add(a)
                files.append(Path(a))
    return files, unmatched


def find_photos(inputs, *, skip=None) -> tuple[list[Photo], list[str], list[tuple[str, str]]]:
    """Expand and fingerprint ``inputs``: (photos, inputs that named nothing, (path, path of
    the same content) pairs left out as duplicates)."""
    files, unmatched = expand_inputs(inputs, skip=skip)
    photos: list[Photo] = []
    by_key: dict[str, Photo] = {}
    dupes: list[tuple[str, str]] = []
    for f in files:
        ph = make_photo(f)
        first = by_key.get(ph.key)
        if first is not None:
            dupes.append((ph.path, first.path))
            continue
        by_key[ph.key] = ph
        photos.append(ph)
    return photos, unmatched, dupes
