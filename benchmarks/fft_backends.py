"""The block search's FFT backends compared: ducc0 (the default when installed) and scipy's
pocketfft (the fallback), on the exact search of quilting jobs A and B (:mod:`benchmarks.quilting`).

Run ``python benchmarks/fft_backends.py`` (also run by ``benchmarks/quilting.py``; alone it
writes ``benchmarks/results/fft_backends.txt``). Rows: one
query (:meth:`engine.matching.SampleSpectrum.ssd` of a batch of blocks, as the job sends it) and
the whole job on 1 and 2 threads, each backend in turn (``QUILT_STUDIO_FFT``), medians of
interleaved repeats; the load average is printed (rerun on a quiet machine).
"""

from __future__ import annotations

import argparse
import contextlib
import io
import os
import sys
import time
from pathlib import Path

import numpy as np

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks._util import Tee, format_table, provenance  # noqa: E402
from benchmarks.quilting_jobs import JOBS, load_sample  # noqa: E402
from engine import fft  # noqa: E402
from engine.matching import SampleSpectrum  # noqa: E402
from engine.quilting import quilt  # noqa: E402

BACKENDS = ("scipy", "ducc0")
#: job: (sample side, block, overlap, blocks per query)
QUERIES = {"A": (128, 32, 6, 8), "B": (256, 48, 8, 3)}


def _with(backend: str, fn):
    old = os.environ.get(fft.ENV)
    os.environ[fft.ENV] = backend
    try:
        return fn()
    finally:
        if old is None:
            del os.environ[fft.ENV]
        else:
            os.environ[fft.ENV] = old


def interleaved(fns: dict, repeats: int) -> dict:
    """Median seconds of each function, the functions called in turn ``repeats`` times."""
    times = {k: [] for k in fns}
    for _ in range(repeats):
        for k, fn in fns.items():
            t0 = time.perf_counter()
            fn()
            times[k].append(time.perf_counter() - t0)
    return {k: float(np.median(v)) for k, v in times.items()}


def query_rows(sample: np.ndarray, repeats: int) -> list[list[str]]:
    rows = []
    rng = np.random.default_rng(0)
    for job, (side, b, ov, n) in QUERIES.items():
        s = np.ascontiguousarray(sample[:side, :side])
        old = rng.random((n, b, b, 3), dtype=np.float32)
        mask = np.zeros((n, b, b), np.float32)
        mask[:, :ov] = mask[:, :, :ov] = 1
        specs = {k: SampleSpectrum(s, backend=k) for k in BACKENDS}
        for spec in specs.values():
            spec.ssd(old, mask)
        fns = {k: (lambda sp=sp, o=old, m=mask: sp.ssd(o, m)) for k, sp in specs.items()}
        t = interleaved(fns, repeats)
        rows.append(
            [job, f"query of {n} blocks {b}² on {side}²", "1"]
            + [f"{t[k] * 1e3:.3f} ms" for k in BACKENDS]
            + [f"{t['scipy'] / t['ducc0']:.2f}"]
        )
    return rows


def job_rows(sample: np.ndarray, jobs: dict, repeats: int) -> list[list[str]]:
    rows = []
    for job, j in jobs.items():
        s = np.ascontiguousarray(sample[: j["crop"], : j["crop"]])
        kw = dict(block=j["block"], overlap=j["overlap"], rng=0, mode="exact")
        for threads in (1, 2):

            def run(k, t=threads, s=s, out=j["out"], kw=kw):
                return _with(k, lambda: quilt(s, out, threads=t, **kw))

            fns = {k: (lambda k=k, run=run: run(k)) for k in BACKENDS}
            for fn in fns.values():
                fn()
            t = interleaved(fns, repeats)
            rows.append(
                [job, "whole job, exact", str(threads)]
                + [f"{t[k]:.3f} s" for k in BACKENDS]
                + [f"{t['scipy'] / t['ducc0']:.2f}"]
            )
    return rows


def compare(sample: np.ndarray, jobs: dict, *, repeats: int = 7, query_repeats: int = 300):
    """Print the table (the caller loads the sample and warms the kernels up)."""
    print(f"## FFT backends (load average {os.getloadavg()[0]:.2f})\n")
    if fft.default_backend() != "ducc0" and os.environ.get(fft.ENV) is None:
        print("(ducc0 is not installed here: nothing to compare)\n")
        return
    rows = query_rows(sample, query_repeats) + job_rows(sample, jobs, repeats)
    head = ["job", "what", "threads", "scipy (pocketfft)", "ducc0", "ducc0 gain ×"]
    print(format_table(head, rows))
    print()


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--repeats", type=int, default=7, help="interleaved runs per whole job")
    args = p.parse_args(argv)
    sample = load_sample("cobblestones", 256)
    quilt(sample[:128, :128], (256, 256), block=32, overlap=6, rng=0, mode="fast")  # kernels
    out = io.StringIO()
    with contextlib.redirect_stdout(Tee(sys.stdout, out)):
        print(f"{provenance()}\npython benchmarks/fft_backends.py\n")
        compare(sample, JOBS, repeats=args.repeats)
    RESULTS.parent.mkdir(exist_ok=True)
    RESULTS.write_text(out.getvalue())
    return 0


RESULTS = Path(__file__).resolve().parent / "results" / "fft_backends.txt"


if __name__ == "__main__":
    raise SystemExit(main())
