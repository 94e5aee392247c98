"""Project.outputs: other images of a session (the editor's quilting output and transfer
target) saved and read back exactly."""

from __future__ import annotations

import numpy as np
import pytest

from engine.project import ProjectError, load_project, save_project
from tests.engine.test_project import make_project


@pytest.mark.parametrize("bit_depth", [8, 16])
def test_outputs_of_any_size_round_trip_exactly(tmp_path, bit_depth):
    p = make_project(bit_depth=bit_depth)
    rng = np.random.default_rng(0)
    levels = 2**bit_depth - 1
    quilt = (rng.integers(0, levels + 1, (37, 53, 3)) / levels).astype(np.float32)
    target = (rng.integers(0, levels + 1, (20, 11, 1)) / levels).astype(np.float32)
    p.outputs = {"quilt": quilt, "transfer_target": target}
    back = load_project(save_project(tmp_path / "o.quiltproj", p))
    assert set(back.outputs) == {"quilt", "transfer_target"}
    np.testing.assert_array_equal(back.outputs["quilt"], quilt)
    np.testing.assert_array_equal(back.outputs["transfer_target"], target)
    assert load_project(save_project(tmp_path / "n.quiltproj", make_project())).outputs == {}


def test_bad_outputs_are_refused(tmp_path):
    p = make_project()
    p.outputs = {"../evil": np.zeros((4, 4, 3), np.float32)}
    with pytest.raises(ProjectError, match="outputs keys"):
        save_project(tmp_path / "x.quiltproj", p)
    p.outputs = {"quilt": np.zeros((4, 4), np.float32)}
    with pytest.raises(ProjectError, match="outputs"):
        save_project(tmp_path / "x.quiltproj", p)
