"""qem.measure, qem.load and qem.save."""

import gzip

import numpy as np
import pytest

import qem
from conftest import REPO, assert_valid, grid


def test_measure_identical_meshes_is_zero(sphere):
    m = qem.measure(sphere, sphere, min_samples=10_000)
    assert m["hausdorff"] == pytest.approx(0.0, abs=1e-12)
    assert m["mean_ab"] == pytest.approx(0.0, abs=1e-12)
    assert m["diagonal"] == pytest.approx(2 * np.sqrt(3), rel=1e-3)
    assert m["faces_facing_away"] == 0 and m["facing_away_area"] == 0.0


def test_measure_counts_faces_facing_away(sphere):
    vertices, faces = sphere
    reversed_faces = np.array(faces, copy=True)
    # Faces of a middle row (the pole rows have zero-area faces, which are not counted).
    reversed_faces[1000:1010] = reversed_faces[1000:1010, ::-1]
    m = qem.measure(sphere, (vertices, reversed_faces), min_samples=10_000)
    assert m["faces_facing_away"] == 10
    assert 0.0 < m["facing_away_area"] < 1.0


def test_measure_a_shifted_copy():
    vertices, faces = grid()
    shifted = vertices + [0.0, 0.0, 0.5]
    m = qem.measure((vertices, faces), (shifted, faces), min_samples=10_000)
    # Every point of one sheet is about 0.5 from the other sheet, but where the bumps
    # slope the nearest point is closer, and at the edges a little farther.
    assert 0.3 / m["diagonal"] < m["mean_ab"] <= 0.5 / m["diagonal"] + 1e-9
    assert m["hausdorff"] >= m["mean_ab"]
    assert m["samples_ab"] >= 10_000 and m["samples_ba"] >= 10_000


def test_measure_is_seeded(sphere):
    small = qem.simplify(*sphere, ratio=0.1)[:2]
    a = qem.measure(sphere, small, min_samples=20_000, seed=3)
    b = qem.measure(sphere, small, min_samples=20_000, seed=3)
    c = qem.measure(sphere, small, min_samples=20_000, seed=4)
    assert a == b
    assert a["mean_ab"] != c["mean_ab"]


def test_measure_takes_objects_with_vertices_and_faces(sphere):
    class Mesh:
        vertices, faces = sphere

    assert qem.measure(Mesh(), sphere, min_samples=1000) == qem.measure(sphere, sphere, min_samples=1000)


def test_measure_errors(sphere):
    with pytest.raises(TypeError, match="must be a \\(vertices, faces\\) pair"):
        qem.measure(sphere, 3)
    with pytest.raises(qem.QemError, match="b faces\\[0\\] refers to vertex 9"):
        qem.measure(sphere, (np.eye(3), [[0, 1, 9]]))
    with pytest.raises(qem.QemError, match="bounding-box diagonal is 0"):
        qem.measure((np.zeros((3, 3)), [[0, 1, 2]]), sphere)
    with pytest.raises(qem.QemError, match="samples_per_face must be a finite number"):
        qem.measure(sphere, sphere, samples_per_face=-1)


@pytest.mark.parametrize("name", ["m.obj", "m.ply", "m.stl", "m.off", "m.ply.gz"])
def test_save_and_load_round_trip(tmp_path, name):
    vertices, faces = qem.simplify(*grid(), ratio=0.5)[:2]
    path = tmp_path / name
    qem.save(path, (vertices, faces))
    v, f = qem.load(str(path))
    assert v.dtype == np.float64 and f.dtype == np.uint32
    assert_valid(v, f)
    assert len(f) == len(faces)
    # Compare the triangles' corners: the OBJ reader numbers vertices in the order faces
    # first use them, and STL stores float32 corners per facet.
    if name.startswith("m.stl"):
        assert np.allclose(v[f], vertices[faces], atol=1e-5)
    else:
        assert np.array_equal(v[f], vertices[faces])


def test_load_the_shipped_cow():
    vertices, faces = qem.load(REPO / "assets" / "spot.obj")
    assert len(faces) == 5856
    v, f, report = qem.simplify(vertices, faces, ratio=0.1)
    assert len(f) <= 586 and report["stop_reason"] == "target_reached"


def test_load_errors_name_the_file_and_line(tmp_path):
    with pytest.raises(qem.QemError, match="missing.obj: cannot read"):
        qem.load(tmp_path / "missing.obj")
    bad = tmp_path / "bad.off"
    bad.write_text("OFF\n3 1 0\n0 0 0\n1 0 0\n")
    with pytest.raises(qem.QemError, match="bad.off: line 4: unexpected end of file"):
        qem.load(bad)
    gz = tmp_path / "bad.obj.gz"
    gz.write_bytes(gzip.compress(b"v 0 0 0\nf 1 2 3\n"))
    with pytest.raises(qem.QemError, match="bad.obj.gz"):
        qem.load(gz)
    with pytest.raises(qem.QemError, match="m.xyz"):
        qem.load(tmp_path / "m.xyz")


def test_save_errors(tmp_path, sphere):
    with pytest.raises(qem.QemError, match="m.xyz"):
        qem.save(tmp_path / "m.xyz", sphere)
    with pytest.raises(qem.QemError, match="mesh faces\\[0\\] refers to vertex 7"):
        qem.save(tmp_path / "m.obj", (np.eye(3), [[0, 1, 7]]))
    assert not (tmp_path / "m.obj").exists()
