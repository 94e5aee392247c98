"""Issue 15's large jobs: quilting and transfer from 4096² and 8192² samples, auto vs exact.

Run through ``python benchmarks/quilting.py`` (``--skip-large``, ``--large-quality``), or alone:
``python benchmarks/quilting_large.py [--repeats 3] [--quality] [--quality-out 1024]
[--quality-samples a,b]`` (printed and written to ``benchmarks/results/quilting_large.txt``).

* **Speed and memory**: each job runs in a process of its own (a warm-up on a small sample
  first, then ``--repeats`` timed runs), so its peak resident memory (``VmHWM``: the whole
  process, interpreter, sample and run) is the job's own. Jobs: L4 — 2048² from a 4096² photo,
  block 96, overlap 16, best + dp, ``mode="auto"`` (target ≤ 15 s, ≤ 2 GB); L8 — the same from
  an 8192² photo (≤ 30 s, ≤ 2 GB); T4 — texture transfer of a 1024² target (the cat photo's
  fur) from a 4096² sample, 3 passes from block 96 (the quilting jobs' block; 96, 64, 43 px:
  1143 blocks; ≤ 30 s). The "photo" is the bundled cobblestones photo upscaled (bilinear); the
  plan's estimate is printed beside the measured figures.
* **Quality** (``--quality``): the grid border ratio of ``auto`` (the coarse-to-fine search at
  this size) against the exhaustive search's, on every bundled sample and two real photos
  (scikit-image's coffee: the wooden table; chelsea: the cat's fur) upscaled to 4096², with
  ``--quality-out`` outputs (default 1024²: the exact search takes about a second per block
  here), block 96, overlap 16, mean of ``--seeds`` seeds. The auto outputs are saved as PNGs
  (path printed) to be looked at.

Samples are made once and cached as ``.npy`` files in the temporary folder.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks._util import Tee, format_table, provenance  # noqa: E402

CACHE = Path(tempfile.gettempdir()) / "quilt-bench-samples"

#: real photos: (scikit-image data function, crop rows, crop cols)
PHOTOS = {
    "coffee-wood": ("coffee", slice(0, 400), slice(440, 600)),
    "chelsea-fur": ("chelsea", slice(10, 170), slice(40, 230)),
}

JOBS = {
    "L4": dict(kind="quilt", sample="cobblestones", side=4096, out=2048, target_s=15.0),
    "L8": dict(kind="quilt", sample="cobblestones", side=8192, out=2048, target_s=30.0),
    "T4": dict(kind="transfer", sample="cobblestones", side=4096, out=1024, target_s=30.0),
}
TARGET_BYTES = 2 * 10**9
BLOCK, OVERLAP = 96, 16


def source_pixels(name: str) -> np.ndarray:
    """RGB float32 of a bundled sample or a photo crop (:data:`PHOTOS`)."""
    if name in PHOTOS:
        import skimage.data

        fn, rows, cols = PHOTOS[name]
        return (getattr(skimage.data, fn)()[rows, cols, :3] / 255.0).astype(np.float32)
    from engine.io import load_image
    from resources import sample_path

    return np.ascontiguousarray(load_image(sample_path(name)).rgb)


def sample_file(name: str, side: int) -> Path:
    """``name`` upscaled (bilinear) so its longer side is ``side``; cached as .npy."""
    path = CACHE / f"{name}_{side}.npy"
    if not path.exists():
        from skimage.transform import resize

        px = source_pixels(name)
        h, w = px.shape[:2]
        scale = side / max(h, w)
        big = resize(px, (round(h * scale), round(w * scale)), order=1)
        CACHE.mkdir(parents=True, exist_ok=True)
        np.save(path, np.clip(big, 0, 1).astype(np.float32))
    return path


def _warm_up() -> None:
    """Compile or load every numba kernel the jobs use (not timed)."""
    from engine.quilting import quilt
    from engine.transfer import transfer

    s = np.random.default_rng(0).random((320, 320, 3), dtype=np.float32)
    for mode in ("exact", "fast"):
        quilt(s, (200, 200), block=32, overlap=8, mode=mode, rng=0)
    transfer(s, s[:100, :100], block=24, iterations=2, rng=0, mode="fast")


def worker(spec: dict) -> dict:
    """Run one job ``spec["repeats"]`` times in this process; seconds, plan, peak memory."""
    from engine.events import drain
    from engine.metrics import block_grid_border_ratio
    from engine.quilting import Estimated, iter_quilt
    from engine.transfer import iter_transfer

    _warm_up()
    sample = np.load(sample_file(spec["sample"], spec["side"]))
    plans: list = []

    def keep_plan(ev):
        if isinstance(ev, Estimated):
            plans.append(ev.plan)

    times, ratio = [], None
    for k in range(spec["repeats"]):
        t0 = time.perf_counter()
        if spec["kind"] == "quilt":
            out = (spec["out"], spec["out"])
            gen = iter_quilt(sample, out, block=BLOCK, overlap=OVERLAP, rng=k, mode="auto")
            res = drain(gen, keep_plan)
            ratio = block_grid_border_ratio(res)
        else:
            target = np.load(sample_file("chelsea-fur", spec["out"]))
            gen = iter_transfer(sample, target, block=BLOCK, iterations=3, rng=k, mode="auto")
            drain(gen, keep_plan)
        times.append(time.perf_counter() - t0)
    plan = plans[0]
    return dict(
        seconds=times,
        maxrss=peak_rss(),
        plan=dict(search=plan.search, seconds=plan.seconds, peak_bytes=plan.peak_bytes),
        grid=ratio,
    )


def peak_rss() -> int:
    """This process's peak resident memory in bytes: ``VmHWM``, which starts afresh with the
    process's own image (``ru_maxrss`` keeps the forking parent's peak across ``exec``)."""
    with open("/proc/self/status", encoding="ascii") as f:
        for line in f:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) * 1024
    return 0


def run_worker(spec: dict) -> dict:
    out = subprocess.run(
        [sys.executable, "-m", "benchmarks.quilting_large", "--worker", json.dumps(spec)],
        capture_output=True,
        text=True,
        cwd=Path(__file__).resolve().parents[1],
        check=False,
    )
    if out.returncode:
        raise RuntimeError(f"job {spec} failed:\n{out.stderr[-3000:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def large(args) -> None:
    load = os.getloadavg()[0]
    print(f"## Large samples (auto search, 2 threads; load average {load:.2f} at the start)\n")
    rows = []
    for name, job in JOBS.items():
        if args.large_jobs and name not in args.large_jobs:
            continue
        sample_file(job["sample"], job["side"])
        if job["kind"] == "transfer":
            sample_file("chelsea-fur", job["out"])
        r = run_worker({**job, "repeats": args.repeats})
        t = float(np.median(r["seconds"]))
        rss = r["maxrss"]
        what = (
            f"{job['out']}² from {job['side']}², block {BLOCK}, overlap {OVERLAP}"
            if job["kind"] == "quilt"
            else f"transfer {job['out']}² from {job['side']}², 3 passes from block {BLOCK}"
        )
        met = t <= job["target_s"] and (job["kind"] == "transfer" or rss <= TARGET_BYTES)
        rows.append(
            [
                name,
                what,
                r["plan"]["search"],
                f"{r['plan']['seconds']:.1f}",
                f"{t:.1f}",
                f"{r['plan']['peak_bytes'] / 2**30:.2f}",
                f"{rss / 2**30:.2f}",
                "" if r["grid"] is None else f"{r['grid']:.3f}",
                f"<= {job['target_s']:.0f} s" + (", <= 2 GB" if job["kind"] == "quilt" else ""),
                "yes" if met else "NO",
            ]
        )
    print(
        format_table(
            [
                "job",
                "what",
                "search",
                "estimate s",
                "median s",
                "estimated peak GiB",
                "process peak RSS GiB",
                "grid border ratio",
                "target",
                "met",
            ],
            rows,
        )
    )
    print(f"\n(load average at the end {os.getloadavg()[0]:.2f})\n")


def large_quality(args) -> None:
    from engine.io import save_image
    from engine.metrics import block_grid_border_ratio
    from engine.quilting import quilt
    from resources import SAMPLE_NAMES

    out = args.quality_out
    side = 4096
    print(
        f"## Quality at {side}²: auto (coarse-to-fine) vs exact, {out}² outputs, block {BLOCK}, "
        f"overlap {OVERLAP}, mean of {args.seeds} seeds (load average {os.getloadavg()[0]:.2f})\n"
    )
    folder = Path(tempfile.gettempdir()) / "quilt-bench-outputs"
    folder.mkdir(exist_ok=True)
    rows = []
    names = args.quality_samples or [*SAMPLE_NAMES, *PHOTOS]
    for name in names:
        s = np.load(sample_file(name, side))
        ratio, secs = {}, {}
        for mode in ("auto", "exact"):
            vals, t0 = [], time.perf_counter()
            for seed in range(args.seeds):
                res = quilt(s, (out, out), block=BLOCK, overlap=OVERLAP, rng=seed, mode=mode)
                vals.append(block_grid_border_ratio(res))
                print(f"  {name} {mode} seed {seed}: {vals[-1]:.3f}", flush=True)
                if mode == "auto" and seed == 0:
                    save_image(folder / f"{name}_{side}_auto_{out}.png", res.image)
            ratio[mode] = float(np.mean(vals))
            secs[mode] = (time.perf_counter() - t0) / args.seeds
        diff = 100 * (ratio["auto"] / ratio["exact"] - 1)
        rows.append(
            [
                name,
                f"{s.shape[1]}x{s.shape[0]}",
                f"{ratio['auto']:.3f}",
                f"{ratio['exact']:.3f}",
                f"{diff:+.1f} %",
                "yes" if diff <= 5 else "NO",
                f"{secs['auto']:.1f}",
                f"{secs['exact']:.0f}",
            ]
        )
        print(" | ".join(rows[-1]), flush=True)
    print()
    print(
        format_table(
            [
                "sample",
                "size",
                "auto ratio",
                "exact ratio",
                "auto vs exact",
                "within 5 %",
                "auto s",
                "exact s",
            ],
            rows,
        )
    )
    print(f"\nThe auto outputs (seed 0) are in {folder}\n")


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--large-jobs", default="", help="jobs to run among L4, L8, T4 (default all)")
    p.add_argument(
        "--quality-out", type=int, default=1024, help="output side of the quality comparison"
    )
    p.add_argument(
        "--quality-samples",
        default="",
        help="samples of the quality comparison, comma-separated (default: every bundled sample "
        f"and the photos {', '.join(PHOTOS)})",
    )


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--worker", default=None, help=argparse.SUPPRESS)
    p.add_argument("--repeats", type=int, default=3, help="timed runs per job (default 3)")
    p.add_argument("--quality", action="store_true", help="also compare auto with exact")
    p.add_argument("--seeds", type=int, default=1, help="seeds of the quality comparison")
    p.add_argument("--skip-large", action="store_true", help="only the quality comparison")
    add_arguments(p)
    args = p.parse_args(argv)
    if args.worker:
        print(json.dumps(worker(json.loads(args.worker))))
        return 0
    args.large_jobs = [j.strip().upper() for j in args.large_jobs.split(",") if j.strip()]
    args.quality_samples = [n.strip() for n in args.quality_samples.split(",") if n.strip()]
    out = io.StringIO()
    with contextlib.redirect_stdout(Tee(sys.stdout, out)):
        command = " ".join(["python benchmarks/quilting_large.py", *(argv or sys.argv[1:])])
        print(f"{provenance()}\n{command}\n")
        if not args.skip_large:
            large(args)
        if args.quality:
            large_quality(args)
    RESULTS.parent.mkdir(exist_ok=True)
    RESULTS.write_text(out.getvalue())
    return 0


RESULTS = Path(__file__).resolve().parent / "results" / "quilting_large.txt"


if __name__ == "__main__":
    raise SystemExit(main())
