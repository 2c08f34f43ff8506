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


def readme_blocks():
    # The workspace README and the package's README show the same examples: they are
    # run once, and the two copies must not drift apart.
    blocks = python_blocks(REPO / "README.md")
    assert len(blocks) == 2, "README.md should have two Python examples"
    assert python_blocks(REPO / "crates" / "qem-py" / "README.md") == blocks
    return blocks


def test_readme_example_runs(capsys):
    exec(compile(readme_blocks()[0], "README.md", "exec"), {})
    out = capsys.readouterr().out
    assert "triangles, max error" in out and "(target_reached)" in out
    assert "Hausdorff distance" in out


def test_readme_tiles_example_runs(capsys, tmp_path, monkeypatch):
    # It reads assets/ from the repository's root and writes beside it: run it in a
    # scratch directory that links to the assets.
    (tmp_path / "assets").symlink_to(REPO / "assets")
    monkeypatch.chdir(tmp_path)
    with pytest.warns(UserWarning, match="tiles carry positions only"):
        exec(compile(readme_blocks()[1], "README.md", "exec"), {"__name__": "__main__"})
    assert "4 tiles: 5856 -> " in capsys.readouterr().out
    assert (tmp_path / "spot-half-dask.ply").read_bytes() == (
        tmp_path / "spot-half.ply"
    ).read_bytes()
