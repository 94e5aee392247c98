"""Small photo folders for the batch tests (few and small: the suite must stay fast)."""

from __future__ import annotations

import json
import os
import time
from pathlib import Path

import numpy as np
from PIL import Image

from engine.batch import BatchSettings
from engine.settings import TilesetSettings
from resources import sample_path

#: options that keep one photo's task well under a second
FAST = ["--tile-size", "32", "--candidates", "3"]
SMALL = BatchSettings(TilesetSettings(tile_min=32, tile_max=32, candidates=3))  # = FAST


def small(**changes) -> BatchSettings:
    """:data:`SMALL` with tile-set ``changes``."""
    return BatchSettings(SMALL.tileset.replace(**changes))


def write_photos(folder: Path, names=("brick", "gravel", "lichen"), size: int = 96) -> list[Path]:
    """Crops of the bundled samples (the second one resized from a larger crop)."""
    folder.mkdir(parents=True, exist_ok=True)
    out = []
    for i, name in enumerate(names):
        im = Image.open(sample_path(name)).convert("RGB")
        if i % 2:
            im = im.crop((0, 0, 2 * size, 2 * size)).resize((size, size), Image.Resampling.BOX)
        else:
            im = im.crop((40 * i, 30, 40 * i + size, 30 + size))
        p = folder / f"{name}.png"
        im.save(p)
        out.append(p)
    return out


def write_bad_photos(folder: Path) -> tuple[Path, Path]:
    """A truncated PNG and a 20x20 photo."""
    corrupt = folder / "corrupt.png"
    corrupt.write_bytes(sample_path("brick").read_bytes()[:2000])
    tiny = folder / "tiny.png"
    Image.fromarray((np.random.default_rng(0).random((20, 20, 3)) * 255).astype(np.uint8)).save(
        tiny
    )
    return corrupt, tiny


def photo_folders(lib: Path) -> dict[str, dict]:
    """key -> batch section of every (non-hidden) photo folder's manifest; a folder without a
    complete manifest raises (a torn folder)."""
    out = {}
    for d in sorted(lib.iterdir()):
        if d.is_dir() and not d.name.startswith("."):
            doc = json.loads((d / "manifest.json").read_text())
            out[d.name] = doc["batch"]
            for name in doc["batch"]["written"]:
                assert (d / name).is_file(), f"{d.name}/{name} missing: torn folder"
    return out


def tile_bytes(lib: Path) -> dict[str, bytes]:
    """Every PNG and project of every photo folder, by relative path."""
    return {
        str(p.relative_to(lib)): p.read_bytes()
        for p in sorted(lib.glob("*/*"))
        if p.suffix in (".png", ".quiltproj") and not p.parent.name.startswith(".")
    }


HOLD = "QUILT_TEST_BATCH_HOLD"
"""Environment of a batch run by a test: ``FOLDER`` + ``os.pathsep`` + ``NAME`` makes its
worker hold photo NAME (file name) once its temporary folder is filled, before the rename
into the library, and touch ``FOLDER/NAME.held``: the test kills or interrupts it there,
whatever the machine's load."""
HOLD_S = 300.0  # a held worker that no one stops fails its photo after this (never reached)


def held_worker_main(*args) -> None:
    """The batch worker's loop (``engine.batch.pool``'s), holding as :data:`HOLD` says; a
    test's ``quilt-studio batch`` process starts its workers on this (it is importable by
    name in a spawned process)."""
    import engine.batch.pool as pool
    import engine.batch.task as task

    folder, name = os.environ[HOLD].split(os.pathsep, 1)
    make = task.make_folder

    def make_folder(tmp, photo, *a, **kw):
        record = make(tmp, photo, *a, **kw)
        if photo.name == name:
            (Path(folder) / f"{name}.held").touch()
            t0 = time.monotonic()
            while time.monotonic() - t0 < HOLD_S:
                time.sleep(0.01)
            raise RuntimeError(f"{name} was held {HOLD_S:.0f} s and not stopped")
        return record

    task.make_folder = make_folder
    pool._worker_main(*args)


def interrupted_at_start_worker_main(*args) -> None:
    """The batch worker's loop, after a Ctrl-C of the worker's own start-up (sent to itself
    before the loop sets its handlers: a Ctrl-C while the interpreter starts)."""
    import signal

    import engine.batch.pool as pool

    os.kill(os.getpid(), signal.SIGINT)
    pool._worker_main(*args)
