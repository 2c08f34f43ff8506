"""Type stubs of the qem package (the functions are in the Rust extension qem._qem).

Every option of :func:`simplify` is an option of the Rust library's ``SimplifyOptions``
with the same name; an option left out keeps the library's default (listed here, and
returned by :func:`default_options`).
"""

import os
from typing import Any, Callable, Literal, Mapping, Sequence, Tuple, TypedDict, Union

import numpy as np
import numpy.typing as npt

# The tile pipeline (qem tiles) and its Dask runner are Python modules, typed inline:
# qem/tiles.py (split, simplify, merge, fingerprint, and the TypedDicts of the manifest,
# a tile's status and the merge report) and qem/distributed.py (simplify_file).
from . import tiles as tiles

__version__: str

class QemError(ValueError):
    """Raised for everything qem refuses: an invalid mesh (no triangles, a non-finite
    coordinate, an index out of range, arrays of the wrong shape or dtype), options it
    cannot honour, or a file it cannot read or write. The message is qem's own and names
    the place (vertex, face, file and line)."""

Vertices = npt.NDArray[Union[np.float32, np.float64]]
"""An (n, 3) float32 or float64 array of positions (nested lists are converted)."""
Faces = npt.NDArray[Union[np.int32, np.int64, np.uint32, np.uint64]]
"""An (m, 3) array of vertex indices, each in [0, n) (nested lists are converted)."""
Mesh = Union[Tuple[Any, Any], Tuple[Any, Any, "Attributes"], Any]
"""A (vertices, faces) pair, a (vertices, faces, attributes) triple, or any object with
.vertices and .faces (trimesh.Trimesh)."""

Attributes = dict[str, Any]
"""Per-vertex attributes, as :func:`simplify` takes and returns them and
``load(path, attributes=True)`` returns them: a dict of NumPy arrays (float32 or
float64; nested lists are converted), one row per vertex.

- ``"uv"``: (n, 2) texture coordinates.
- ``"normal"``: (n, 3) normals (the simplified ones are unit length).
- ``"colour"`` or ``"color"`` (one of them): (n, 3) or (n, 4) RGB(A) floats in [0, 1]
  (divide 8-bit colours by 255).
- any other key: a generic channel of that name, (n,) or (n, k) with k from 1 to 4.
- ``"material"``: a per-face integer array (m,) (int32, int64, uint32 or uint64) of
  labels; faces with different labels are never merged across their border, and each
  output face has its input face's label.
- ``"material_names"``: a list of str, ``load`` gives it with ``"material"`` (label i is
  the material named ``material_names[i]``, -1 none) and ``save`` writes the names
  (OBJ ``usemtl``); :func:`simplify` returns it as it is.

Per vertex means each triangle corner takes its vertex's value. A seam (a UV island's
border, a hard normal edge) is two vertices at one position with different values:
qem welds them into one vertex with a value per side, keeps the seam through the
simplification, and splits the output there again.
"""

class AttributeWeights(TypedDict, total=False):
    """How much each kind of channel weighs against positions (each key optional; the
    others keep their defaults): an attribute difference of 1 costs as much as a
    distance of ``weight`` in the mesh scaled so its bounding box spans about 2. 0 leaves
    a kind out of the cost (its values still follow the vertices)."""

    uv: float
    """Texture coordinates. Default: 0.3."""
    normal: float
    """Normals. Default: 0.15."""
    colour: float
    """Colours (``color`` is accepted too). Default: 1.0."""
    generic: float
    """Every generic channel. Default: 1.0."""

class CleanOptions(TypedDict, total=False):
    """The cleaning passes run before simplification (each key optional)."""

    weld_exact: bool
    """Merge vertices with bit-identical positions. Default: True."""
    weld_tolerance: float | None
    """Merge each vertex into the earliest kept vertex within this distance (model
    units); None = off. Default: None."""
    drop_repeated_index: bool
    """Drop faces that use a vertex twice. Default: True."""
    drop_zero_area: bool
    """Drop faces whose area is at most 1e-14 of the squared bounding-box diagonal.
    Default: True."""
    drop_duplicates: bool
    """Drop faces with the same three vertices as an earlier face. Default: True."""
    drop_unreferenced: bool
    """Drop vertices no face uses. Default: True."""

class Relaxation(TypedDict):
    """A step of the ladder of relaxations that a run climbed."""

    step: Literal["fold_over", "border_loops", "merged_faces", "flipped_faces"]
    contractions: int
    """Contractions made while the step was in force."""

class Report(TypedDict):
    """What a simplification did (the keys of ``qem simplify --report``)."""

    triangles_in: int
    triangles_out: int
    vertices_in: int
    vertices_out: int
    target_triangles: int
    edge_contractions: int
    virtual_contractions: int
    virtual_pairs: int
    virtual_pairs_capped: int
    max_error: float
    """The largest contraction error (the RMS distance of the new vertex to the planes
    it accumulated) as a fraction of the input's bounding-box diagonal."""
    max_error_abs: float
    """max_error in model units."""
    bbox_diagonal: float
    stop_reason: Literal["target_reached", "max_error_reached", "no_valid_pair", "cancelled"]
    cleanup: dict[str, int]
    """welded_vertices, tolerance_welded_vertices, repeated_index_faces, zero_area_faces,
    duplicate_faces, unreferenced_vertices."""
    degenerate_faces_removed: int
    rejected: dict[str, int]
    """Contractions refused, by reason: degenerate, flip, sliver, topology, locked,
    border, merge, orientation, last_triangles, seam."""
    relaxations: list[Relaxation]
    """The steps of the ladder of relaxations the run climbed because no pair passed
    every check, in order (empty when it never got stuck)."""
    stopped_by: Literal["strict", "preserve_topology", "locks", "locked_boundary",
                        "zero_area", "last_triangles", "seams", "no_pairs"] | None
    """With stop_reason "no_valid_pair": what stopped the run; None otherwise."""
    locked_vertices: int
    faces_flipped: int
    faces_turned_back: int
    """Faces facing away from the input turned back by an edge flip after the run."""
    timings_ms: dict[str, float]
    """simplify (the whole library call), clean, setup, contract, compact."""

class Measurement(TypedDict):
    """Distances between two meshes as fractions of a's bounding-box diagonal; "ab"
    means samples on a, distances to b."""

    hausdorff: float
    hausdorff_ab: float
    hausdorff_ba: float
    mean_ab: float
    mean_ba: float
    rms_ab: float
    rms_ba: float
    samples_ab: int
    samples_ba: int
    diagonal: float
    """a's bounding-box diagonal in model units."""
    faces_facing_away: int
    """b's faces whose normal points away from a's triangle nearest to their centroid
    (Metro-style tools count them as flipped)."""
    facing_away_area: float
    """Their share of b's area (0 to 1)."""

def simplify(
    vertices: Vertices | Sequence[Sequence[float]],
    faces: Faces | Sequence[Sequence[int]],
    *,
    progress: Callable[[float], object] | None = None,
    attributes: Attributes | None = None,
    fast: bool = False,
    ratio: float | None = None,
    triangles: int | None = None,
    max_error: float | None = None,
    absolute: bool = False,
    pair_threshold: float = 0.0,
    max_virtual_pairs_per_vertex: int = 8,
    virtual_pairs: Literal["any", "between_components"] = "any",
    placement: Literal["optimal", "endpoint_or_midpoint", "solve_first"] = "optimal",
    weighting: Literal["area", "unweighted"] | float = 0.75,
    quadrics: Literal["sum", "exact"] = "exact",
    boundary: Literal["free", "locked"] | float = 10.0,
    max_normal_angle: float = 90.0,
    min_triangle_quality: float = 0.0,
    orientation_check: bool = True,
    preserve_topology: bool = False,
    locked_vertices: Sequence[int] | npt.NDArray[np.integer[Any]] = (),
    clean: CleanOptions | None = None,
    order: Literal["greedy", "passes"] = "passes",
    strict: bool = False,
    method: Literal["contraction", "clustering"] = "contraction",
    attribute_weights: AttributeWeights | None = {"uv": 0.3, "normal": 0.15, "colour": 1.0, "generic": 1.0},
) -> Union[Tuple[Vertices, Faces, Report], Tuple[Vertices, Faces, Attributes, Report]]:
    """Simplifies a triangle mesh by Garland-Heckbert pair contraction.

    Returns ``(vertices, faces, report)``: new arrays with the input's dtypes and the
    report; with ``attributes``, ``(vertices, faces, attributes, report)``. Any triangle input is accepted (non-manifold, open, unwelded, several
    parts, degenerate or duplicate faces); the output is always valid (indices in
    range, no repeated vertex in a face, no zero-area face, finite coordinates, never
    more triangles than the input), and the same input and options give the same
    output bit for bit. Reaching the target is not guaranteed: ``stop_reason`` says
    why a run stopped short. The GIL is released during the work.

    - ``attributes``: per-vertex texture coordinates, normals, colours, generic
      channels and per-face material labels (:data:`Attributes`), checked (a QemError
      naming the key and the shape it expects) and simplified with the mesh: seams and
      material borders are kept (a seam vertex only moves along its seam), the values
      at a moved vertex come from attribute quadrics, normals come out unit length and
      colours in [0, 1]. The result is then the 4-tuple, its attributes a dict with the
      same keys, dtypes and shapes, one row per output vertex; the output is split at
      its seams, so a vertex on a seam is returned once per side and ``len(vertices)``
      can exceed ``report["vertices_out"]`` (which counts it once). ``None`` (the
      default) returns the 3-tuple exactly as without it. Not with
      ``method="clustering"``, which keeps positions only (QemError).

    Options (the defaults shown are those with ``fast=False``):

    - ``progress``: called as ``progress(fraction)`` every few thousand contractions
      (fraction in [0, 1]) with the GIL held. Returning ``False`` cancels the run: the
      partial result, a valid mesh, is returned with stop_reason ``"cancelled"``. An
      exception raised in it cancels the run and propagates (so does Ctrl-C).
    - ``fast``: start from the library's ``SimplifyOptions.FAST`` instead of
      ``DEFAULT``: the pass-based order, summed quadrics, no orientation check, the
      "solve_first" placement; several times faster, a little less accurate. The other
      options then change that preset.
    - ``ratio`` / ``triangles``: the target, a fraction of the input's triangles (in
      [0, 1], rounded to the nearest count and at least 1) or a count; at most one.
      Default: ratio 0.5.
    - ``max_error``: stop before the first contraction whose error would exceed this
      distance (a fraction of the bounding-box diagonal, or model units with
      ``absolute``); None = no bound.
    - ``absolute``: read ``max_error`` and ``pair_threshold`` in model units.
    - ``pair_threshold``: unconnected vertex pairs closer than this are candidates too
      (virtual pairs), so separate parts can merge; 0 = edges only.
    - ``max_virtual_pairs_per_vertex``: the nearest this many virtual pairs per vertex.
    - ``virtual_pairs``: ``"any"`` close pair, or only ``"between_components"``.
    - ``placement``: where the new vertex goes: ``"optimal"`` (the quadric's minimum with
      Garland-Heckbert's fallback chain), ``"endpoint_or_midpoint"``, ``"solve_first"``.
    - ``weighting``: face planes weighted by ``"area"``, ``"unweighted"``, or a number s:
      area + s times the mean face area.
    - ``quadrics``: ``"sum"`` (Garland-Heckbert's Q_a + Q_b) or ``"exact"`` (the union of
      the plane sets: every plane counts once).
    - ``boundary``: a number w (border constraint planes of weight w, default 10; seams
      get planes of weight 1 when w is above 0; 0 lets borders move,
      though border loops are never pinched or closed unless the run is stuck, see
      ``strict``), ``"free"`` (no planes, no
      loop rule) or ``"locked"`` (border vertices never move).
    - ``max_normal_angle``: refuse a contraction that turns a surviving face's normal by
      more than this many degrees; 180 turns the check off.
    - ``min_triangle_quality``: refuse new slivers below this quality (0 to 1; 0 = off).
    - ``orientation_check``: refuse a contraction that leaves a face facing away from the
      input surface nearest to it.
    - ``preserve_topology``: keep the Euler characteristic, parts and border loops.
    - ``locked_vertices``: input vertex indices that must come out unmoved and present.
    - ``clean``: the cleaning passes (:class:`CleanOptions`); keys left out keep their
      defaults.
    - ``order``: ``"greedy"`` (cheapest pair first) or ``"passes"`` (batches of the
      cheapest pairs that share no vertex); every other option works in both.
    - ``strict``: stop when no pair passes every check, instead of climbing the ladder
      of relaxations (the fold-over rules, then the border-loop rule, then merged
      faces, each only when the stricter rules have nothing left; the report's
      ``relaxations`` lists the steps climbed and ``stopped_by`` what stopped a run
      with stop_reason ``"no_valid_pair"``). Options you set yourself
      (``preserve_topology``, ``locked_vertices``, ``boundary="locked"``,
      ``max_error``) are never relaxed.
    - ``method``: ``"contraction"`` (pair contraction, what every option above
      describes) or ``"clustering"`` (vertex clustering on a grid, ``qem simplify
      --cluster``: many times faster, near the count on any input, no topology kept;
      only the target applies, and ``preserve_topology``, ``locked_vertices``,
      ``boundary="locked"`` and ``max_error`` are refused with QemError).
    - ``attribute_weights``: how much each kind of attribute weighs against positions
      (:class:`AttributeWeights`; kinds left out keep their defaults, an unknown key is
      a QemError); no effect without ``attributes``.

    Raises QemError (a ValueError) when the input or the options are refused, with
    qem's message; TypeError for an argument of the wrong kind or an unknown option.
    """

def simplify_trimesh(
    mesh: Any,
    *,
    progress: Callable[[float], object] | None = None,
    keep_attributes: bool = True,
    **options: Any,
) -> Tuple[Any, Report]:
    """Simplifies a ``trimesh.Trimesh`` with :func:`simplify`'s options; returns
    ``(new_trimesh, report)``. The new mesh is built with ``process=False``. Needs
    trimesh, imported only when called.

    With ``keep_attributes`` (the default) the texture coordinates (``visual.uv`` of a
    ``TextureVisuals``, whose material is kept), vertex colours and vertex normals (only
    when the mesh already has them: read from its file or computed before the call) are
    simplified along and set on the new mesh, which is then split at its seams (it can
    have more vertices than ``report["vertices_out"]``). A mesh without any of them
    gives what :func:`simplify` gives."""

def default_options(fast: bool = False) -> dict[str, Any]:
    """The options :func:`simplify` uses when none is given (with ``fast=True``: its
    ``fast=True`` preset) as a dict of its keyword arguments; passing it back as
    ``**options`` changes nothing. Read from the library, so always current. It lists
    ``attributes`` too, as None (no attributes, the 3-tuple), and ``attribute_weights``
    with every kind's weight."""

def measure(
    a: Mesh,
    b: Mesh,
    *,
    samples_per_face: float = 10.0,
    min_samples: int = 1_000_000,
    max_samples: int | None = None,
    seed: int = 0,
) -> Measurement:
    """How far two meshes are apart, Metro-style (as ``qem measure``): every vertex,
    ``samples_per_face`` area-uniform points per triangle (at least ``min_samples``, at
    most ``max_samples``) and points along border edges are sampled on each mesh, and
    each sample's exact distance to the other surface is found. The same seed gives the
    same figures to the bit whatever the number of cores. The GIL is released during
    the work. Raises QemError when a mesh is invalid or a's extent is zero."""

def load(
    path: str | os.PathLike[str], *, attributes: bool = False
) -> Union[
    Tuple[npt.NDArray[np.float64], npt.NDArray[np.uint32]],
    Tuple[npt.NDArray[np.float64], npt.NDArray[np.uint32], Attributes],
]:
    """Reads an .obj .ply .stl or .off file (optionally .gz): ``(vertices, faces)`` as
    float64 (n, 3) and uint32 (m, 3) arrays, polygons split into triangles. Raises
    QemError naming the file and the place when it cannot be read or is malformed.

    With ``attributes=True``: ``(vertices, faces, attributes)``, the file's texture
    coordinates, normals, colours and other channels per vertex (:data:`Attributes`,
    float32 (n, k) arrays under the channels' names: ``"uv"``, ``"normal"``,
    ``"colour"``, a PLY property's name) and its materials (``"material"``, int32 per
    face, -1 for none, with ``"material_names"``). The mesh is split at its seams for
    this: a vertex with a different texture coordinate (or normal) in different faces
    comes out once per value, so ``vertices`` can be longer than without attributes.
    OBJ groups and material libraries are not returned."""

def save(path: str | os.PathLike[str], mesh: Mesh) -> None:
    """Writes a mesh in the format its name gives (.obj .ply .stl .off, gzipped with
    .gz), atomically: on any error the file keeps its old content. Raises QemError.

    ``mesh`` may be a ``(vertices, faces, attributes)`` triple: the channels are written
    where the format holds them (OBJ ``vt``/``vn``, PLY vertex properties, OFF colours)
    and the materials as OBJ ``usemtl`` (named by ``"material_names"`` when given, else
    by their labels); what the format cannot hold is left out with a ``UserWarning``
    naming it. A trimesh's visuals are not written (only its vertices and faces)."""

__all__: list[str]
