"""A texture library from a folder of photos: ``quilt-studio batch`` without the command line.

One task per photo (:func:`engine.batch.task.run_photo`, a plain function of the photo and the
:class:`BatchSettings`) makes that photo's folder ``LIB/<key>/`` as a whole; a scheduler runs
the tasks on a local process pool (:mod:`engine.batch.pool`) or on a Dask cluster
(:mod:`engine.batch.cluster`); :mod:`engine.batch.index` writes ``LIB/index.csv`` and
``LIB/index.html`` from the folders (:mod:`engine.batch.library`).

Resuming: :func:`plan` skips the photos whose folder was made with the same settings (the hash
in its manifest), keeps those edited since in the editor, and redoes the others; seeds come
from each photo's content, so a re-run, a different number of workers or a cluster makes the
same bytes.
"""

from __future__ import annotations

import contextlib
import os
import re
import shutil
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

from engine.batch.inputs import Photo, find_photos, photo_seed
from engine.batch.settings import BatchSettings
from engine.batch.task import PhotoRecord, folder_state

__all__ = [
    "BatchSettings",
    "LibraryBusy",
    "Photo",
    "PhotoRecord",
    "Plan",
    "clean_library",
    "find_photos",
    "iter_batch",
    "lock_library",
    "photo_seed",
    "plan",
    "remove_superseded",
]

LOCK = ".quilt-batch.lock"
_TEMP = re.compile(r"^\.(?P<name>.+?)\.(?:(?:tmp|old)-\d+-[a-z0-9_]+|\d+-[a-z0-9_]+\.\w+)$")


@dataclass
class Plan:
    """Which photos a run makes (``todo``), finds up to date (``done``) or keeps because
    they were edited in the editor since (``edited``; ``force`` redoes them too)."""

    todo: list[Photo] = field(default_factory=list)
    done: list[Photo] = field(default_factory=list)
    edited: list[Photo] = field(default_factory=list)


def plan(photos, settings: BatchSettings, library, *, force: bool = False) -> Plan:
    """Sort ``photos`` by the state of their folder in ``library``."""
    out = Plan()
    digest = settings.digest()
    for ph in photos:
        state = "todo" if force else folder_state(Path(library) / ph.key, digest)
        {"todo": out.todo, "done": out.done, "edited": out.edited}[state].append(ph)
    return out


def iter_batch(
    photos, settings: BatchSettings, library, *, jobs: int | None = None, scheduler: str = ""
) -> Iterator[PhotoRecord]:
    """Make every photo's folder; yields a :class:`PhotoRecord` per photo as it finishes, on
    ``jobs`` local processes or, with ``scheduler`` (``tcp://HOST:PORT``), on that Dask
    cluster. Close the generator to stop the workers."""
    if scheduler:
        from engine.batch.cluster import iter_cluster

        return iter_cluster(photos, settings, library, address=scheduler)
    from engine.batch.pool import iter_local

    return iter_local(photos, settings, library, jobs=jobs)


class LibraryBusy(RuntimeError):
    """Another batch is writing into the library."""


@contextlib.contextmanager
def lock_library(library):
    """Hold the library for one batch (an advisory lock on ``LIB/.quilt-batch.lock``; released
    when the process ends however it ends)."""
    path = Path(library) / LOCK
    f = open(path, "a+b")  # noqa: SIM115 - held for the whole run
    try:
        try:
            import fcntl

            fcntl.flock(f.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
        except ImportError:  # no fcntl (Windows): no lock
            pass
        except OSError:
            raise LibraryBusy(f"{library}: another batch is writing into this library") from None
        yield
    finally:
        f.close()


def clean_library(library) -> list[Path]:
    """Remove the temporaries that killed runs left in ``library`` (see
    :func:`engine._fs.clean_stale`); returns what was removed."""
    from engine._fs import clean_stale

    names = set()
    with contextlib.suppress(OSError):
        for e in os.scandir(library):
            m = _TEMP.match(e.name)
            if m:
                names.add(m["name"])
    removed = []
    for name in sorted(names):
        removed += clean_stale(library, name)
    return removed


def remove_superseded(library, photos) -> list[str]:
    """Remove the folders made from an earlier content of one of ``photos``' paths (the photo
    was changed since), unless edited in the editor; returns their keys."""
    from engine.batch.library import read_library

    current = {ph.path: ph.key for ph in photos}
    removed = []
    for e in read_library(library):
        key = current.get(e.source)
        if key is None or key == e.key or folder_state(e.folder, "") == "edited":
            continue
        aside = Path(library) / f".{e.key}.old-{os.getpid()}-superseded"
        try:
            os.replace(e.folder, aside)
        except OSError:
            continue
        shutil.rmtree(aside, ignore_errors=True)
        removed.append(e.key)
    return removed
