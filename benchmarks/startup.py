"""Start-up: whole-process times of ``quilt-studio --help``, ``synth`` job A and the editor.

Usage: ``python -m benchmarks.startup [--repeats 7]``. Every figure is the median of
``--repeats`` fresh processes, run interleaved so that a busy machine slows them alike; wall
time (the targets) and CPU time (user + system of all threads, steadier under load):

* ``python -c "import numpy"`` — the reference;
* ``quilt-studio --help`` — target <= 2.5x the reference (it imports no numpy at all);
* ``quilt-studio synth`` job A (512x512 from a 128x128 crop of cobblestones, block 32,
  overlap 6, best match, dp) — target <= 1.2 s, from process start to the file written;
* the editor, from process start until its window is shown (offscreen), no target.

The processes run as on a user's machine: Python caches the bytecode of what it imports (the
warm-up run writes it), even where the calling shell sets ``PYTHONDONTWRITEBYTECODE`` (the
agents' shells here do: every process would then compile the engine's sources again, ~0.07 s
of job A); ``--no-bytecode`` measures that way instead.

The table is printed and saved to ``benchmarks/results/startup.txt``.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
HELP_RATIO, SYNTH_S = 2.5, 1.2

#: the editor up to its first shown window, then quit (QT_QPA_PLATFORM=offscreen)
EDITOR_PROBE = """
import sys
import quilt_gui.app as app
from PySide6.QtCore import QTimer

make = app.make_app

def probed(*args, **kwargs):
    qapp = make(*args, **kwargs)
    QTimer.singleShot(0, qapp.quit)  # the first event-loop turn: the window is shown
    return qapp

app.make_app = probed
sys.exit(app.run([]))
"""


def _run(cmd: list[str], env: dict) -> tuple[float, float]:
    """(wall, CPU) seconds of one process; CPU (user + system, all threads) is what a busy
    machine changes least."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, env=env, cwd=ROOT, capture_output=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def measure(repeats: int, bytecode: bool = True) -> dict[str, tuple[float, float]]:
    """Median whole-process (wall, CPU) seconds of each command (runs interleaved)."""
    from benchmarks.quilting import load_sample
    from engine.io import save_image

    tmp = Path(tempfile.mkdtemp(prefix="quilt_startup_"))
    crop = tmp / "crop128.png"
    save_image(crop, load_sample("cobblestones", 128))
    env = {**os.environ, "QT_QPA_PLATFORM": "offscreen", "XDG_CONFIG_HOME": str(tmp / "cfg")}
    if bytecode:
        env.pop("PYTHONDONTWRITEBYTECODE", None)
    else:
        env["PYTHONDONTWRITEBYTECODE"] = "1"
    exe = [sys.executable, "-m", "quilt_gui"]
    synth = [*exe, "synth", str(crop), "--size", "512x512", "--block", "32", "--overlap", "6"]
    synth += ["--select", "best", "--seam", "dp", "--seed", "1", "-o", str(tmp / "out.png")]
    commands = {
        'python -c "import numpy"': [sys.executable, "-c", "import numpy"],
        "quilt-studio --help": [*exe, "--help"],
        "quilt-studio synth (job A)": synth,
        "editor: first window": [sys.executable, "-c", EDITOR_PROBE],
    }
    for cmd in commands.values():  # warm the OS file cache and numba's cache once
        _run(cmd, env)
    times: dict[str, list[tuple[float, float]]] = {name: [] for name in commands}
    for _ in range(repeats):
        for name, cmd in commands.items():
            times[name].append(_run(cmd, env))
    return {
        name: (statistics.median(t[0] for t in ts), statistics.median(t[1] for t in ts))
        for name, ts in times.items()
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=7, help="processes per command (median)")
    ap.add_argument(
        "--no-bytecode",
        dest="bytecode",
        action="store_false",
        help="every process compiles the sources it imports (PYTHONDONTWRITEBYTECODE=1)",
    )
    args = ap.parse_args(argv)
    sys.path.insert(0, str(ROOT))
    from benchmarks._util import format_table, provenance

    first = provenance()
    med = measure(args.repeats, args.bytecode)
    load = ", ".join(f"{v:.1f}" for v in os.getloadavg())
    ref, ref_cpu = med['python -c "import numpy"']
    rows = [
        [name, f"{t:.3f}", f"{t / ref:.2f}x", f"{cpu:.3f}", f"{cpu / ref_cpu:.2f}x"]
        + [
            f"<= {HELP_RATIO}x numpy"
            if "help" in name
            else f"<= {SYNTH_S} s"
            if "synth" in name
            else ""
        ]
        for name, (t, cpu) in med.items()
    ]
    ok_help = med["quilt-studio --help"][0] <= HELP_RATIO * ref
    ok_synth = med["quilt-studio synth (job A)"][0] <= SYNTH_S
    text = "\n".join(
        [
            first + f" (at the end: {load})",
            f"python -m benchmarks.startup --repeats {args.repeats}"
            + ("" if args.bytecode else " --no-bytecode")
            + " (whole processes, medians, interleaved; bytecode "
            + ("cached as a user's Python does)" if args.bytecode else "compiled every time)"),
            "",
            format_table(
                ["command", "wall s", "vs import numpy", "CPU s", "CPU vs numpy's", "target"],
                rows,
            ),
            "",
            f"--help {'meets' if ok_help else 'MISSES'} its target; "
            f"synth job A {'meets' if ok_synth else 'MISSES'} its target (wall time; on a busy "
            "machine the CPU column is the steadier figure).",
        ]
    )
    print(text)
    out = ROOT / "benchmarks" / "results" / "startup.txt"
    out.write_text(text + "\n", encoding="utf-8")
    return 0 if ok_help and ok_synth else 1


if __name__ == "__main__":
    sys.exit(main())
