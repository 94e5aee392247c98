"""Fixtures shared by the engine tests."""

import os
from pathlib import Path

import pytest


@pytest.fixture
def tmpfs(tmp_path):
    """Mount small tmpfs file systems under ``tmp_path`` (root only; unmounted afterwards):
    a real full disk and a real read-only folder, which root's permissions cannot fake."""
    import subprocess

    if not hasattr(os, "geteuid") or os.geteuid() != 0:
        pytest.skip("mounting a tmpfs needs root (the permission-based tests cover other users)")
    mounted = []

    def mount(name: str, options: str) -> Path:
        point = tmp_path / name
        point.mkdir()
        res = subprocess.run(
            ["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(point)], capture_output=True
        )
        if res.returncode:
            pytest.skip(f"cannot mount a tmpfs here: {res.stderr.decode().strip()}")
        mounted.append(point)
        return point

    yield mount
    for point in mounted:
        subprocess.run(["umount", str(point)], capture_output=True)
