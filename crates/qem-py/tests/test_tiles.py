"""qem.tiles: the tile pipeline of `qem tiles` from Python, in one process. The files are
the command's, byte for byte; jobs are idempotent; errors name the file and the call
that fixes them."""

import json
import os
import subprocess
import sys

import pytest

import qem
from conftest import REPO, SPOT, assert_gil_released, files, run_qem, uv_sphere


def split_spot(directory):
    with pytest.warns(UserWarning, match="tiles carry positions only"):
        return qem.tiles.split(SPOT, directory, tiles=5)


def test_the_files_are_the_commands_byte_for_byte(tmp_path):
    py, cli = tmp_path / "py", tmp_path / "cli"
    manifest = split_spot(py)
    assert len(manifest["tiles"]) == 5 and manifest["input"]["triangles"] == 5856
    assert manifest["input"]["name"] == "spot.obj"
    statuses = qem.tiles.simplify(py, ratio=0.5)
    assert [s["tile"] for s in statuses] == [0, 1, 2, 3, 4]
    assert not any(s["already_done"] for s in statuses)
    assert all(s["split_id"] == manifest["split_id"] for s in statuses)
    report = qem.tiles.merge(py, tmp_path / "py.ply")
    assert report["tiles"] == 5 and report["triangles_in"] == 5856
    assert report["options"] == qem.tiles.fingerprint(ratio=0.5)

    run_qem("tiles", "split", SPOT, cli, "--tiles", "5", "-q")
    run_qem("tiles", "simplify", cli, "--ratio", "0.5", "-q")
    run_qem("tiles", "merge", cli, "-o", tmp_path / "cli.ply", "-q")
    assert files(py) == files(cli)
    assert (tmp_path / "py.ply").read_bytes() == (tmp_path / "cli.ply").read_bytes()
    # What the functions return is what the files say.
    assert json.loads((py / "tiles.json").read_text()) == manifest
    status = json.loads((py / "tile-00003.done.json").read_text())
    assert {**status, "already_done": False} == statuses[3]


def test_a_job_run_again_leaves_the_same_bytes(tmp_path):
    d = tmp_path / "t"
    split_spot(d)
    qem.tiles.simplify(d, ratio=0.5)
    done = files(d)
    again = qem.tiles.simplify(d, tile=2, ratio=0.5)
    assert again["already_done"] and again["tile"] == 2
    assert files(d) == done
    # A job killed after its tile, before its status: redone, to the same bytes.
    (d / "tile-00002.done.json").unlink()
    redone = qem.tiles.simplify(d, tile=2, ratio=0.5)
    assert not redone["already_done"]
    assert files(d) == done
    # A simplified file cut short: not done, redone.
    path = d / "tile-00004.simplified.ply"
    path.write_bytes(path.read_bytes()[:100])
    assert [s["already_done"] for s in qem.tiles.simplify(d, ratio=0.5)] == [
        True, True, True, True, False
    ]
    assert files(d) == done
    # Other options are other work.
    assert not qem.tiles.simplify(d, tile=0, ratio=0.6)["already_done"]
    # The same split again keeps the tiles done with the same options.
    split_spot(d)
    assert qem.tiles.simplify(d, tile=1, ratio=0.5)["already_done"]


def test_errors_name_the_file_and_the_call_that_fixes_it(tmp_path):
    with pytest.raises(qem.QemError, match="no-such-mesh.obj: cannot read"):
        qem.tiles.split(tmp_path / "no-such-mesh.obj", tmp_path / "t")
    with pytest.raises(qem.QemError, match=r"missing: .*qem\.tiles\.split\(input, "):
        qem.tiles.simplify(tmp_path / "t", ratio=0.5)
    d = tmp_path / "spot"
    split_spot(d)
    with pytest.raises(qem.QemError, match=r"tile-00000\.done\.json: missing: .*"
                       r"qem\.tiles\.simplify\(.*, tile=0, \.\.\.\)"):
        qem.tiles.merge(d, tmp_path / "m.ply")
    with pytest.raises(qem.QemError, match="tiles.json: there is no tile 5"):
        qem.tiles.simplify(d, tile=5)
    with pytest.raises(qem.QemError, match="m.xyz: unsupported file extension"):
        qem.tiles.merge(d, tmp_path / "m.xyz")
    for options, name in [
        ({"triangles": 100}, "triangles"),
        ({"locked_vertices": [1, 2]}, "locked_vertices"),
        ({"method": "clustering"}, "method='clustering'"),
        ({"pair_threshold": 0.01}, "pair_threshold"),
    ]:
        with pytest.raises(qem.QemError, match=f"does not take {name}"):
            qem.tiles.simplify(d, tile=0, **options)
        with pytest.raises(qem.QemError, match=f"does not take {name}"):
            qem.tiles.fingerprint(**options)
    with pytest.raises(TypeError, match="unexpected keyword argument 'ratoi'"):
        qem.tiles.simplify(d, ratoi=0.5)
    with pytest.raises(qem.QemError, match="give tile_triangles or tiles, not both"):
        qem.tiles.split(SPOT, d, tiles=2, tile_triangles=100)
    with pytest.raises(qem.QemError, match="tile_triangles must be a whole number above 0"):
        qem.tiles.split(SPOT, d, tile_triangles=0)
    assert not (tmp_path / "m.ply").exists()


def test_a_crowded_tile_is_warned_of(tmp_path):
    d = tmp_path / "t"
    split_spot(d)
    with pytest.warns(UserWarning, match="tile 0: its .* locked vertices"):
        qem.tiles.simplify(d, tile=0, ratio=0.05)


def test_import_qem_does_not_import_dask():
    code = (
        "import sys, qem, qem.tiles; "
        "assert not {'dask', 'distributed'} & set(sys.modules), sorted(sys.modules)"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=REPO, env={**os.environ, "PYTHONWARNINGS": "ignore"})
    assert done.returncode == 0, done.stderr


def test_the_gil_is_released_during_a_tile_job(tmp_path):
    # As for qem.simplify: while a tile job works in a thread, the main thread keeps
    # running Python code (so a Dask worker's threads run tiles in parallel).
    qem.save(tmp_path / "sphere.ply", uv_sphere(200, 100))
    d = tmp_path / "t"
    qem.tiles.split(tmp_path / "sphere.ply", d, tiles=1)
    assert_gil_released(lambda: qem.tiles.simplify(d, tile=0, ratio=0.05))
