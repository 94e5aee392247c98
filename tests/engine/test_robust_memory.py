"""D3 (issue 12): every sub-command estimates its peak memory before it starts and refuses a
job that does not fit, with a message naming the memory needed, the limit and the way out —
never a MemoryError halfway. The limit is set small with QUILT_MEMORY_LIMIT (a smaller
machine), and the real address space is capped too, so a job that ignored the estimate would
fail with a MemoryError instead of the message."""

from __future__ import annotations

import numpy as np
import pytest

from engine.cli import main
from engine.png import encode_png
from tests.engine.hostile import cli, sample_png

GiB = 2**30


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("mem")
    _, q = sample_png(d, "s.png")
    mask = np.zeros(q.shape[:2], np.uint8)
    mask[200:260, 200:260] = 255
    (d / "m.png").write_bytes(encode_png(mask))
    small = d / "small"
    assert main(["tileset", str(d / "s.png"), "--out", str(small), "--candidates", "4",
                 "--tile-min", "128", "--preview", "2x2", "--project",
                 str(d / "p.quiltproj")]) == 0  # fmt: skip
    return d


def jobs(d, out):
    return {
        "tileset": ["tileset", d / "s.png", "--out", out / "t"],
        "synth": [
            "synth",
            d / "s.png",
            "--size",
            "2048x2048",
            "--block",
            "48",
            "-o",
            out / "o.png",
        ],
        "transfer": ["transfer", d / "s.png", d / "s.png", "--block", "24", "-o", out / "o.png"],
        "export": ["export", d / "p.quiltproj", "--out", out / "b"],
        "seam": ["seam", d / "s.png", d / "s.png", "--save-mask", out / "m.png"],
        "heal": ["heal", d / "s.png", d / "m.png", "-o", out / "h.png"],
    }


@pytest.mark.parametrize("command", ["tileset", "synth", "transfer", "export", "seam", "heal"])
def test_d3_every_command_refuses_what_does_not_fit_before_the_work(files, tmp_path, command):
    limit = "2M" if command == "export" else "8M"  # a machine with that much to spare
    res = cli(
        *jobs(files, tmp_path / "out")[command],
        env={"QUILT_MEMORY_LIMIT": limit},
        rlimit_as=4 * GiB,  # and a real ceiling: ignoring the estimate would end in MemoryError
    )
    assert res.returncode == 1, res.stderr
    err = res.stderr.strip().splitlines()[-1]
    assert err.startswith(f"quilt-studio {command}: error: ")
    assert "needs about" in err and f"more than the {limit[0]}.0 MiB available here;" in err, err
    assert "Traceback" not in res.stderr and "MemoryError" not in res.stderr
    assert not (tmp_path / "out").exists()  # nothing written


def test_d3_a_job_that_fits_runs(files, tmp_path):
    res = cli("seam", files / "s.png", files / "s.png", "--json", env={"QUILT_MEMORY_LIMIT": "2G"})
    assert res.returncode == 0, res.stderr
