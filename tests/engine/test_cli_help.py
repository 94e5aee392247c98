"""``quilt-studio --help`` lists every sub-command and starts fast: it loads no numpy, numba,
scipy or Qt; a sub-command loads only its own module of the command line; the tables the
parsers read (seam methods, tile-set settings) load without numpy."""

import json
import subprocess
import sys

import pytest

from engine.cli import SUBCOMMANDS

HEAVY = ("numpy", "numba", "scipy", "PySide6", "skimage", "PIL", "superqt")

PROBE = """
import contextlib, io, json, sys
from quilt_gui.__main__ import main
with contextlib.redirect_stdout(io.StringIO()):
    try:
        main({argv!r})
    except SystemExit:
        pass
loaded = sorted(m for m in sys.modules if m.split(".")[0] in {heavy!r})
cli = sorted(m for m in sys.modules if m.startswith("engine.cli."))
print(json.dumps([loaded, cli]))
"""


def _loaded(argv: list[str]) -> tuple[list[str], list[str]]:
    code = PROBE.format(argv=argv, heavy=HEAVY)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    heavy, cli = json.loads(out.stdout)
    return heavy, cli


def test_help_lists_subcommands():
    out = subprocess.run(
        [sys.executable, "-m", "quilt_gui", "--help"], capture_output=True, text=True, check=True
    )
    assert "SUBCOMMAND" in out.stdout
    for name, line in SUBCOMMANDS.items():
        assert name in out.stdout and line.split()[0] in out.stdout


def test_help_loads_no_numerical_library_and_no_subcommand():
    heavy, cli = _loaded(["--help"])
    assert heavy == [] and cli == []


@pytest.mark.parametrize("name", ["seam", "tileset", "export", "synth", "transfer"])
def test_a_subcommands_help_loads_only_its_own_command(name):
    heavy, cli = _loaded([name, "--help"])
    assert heavy == []  # their parsers read the engine's light tables
    own = {f"engine.cli.{name}", "engine.cli._args", "engine.cli.outcome"}  # outcome: exit codes
    if name == "tileset":
        own |= {"engine.cli.export", "engine.cli.tileset_output", "engine.cli.tileset_wang"}
    if name == "transfer":
        own.add("engine.cli.synth")  # the cut options it shares
    assert set(cli) <= own, cli


@pytest.mark.parametrize(
    "module", ["engine.seams.spec", "engine.settings", "engine.cli", "engine.quilting.names"]
)
def test_the_tables_the_parsers_read_load_without_numpy(module):
    code = f"import sys, json, {module}; print(json.dumps(sorted(sys.modules)))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert not {m.split(".")[0] for m in json.loads(out.stdout)} & set(HEAVY)


def test_a_small_synth_job_loads_neither_numba_nor_scipy(tmp_path):
    """A small exact dp synthesis (like benchmarks/startup.py's job A) runs on numpy alone:
    numba's start-up (~0.6 s) and scipy.fft's import (~0.25 s) would be most of its time."""
    import numpy as np

    from engine.io import save_image

    sample = tmp_path / "s.png"
    save_image(sample, np.random.default_rng(0).random((64, 64, 3), dtype=np.float32))
    argv = ["synth", str(sample), "--size", "160x160", "--block", "16", "--overlap", "3"]
    argv += ["--seed", "1", "-o", str(tmp_path / "out.png")]
    heavy, _ = _loaded(argv)
    assert not [m for m in heavy if m.split(".")[0] in ("numba", "scipy")], heavy
    assert (tmp_path / "out.png").exists()
