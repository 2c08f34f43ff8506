"""Attributes (issue 29): texture coordinates, normals, colours, generic channels and
materials through simplify, load, save and simplify_trimesh."""

import warnings

import numpy as np
import pytest

import qem
from conftest import REPO, assert_valid

SPOT = REPO / "assets" / "spot.obj"


def flat_grid(n=24):
    """A flat n x n grid of squares over [0, 1]^2 (z = 0), with uv = (x, y): a linear
    field, which the simplifier must reproduce exactly at every vertex it keeps or
    moves. float64 vertices, int64 faces, float64 uv."""
    x, y = np.meshgrid(np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1))
    vertices = np.stack([x, y, np.zeros_like(x)], axis=-1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(n), np.arange(n))
    v = j * (n + 1) + i
    faces = np.concatenate(
        [np.stack([v, v + 1, v + n + 1], -1), np.stack([v + 1, v + n + 2, v + n + 1], -1)]
    ).reshape(-1, 3)
    return vertices, faces, vertices[:, :2].copy()


def uv_mapped_sphere(n=32, m=16):
    """A unit sphere with the usual longitude/latitude UV map: the column u = 1 repeats
    the positions of the column u = 0 (a UV seam, welded by qem into one vertex with two
    texture coordinates), and each pole row is one point with n + 1 texture
    coordinates. Returns vertices, faces and attributes uv, normal, colour."""
    u, w = np.meshgrid(np.linspace(0, 1, n + 1), np.linspace(0, 1, m + 1))
    theta, phi = 2 * np.pi * u, np.pi * w
    p = np.stack(
        [np.sin(phi) * np.cos(theta), np.sin(phi) * np.sin(theta), np.cos(phi)], axis=-1
    )
    p[:, n] = p[:, 0]  # the seam: bit-identical positions on both sides
    p[0] = [0.0, 0.0, 1.0]
    p[m] = [0.0, 0.0, -1.0]
    vertices = p.reshape(-1, 3)
    i, j = np.meshgrid(np.arange(n), np.arange(m))
    a = j * (n + 1) + i
    b, c, d = a + 1, a + n + 1, a + n + 2
    faces = np.concatenate([np.stack([a, c, b], -1), np.stack([b, c, d], -1)]).reshape(-1, 3)
    attributes = {
        "uv": np.stack([u, 1 - w], axis=-1).reshape(-1, 2),
        "normal": vertices.copy(),
        "colour": (vertices + 1) / 2,
    }
    return vertices, faces, attributes


# ------------------------------------------------------------------------- simplify


def test_outputs_have_one_row_per_vertex_and_the_input_dtypes():
    v, f, a = uv_mapped_sphere()
    a = {**a, "uv": a["uv"].astype(np.float32), "weight": v[:, 2].copy()}
    out = qem.simplify(v, f, attributes=a, ratio=0.2)
    assert len(out) == 4
    sv, sf, sa, report = out
    assert_valid(sv, sf)
    assert list(sa) == ["uv", "normal", "colour", "weight"]
    assert sa["uv"].shape == (len(sv), 2) and sa["uv"].dtype == np.float32
    assert sa["normal"].shape == (len(sv), 3) and sa["normal"].dtype == np.float64
    assert sa["colour"].shape == (len(sv), 3)
    assert sa["weight"].shape == (len(sv),)  # a 1-d generic channel stays 1-d
    assert report["triangles_out"] == len(sf) <= 0.2 * len(f) + 2
    # The output is split at the seams: the vertices the report counts, and more.
    assert len(sv) >= report["vertices_out"]
    assert np.isfinite(sa["uv"]).all()
    # Attribute quadrics may extrapolate a little near the seam (u is not clamped).
    assert (sa["uv"] >= -0.02).all() and (sa["uv"] <= 1.02).all()


def test_a_linear_uv_field_comes_out_exact():
    v, f, uv = flat_grid()
    sv, sf, sa, report = qem.simplify(v, f, attributes={"uv": uv}, ratio=0.1)
    assert report["stop_reason"] == "target_reached"
    assert len(sf) < 0.15 * len(f)
    np.testing.assert_allclose(sa["uv"], sv[:, :2], rtol=0, atol=1e-5)


def test_normals_come_out_unit_and_colours_in_range():
    v, f, a = uv_mapped_sphere()
    sv, sf, sa, _ = qem.simplify(v, f, attributes=a, ratio=0.15)
    np.testing.assert_allclose(np.linalg.norm(sa["normal"], axis=1), 1.0, atol=1e-5)
    assert (sa["colour"] >= 0).all() and (sa["colour"] <= 1).all()
    # On a sphere the normals stay near the positions' directions.
    direction = sv / np.linalg.norm(sv, axis=1, keepdims=True)
    assert (np.sum(direction * sa["normal"], axis=1) > 0.9).all()


def test_rgba_and_color_keys():
    v, f, a = uv_mapped_sphere()
    rgba = np.concatenate([a["colour"], np.full((len(v), 1), 0.5)], axis=1)
    sv, _, sa, _ = qem.simplify(v, f, attributes={"color": rgba}, ratio=0.3)
    assert list(sa) == ["color"] and sa["color"].shape == (len(sv), 4)
    np.testing.assert_allclose(sa["color"][:, 3], 0.5, atol=1e-5)


def test_the_same_call_gives_the_same_result():
    v, f, a = uv_mapped_sphere()
    first = qem.simplify(v, f, attributes=a, ratio=0.2)
    second = qem.simplify(v, f, attributes=a, ratio=0.2)
    for x, y in zip(first[:2], second[:2]):
        assert np.array_equal(x, y)
    for key in a:
        assert np.array_equal(first[2][key], second[2][key]), key


def test_materials_keep_their_border_and_their_labels():
    v, f, uv = flat_grid()
    centroid_x = v[f][:, :, 0].mean(axis=1)
    material = np.where(centroid_x < 0.5, 7, -3).astype(np.int32)
    sv, sf, sa, _ = qem.simplify(v, f, attributes={"uv": uv, "material": material}, ratio=0.1)
    out = sa["material"]
    assert out.dtype == np.int32 and out.shape == (len(sf),)
    assert set(out.tolist()) == {7, -3}
    x = sv[sf][:, :, 0]
    assert (x[out == 7] <= 0.5 + 1e-9).all() and (x[out == -3] >= 0.5 - 1e-9).all()


def test_without_attributes_the_result_is_the_three_tuple_as_before(sphere):
    v, f = sphere
    plain = qem.simplify(v, f, ratio=0.1)
    none = qem.simplify(v, f, ratio=0.1, attributes=None)
    weighted = qem.simplify(v, f, ratio=0.1, attribute_weights={"uv": 5.0})
    for other in (none, weighted):
        assert len(other) == 3
        assert np.array_equal(plain[0], other[0]) and np.array_equal(plain[1], other[1])
    assert plain[2]["vertices_out"] == len(plain[0])


def test_default_options_round_trip_with_attributes():
    v, f, a = uv_mapped_sphere()
    defaults = qem.default_options()
    assert defaults["attributes"] is None
    assert defaults["attribute_weights"] == {
        "uv": 0.3,
        "normal": 0.15,
        "colour": 1.0,
        "generic": 1.0,
    }
    plain = qem.simplify(v, f, ratio=0.2, attributes=a)
    spelled = qem.simplify(v, f, **{**defaults, "ratio": 0.2, "attributes": a})
    assert np.array_equal(plain[0], spelled[0]) and np.array_equal(plain[1], spelled[1])
    assert np.array_equal(plain[2]["uv"], spelled[2]["uv"])


def test_attribute_weights_change_the_result():
    v, f, a = uv_mapped_sphere()
    base = qem.simplify(v, f, ratio=0.2, attributes=a)
    heavy = qem.simplify(
        v, f, ratio=0.2, attributes=a, attribute_weights={"uv": 3.0, "color": 0.0}
    )
    assert not np.array_equal(base[0], heavy[0])
    with pytest.raises(ValueError, match="attribute_weights has no key 'texcoord'"):
        qem.simplify(v, f, attributes=a, attribute_weights={"texcoord": 1.0})
    with pytest.raises(ValueError, match="attribute_weights\\['uv'\\]"):
        qem.simplify(v, f, attributes=a, attribute_weights={"uv": -1.0})
    with pytest.raises(TypeError, match="attribute_weights must be a dict"):
        qem.simplify(v, f, attributes=a, attribute_weights=0.3)


@pytest.mark.parametrize(
    "key, value, message",
    [
        ("uv", lambda n: np.zeros((n, 3)), r"attributes\['uv'\] must have shape \(n, 2\)"),
        ("uv", lambda n: np.zeros((n - 1, 2)), r"attributes\['uv'\] .*\(n = \d+\), not"),
        ("normal", lambda n: np.zeros((n, 2)), r"attributes\['normal'\] must have shape \(n, 3\)"),
        ("colour", lambda n: np.zeros((n, 5)), r"attributes\['colour'\] .*\(n, 3\) or \(n, 4\)"),
        ("colour", lambda n: np.full((n, 3), 2.0), r"attributes\['colour'\]\[0\] holds 2"),
        ("color", lambda n: np.zeros((n, 3), np.uint8), r"attributes\['color'\] must be float"),
        ("temperature", lambda n: np.zeros((n, 5)), r"attributes\['temperature'\] .*k from 1 to 4"),
        ("uv", lambda n: np.full((n, 2), np.nan), r"attributes\['uv'\]\[0\] .*finite"),
        ("material", lambda n: np.zeros(3, np.int64), r"attributes\['material'\] .*one label per face"),
        ("material", lambda n: np.zeros(2048, np.float64), r"attributes\['material'\] must be int"),
    ],
)
def test_bad_arrays_are_refused_naming_the_key(key, value, message):
    v, f, _ = flat_grid(n=32)  # 2048 faces, 1089 vertices
    with pytest.raises(ValueError, match=message):
        qem.simplify(v, f, attributes={key: value(len(v))})


def test_other_bad_attributes():
    v, f, a = uv_mapped_sphere()
    with pytest.raises(TypeError, match="attributes must be a dict"):
        qem.simplify(v, f, attributes=[a["uv"]])
    with pytest.raises(ValueError, match="both 'colour' and 'color'"):
        qem.simplify(v, f, attributes={"colour": a["colour"], "color": a["colour"]})
    with pytest.raises(qem.QemError, match="clustering.*cannot carry attributes"):
        qem.simplify(v, f, attributes=a, method="clustering")


# ------------------------------------------------------------------------ load, save


def obj_corners(path):
    """The (position, uv) of every triangle corner of an OBJ of `v`, `vt` and
    `f v/vt ...` lines, read here without qem."""
    positions, uvs, rows = [], [], []
    for line in path.read_text().splitlines():
        parts = line.split()
        if not parts:
            continue
        if parts[0] == "v":
            positions.append([float(x) for x in parts[1:4]])
        elif parts[0] == "vt":
            uvs.append([float(x) for x in parts[1:3]])
        elif parts[0] == "f":
            corners = [tuple(int(i) - 1 for i in c.split("/")[:2]) for c in parts[1:]]
            for k in range(1, len(corners) - 1):
                for vi, ti in (corners[0], corners[k], corners[k + 1]):
                    rows.append(positions[vi] + uvs[ti])
    return np.array(rows)


def corner_rows(vertices, faces, uv):
    rows = np.hstack([vertices[faces].reshape(-1, 3), uv[faces].reshape(-1, 2)])
    return np.unique(rows.astype(np.float64), axis=0)


def test_load_with_attributes_is_per_vertex_and_keeps_every_corner():
    v0, f0 = qem.load(SPOT)
    v, f, a = qem.load(SPOT, attributes=True)
    assert list(a) == ["uv", "material", "material_names"] and a["uv"].dtype == np.float32
    assert a["material_names"] == ["spot"] and (a["material"] == 0).all()
    assert a["uv"].shape == (len(v), 2) and len(f) == len(f0)
    assert len(v) > len(v0)  # split at the UV seams
    expected = np.unique(obj_corners(SPOT), axis=0)
    got = corner_rows(v, f, a["uv"])
    assert got.shape == expected.shape
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-6)


def test_save_and_load_round_trip_the_uv(tmp_path):
    v, f, a = qem.load(SPOT, attributes=True)
    path = tmp_path / "spot.obj"
    qem.save(path, (v, f, a))
    v2, f2, a2 = qem.load(path, attributes=True)
    assert np.array_equal(corner_rows(v, f, a["uv"]), corner_rows(v2, f2, a2["uv"]))
    # And a simplified copy, through a PLY file.
    sv, sf, sa, _ = qem.simplify(v, f, attributes=a, ratio=0.25)
    assert sa["uv"].dtype == np.float32
    ply = tmp_path / "small.ply"
    # PLY holds no materials: saving says what it leaves out.
    with pytest.warns(UserWarning, match="materials"):
        qem.save(ply, (sv, sf, sa))
    pv, pf, pa = qem.load(ply, attributes=True)
    assert np.array_equal(corner_rows(sv, sf, sa["uv"]), corner_rows(pv, pf, pa["uv"]))


def test_materials_round_trip_through_obj(tmp_path):
    v, f, uv = flat_grid(n=8)
    material = (v[f][:, :, 0].mean(axis=1) > 0.5).astype(np.int64)
    path = tmp_path / "two.obj"
    qem.save(path, (v, f, {"uv": uv, "material": material, "material_names": ["wood", "steel"]}))
    assert "usemtl steel" in path.read_text()
    _, lf, la = qem.load(path, attributes=True)
    assert la["material_names"] == ["wood", "steel"]
    assert np.array_equal(np.sort(la["material"]), np.sort(material))
    with pytest.raises(ValueError, match=r"attributes\['material'\]\[0\] is 5"):
        qem.save(path, (v, f, {"material": material + 5, "material_names": ["a"]}))


def test_save_warns_about_what_the_format_cannot_hold(tmp_path):
    v, f, a = uv_mapped_sphere()
    with pytest.warns(UserWarning, match=r"left out of .*s\.stl: uv \(STL holds positions only\), normal"):
        qem.save(tmp_path / "s.stl", (v, f, a))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        qem.save(tmp_path / "s.obj", (v, f, {"uv": a["uv"], "normal": a["normal"]}))
        qem.save(tmp_path / "plain.obj", (v, f))


def test_measure_takes_a_triple():
    v, f, a = qem.load(SPOT, attributes=True)
    assert qem.measure((v, f, a), (v, f), min_samples=1000)["hausdorff"] < 1e-12


# -------------------------------------------------------------------------- trimesh


def test_simplify_trimesh_carries_texture_coordinates():
    trimesh = pytest.importorskip("trimesh")
    v, f, uv = flat_grid()
    material = trimesh.visual.material.SimpleMaterial()
    mesh = trimesh.Trimesh(
        vertices=v,
        faces=f,
        visual=trimesh.visual.TextureVisuals(uv=uv, material=material),
        process=False,
    )
    small, report = qem.simplify_trimesh(mesh, ratio=0.1)
    assert isinstance(small.visual, trimesh.visual.TextureVisuals)
    assert small.visual.material is material
    out_uv = np.asarray(small.visual.uv)
    assert out_uv.shape == (len(small.vertices), 2)
    np.testing.assert_allclose(out_uv, np.asarray(small.vertices)[:, :2], atol=1e-5)
    assert len(small.faces) == report["triangles_out"]
    # keep_attributes=False: the positions-only result.
    bare, _ = qem.simplify_trimesh(mesh, ratio=0.1, keep_attributes=False)
    v2, f2, _ = qem.simplify(v, f, ratio=0.1)
    assert np.array_equal(bare.vertices, v2) and np.array_equal(bare.faces, f2)
    with pytest.raises(TypeError, match="takes the attributes from the mesh"):
        qem.simplify_trimesh(mesh, attributes={"uv": uv})
    # default_options() passes through (its attributes is None).
    qem.simplify_trimesh(mesh, **qem.default_options())


def test_simplify_trimesh_carries_colours_and_normals():
    trimesh = pytest.importorskip("trimesh")
    v, f, a = uv_mapped_sphere()
    rgba = np.concatenate(
        [np.rint(a["colour"] * 255), np.full((len(v), 1), 255)], axis=1
    ).astype(np.uint8)
    mesh = trimesh.Trimesh(
        vertices=v, faces=f, vertex_colors=rgba, vertex_normals=a["normal"], process=False
    )
    small, _ = qem.simplify_trimesh(mesh, ratio=0.2)
    colours = np.asarray(small.visual.vertex_colors)
    assert colours.shape == (len(small.vertices), 4) and colours.dtype == np.uint8
    assert (colours[:, 3] == 255).all()
    normals = np.asarray(small.vertex_normals)
    assert normals.shape == (len(small.vertices), 3)
    np.testing.assert_allclose(np.linalg.norm(normals, axis=1), 1.0, atol=1e-5)
