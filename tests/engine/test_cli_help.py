import subprocess
import sys


def test_help_lists_subcommands():
    out = subprocess.run(
        [sys.executable, "-m", "quilt_gui", "--help"], capture_output=True, text=True, check=True
    )
    assert "SUBCOMMAND" in out.stdout
