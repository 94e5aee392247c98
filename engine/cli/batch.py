"""``quilt-studio batch INPUTS... --out LIB``: a tile set for every photo, resumable.

For every photo a folder ``LIB/<name>-<digest>/`` (seamless tile, tile set, manifest with the
quality metrics and the settings hash, a ``.quiltproj`` for the editor, a thumbnail of the 8x8
preview), and ``LIB/index.html`` / ``LIB/index.csv`` over all of them. A re-run skips the photos
already made with the same settings. Exit codes: 0 every photo done, 3 some failed (listed),
2 bad arguments, 1 the batch could not run, 130 interrupted (143 terminated; re-run to finish).

Imports stay inside :func:`run`: ``quilt-studio --help`` loads nothing heavy, and Dask is
imported only with ``--scheduler``.
"""

from __future__ import annotations

import argparse
import re
import sys
import time

from engine.cli._args import int_at_least

BAD_ARGUMENTS = 2
SOME_FAILED = 3
INTERRUPTED = 130
TERMINATED = 143


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "batch",
        help="make a tile set for every photo of a folder: a browsable, resumable library",
        description="For every photo (INPUTS: files, folders searched recursively, or globs) "
        "write LIB/<photo>-<digest>/ with the seamless tile, the tile set, a manifest with "
        "the quality metrics, a .quiltproj project for the editor and a thumbnail of the 8x8 "
        "preview; then LIB/index.html (a contact sheet, failed and warned photos first) and "
        "LIB/index.csv. Re-running skips the photos already made with the same settings; one "
        "failing photo never stops the others. Exit code 0: all done; 3: some failed; 2: bad "
        "arguments; 130: interrupted (re-run to resume).",
    )
    p.add_argument("inputs", nargs="+", metavar="INPUT", help="photo files, folders or globs")
    p.add_argument("--out", required=True, metavar="LIB", help="library folder (created)")
    size = p.add_argument_group("tile size (default: the tileset command's range per photo)")
    size.add_argument(
        "--tile-size",
        type=_size_or_auto,
        default=None,
        metavar="N|auto",
        help="tiles of N x N px; auto (--wang sets): the tileset command's --tile-size auto for "
        "each photo (its default size moved to the nearest one within 25%% that holds whole "
        "periods of a periodic texture; a line per photo says which)",
    )
    size.add_argument(
        "--tile-min", type=int_at_least(8), default=None, metavar="N", help="smallest tile side"
    )
    size.add_argument(
        "--tile-max", type=int_at_least(8), default=None, metavar="N", help="largest tile side"
    )
    p.add_argument(
        "--candidates",
        type=int_at_least(1),
        default=None,
        metavar="K",
        help="candidate tiles per photo (default 30)",
    )
    p.add_argument(
        "--wang",
        type=int_at_least(1),
        default=None,
        metavar="K",
        help="a Wang tile set of K colours per edge direction (K^4 tiles) instead of a "
        "template and candidates; --tile-size N sets its square tiles",
    )
    p.add_argument(
        "--flatten",
        action="store_true",
        help="flatten each photo's lighting before the template search (the low-frequency "
        "illumination removed, as the tileset command's --flatten; default: automatic, as "
        "there)",
    )
    p.add_argument(
        "--no-flatten",
        action="store_true",
        help="never flatten the lighting (the tileset command's --no-flatten)",
    )
    p.add_argument(
        "--settings",
        metavar="FILE",
        default=None,
        help="every other tile-set option from a tileset manifest.json, a .quiltproj project "
        "or a JSON file of settings (the options above override it)",
    )
    p.add_argument(
        "--seed",
        type=int_at_least(0),
        default=None,
        help="batch seed (default 0); each photo's seed is derived from it and the photo's content",
    )
    p.add_argument(
        "--jobs",
        type=int_at_least(1),
        default=None,
        metavar="N",
        help="local worker processes (default: the cores)",
    )
    p.add_argument(
        "--scheduler",
        default="",
        metavar="ADDRESS",
        help="run on the Dask cluster at tcp://HOST:PORT instead of local processes (needs "
        "pip install 'quilt-studio[distributed]'; photos are sent to the workers as bytes, "
        "no shared folder is needed)",
    )
    p.add_argument(
        "--force",
        action="store_true",
        help="redo every photo, also those already made or edited in the editor since",
    )
    p.add_argument("-v", "--verbose", action="store_true", help="one line per photo")
    p.set_defaults(func=run)
    return p


def _size_or_auto(text: str):
    from engine.cli.tileset_wang import AUTO

    return AUTO if text.strip().lower() == AUTO else int_at_least(8)(text)


def _settings(args, fail):
    """The batch's settings from the flags (and ``--settings``); a bad value fails with
    exit code 2."""
    from engine.batch import BatchSettings
    from engine.cli.tileset import read_settings
    from engine.settings import TilesetSettings

    if args.tile_size is not None and (args.tile_min is not None or args.tile_max is not None):
        fail("--tile-size cannot be combined with --tile-min / --tile-max")
    auto = args.tile_size == "auto"
    fixed = None if auto else args.tile_size
    changes = {
        k: v
        for k, v in (
            ("tile_min", fixed or args.tile_min),
            ("tile_max", fixed or args.tile_max),
            ("candidates", args.candidates),
            ("wang", args.wang),
            ("seed", args.seed),
            ("flatten", True if args.flatten else False if args.no_flatten else None),
        )
        if v is not None
    }
    try:
        base = read_settings(args.settings) if args.settings else TilesetSettings()
        settings = base.replace(**changes)
    except (TypeError, ValueError) as exc:
        fail(str(exc))
    if settings.wang is not None and settings.flatten:
        fail("--flatten is not available for Wang sets (the Wang workflow does not flatten)")
    if auto and settings.wang is None:
        fail(
            "--tile-size auto is for --wang sets (the template search's range keeps whole "
            "periods by itself)"
        )
    if auto and (settings.tile_min is not None or settings.tile_max is not None):
        fail("--tile-size auto moves the default size: --settings fixes one (tile_min/tile_max)")
    return BatchSettings(settings, tile_size_auto=auto)


class _Usage(Exception):
    pass


def run(args) -> int:
    """Run the batch; returns the exit code."""

    def fail(text: str):
        raise _Usage(text)

    try:
        return _run(args, fail)
    except _Usage as exc:
        print(f"quilt-studio batch: error: {exc}", file=sys.stderr)
        return BAD_ARGUMENTS


def _run(args, fail) -> int:
    from pathlib import Path

    from engine.batch import LibraryBusy, clean_library, find_photos, lock_library, plan

    settings = _settings(args, fail)
    if args.scheduler and not re.fullmatch(r"(tcp|tls)://[^\s/:]+:\d+/?", args.scheduler):
        fail(f"--scheduler must look like tcp://HOST:PORT, got {args.scheduler!r}")
    lib = Path(args.out)
    try:
        lib.mkdir(parents=True, exist_ok=True)
        from engine._fs import check_writable

        check_writable(lib)
    except OSError as exc:
        fail(f"--out {lib}: {exc}")
    photos, unmatched, dupes = find_photos(args.inputs, skip=lib)
    if unmatched:
        fail("no photo found for " + ", ".join(repr(u) for u in unmatched))
    try:
        with lock_library(lib):
            clean_library(lib)
            return _make(args, settings, lib, photos, dupes, plan)
    except LibraryBusy as exc:
        print(f"quilt-studio batch: error: {exc}", file=sys.stderr)
        return 1


def _say(text: str) -> None:
    print(f"quilt-studio batch: {text}", file=sys.stderr, flush=True)


def _make(args, settings, lib, photos, dupes, plan) -> int:
    from engine.batch import iter_batch, remove_superseded
    from engine.batch.index import write_index
    from engine.cli.outcome import Terminated

    for path, first in dupes:
        _say(f"{path}: same content as {first}, made once")
    work = plan(photos, settings, lib, force=args.force)
    _say(
        f"{len(photos)} photos: {len(work.todo)} to make, {len(work.done)} already done"
        + (
            f", {len(work.edited)} edited in the editor (kept; --force redoes them)"
            if work.edited
            else ""
        )
    )
    failed: list = []
    made = 0
    reported: set[str] = set()
    interrupted: KeyboardInterrupt | None = None
    broken = None
    t0 = time.perf_counter()
    bar = _progress(len(work.todo))
    records = iter_batch(work.todo, settings, lib, jobs=args.jobs, scheduler=args.scheduler)
    try:
        for r in records:
            reported.add(r.key)
            if r.failed:
                failed.append(r)
            else:
                made += 1
            bar.update(1)
            bar.set_postfix_str(f"done {made}, failed {len(failed)}", refresh=True)
            for note in r.notes:  # the tileset command's own line, for each photo
                bar.write(f"quilt-studio batch: {r.path}: {note}", file=sys.stderr)
            if args.verbose:
                bar.write(_line(r), file=sys.stderr)
    except KeyboardInterrupt as exc:  # Ctrl-C, or SIGTERM (Terminated)
        interrupted = exc
    except Exception as exc:  # the scheduler itself failed (e.g. the cluster went away)
        broken = exc
    finally:
        records.close()
        bar.close()
    if interrupted is not None or broken is not None:
        made += _finished_unheard(lib, settings, work.todo, reported)
    superseded = remove_superseded(lib, photos)
    if superseded:
        _say(
            f"removed {len(superseded)} folder(s) of photos changed since: " + ", ".join(superseded)
        )
    index = _finish_index(lib, write_index)
    if broken is not None:
        _say(f"error: {broken}")
        return 1
    elapsed = time.perf_counter() - t0
    _say(
        f"{len(photos)} photos: {made} made now, {len(work.done)} already done, "
        f"{len(work.edited)} kept, {len(failed)} failed ({elapsed:.1f} s)"
        + (f"; index: {index}" if index else "")
    )
    for r in failed:
        _say(f"FAILED {r.path}: {r.error}")
    if interrupted is not None:
        _say("interrupted: the photos made so far are kept; run the same command to finish")
        return TERMINATED if isinstance(interrupted, Terminated) else INTERRUPTED
    return SOME_FAILED if failed else 0


def _finished_unheard(lib, settings, todo, reported) -> int:
    """Photos a worker finished (its folder is in place) whose record the stopped batch did
    not receive: counted as made, as the next run will find them done."""
    from engine.batch.task import folder_state

    digest = settings.digest()
    return sum(
        folder_state(lib / ph.key, digest) == "done" for ph in todo if ph.key not in reported
    )


def _finish_index(lib, write_index):
    try:
        return write_index(lib)[1]
    except OSError as exc:
        _say(f"error: cannot write the index: {exc}")
        return None


def _line(r) -> str:
    if r.failed:
        return f"FAILED {r.path}: {r.error}"
    warn = f", {len(r.warnings)} warning(s): {'; '.join(r.warnings)}" if r.warnings else ""
    return f"done {r.path} -> {r.key} ({r.seconds:.1f} s{warn})"


def _progress(total: int):
    """A tqdm bar on stderr (photos done / failed / time left); silent when not a terminal."""
    from tqdm import tqdm

    return tqdm(
        total=total,
        unit="photo",
        file=sys.stderr,
        disable=None if total else True,
        dynamic_ncols=True,
        bar_format="{l_bar}{bar}| {n_fmt}/{total_fmt} [{elapsed}<{remaining}{postfix}]",
    )
