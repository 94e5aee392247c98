"""``quilt-studio batch`` as a user runs it: worker processes, exit codes, resuming after
``kill -9`` and Ctrl-C, and the same bytes on a Dask cluster."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from engine.batch import find_photos
from engine.batch.task import run_photo
from engine.cli import main
from tests.engine.batch_helpers import (
    FAST,
    HOLD,
    SMALL,
    photo_folders,
    tile_bytes,
    write_bad_photos,
    write_photos,
)

SUMMARY = re.compile(r"(\d+) photos: (\d+) made now, (\d+) already done, (\d+) kept, (\d+) failed")


def summary(err: str) -> tuple[int, ...]:
    """(photos, made now, already done, kept, failed) from the batch's last summary line."""
    return tuple(int(v) for v in SUMMARY.findall(err)[-1])


def batch(*args, capsys=None) -> tuple[int, str]:
    code = main(["batch", *map(str, args)])
    err = capsys.readouterr().err if capsys is not None else ""
    return code, err


ROOT = Path(__file__).resolve().parents[2]


def cli(*args, hold: tuple[Path, str] | None = None, **kwargs) -> subprocess.Popen:
    """``quilt-studio batch ARGS`` in a process of its own; with ``hold`` (folder, photo file
    name) its worker holds that photo before its rename (:func:`held_worker_main`)."""
    code = "import sys; from engine.cli import main; sys.exit(main())"
    env = None
    if hold is not None:
        code = (
            f"import sys; sys.path.insert(0, {str(ROOT)!r}); import engine.batch.pool as p; "
            "from tests.engine.batch_helpers import held_worker_main as w; "
            f"p._worker_main = w; {code}"
        )
        env = {**os.environ, HOLD: f"{hold[0]}{os.pathsep}{hold[1]}"}
    return subprocess.Popen(
        [sys.executable, "-c", code, "batch", *map(str, args)],
        stderr=subprocess.PIPE,
        text=True,
        env=env,
        **kwargs,
    )


def wait_for_held(folder: Path, name: str, proc: subprocess.Popen, timeout: float = 120) -> None:
    """Wait until the batch's worker holds photo ``name`` (a margin, not a bound)."""
    t0 = time.monotonic()
    while not (folder / f"{name}.held").exists():
        assert proc.poll() is None, proc.stderr.read()
        if time.monotonic() - t0 > timeout:
            pytest.fail(f"the batch did not reach {name} in {timeout} s")
        time.sleep(0.02)


def test_failures_are_listed_the_rest_done_exit_3_then_resume(tmp_path, capsys):
    write_photos(tmp_path / "in")
    write_bad_photos(tmp_path / "in")
    lib = tmp_path / "lib"
    code, err = batch(tmp_path / "in", "--out", lib, *FAST, "--jobs", "2", "-v", capsys=capsys)
    assert code == 3, err
    assert summary(err) == (5, 3, 0, 0, 2)
    assert re.search(r"FAILED .*corrupt\.png: .*truncated or corrupt", err)
    assert re.search(r"FAILED .*tiny\.png: too small", err)
    assert len(re.findall(r"^done ", err, re.M)) == 3  # -v: one line per photo
    assert len(photo_folders(lib)) == 5
    assert (lib / "index.html").is_file() and (lib / "index.csv").is_file()
    stamps = {d: (lib / d / "manifest.json").stat().st_mtime_ns for d in photo_folders(lib)}
    code, err = batch(tmp_path / "in", "--out", lib, *FAST, capsys=capsys)
    assert code == 3 and summary(err) == (5, 0, 3, 0, 2)  # only the failed ones tried again
    done = [d for d, b in photo_folders(lib).items() if b["status"] == "done"]
    assert all((lib / d / "manifest.json").stat().st_mtime_ns == stamps[d] for d in done)
    code, err = batch(tmp_path / "in" / "brick.png", "--out", lib, *FAST, capsys=capsys)
    assert code == 0 and summary(err) == (1, 0, 1, 0, 0)


def test_bad_arguments_exit_2(tmp_path, capsys):
    (p,) = write_photos(tmp_path / "in", names=("brick",))
    lib = tmp_path / "lib"
    assert batch(p, "--out", lib, "--tile-size", "32", "--tile-min", "16", capsys=capsys)[0] == 2
    assert batch(tmp_path / "nothing*.png", "--out", lib, capsys=capsys)[0] == 2
    assert batch(p, "--out", lib, "--scheduler", "localhost", capsys=capsys)[0] == 2
    assert batch(p, "--out", lib, "--wang", "2", "--flatten", capsys=capsys)[0] == 2
    assert batch(p, "--out", lib, "--settings", tmp_path / "none.json", capsys=capsys)[0] == 2
    with pytest.raises(SystemExit) as exc:
        batch(p, "--out", lib, "--jobs", "0")
    assert exc.value.code == 2


def test_wang_tile_size_auto_per_photo_says_which(tmp_path, capsys):
    import json

    from PIL import Image

    from benchmarks.evalset import planks

    p = tmp_path / "in" / "planks.png"
    p.parent.mkdir()
    Image.fromarray(planks(512)).save(p)  # boards every 48 px: the default 128 holds 2.67
    lib = tmp_path / "lib"
    assert batch(p, "--out", lib, "--tile-size", "auto", capsys=capsys)[0] == 2  # not --wang
    code, err = batch(p, "--out", lib, "--wang", "2", "--tile-size", "auto", capsys=capsys)
    assert code == 0 and summary(err) == (1, 1, 0, 0, 0)
    assert "planks.png: tile size (auto): 144 px instead of 128 px: the texture repeats" in err
    (folder,) = photo_folders(lib)
    manifest = json.loads((lib / folder / "manifest.json").read_text())
    assert manifest["tile_size_auto"]["used"] == 144
    assert Image.open(lib / folder / manifest["tiles"][0]["file"]).size == (144, 144)
    assert manifest["batch"]["settings"]["tile_size_auto"] is True
    code, err = batch(p, "--out", lib, "--wang", "2", capsys=capsys)  # not auto: made again
    assert code == 0 and summary(err) == (1, 1, 0, 0, 0) and "tile size (auto)" not in err


def temporaries(lib: Path) -> list[str]:
    return [p.name for p in lib.iterdir() if p.name.startswith(".") and "tmp" in p.name]


def group_alive(pgid: int) -> list[int]:
    """The processes of group ``pgid`` that have not exited (Linux /proc; zombies have)."""
    alive = []
    for name in os.listdir("/proc") if os.path.isdir("/proc") else ():
        try:
            with open(f"/proc/{name}/stat", "rb") as f:
                state, _ppid, group = f.read().rsplit(b")", 1)[1].split()[:3]
        except (OSError, ValueError):
            continue  # not a process, or gone meanwhile
        if int(group) == pgid and state != b"Z":
            alive.append(int(name))
    return alive


def test_kill_9_then_ctrl_c_each_rerun_finishes_only_the_rest(tmp_path, capsys):
    """Each stop lands while a photo's folder is filled but not yet in place (the worker holds
    there: the test does not race the batch, which on a loaded machine had made one photo
    more, or all of them, before the signal came)."""
    names = ("brick", "cobblestones", "grass", "gravel", "lichen")  # the order they are made
    write_photos(tmp_path / "in", names=names)
    lib, gate = tmp_path / "lib", tmp_path / "gate"
    gate.mkdir()

    def batch_held_at(photo: str):
        """The batch on one worker, started in its own session, held once ``photo``'s folder
        is filled."""
        proc = cli(
            tmp_path / "in",
            "--out",
            lib,
            *FAST,
            "--jobs",
            "1",
            start_new_session=True,
            hold=(gate, photo),
        )
        wait_for_held(gate, photo, proc)
        return proc

    # 1. kill -9 halfway: complete folders or none, never a torn one. The library is read once
    # every process of the batch has ended (the worker dies with the batch)
    proc = batch_held_at("cobblestones.png")
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    proc.stderr.close()  # (unread: an open pipe would warn later, in another test's output)
    t0 = time.monotonic()
    while group_alive(proc.pid) and time.monotonic() - t0 < 120:  # a margin, not a bound
        time.sleep(0.02)
    assert group_alive(proc.pid) == [], "the killed batch's worker did not end"
    first = photo_folders(lib)  # raises on a torn folder
    assert [d.split("-")[0] for d in first] == ["brick"]  # the filled temporary is not done
    assert any(t.startswith(".cobblestones-") for t in temporaries(lib))
    stamps = {d: (lib / d / "manifest.json").stat().st_mtime_ns for d in first}
    # 2. the re-run skips those, makes more, and is stopped by Ctrl-C (the process group's)
    proc = batch_held_at("gravel.png")
    os.killpg(proc.pid, signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    assert "interrupted: the photos made so far are kept" in err and "as it finished" not in err
    second = photo_folders(lib)
    assert [d.split("-")[0] for d in second] == ["brick", "cobblestones", "grass"]
    assert summary(err) == (5, 2, 1, 0, 0)
    assert temporaries(lib) == []  # the killed run's are cleaned, Ctrl-C leaves none
    # 3. the last run finishes the rest only; nothing made before is touched
    code, err = batch(tmp_path / "in", "--out", lib, *FAST, "--jobs", "1", capsys=capsys)
    assert code == 0, err
    assert summary(err) == (5, 2, 3, 0, 0)
    assert len(photo_folders(lib)) == 5 and temporaries(lib) == []
    assert all((lib / d / "manifest.json").stat().st_mtime_ns == stamps[d] for d in first)


def test_dask_is_imported_only_with_a_scheduler():
    code = (
        "import sys, engine.cli.batch, engine.batch, engine.batch.pool, engine.batch.task, "
        "engine.batch.index; from engine.cli import build_parser; "
        "build_parser(command='batch').parse_args(['batch', 'x', '--out', 'y']); "
        "print(sorted(m for m in sys.modules if m.split('.')[0] in ('dask', 'distributed')))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "[]"


def test_dask_cluster_makes_byte_identical_tiles(tmp_path, capsys):
    pytest.importorskip("distributed")
    write_photos(tmp_path / "in", names=("brick", "gravel"))
    corrupt, tiny = write_bad_photos(tmp_path / "in")
    tiny.unlink()
    local, remote = tmp_path / "local", tmp_path / "dask"
    local.mkdir()
    for ph in find_photos([str(tmp_path / "in")])[0]:
        run_photo(ph, SMALL, local, threads=2)  # the local pool's task, in this process
    from engine.batch.cluster import local_cluster

    with local_cluster(2) as cluster:
        code, err = batch(
            tmp_path / "in",
            "--out",
            remote,
            *FAST,
            "--scheduler",
            cluster.scheduler_address,
            capsys=capsys,
        )
    assert code == 3, err
    assert summary(err) == (3, 2, 0, 0, 1)
    a, b = tile_bytes(local), tile_bytes(remote)
    assert len(a) == 2 * (1 + 3 + 1 + 1 + 1)  # template, 3 tiles, preview, thumbnail, project
    assert a.keys() == b.keys()
    assert [k for k in a if a[k] != b[k]] == []
    assert {k: v["status"] for k, v in photo_folders(local).items()} == {
        k: v["status"] for k, v in photo_folders(remote).items()
    }


def test_a_worker_stopped_by_ctrl_c_stops_the_batch_and_fails_no_photo(tmp_path):
    """Ctrl-C reaches the workers and the batch at once; when the batch hears of the stopped
    worker first, it stops (interrupted) rather than marking that photo failed."""
    import multiprocessing as mp

    from engine.batch.pool import iter_local

    photos, _, _ = find_photos(
        [str(p) for p in write_photos(tmp_path / "in", names=("brick", "gravel", "lichen"))]
    )
    lib = tmp_path / "lib"
    lib.mkdir()
    records = iter_local(photos, SMALL, lib, jobs=1)
    first = next(records)
    (worker,) = mp.active_children()
    os.kill(worker.pid, signal.SIGINT)  # the worker only: the batch hears it from the pool
    with pytest.raises(KeyboardInterrupt):
        for _ in records:
            pass
    assert not worker.is_alive() and worker.exitcode == 130
    assert {k: v["status"] for k, v in photo_folders(lib).items()} == {first.key: "done"}
    assert temporaries(lib) == []


@pytest.mark.skipif(not hasattr(signal, "pthread_sigmask"), reason="POSIX signal masks only")
def test_a_ctrl_c_while_a_worker_starts_stops_the_batch_and_fails_no_photo(tmp_path, monkeypatch):
    """A Ctrl-C that reaches a worker while its interpreter starts (before its handler is
    set: the first second of a batch) waits for the handler: the worker stops as interrupted
    (130), not with a traceback of its start-up and code 1 that failed its photo."""
    import engine.batch.pool as pool
    from tests.engine.batch_helpers import interrupted_at_start_worker_main

    photos, _, _ = find_photos([str(p) for p in write_photos(tmp_path / "in", names=("brick",))])
    lib = tmp_path / "lib"
    lib.mkdir()
    monkeypatch.setattr(pool, "_worker_main", interrupted_at_start_worker_main)
    records = pool.iter_local(photos, SMALL, lib, jobs=1)
    with pytest.raises(KeyboardInterrupt):
        next(records)
    assert photo_folders(lib) == {} and temporaries(lib) == []
