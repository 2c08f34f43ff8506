"""The tile pipeline of ``qem tiles`` as Python calls: a mesh file cut into spatial tiles
in a directory, each tile simplified on its own with its border locked, the tiles
merged back. Each step is a job any scheduler can run, in any process that sees the
directory; :mod:`qem.distributed` runs them on Dask.

These are the same library calls as ``qem tiles split | simplify | merge``, so a
directory written here is the command's, byte for byte, and either can carry on the
other's work. In the directory:

- ``tiles.json``, the manifest (what :func:`split` returns), with a ``split_id``;
- ``tile-NNNNN.ply``, each tile (binary PLY, its border vertices first);
- ``tile-NNNNN.simplified.ply``, ``tile-NNNNN.quadrics`` and ``tile-NNNNN.done.json``,
  each simplified tile, its vertices' quadrics and its status (what :func:`simplify`
  returns), written atomically, the status last.

A tile is **done** when its status names this split, this tile's file, the same options
(a :func:`fingerprint`) and qem version, and a simplified file and quadrics of the
recorded sizes and CRC-32s; anything else (a job killed before its status, a file cut short or changed,
other options) is simplified again, to the same bytes. So a job is idempotent: run
twice, retried by a scheduler, or run twice at once, it leaves the same files. Each tile
job writes only its own tile's files, and removes only the leftovers of its own tile's
killed writers. (Two jobs of one tile at once on two machines still leave the same
files, but one of them may fail: the other can take its unfinished temporary file,
whose writer no process table on that machine lists, for a killed writer's.)

Every call releases the GIL while qem works. Errors are :class:`qem.QemError` naming the
file, and say which call fixes them (``qem.tiles.simplify(directory, tile=3, ...)``).
Tiles carry positions only: an input's attributes are left out, with a
``UserWarning``.

Example::

    import qem
    manifest = qem.tiles.split("scan.ply", "scan-tiles", tile_triangles=2_000_000)
    for k in range(len(manifest["tiles"])):  # or one job per tile, anywhere
        qem.tiles.simplify("scan-tiles", tile=k, ratio=0.1)
    report = qem.tiles.merge("scan-tiles", "scan-10.ply")
"""

from __future__ import annotations

import os
from typing import Any, List, Optional, TypedDict, Union, overload

from ._qem import tiles_fingerprint, tiles_merge, tiles_simplify, tiles_split

__all__ = ["split", "simplify", "merge", "fingerprint"]

PathLike = Union[str, "os.PathLike[str]"]


class Stamp(TypedDict):
    """A file's size in bytes and the CRC-32 of its bytes."""

    size: int
    crc32: int


class InputInfo(TypedDict):
    """The input of a split (``manifest["input"]``)."""

    name: str
    """The input's file name (not its path)."""
    size_bytes: int
    vertices: int
    triangles: int
    welded_vertices: int
    """Vertices merged into another with a bit-identical position before the cut."""
    attributes_dropped: bool
    """Whether the input had attributes, which the tiles do not carry."""


class Partition(TypedDict):
    """How the input was cut (``manifest["partition"]``)."""

    method: str
    """``"kd-median"``: halves at the median triangle centroid along the axis of their
    largest spread."""
    tiles_requested: int
    bbox_min: List[float]
    bbox_max: List[float]


class TileEntry(TypedDict):
    """One tile, as the manifest lists it."""

    index: int
    file: str
    triangles: int
    vertices: int
    border_vertices: int
    """The tile's first ``border_vertices`` vertices are used by other tiles too."""
    centroid_min: List[float]
    centroid_max: List[float]
    stamp: Stamp


class Manifest(TypedDict):
    """``tiles.json``: what :func:`split` wrote."""

    qem_tiles: int
    """The format version (2)."""
    split_id: str
    """A CRC-32 of the rest of the manifest: which split a status belongs to."""
    input: InputInfo
    partition: Partition
    tiles: List[TileEntry]


class TileStatus(TypedDict):
    """``tile-NNNNN.done.json``, plus ``already_done``."""

    qem_tiles_status: int
    split_id: str
    tile: int
    input_stamp: Stamp
    options: str
    """The :func:`fingerprint` of the options the tile was simplified with."""
    output: str
    """The simplified tile's file name."""
    output_stamp: Stamp
    quadrics_stamp: Stamp
    """The size and CRC-32 of ``tile-NNNNN.quadrics``."""
    border_vertices: int
    triangles_in: int
    triangles_out: int
    stop_reason: str
    """Why the simplification stopped (``"target_reached"``, ``"no_valid_pair"``, ...)."""
    already_done: bool
    """True when the tile was done already with these options and was left as it was
    (not in the file)."""


class MergeReport(TypedDict):
    """What :func:`merge` did."""

    split_id: str
    options: str
    """The :func:`fingerprint` of the options every tile was simplified with."""
    tiles: int
    triangles_in: int
    """The tiles' triangles before simplification."""
    triangles_out: int
    vertices_out: int


def split(
    input: PathLike,
    directory: PathLike,
    *,
    tile_triangles: Optional[int] = None,
    tiles: Optional[int] = None,
) -> Manifest:
    """Cuts the mesh file ``input`` (any format :func:`qem.load` reads) into spatial
    tiles in ``directory`` (created if missing), and returns the manifest. The file is
    streamed to a temporary directory inside ``directory`` as it is read (PLY, OFF, STL
    and OBJ without holding their triangles; glTF is read whole first).

    ``tile_triangles``: at most this many triangles per tile (default 1,000,000: a
    tile's simplification then takes about 200 MB); or ``tiles``: this many tiles, of
    equal triangle counts within one (within a fraction of a percent past 2^20
    triangles, where the cut is made from a sample of the centroids). Vertices with bit-identical positions are merged
    first (so an STL soup's tiles find their shared vertices), and the triangles are cut
    by a k-d bisection of their centroids. The same input gives the same files, bit for
    bit. An earlier split in ``directory`` is replaced; its done tiles stay done when
    the new split is the same.
    """
    return tiles_split(input, directory, tile_triangles=tile_triangles, tiles=tiles)


@overload
def simplify(directory: PathLike, tile: int, **options: Any) -> TileStatus: ...
@overload
def simplify(
    directory: PathLike, tile: None = None, **options: Any
) -> List[TileStatus]: ...
def simplify(directory, tile=None, **options):
    """Simplifies tile ``tile`` of the split in ``directory`` (or, without ``tile``,
    every tile, in order), each with its border vertices and their neighbours locked so
    that the tiles still meet edge for edge. A tile already done with these options is
    left as it is. Returns the tile's status (a dict, the keys of its ``done.json`` and
    ``already_done``), or without ``tile`` the list of every tile's.

    ``options`` are those of :func:`qem.simplify` (``ratio`` applies to each tile;
    default 0.5), except ``triangles``, ``locked_vertices``,
    ``method="clustering"`` and a ``pair_threshold`` above 0, which the tiles cannot
    keep (a ``QemError``). A tile whose locked vertices leave little room for its target
    gets a ``UserWarning`` (split into fewer, larger tiles, or use a higher ratio).

    Idempotent: a task that runs this twice, or twice at once, leaves the same bytes.
    This is the function :func:`qem.distributed.simplify_file` maps over the tiles.
    """
    return tiles_simplify(directory, tile, **options)


def merge(directory: PathLike, output: PathLike) -> MergeReport:
    """Joins the simplified tiles of ``directory`` into one mesh, merging the border
    vertices the tiles share, and writes it to ``output`` (atomically; the format from
    its extension). Every tile must be simplified, all with the same options, and its
    simplified file unchanged since: a tile that is not raises a ``QemError`` naming the
    file and the call that fixes it (its quadrics file is not needed here).
    Returns the merge report.
    """
    return tiles_merge(directory, output)


def fingerprint(**options: Any) -> str:
    """The fingerprint a tile's status records for ``options`` (those of
    :func:`simplify`) with this version of qem: 8 hex digits. Raises as
    :func:`simplify` does for options the tiles do not take, so it also checks options
    before any work."""
    return tiles_fingerprint(**options)
