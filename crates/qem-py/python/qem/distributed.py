"""The tile pipeline (:mod:`qem.tiles`) on a ``dask.distributed`` cluster: one task splits
the mesh file into tiles, one task per tile simplifies it, one task merges them. The
output is the same file, bit for bit, as ``qem tiles split | simplify | merge`` (or the
:mod:`qem.tiles` calls in turn) with the same options.

Needs ``distributed`` (``pip install distributed``), which only this module imports, and
only when :func:`simplify_file` runs: ``import qem`` works without Dask.

Every task reads and writes files, so the workers must see the input, the output and
the tile directory under the same paths (made absolute on the client): on one machine
(a ``LocalCluster``) they do; on a cluster, put them on a shared file system. The tasks are idempotent (each tile's
writes the same bytes however often it runs, and a tile already done is skipped), so
Dask may retry them or run one twice; and they release the GIL while qem works, so a
worker's threads simplify tiles in parallel.
"""

from __future__ import annotations

import functools
import os
import shutil
import tempfile
from typing import Any, Optional

from . import tiles as _tiles

__all__ = ["simplify_file"]


def simplify_file(
    input: _tiles.PathLike,
    output: _tiles.PathLike,
    *,
    ratio: Optional[float] = None,
    client: Any = None,
    directory: Optional[_tiles.PathLike] = None,
    tile_triangles: Optional[int] = None,
    tiles: Optional[int] = None,
    **options: Any,
) -> _tiles.MergeReport:
    """Simplifies the mesh file ``input`` into ``output`` on a Dask cluster, as tiles:
    :func:`qem.tiles.split` as one task, :func:`qem.tiles.simplify` as one task per
    tile (``client.map``), :func:`qem.tiles.merge` as one task. Returns the merge report
    (a dict: ``tiles``, ``triangles_in``, ``triangles_out``, ``vertices_out``,
    ``split_id``, ``options``).

    ``ratio`` applies to each tile (default: the library's, 0.5); ``options`` are the
    other options of :func:`qem.tiles.simplify`, checked before any task runs.
    ``client`` is a ``distributed.Client`` (default: the current one,
    ``distributed.get_client()``). ``tile_triangles`` or ``tiles`` say how finely to
    split (default: at most 1,000,000 triangles a tile). ``directory`` holds the tiles
    (default: a temporary directory beside ``output``, removed at the end, whether the
    run succeeds or not); given, it is kept, and a run again on it skips the tiles
    already done with the same options, so a run stopped half way carries on.

    A task's error (a ``qem.QemError`` naming the file) is raised here, the tasks still
    pending cancelled. Tiles carry positions only (the input's attributes are left out).
    """
    import distributed  # Only here: qem itself does not need Dask.

    if ratio is not None:
        options["ratio"] = ratio
    # Refused options are found now, not by every tile's task after the split.
    _tiles.fingerprint(**options)
    if client is None:
        client = distributed.get_client()
    # Absolute, so a worker started in another directory finds the same files.
    input, output = os.path.abspath(input), os.path.abspath(output)
    temporary = directory is None
    if directory is None:
        directory = tempfile.mkdtemp(prefix=".qem-tiles-", dir=os.path.dirname(output))
    directory = os.path.abspath(directory)
    futures = []
    try:
        # pure=False throughout: the tasks' effects are files, so two calls with the
        # same arguments must both run, not share a result Dask kept from the first.
        split = client.submit(
            _tiles.split,
            input,
            directory,
            tile_triangles=tile_triangles,
            tiles=tiles,
            pure=False,
        )
        futures.append(split)
        manifest = split.result()
        count = len(manifest["tiles"])
        job = functools.partial(_tiles.simplify, **options)
        futures = client.map(job, [directory] * count, range(count), pure=False)
        client.gather(futures)
        merge = client.submit(_tiles.merge, directory, output, pure=False)
        futures = [merge]
        return merge.result()
    finally:
        # Nothing left running in a directory about to be removed (after success,
        # there is nothing to cancel).
        client.cancel(futures)
        if temporary:
            shutil.rmtree(directory, ignore_errors=True)
