"""Image quilting benchmark: speed of the candidate search, streaming overhead, output quality.

Run ``python -m benchmarks.quilting`` (``--help`` for options). Jobs (issue 4), on a 3-channel
sample (``resources/samples/cobblestones.png`` by default):

* A — 512×512 from a 128×128 sample, block 32, overlap 6, best match (tolerance 0.1), dp cut;
* B — 1024×1024 from a 256×256 sample, block 48, overlap 8, same settings.

Rows: a straightforward baseline (numpy: ``scipy.signal.fftconvolve`` per channel and block in
float64, union L mask, the compiled dp L-cut, single thread), with ``--start DIR`` the exact search
of the commit issue 15 started from (a219639, in a process of its own: the "× start" column), the
exact FFT search and the fast (principal components + exact re-ranking) search, on 1 and 2
threads. Every time is the median
of repeats (the load average is printed: on a shared machine rerun when it is near 0); the 1- and
2-thread runs of a mode alternate, at least 9 rounds (:func:`interleaved_threads`), and the
2-vs-1-thread line gives the ratio of the medians and the median of the rounds' ratios.
Samples under 200×200 (job A) run on one thread whatever ``threads`` says
(:data:`engine.quilting.scheduler.POOL_MIN_SAMPLE_AREA`). Each output's border ratio along the
block grid (max over the offsets the cuts run in,
:func:`engine.metrics.block_grid_border_ratio`) is shown beside it, and the CPU time OpenBLAS's
helper threads spent during the runs (0 when every product stays on the calling thread, as it
should on a small shared machine). Then: the streaming overhead (``quilt`` draining every event
vs the same run creating none, the two run in turn), and the quality figures: grid border ratio
of best+dp vs best+straight vs random on every bundled sample, and the mean seam peak of Long &
Mould's minimax at half-block overlap vs dp at the same overlap. After the speed rows, the FFT
backends compared (:mod:`benchmarks.fft_backends`: ducc0 vs scipy's pocketfft). Between them the
large jobs of
:mod:`benchmarks.quilting_large` (4096² and 8192² samples in ``auto``, transfer at 4096²;
``--large-quality`` adds auto vs exact at 4096²). Everything printed is also written to
``benchmarks/results/quilting.txt``.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import os
import sys
import threading
import time
from pathlib import Path

import numpy as np
from scipy import signal

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks import fft_backends, quilting_large  # noqa: E402
from benchmarks._util import Tee, format_table, median_time, provenance  # noqa: E402
from benchmarks.quilting_jobs import JOBS, load_sample  # noqa: E402
from engine.errormap import error_map  # noqa: E402
from engine.matching import ZERO_ERROR_FRACTION, error_floor, select_within_tolerance  # noqa: E402
from engine.metrics import block_grid_border_ratio  # noqa: E402
from engine.quilting import quilt  # noqa: E402
from engine.quilting.synthesis import quilt_unstreamed  # noqa: E402
from engine.seams import SeamSpec  # noqa: E402
from engine.stitch import l_cut  # noqa: E402
from resources import SAMPLE_NAMES  # noqa: E402

TARGETS = {("A", "exact"): 0.25, ("B", "exact"): 1.2, ("B", "fast"): 0.36}


def _cut(method: str, metric: str = "ssd") -> SeamSpec:
    return SeamSpec(method, metric=metric)


def baseline_quilt(sample, out_shape, *, block, overlap, tolerance=0.1, rng=0):
    """The straightforward implementation the issue measures against: for every block, the
    masked SSD of every sample position by ``fftconvolve`` per channel (float64, no reuse of the
    sample's spectrum), selection within the tolerance, the compiled dp L-cut, a hard paste."""
    rng = np.random.default_rng(rng)
    s = np.asarray(sample, np.float64)
    h, w, c = s.shape
    sq = (s**2).sum(axis=2)
    floor = error_floor(sample)
    ho, wo = out_shape
    step = block - overlap
    out = np.zeros((ho, wo, c))
    for y in range(0, max(1, -(-(ho - overlap) // step)) * step, step):
        for x in range(0, max(1, -(-(wo - overlap) // step)) * step, step):
            bh, bw = min(block, ho - y), min(block, wo - x)
            ot, ol = (overlap if y else 0), (overlap if x else 0)
            if not (ot or ol):
                ay, ax = rng.integers(h - bh + 1), rng.integers(w - bw + 1)
                out[y : y + bh, x : x + bw] = s[ay : ay + bh, ax : ax + bw]
                continue
            m = np.zeros((bh, bw))
            m[:ot] = 1
            m[:, :ol] = 1
            old = out[y : y + bh, x : x + bw]
            e = signal.fftconvolve(sq, m[::-1, ::-1], mode="valid") + (m[:, :, None] * old**2).sum()
            for k in range(c):
                e -= 2 * signal.fftconvolve(s[:, :, k], (m * old[:, :, k])[::-1, ::-1], "valid")
            zero = ZERO_ERROR_FRACTION * floor * m.sum() * c
            i, _, _ = select_within_tolerance(e, tolerance=tolerance, zero_level=zero, rng=rng)
            ay, ax = divmod(i, e.shape[1])
            new = s[ay : ay + bh, ax : ax + bw]
            cut = l_cut(error_map(old, new, metric="ssd"), overlap_left=ol, overlap_top=ot)
            out[y : y + bh, x : x + bw] = np.where(cut.mask[:, :, None], old, new)
    return out.astype(np.float32)


class _Grid:
    """What :func:`engine.metrics.block_grid_border_ratio` needs from a result."""

    def __init__(self, image, block, overlap):
        self.image, self.step, self.band = image, (block - overlap,) * 2, overlap


def _threads() -> set[str]:
    try:
        return set(os.listdir("/proc/self/task")) - {str(threading.get_native_id())}
    except OSError:  # no /proc
        return set()


BLAS_THREADS = _threads()
"""Threads alive once numpy and scipy are imported: OpenBLAS's helper threads (numpy's and
scipy's libraries each start theirs; FFT worker pools start later, on first use)."""


def blas_cpu_seconds() -> float | None:
    """CPU seconds used so far by :data:`BLAS_THREADS` (None without /proc, or once one of
    them is gone: OpenBLAS ends its threads before a ``fork``, as exact quilting's worker
    processes do, and starts new ones when next needed)."""
    if not BLAS_THREADS:
        return None
    total = 0
    for tid in BLAS_THREADS:
        try:
            with open(f"/proc/self/task/{tid}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
        except OSError:
            return None
        total += int(fields[11]) + int(fields[12])  # utime + stime, in clock ticks
    return total / os.sysconf("SC_CLK_TCK")


START_SNIPPET = """
import json, sys, time
import numpy as np
from engine.quilting import quilt
s = np.load(sys.argv[1])
out, block, overlap, threads, repeats = json.loads(sys.argv[2])
quilt(s, tuple(out), block=block, overlap=overlap, rng=0, threads=threads)
times = []
for _ in range(repeats):
    t0 = time.perf_counter()
    quilt(s, tuple(out), block=block, overlap=overlap, rng=0, threads=threads)
    times.append(time.perf_counter() - t0)
print(json.dumps(times))
"""


START_COMMIT = "a219639"
"""The commit issue 15's work started from (the "× start" column's reference)."""


def start_checkout(arg: str | None) -> str | None:
    """The folder of the start commit's files: ``arg`` itself, or with ``"auto"`` a copy
    extracted once by ``git archive`` into the temporary folder (None when git or the commit is
    not at hand: the column is then left out, with a note)."""
    import subprocess
    import tarfile
    import tempfile

    if arg is None or arg.lower() == "none":
        return None
    if arg != "auto":
        return arg
    folder = Path(tempfile.gettempdir()) / f"quilt-bench-start-{START_COMMIT}"
    if (folder / "engine").is_dir():
        return str(folder)
    repo = Path(__file__).resolve().parents[1]
    try:
        archive = subprocess.run(
            ["git", "-C", str(repo), "archive", "--format=tar", START_COMMIT],
            capture_output=True,
            check=True,
        ).stdout
    except (OSError, subprocess.CalledProcessError) as exc:
        print(f"(no start column: git archive {START_COMMIT} failed: {exc})\n")
        return None
    partial = folder.with_name(folder.name + ".partial")
    partial.mkdir(parents=True, exist_ok=True)
    with tarfile.open(fileobj=io.BytesIO(archive)) as tar:
        tar.extractall(partial, filter="data")
    partial.rename(folder)
    return str(folder)


def start_time(start_dir: str, sample: np.ndarray, j: dict, threads: int, repeats: int) -> float:
    """Median seconds of the exact search (then the only one) of job ``j`` in a checkout of the
    commit issue 15's work started from (``--start DIR``), in a process of its own."""
    import json
    import subprocess
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "sample.npy"
        np.save(path, sample)
        spec = json.dumps([list(j["out"]), j["block"], j["overlap"], threads, repeats])
        env = {**os.environ, "PYTHONPATH": start_dir}
        out = subprocess.run(
            [sys.executable, "-c", START_SNIPPET, str(path), spec],
            capture_output=True,
            text=True,
            cwd=start_dir,
            env=env,
            check=True,
        )
    return float(np.median(json.loads(out.stdout.strip().splitlines()[-1])))


def speed(args) -> None:
    print(f"## Speed (sample {args.sample}; load average {os.getloadavg()[0]:.2f})\n")
    start = {}
    blas_before = blas_cpu_seconds()
    rows = []
    for job in args.jobs:
        j = JOBS[job]
        s = load_sample(args.sample, j["crop"])
        kw = dict(block=j["block"], overlap=j["overlap"])
        quilt(s, j["out"], rng=0, threads=1, mode="fast", **kw)  # compile numba kernels
        base_t, base_img = median_time(
            lambda s=s, j=j, kw=kw: baseline_quilt(s, j["out"], rng=0, **kw),
            min_repeats=max(1, args.repeats // 2),
            max_time=args.max_time,
        )
        rows.append(
            [
                job,
                "baseline (numpy + fftconvolve per block, dp)",
                1,
                f"{base_t:.3f}",
                "1.00",
                "",
                "",
                f"{block_grid_border_ratio(_Grid(base_img, **kw)):.3f}",
                "",
            ]
        )
        images, exact_t, ratios = {}, {}, {}
        if args.start:
            for threads in (1, 2):
                start[job, threads] = start_time(args.start, s, j, threads, args.repeats)
                rows.append(
                    [
                        job,
                        f"exact at the start ({START_COMMIT})",
                        threads,
                        f"{start[job, threads]:.3f}",
                        f"{base_t / start[job, threads]:.2f}",
                        "",
                        "",
                        "",
                        "1.00",
                    ]
                )
        for mode in ("exact", "fast"):
            times, ratio = interleaved_threads(s, j, kw, mode, args.repeats, images)
            ratios[mode] = ratio
            for threads in (1, 2):
                t = times[threads]
                vs_start = ""
                if mode == "exact" and (job, threads) in start:
                    gain = start[job, threads] / t
                    vs_start = f"{gain:.2f} ({'yes' if gain >= 1.8 else 'NO'}: >= 1.8)"
                target = TARGETS.get((job, mode))
                rows.append(
                    [
                        job,
                        mode,
                        threads,
                        f"{t:.3f}",
                        f"{base_t / t:.2f}",
                        "" if target is None else f"<= {target}",
                        "" if target is None else ("yes" if t <= target else "NO"),
                        f"{block_grid_border_ratio(_Grid(images[mode, threads], **kw)):.3f}",
                        vs_start,
                    ]
                )
                if mode == "exact":
                    exact_t[threads] = t
            same = np.array_equal(images[mode, 1], images[mode, 2])
            print(f"job {job} {mode}: identical output on 1 and 2 threads: {same}")
        scale = exact_t[1] / exact_t[2]
        print(
            f"job {job} exact: 2 threads {scale:.2f}x faster than 1 (target for B: >= 1.5; "
            f"ratio of the medians; median of the {ratios['exact'][1]} rounds' ratios "
            f"{ratios['exact'][0]:.2f}x)"
        )
    print()
    print(
        format_table(
            [
                "job",
                "implementation",
                "threads",
                "median s",
                "× baseline",
                "target",
                "met",
                "grid border ratio",
                "× start (target >= 1.8)",
            ],
            rows,
        )
    )
    blas_after = blas_cpu_seconds()
    if blas_before is not None and blas_after is not None:
        print(
            "\nCPU time of OpenBLAS's helper threads during these runs: "
            f"{blas_after - blas_before:.2f} s (the engine's products stay on one thread)"
        )
    elif blas_before is not None:
        print("\nOpenBLAS's helper threads ended at a fork (worker processes): CPU not measured")
    print()


INTERLEAVED_ROUNDS = 9
"""Least number of rounds of the 1- and 2-thread runs of a job (one run of each per round)."""


def interleaved_threads(s, j, kw, mode, repeats, images):
    """Job ``j`` in ``mode`` on 1 and 2 threads, the two run in turn (a change of the machine's
    load hits both alike) for max(``repeats``, :data:`INTERLEAVED_ROUNDS`) rounds after one
    untimed run of each: ({threads: median seconds}, (median of the rounds' 1-thread /
    2-thread ratios, rounds)); the outputs go into ``images[mode, threads]``."""
    rounds = max(repeats, INTERLEAVED_ROUNDS)

    def run(threads):
        images[mode, threads] = quilt(s, j["out"], rng=0, mode=mode, threads=threads, **kw).image

    one, two = alternating_times([lambda: run(1), lambda: run(2)], rounds, warmup=1)
    ratio = float(np.median(np.divide(one, two)))
    return {1: float(np.median(one)), 2: float(np.median(two))}, (ratio, rounds)


def alternating_times(fns, repeats: int, warmup: int = 0) -> list[list[float]]:
    """Wall times of each function, the functions run in turn ``repeats`` times after
    ``warmup`` untimed rounds (a change of the machine's load hits all of them alike, unlike
    timing one after the other)."""
    times = [[] for _ in fns]
    for r in range(warmup + repeats):
        for fn, ts in zip(fns, times, strict=True):
            t0 = time.perf_counter()
            fn()
            if r >= warmup:
                ts.append(time.perf_counter() - t0)
    return times


def alternating_medians(fns, repeats: int) -> list[float]:
    """Median wall time of each function, run in turn (:func:`alternating_times`)."""
    return [float(np.median(ts)) for ts in alternating_times(fns, repeats)]


def streaming(args) -> None:
    print("## Streaming overhead (exact, 1 thread; quilt() drains every event vs no events)\n")
    rows = []
    for job in args.jobs:
        j = JOBS[job]
        s = load_sample(args.sample, j["crop"])
        kw = dict(block=j["block"], overlap=j["overlap"], rng=0, threads=1)
        t_stream, t_plain = alternating_medians(
            [
                lambda s=s, j=j, kw=kw: quilt(s, j["out"], **kw),
                lambda s=s, j=j, kw=kw: quilt_unstreamed(s, j["out"], **kw),
            ],
            max(args.repeats, 7),
        )
        over = 100 * (t_stream / t_plain - 1)
        rows.append(
            [
                job,
                f"{t_plain:.3f}",
                f"{t_stream:.3f}",
                f"{over:+.1f} %",
                "<= 10 %",
                "yes" if over <= 10 else "NO",
            ]
        )
    print(format_table(["job", "no events s", "streamed s", "overhead", "target", "met"], rows))
    print()


def quality(args) -> None:
    seeds = range(args.seeds)
    print(
        f"## Quality (job A settings: 128×128 crops → 512×512, block 32, overlap 6; mean over "
        f"{len(seeds)} seeds)\n"
    )
    print("Grid border ratio, max over the offsets 0..overlap (mean over offsets in brackets):\n")
    variants = [
        ("best+dp", dict(seam=_cut("dp"))),
        ("best+dp fast", dict(seam=_cut("dp"), mode="fast")),
        ("best+straight", dict(seam=_cut("straight"))),
        ("random+straight", dict(select="random", seam=_cut("straight"))),
        ("random+dp", dict(select="random", seam=_cut("dp"))),
        ("bhatia+resistance", dict(select="bhatia", seam=_cut("resistance"), overlap=8)),
    ]
    rows = []
    for name in SAMPLE_NAMES:
        s = load_sample(name, 128)
        row = [name]
        base = None
        for label, kw in variants:
            kw = {"block": 32, "overlap": 6, **kw}
            res = [quilt(s, (512, 512), rng=seed, **kw) for seed in seeds]
            mx = float(np.mean([block_grid_border_ratio(r) for r in res]))
            mean = float(np.mean([block_grid_border_ratio(r, reduce="mean") for r in res]))
            cell = f"{mx:.3f} ({mean:.3f})"
            if label == "best+dp":
                base = mx
            elif label == "best+dp fast":
                cell += f" {100 * (mx / base - 1):+.1f} %"
            row.append(cell)
        rows.append(row)
    print(format_table(["sample", *(v[0] for v in variants)], rows))
    print()
    print(
        "Mean seam peak over all cuts (128×128 → 256×256, block 32, overlap 16 = half block, "
        "error map euclid):\n"
    )
    rows = []
    for name in SAMPLE_NAMES:
        s = load_sample(name, 128)
        kw = dict(block=32, overlap=16)
        peaks = {}
        for method in ("dp", "minimax"):
            peaks[method] = float(
                np.mean(
                    [
                        np.nanmean(
                            [
                                r.peak
                                for r in quilt(
                                    s,
                                    (256, 256),
                                    seam=_cut(method, metric="euclid"),
                                    rng=seed,
                                    **kw,
                                ).blocks
                            ]
                        )
                        for seed in seeds
                    ]
                )
            )
        rows.append(
            [
                name,
                f"{peaks['dp']:.4f}",
                f"{peaks['minimax']:.4f}",
                f"{100 * (peaks['minimax'] / peaks['dp'] - 1):+.1f} %",
            ]
        )
    print(format_table(["sample", "dp mean peak", "minimax mean peak", "minimax vs dp"], rows))
    print()


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--sample", default="cobblestones", choices=SAMPLE_NAMES)
    p.add_argument("--jobs", default="AB", help="which jobs to time (default AB)")
    p.add_argument("--repeats", type=int, default=5, help="minimum repeats per timing (default 5)")
    p.add_argument("--max-time", type=float, default=30.0, help="time budget per timing (s)")
    p.add_argument("--seeds", type=int, default=2, help="seeds averaged in the quality tables")
    p.add_argument(
        "--start",
        default="auto",
        metavar="DIR",
        help="a checkout of the commit issue 15 started from (a219639), whose exact search is "
        "timed on jobs A and B too; default 'auto': extracted once from this repository's git "
        "history into the temporary folder; 'none' skips it",
    )
    p.add_argument("--skip-speed", action="store_true")
    p.add_argument("--skip-quality", action="store_true")
    p.add_argument("--skip-fft", action="store_true", help="skip the FFT backends' comparison")
    p.add_argument("--skip-large", action="store_true", help="skip the 4096²/8192² jobs")
    p.add_argument(
        "--large-quality",
        action="store_true",
        help="auto vs exact at 4096² on every sample (about 20 min on a quiet machine)",
    )
    p.add_argument("--large-repeats", type=int, default=3, help="timed runs per large job")
    quilting_large.add_arguments(p)
    args = p.parse_args(argv)
    args.jobs = [j for j in args.jobs.upper() if j in JOBS]
    args.start = start_checkout(args.start)
    args.large_jobs = [j.strip().upper() for j in args.large_jobs.split(",") if j.strip()]
    args.quality_samples = [n.strip() for n in args.quality_samples.split(",") if n.strip()]
    out = io.StringIO()
    with contextlib.redirect_stdout(Tee(sys.stdout, out)):
        print(f"{provenance()}\npython benchmarks/quilting.py {' '.join(argv or sys.argv[1:])}\n")
        if not args.skip_speed:
            speed(args)
            streaming(args)
        if not args.skip_fft:
            jobs = {k: JOBS[k] for k in args.jobs}
            fft_backends.compare(load_sample(args.sample, 256), jobs, repeats=args.repeats)
        if not args.skip_large:
            quilting_large.large(
                argparse.Namespace(**{**vars(args), "repeats": args.large_repeats})
            )
        if args.large_quality:
            quilting_large.large_quality(args)
        if not args.skip_quality:
            quality(args)
    RESULTS.parent.mkdir(exist_ok=True)
    RESULTS.write_text(out.getvalue())
    return 0


RESULTS = Path(__file__).resolve().parent / "results" / "quilting.txt"


if __name__ == "__main__":
    raise SystemExit(main())
