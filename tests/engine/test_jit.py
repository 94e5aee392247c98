"""engine._jit: numba is imported at a kernel's first call, and kernels still find each other."""

import subprocess
import sys

PROBE = """
import sys
sys.path.insert(0, {folder!r})
import numpy as np
import engine._jit as jit
import lazy_kernels
assert "numba" not in sys.modules and not jit.loaded()
assert isinstance(lazy_kernels.outer, jit.Kernel)
print(lazy_kernels.outer(np.arange(4.0)), jit.loaded(), "numba" in sys.modules)
"""

MODULE = """
from engine._jit import njit

@njit
def inner(x):
    return x * 2.0

@njit(nogil=True)
def outer(a):
    s = 0.0
    for v in a:
        s += inner(v)  # a stand-in here (not an engine module: never swapped): typed by numba
    return s
"""


def test_kernels_load_numba_at_their_first_call_and_call_each_other(tmp_path):
    (tmp_path / "lazy_kernels.py").write_text(MODULE)
    code = PROBE.format(folder=str(tmp_path))
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["12.0", "True", "True"]
