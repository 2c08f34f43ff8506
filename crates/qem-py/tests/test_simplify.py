"""qem.simplify: arrays in and out, options, errors, progress and the GIL."""

import numpy as np
import pytest

import qem
from conftest import assert_gil_released, assert_valid, grid, uv_sphere


def test_returns_valid_arrays_and_a_report(sphere):
    vertices, faces = sphere
    v, f, report = qem.simplify(vertices, faces, ratio=0.1)
    assert_valid(v, f)
    assert report["triangles_in"] == len(faces)
    assert report["triangles_out"] == len(f)
    assert report["vertices_out"] == len(v)
    assert report["target_triangles"] == int(0.1 * len(faces))
    assert len(f) <= report["target_triangles"]
    assert report["stop_reason"] == "target_reached"
    # The pole rows repeat one point: welded, and the faces that collapse dropped.
    assert report["cleanup"]["welded_vertices"] == 2 * (48 - 1)
    assert report["cleanup"]["repeated_index_faces"] == 2 * 48
    assert 0 < report["max_error"] < 0.05
    assert report["max_error_abs"] == pytest.approx(
        report["max_error"] * report["bbox_diagonal"]
    )
    assert set(report["rejected"]) == {
        "degenerate", "flip", "sliver", "topology", "locked", "border", "merge",
        "orientation", "last_triangles", "seam",
    }
    assert report["timings_ms"]["simplify"] >= report["timings_ms"]["contract"] >= 0


@pytest.mark.parametrize("float_type", [np.float32, np.float64])
@pytest.mark.parametrize("index_type", [np.int32, np.int64, np.uint32, np.uint64])
def test_output_keeps_the_input_dtypes(sphere, float_type, index_type):
    vertices, faces = sphere
    v, f, _ = qem.simplify(vertices.astype(float_type), faces.astype(index_type), ratio=0.2)
    assert v.dtype == float_type and f.dtype == index_type
    assert_valid(v, f)


def test_index_dtype_does_not_change_the_result(sphere):
    vertices, faces = sphere
    v32, f32, _ = qem.simplify(vertices, faces.astype(np.int32), ratio=0.2)
    v64, f64, _ = qem.simplify(vertices, faces.astype(np.uint64), ratio=0.2)
    assert np.array_equal(v32, v64) and np.array_equal(f32, f64)


def test_deterministic(sphere):
    first = qem.simplify(*sphere, ratio=0.1)
    second = qem.simplify(*sphere, ratio=0.1)
    assert np.array_equal(first[0], second[0]) and np.array_equal(first[1], second[1])


def test_strided_and_fortran_inputs_read_like_contiguous_ones(sphere):
    vertices, faces = sphere
    expected = qem.simplify(vertices, faces, ratio=0.2)
    # Every other column of a wider array: a non-contiguous view.
    wide = np.zeros((len(vertices), 6))
    wide[:, ::2] = vertices
    for v_in, f_in in [
        (wide[:, ::2], faces),
        (np.asfortranarray(vertices), np.asfortranarray(faces)),
    ]:
        assert not v_in.flags.c_contiguous
        v, f, _ = qem.simplify(v_in, f_in, ratio=0.2)
        assert np.array_equal(v, expected[0]) and np.array_equal(f, expected[1])


def test_nested_lists_are_accepted():
    # A square pyramid without its base; int coordinates in a list become float64.
    vertices = [[0, 0, 1], [1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0]]
    faces = [[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]]
    v, f, report = qem.simplify(vertices, faces, triangles=2)
    assert v.dtype == np.float64 and f.dtype == np.int64
    assert len(f) <= 2 and report["stop_reason"] == "target_reached"


def test_the_inputs_are_not_modified(sphere):
    vertices, faces = sphere
    v0, f0 = vertices.copy(), faces.copy()
    qem.simplify(vertices, faces, ratio=0.1)
    assert np.array_equal(vertices, v0) and np.array_equal(faces, f0)


# ---------------------------------------------------------------------------- options


def test_default_options_round_trip(sphere):
    # Every option written out as the defaults says must change nothing: this checks
    # each option's reading against its writing, for both presets.
    plain = qem.simplify(*sphere, ratio=0.1)
    spelled = qem.simplify(*sphere, **{**qem.default_options(), "ratio": 0.1})
    assert np.array_equal(plain[0], spelled[0]) and np.array_equal(plain[1], spelled[1])
    fast = qem.simplify(*sphere, ratio=0.1, fast=True)
    spelled = qem.simplify(*sphere, **{**qem.default_options(fast=True), "ratio": 0.1})
    assert np.array_equal(fast[0], spelled[0]) and np.array_equal(fast[1], spelled[1])
    assert not np.array_equal(plain[0], fast[0]), "fast=True should change the result"


def test_default_options_are_the_libraries():
    d = qem.default_options()
    assert d["ratio"] == 0.5 and d["order"] == "passes" and d["quadrics"] == "exact"
    f = qem.default_options(fast=True)
    assert f["order"] == "passes" and f["quadrics"] == "sum"
    assert f["orientation_check"] is False and f["placement"] == "solve_first"


def test_clustering_reaches_the_count_and_refuses_what_it_cannot_honour(sphere):
    v, f = sphere
    target = len(f) // 10
    cv, cf, report = qem.simplify(v, f, triangles=target, method="clustering")
    assert abs(len(cf) - target) <= 0.05 * target, (len(cf), target)
    assert report["edge_contractions"] == 0 and report["triangles_out"] == len(cf)
    assert_valid(cv, cf)
    again = qem.simplify(v, f, triangles=target, method="clustering")
    assert np.array_equal(cv, again[0]) and np.array_equal(cf, again[1])
    with pytest.raises(qem.QemError, match="preserve_topology"):
        qem.simplify(v, f, triangles=target, method="clustering", preserve_topology=True)
    with pytest.raises(ValueError):
        qem.simplify(v, f, method="grid")
    assert qem.default_options()["method"] == "contraction"


def test_stub_defaults_match_the_library():
    # The stub writes each default out for readers; they must be the library's.
    import ast
    from pathlib import Path

    stub = Path(qem.__file__).with_name("__init__.pyi")
    tree = ast.parse(stub.read_text())
    (fn,) = [n for n in tree.body if isinstance(n, ast.FunctionDef) and n.name == "simplify"]
    stub_defaults = {
        arg.arg: ast.literal_eval(default)
        for arg, default in zip(fn.args.kwonlyargs, fn.args.kw_defaults)
    }
    library = qem.default_options()
    for name, value in library.items():
        if name in ("ratio", "clean"):
            continue  # ratio=None means the library's 0.5; clean=None its defaults
        expected = tuple(value) if name == "locked_vertices" else value
        assert stub_defaults[name] == expected, name
    assert set(stub_defaults) == set(library) | {"progress", "fast", "absolute", "triangles"}


def test_triangles_target(sphere):
    _, f, report = qem.simplify(*sphere, triangles=100)
    assert len(f) <= 100 and report["target_triangles"] == 100


def test_max_error_stops_early(sphere):
    _, f, report = qem.simplify(*sphere, ratio=0.0, max_error=0.001)
    assert report["stop_reason"] == "max_error_reached"
    assert report["max_error"] <= 0.001
    assert len(f) > 10


def test_absolute_reads_max_error_in_model_units(sphere):
    vertices, faces = sphere
    # The same bound in model units on a scaled copy stops at the same place.
    _, f1, r1 = qem.simplify(vertices, faces, ratio=0.0, max_error=0.001)
    # Scaling by a power of two is exact, so the normalised meshes are the same bits.
    bound = 0.001 * r1["bbox_diagonal"] * 8
    _, f2, r2 = qem.simplify(vertices * 8, faces, ratio=0.0, max_error=bound, absolute=True)
    assert len(f1) == len(f2)
    assert r2["max_error_abs"] <= bound
    # The same number read as a fraction of the diagonal (8 * 3.46 times larger) goes
    # much further.
    _, f3, _ = qem.simplify(vertices * 8, faces, ratio=0.0, max_error=bound)
    assert len(f3) < len(f2)


def test_locked_boundary_keeps_the_border():
    vertices, faces = grid()
    v, f, report = qem.simplify(vertices, faces, ratio=0.2, boundary="locked")
    on_border = (
        (vertices[:, 0] == 0) | (vertices[:, 0] == 20) | (vertices[:, 1] == 0) | (vertices[:, 1] == 20)
    )
    border = {tuple(p) for p in vertices[on_border]}
    assert border <= {tuple(p) for p in v}
    assert report["locked_vertices"] == on_border.sum()


def test_locked_vertices_come_out_unmoved(sphere):
    vertices, faces = sphere
    locked = np.array([100, 200, 300])
    v, _, report = qem.simplify(vertices, faces, ratio=0.05, locked_vertices=locked)
    out = {tuple(p) for p in v}
    assert all(tuple(vertices[i]) in out for i in locked)
    assert report["locked_vertices"] == 3


@pytest.mark.parametrize("order", ["greedy", "passes"])
def test_preserve_topology_in_both_orders(sphere, order):
    vertices, faces = sphere
    v, f, report = qem.simplify(
        vertices, faces, ratio=0.1, order=order, preserve_topology=True
    )
    # A closed sphere stays one closed part: V - E + F = 2.
    edges = {tuple(sorted(e)) for t in f.tolist() for e in ((t[0], t[1]), (t[1], t[2]), (t[0], t[2]))}
    assert len(v) - len(edges) + len(f) == 2
    assert report["virtual_contractions"] == 0


def tetrahedra(n):
    """n separate closed tetrahedra: stuck without the ladder of relaxations."""
    corners = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float64)
    vertices = np.concatenate([corners * (1 + 0.01 * i) + [3.0 * i, 0, 0] for i in range(n)])
    one = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    faces = np.concatenate([one + 4 * i for i in range(n)])
    return vertices, faces


@pytest.mark.parametrize("order", ["greedy", "passes"])
def test_stuck_runs_climb_the_ladder_unless_strict(order):
    vertices, faces = tetrahedra(20)
    v, f, report = qem.simplify(vertices, faces, ratio=0.1, order=order)
    assert_valid(v, f)
    assert report["stop_reason"] == "target_reached"
    assert len(f) == 8
    assert report["stopped_by"] is None
    steps = [r["step"] for r in report["relaxations"]]
    assert steps == ["fold_over", "border_loops", "merged_faces"]
    assert report["relaxations"][-1]["contractions"] == 18
    v, f, report = qem.simplify(vertices, faces, ratio=0.1, order=order, strict=True)
    assert len(f) == 80
    assert report["stop_reason"] == "no_valid_pair"
    assert report["stopped_by"] == "strict"
    assert report["relaxations"] == []


def test_clean_options(sphere):
    # Without the exact weld the pole rows stay separate vertices.
    _, _, report = qem.simplify(*sphere, ratio=0.5, clean={"weld_exact": False})
    assert report["cleanup"]["welded_vertices"] == 0
    with pytest.raises(TypeError, match="clean has no key 'weld'"):
        qem.simplify(*sphere, clean={"weld": True})


@pytest.mark.parametrize(
    "options, message",
    [
        ({"ratio": 0.5, "triangles": 10}, "ratio or triangles, not both"),
        ({"ratio": 1.5}, "ratio must be between 0 and 1"),
        ({"ratio": float("nan")}, "ratio must be a finite number"),
        ({"triangles": -1}, "triangles must be ≥ 0"),
        ({"max_error": -0.1}, "max_error must be a finite number ≥ 0"),
        ({"min_triangle_quality": 2.0}, "between 0 and 1"),
        ({"quadrics": "product"}, "quadrics must be one of sum, exact"),
        ({"boundary": "sticky"}, "boundary must be one of free, locked"),
        ({"locked_vertices": [5, -1]}, "locked_vertices holds -1"),
        ({"locked_vertices": [10**9]}, "locked vertex 1000000000 is out of range"),
    ],
)
def test_bad_option_values(sphere, options, message):
    with pytest.raises(qem.QemError, match=message):
        qem.simplify(*sphere, **options)


def test_unknown_option_and_wrong_types(sphere):
    with pytest.raises(TypeError, match="unexpected keyword argument 'ratoi'"):
        qem.simplify(*sphere, ratoi=0.1)
    with pytest.raises(TypeError, match="orientation_check must be True or False"):
        qem.simplify(*sphere, orientation_check="yes")
    with pytest.raises(TypeError, match="progress must be callable"):
        qem.simplify(*sphere, progress=3)


# ----------------------------------------------------------------------------- errors


@pytest.mark.parametrize(
    "vertices, faces, message",
    [
        (np.zeros((3, 2)), [[0, 1, 2]], r"vertices must have shape \(n, 3\), not \(3, 2\)"),
        (np.zeros(9), [[0, 1, 2]], r"vertices must have shape \(n, 3\), not \(9,\)"),
        (np.eye(3, dtype=np.int32), [[0, 1, 2]], "vertices must be float32 or float64, not int32"),
        (np.eye(3), np.array([[0, 1, 2]], dtype=np.int8), "faces must be int32, int64, uint32 or uint64, not int8"),
        (np.eye(3), [[0.0, 1.0, 2.0]], "faces must be int32, int64, uint32 or uint64, not float64"),
        (np.eye(3), [[0, 1, 2, 3]], r"faces must have shape \(n, 3\), not \(1, 4\)"),
        (np.eye(3), [[0, 1, 2], [0, -1, 2]], r"faces\[1\] holds the index -1: indices must be ≥ 0"),
        (np.eye(3), [[0, 1, 3]], r"faces\[0\] refers to vertex 3, but there are only 3 vertices"),
        (np.eye(3), np.array([[0, 1, 2**40]]), r"faces\[0\] refers to vertex 1099511627776"),
        (np.eye(3), np.zeros((0, 3), dtype=np.int64), "the mesh has no triangles"),
        (np.array([[0, 0, 0], [1, 0, np.nan], [0, 1, 0]]), [[0, 1, 2]], "vertex 1 has a non-finite coordinate"),
        (np.zeros((3, 3)), [[0, 1, 2]], "all 1 triangles are degenerate"),
    ],
)
def test_bad_input_raises_qem_error(vertices, faces, message):
    with pytest.raises(qem.QemError, match=message):
        qem.simplify(vertices, faces)


def test_qem_error_is_a_value_error():
    assert issubclass(qem.QemError, ValueError)
    with pytest.raises(ValueError):
        qem.simplify(np.eye(3), [[0, 1, 5]])


# --------------------------------------------------------------------------- progress


def test_progress_is_called_with_rising_fractions():
    vertices, faces = uv_sphere(128, 64)  # enough contractions for several calls
    seen = []
    _, _, report = qem.simplify(vertices, faces, ratio=0.05, progress=seen.append)
    assert report["stop_reason"] == "target_reached"
    assert len(seen) >= 2
    assert all(0.0 <= x <= 1.0 for x in seen)
    assert seen == sorted(seen) and seen[-1] == 1.0


@pytest.mark.parametrize("fast", [False, True])
def test_progress_returning_false_cancels(fast):
    vertices, faces = uv_sphere(128, 64)
    calls = []

    def stop(fraction):
        calls.append(fraction)
        return False

    v, f, report = qem.simplify(vertices, faces, ratio=0.05, progress=stop, fast=fast)
    assert report["stop_reason"] == "cancelled"
    assert len(calls) == 1, "no call after the one that cancelled"
    assert len(f) > report["target_triangles"]
    assert_valid(v, f)


def test_progress_exception_propagates():
    vertices, faces = uv_sphere(128, 64)

    class Stop(Exception):
        pass

    def fail(fraction):
        raise Stop("from the callback")

    with pytest.raises(Stop, match="from the callback"):
        qem.simplify(vertices, faces, ratio=0.05, progress=fail)
    # KeyboardInterrupt (what Ctrl-C raises) takes the same way out.
    def interrupt(fraction):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        qem.simplify(vertices, faces, ratio=0.05, progress=interrupt)


def test_returning_none_or_true_does_not_cancel():
    vertices, faces = uv_sphere(128, 64)
    for answer in (None, True, 0):
        _, _, report = qem.simplify(vertices, faces, ratio=0.05, progress=lambda x: answer)
        assert report["stop_reason"] == "target_reached", answer


# ------------------------------------------------------------------------------ GIL


def test_the_gil_is_released_during_the_work():
    # A run long enough to see: while it works in a thread, the main thread must keep
    # running Python code.
    vertices, faces = uv_sphere(200, 100)
    assert_gil_released(lambda: qem.simplify(vertices, faces, ratio=0.05))
