"""Writing a bundle folder all or nothing: the files go into a hidden temporary sibling folder
that replaces ``out`` in one swap (:func:`engine._fs.replace_folder`), and images are encoded as
they are written."""

from __future__ import annotations

import io
from collections.abc import Callable, Iterable, Mapping, Sequence
from pathlib import Path

import numpy as np

from engine._fs import OutputError, replace_folder
from engine.png import encode_png

__all__ = ["ExportError", "write_bundle"]


class ExportError(OutputError):
    """The bundle could not be written; nothing was left behind. The message says where and why.

    ``errno`` holds the underlying error number (e.g. ``ENOSPC``) when there is one.
    """


def write_bundle(
    out: Path,
    files: Mapping[str, object],
    *,
    owned: Callable[[Path], Iterable[str]],
    overwrite: bool,
    inputs: Sequence = (),
) -> None:
    """Write ``files`` (name -> uint image array or text) as the folder ``out``; an existing
    folder is replaced only if ``owned(out)`` names every file in it."""

    def fill(tmp: Path) -> None:
        for rel, content in files.items():
            _write_file(tmp / rel, content)

    try:
        replace_folder(
            out, fill, owned=owned, inputs=inputs, overwrite=overwrite, action="export to"
        )
    except OutputError as exc:
        raise ExportError(exc.errno, str(exc)) from exc.__cause__


def _write_file(path: Path, content) -> None:
    if isinstance(content, str):
        _write_bytes(path, content.encode("utf-8"))
        return
    q = np.asarray(content)
    if path.suffix == ".tif":
        import tifffile

        buf = io.BytesIO()
        tifffile.imwrite(
            buf,
            q[:, :, 0] if q.ndim == 3 and q.shape[2] == 1 else q,
            photometric="minisblack" if q.ndim == 2 or q.shape[2] < 3 else "rgb",
            extrasamples=("unassalpha",) if q.ndim == 3 and q.shape[2] in (2, 4) else None,
            compression="zlib",
            metadata=None,
        )
        _write_bytes(path, buf.getvalue())
        return
    _write_bytes(path, encode_png(q))


def _write_bytes(path: Path, data: bytes) -> None:
    """Every byte of the bundle goes through here (tests simulate a full disk on it)."""
    with open(path, "wb") as f:
        f.write(data)
