"""Now against the round's start commit: is anything slower (issue 14: "benchmarks not slower")?

Run ``python -m benchmarks.versus_start`` (``--rounds N``). Each tree, this one and a copy of the
start commit (:data:`benchmarks.quilting.START_COMMIT`, extracted by ``git archive`` into the
temporary folder), runs its *own* benchmark scripts in a process of its own:

* ``benchmarks/seams.py --sizes 32x6,256x16``: every seam method on a quilting-sized and a
  tile-sized overlap (median ms per call);
* ``benchmarks/tileset.py --skip-quality --skip-big``: template search, seamless tile and
  30 candidates of 256² from a 512² source (seconds).

The two trees run alternately, ``rounds`` times, and each row keeps its best time (the least
disturbed by other processes). Rows are joined by their labels; only rows both trees print are
compared. Quilting jobs A/B have their own "× start" column in :mod:`benchmarks.quilting`, the
start-up times their own targets in :mod:`benchmarks.startup`.

The tile-set rows do not run the same algorithm in both trees: issue 10 added the template's
detail term and stationarity check and the candidates' search over the whole source on purpose.
A slower row there is the price of a feature, not of the renovation; the seam rows run the same
algorithms in both trees. Everything printed is also written to
``benchmarks/results/versus_start.txt``.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(ROOT))

from benchmarks._util import format_table, provenance  # noqa: E402

SUITES = {
    # name: (arguments, number of label columns, index of the time column, unit)
    "seams": (["--sizes", "32x6,256x16"], 3, 3, "ms"),
    "tileset": (["--skip-quality", "--skip-big"], 2, 2, "s"),
}

TILESET_TIMES = ("template", "candidate")
"""Tile-set rows that are times (the others are MiB, CPU shares and speed-ups)."""


def table_rows(text: str, labels: int, column: int) -> dict[tuple[str, ...], float]:
    """The numeric ``column`` of every Markdown table row of ``text``, keyed by its first
    ``labels`` cells."""
    rows = {}
    for line in text.splitlines():
        if not line.startswith("|") or line.startswith("|-"):
            continue
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) <= column:
            continue
        try:
            rows[tuple(cells[:labels])] = float(cells[column])
        except ValueError:
            continue  # a header
    return rows


def run_suite(tree: Path, suite: str) -> dict[tuple[str, ...], float]:
    """Run ``suite``'s script of ``tree`` in a process of its own; its timed rows."""
    args, labels, column, _ = SUITES[suite]
    env = {**os.environ, "PYTHONPATH": str(tree)}
    out = subprocess.run(
        [sys.executable, "-m", f"benchmarks.{suite}", *args],
        cwd=tree,
        env=env,
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    rows = table_rows(out, labels, column)
    if suite == "tileset":
        rows = {k: v for k, v in rows.items() if any(w in k[-1] for w in TILESET_TIMES)}
        rows = {k: v for k, v in rows.items() if "speed-up" not in k[-1]}
    return rows


def compare(start: Path, rounds: int) -> str:
    best: dict[str, dict[Path, dict]] = {s: {start: {}, ROOT: {}} for s in SUITES}
    for _ in range(rounds):
        for suite in SUITES:
            for tree in (start, ROOT):
                for key, t in run_suite(tree, suite).items():
                    seen = best[suite][tree]
                    seen[key] = min(t, seen.get(key, t))
    rows, slower = [], []
    for suite, (_, _, _, unit) in SUITES.items():
        old, new = best[suite][start], best[suite][ROOT]
        for key in new:
            if key not in old or old[key] <= 0:
                continue
            ratio = new[key] / old[key]
            label = " / ".join(key)
            rows.append([suite, label, f"{old[key]:.3f} {unit}", f"{new[key]:.3f} {unit}", ratio])
            if ratio > 1.10:
                slower.append(f"{suite}: {label} ({ratio:.2f}x)")
    table = format_table(
        ["suite", "row", "start", "now", "now / start"],
        [[*r[:4], f"{r[4]:.2f}"] for r in rows],
    )
    seam_ratios = sorted(r[4] for r in rows if r[0] == "seams")
    summary = (
        f"seam rows: median now/start {seam_ratios[len(seam_ratios) // 2]:.2f} "
        f"(range {seam_ratios[0]:.2f}-{seam_ratios[-1]:.2f}) over {len(seam_ratios)} rows"
        if seam_ratios
        else "no seam rows in common"
    )
    verdict = (
        "rows more than 10 % slower now: " + "; ".join(slower)
        if slower
        else "no row is more than 10 % slower now"
    )
    return f"{table}\n\n{summary}\n{verdict}"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=2, help="alternate runs per tree (best kept)")
    args = ap.parse_args(argv)
    from benchmarks.quilting import START_COMMIT, start_checkout

    start = start_checkout("auto")
    if start is None:
        print(f"the start commit {START_COMMIT} is not at hand (git archive failed)")
        return 1
    text = "\n".join(
        [
            provenance(),
            f"python -m benchmarks.versus_start --rounds {args.rounds} "
            f"(start = {START_COMMIT}; best of {args.rounds} alternate runs per tree)",
            "",
            compare(Path(start), args.rounds),
        ]
    )
    print(text)
    (ROOT / "benchmarks" / "results" / "versus_start.txt").write_text(text + "\n", "utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
