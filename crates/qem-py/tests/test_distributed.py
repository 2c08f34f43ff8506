"""qem.distributed: the tile jobs on a Dask LocalCluster of two worker processes give the
file `qem tiles split | simplify | merge` gives, bit for bit.

`distributed` is pinned in requirements-ci.txt; it is imported plainly, so without it
this module fails to import (and CI fails) rather than skipping.
"""

import time

import distributed
import pytest

import qem
import qem.distributed
from conftest import SPOT, files, run_qem

# 5,856 triangles at most 1,200 a tile: 5 tiles.
TILE_TRIANGLES = 1200
RATIO = 0.5


@pytest.fixture(scope="module")
def client():
    """Two single-threaded worker processes, started once for the module."""
    with distributed.LocalCluster(
        n_workers=2,
        threads_per_worker=1,
        processes=True,
        dashboard_address=":0",
    ) as cluster, distributed.Client(cluster) as client:
        yield client


@pytest.fixture(scope="module")
def cli_run(tmp_path_factory):
    """The single-machine run: `qem tiles` with the same options; its directory and
    output."""
    base = tmp_path_factory.mktemp("cli")
    d, out = base / "tiles", base / "spot.ply"
    run_qem("tiles", "split", SPOT, d, "--tile-triangles", TILE_TRIANGLES, "-q")
    run_qem("tiles", "simplify", d, "--ratio", RATIO, "-q")
    run_qem("tiles", "merge", d, "-o", out, "-q")
    return d, out


def test_the_dask_run_is_the_cli_run_bit_for_bit(client, cli_run, tmp_path):
    cli_dir, cli_out = cli_run
    d, out = tmp_path / "tiles", tmp_path / "spot.ply"
    start = time.perf_counter()
    with distributed.get_task_stream(client) as stream:
        report = qem.distributed.simplify_file(
            SPOT, out, ratio=RATIO, client=client, directory=d,
            tile_triangles=TILE_TRIANGLES,
        )
    seconds = time.perf_counter() - start
    assert out.read_bytes() == cli_out.read_bytes()
    # Every file of the tile directory too: manifest, tiles, simplified tiles, statuses.
    assert files(d) == files(cli_dir)
    assert report["tiles"] == 5 and report["triangles_in"] == 5856
    assert report["options"] == qem.tiles.fingerprint(ratio=RATIO)
    # One task per tile, spread over both worker processes.
    tile_tasks = [t for t in stream.data if t["key"].startswith("simplify-")]
    assert len(tile_tasks) == 5
    assert len({t["worker"] for t in tile_tasks}) == 2
    print(f"simplify_file on the LocalCluster: {seconds:.2f} s")


def test_a_temporary_directory_is_removed(client, cli_run, tmp_path):
    _, cli_out = cli_run
    out = tmp_path / "spot.ply"
    qem.distributed.simplify_file(
        SPOT, out, ratio=RATIO, client=client, tile_triangles=TILE_TRIANGLES
    )
    assert out.read_bytes() == cli_out.read_bytes()
    assert [p.name for p in tmp_path.iterdir()] == ["spot.ply"]


def test_a_task_run_twice_gives_the_same_bytes(client, cli_run, tmp_path):
    cli_dir, _ = cli_run
    d = tmp_path / "tiles"
    # The split as the command left it, tile 3 never simplified (a task lost before it
    # wrote its status).
    run_qem("tiles", "split", SPOT, d, "--tile-triangles", TILE_TRIANGLES, "-q")
    run_qem("tiles", "simplify", d, "--ratio", RATIO, "-q")
    (d / "tile-00003.done.json").unlink()
    (d / "tile-00003.simplified.ply").unlink()
    # The same tile on both workers at once, as a retry racing a slow first attempt.
    workers = sorted(client.scheduler_info()["workers"])
    futures = [
        client.submit(qem.tiles.simplify, d, 3, ratio=RATIO, workers=[w], pure=False)
        for w in workers
    ]
    first = client.gather(futures)
    assert [s["tile"] for s in first] == [3, 3]
    assert files(d) == files(cli_dir)
    # Once more: done already, nothing rewritten.
    again = client.submit(qem.tiles.simplify, d, 3, ratio=RATIO, pure=False).result()
    assert again["already_done"]
    assert again == {**first[0], "already_done": True}
    assert files(d) == files(cli_dir)


def test_a_bad_input_raises_qem_error_naming_the_file(client, tmp_path):
    missing = tmp_path / "no-such-mesh.obj"
    with pytest.raises(qem.QemError, match="no-such-mesh.obj: cannot read"):
        qem.distributed.simplify_file(missing, tmp_path / "out.ply", ratio=RATIO,
                                      client=client)
    # Its temporary tile directory went with it, and nothing was written.
    assert list(tmp_path.iterdir()) == []


def test_refused_options_raise_before_any_task(client, tmp_path):
    with pytest.raises(qem.QemError, match="does not take triangles"):
        qem.distributed.simplify_file(SPOT, tmp_path / "out.ply", triangles=1000,
                                      client=client)
    assert list(tmp_path.iterdir()) == []
