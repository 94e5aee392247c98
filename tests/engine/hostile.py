"""Small crafted hostile files and a CLI runner for the robustness tests (issue 12).

Huge images are never made: a PNG header *declaring* a huge size is enough to prove that a
reader refuses it before decoding. Memory is measured with tracemalloc in-process (numpy
allocations are traced) or with an address-space limit on a CLI subprocess.
"""

from __future__ import annotations

import json
import os
import resource
import signal
import struct
import subprocess
import sys
import time
import tracemalloc
import zipfile
import zlib
from contextlib import contextmanager
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]


def chunk(tag: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data))


def png_header(width: int, height: int, *, depth: int = 8, ctype: int = 2, idat=b"") -> bytes:
    """A PNG that declares ``width`` x ``height`` and holds (almost) no pixels."""
    ihdr = struct.pack(">IIBBBBB", width, height, depth, ctype, 0, 0, 0)
    return (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", ihdr)
        + chunk(b"IDAT", zlib.compress(idat))
        + chunk(b"IEND", b"")
    )


@contextmanager
def peak_traced():
    """Yields a dict whose "peak" is the peak traced allocation (bytes) inside the block."""
    out = {"peak": 0}
    tracemalloc.start()
    try:
        yield out
    finally:
        out["peak"] = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()


def refused_by(read, error, path, reasons, peak_mib: float) -> str:
    """``read(path)`` raises ``error`` whose message starts with the path and holds every
    reason, allocating at most ``peak_mib`` MiB (traced) on the way; returns the message."""
    import pytest

    with peak_traced() as mem, pytest.raises(error) as info:
        read(path)
    msg = str(info.value)
    assert msg.startswith(f"{path}: "), msg
    for r in reasons:
        assert r in msg, msg
    assert mem["peak"] < peak_mib * 2**20, (mem["peak"] / 2**20, msg)
    return msg


def sample_png(folder: Path, name: str = "sample.png"):
    """The cobblestones sample as an 8-bit PNG in ``folder``; returns (path, uint8 pixels)."""
    import numpy as np

    import resources
    from engine.io import load_image
    from engine.png import encode_png

    q = np.round(load_image(resources.sample_path("cobblestones")).pixels * 255).astype(np.uint8)
    (folder / name).write_bytes(encode_png(q))
    return folder / name, q


def project_zip(path: Path, doc: dict, entries: dict[str, bytes], *, compress=True) -> Path:
    """A .quiltproj zip holding ``doc`` as project.json and raw ``entries``."""
    method = zipfile.ZIP_DEFLATED if compress else zipfile.ZIP_STORED
    with zipfile.ZipFile(path, "w", method) as zf:
        zf.writestr("project.json", json.dumps(doc))
        for name, data in entries.items():
            zf.writestr(name, data)
    return path


def project_doc(candidates: list[dict], *, source="images/s.png", maps=("albedo",)) -> dict:
    """A minimal valid project.json whose images are the given entry names."""
    return {
        "format": "quilt-studio-project",
        "version": 1,
        "name": "hostile",
        "bit_depth": 8,
        "normal_convention": "opengl",
        "maps": list(maps),
        "sources": {m: source for m in maps},
        "parameters": {},
        "seeds": {},
        "candidates": candidates,
        "picks": [],
    }


def candidate(entry: str, maps=("albedo",), **extra) -> dict:
    return {"images": {m: entry for m in maps}, "locked": False, **extra}


def _limit(address_space: int | None):
    def apply():
        os.setsid()  # its own process group: a signal to it reaches only it
        if address_space:
            resource.setrlimit(resource.RLIMIT_AS, (address_space, address_space))

    return apply


def cli(*args, rlimit_as: int | None = None, timeout: float = 120, env=None, cwd=None):
    """Run ``python -m quilt_gui ARGS`` (the ``quilt-studio`` entry point) to completion;
    returns the CompletedProcess (text output)."""
    return subprocess.run(
        [sys.executable, "-m", "quilt_gui", *map(str, args)],
        capture_output=True,
        text=True,
        timeout=timeout,
        cwd=cwd or REPO,
        env={**os.environ, **(env or {})},
        preexec_fn=_limit(rlimit_as),
    )


def start_cli(*args, env=None, cwd=None) -> subprocess.Popen:
    """Start the CLI; stderr is a pipe (read it with :func:`wait_for_line`)."""
    return subprocess.Popen(
        [sys.executable, "-u", "-m", "quilt_gui", *map(str, args)],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        cwd=cwd or REPO,
        env={**os.environ, "PYTHONUNBUFFERED": "1", **(env or {})},
        preexec_fn=_limit(None),
    )


def wait_for_line(proc: subprocess.Popen, needle: str, timeout: float = 120) -> list[str]:
    """Read stderr lines until one contains ``needle``; returns the lines read."""
    lines = []
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        line = proc.stderr.readline()
        if not line:
            break
        lines.append(line)
        if needle in line:
            return lines
    raise AssertionError(f"{needle!r} never appeared on stderr: {''.join(lines)[-2000:]}")


def signal_and_wait(proc: subprocess.Popen, sig: int, timeout: float = 60) -> tuple[int, str]:
    """Send ``sig``, wait for the exit; (return code, the rest of stderr)."""
    os.kill(proc.pid, sig)
    rest = proc.stderr.read()
    return proc.wait(timeout=timeout), rest


SIGNALS = {
    "SIGINT": (signal.SIGINT, 130, "interrupted"),
    "SIGTERM": (signal.SIGTERM, 143, "terminated"),
}
