"""The trimesh helper (skipped without trimesh) and the READMEs' Python examples."""

import re

import numpy as np
import pytest

import qem
from conftest import REPO, assert_valid


def test_simplify_trimesh():
    trimesh = pytest.importorskip("trimesh")
    mesh = trimesh.creation.icosphere(subdivisions=4)
    small, report = qem.simplify_trimesh(mesh, triangles=500)
    assert isinstance(small, trimesh.Trimesh)
    assert len(small.faces) <= 500 and report["stop_reason"] == "target_reached"
    assert small.faces.dtype == mesh.faces.dtype and small.vertices.dtype == mesh.vertices.dtype
    assert_valid(np.asarray(small.vertices), np.asarray(small.faces))
    # trimesh must not have merged or dropped anything qem wrote (process=False).
    assert len(small.faces) == report["triangles_out"]
    assert small.is_watertight  # a closed input stays closed
    # The same as qem.simplify on the arrays.
    v, f, _ = qem.simplify(mesh.vertices, mesh.faces, triangles=500)
    assert np.array_equal(small.vertices, v) and np.array_equal(small.faces, f)
    # measure takes trimesh objects as they are.
    assert qem.measure(mesh, small, min_samples=10_000)["hausdorff"] < 0.05


def test_simplify_trimesh_refuses_other_objects():
    pytest.importorskip("trimesh")
    with pytest.raises(TypeError, match="takes a trimesh.Trimesh, not tuple"):
        qem.simplify_trimesh((np.eye(3), [[0, 1, 2]]))


def python_blocks(path):
    return re.findall(r"```python\n(.*?)```", path.read_text(), re.S)


def test_readme_example_runs(capsys):
    # The workspace README and the package's README show the same example: run it once,
    # and make sure the two copies have not drifted apart.
    blocks = python_blocks(REPO / "README.md")
    assert len(blocks) == 1, "README.md should have one Python example"
    assert python_blocks(REPO / "crates" / "qem-py" / "README.md") == blocks
    exec(compile(blocks[0], "README.md", "exec"), {})
    out = capsys.readouterr().out
    assert "triangles, max error" in out and "(target_reached)" in out
    assert "Hausdorff distance" in out
