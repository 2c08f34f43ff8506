"""qem: quadric error metric mesh simplification for messy real-world meshes.

Garland and Heckbert's pair contraction (SIGGRAPH 97) on any triangle input: CAD
exports and STL soups, scans with holes and several parts, non-manifold fins,
duplicate and degenerate faces. Never a crash on bad input (a ``QemError`` instead),
always a valid mesh out, the error it made reported.

Meshes are NumPy arrays: ``vertices`` of shape (n, 3) (float32 or float64) and
``faces`` of shape (m, 3) (int32, int64, uint32 or uint64). Where a function takes a
whole mesh it accepts a ``(vertices, faces)`` pair or any object with ``.vertices`` and
``.faces`` (such as a ``trimesh.Trimesh``).

- :func:`simplify` -- simplify arrays, with every option of the Rust library; with
  ``attributes=`` (per-vertex uv, normals, colours, per-face materials) carried along.
- :func:`simplify_trimesh` -- the same for a ``trimesh.Trimesh``.
- :func:`measure` -- Metro-style distances between two meshes.
- :func:`load` / :func:`save` -- OBJ, PLY, STL and OFF files (optionally gzipped).
- :func:`default_options` -- the defaults of :func:`simplify`'s options.
- :class:`QemError` -- raised for everything qem refuses (a ``ValueError``).
- :mod:`qem.tiles` -- the tile pipeline of ``qem tiles`` (split a mesh file into tiles,
  simplify each, merge), as jobs any scheduler can run.
- :mod:`qem.distributed` -- those jobs on a Dask cluster (``simplify_file``); imports
  ``distributed``, so it is not imported here.

The type stubs (``__init__.pyi``) document every option and the ``attributes`` dict.
"""

from ._qem import (
    QemError,
    __version__,
    default_options,
    load,
    measure,
    save,
    simplify,
)

from . import tiles

__all__ = [
    "QemError",
    "__version__",
    "default_options",
    "load",
    "measure",
    "save",
    "simplify",
    "simplify_trimesh",
    "tiles",
]


def simplify_trimesh(mesh, *, progress=None, keep_attributes=True, **options):
    """Simplifies a ``trimesh.Trimesh``; returns ``(new_mesh, report)``.

    Takes the same keyword options as :func:`simplify`. The new mesh is built with
    ``process=False``, so trimesh does not merge or reorder what qem wrote; its vertices
    and faces have the input's dtypes. Needs trimesh (``pip install trimesh``), which is
    imported only when this function is called.

    With ``keep_attributes`` (the default) the mesh's texture coordinates
    (``visual.uv`` of a ``TextureVisuals``, whose material the new mesh keeps), vertex
    colours (``visual.vertex_colors`` of a ``ColorVisuals`` that has them) and vertex
    normals (when the mesh has them: loaded from the file or computed before the call,
    not computed here) are simplified with it and set on the new mesh. The new mesh is
    then split at its seams, so it can have more vertices than ``report["vertices_out"]``.
    A mesh with none of these is simplified exactly as :func:`simplify` does it.
    """
    try:
        import trimesh
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError(
            "qem.simplify_trimesh needs trimesh: pip install trimesh "
            "(or use qem.simplify on the mesh's vertices and faces arrays)"
        ) from e
    if not isinstance(mesh, trimesh.Trimesh):
        raise TypeError(
            f"simplify_trimesh takes a trimesh.Trimesh, not {type(mesh).__name__}"
        )
    # default_options() lists attributes=None; anything else has no meaning here.
    if options.pop("attributes", None) is not None:
        raise TypeError(
            "simplify_trimesh takes the attributes from the mesh; "
            "pass keep_attributes=False to leave them out"
        )
    attributes = _trimesh_attributes(mesh, trimesh) if keep_attributes else {}
    if not attributes:
        vertices, faces, report = simplify(
            mesh.vertices, mesh.faces, progress=progress, **options
        )
        return trimesh.Trimesh(vertices=vertices, faces=faces, process=False), report
    vertices, faces, out, report = simplify(
        mesh.vertices, mesh.faces, progress=progress, attributes=attributes, **options
    )
    kwargs = {}
    if "normal" in out:
        kwargs["vertex_normals"] = out["normal"]
    if "uv" in out:
        kwargs["visual"] = trimesh.visual.TextureVisuals(
            uv=out["uv"], material=getattr(mesh.visual, "material", None)
        )
    elif "colour" in out:
        import numpy as np

        rgba = np.clip(np.rint(out["colour"] * 255.0), 0, 255).astype(np.uint8)
        kwargs["vertex_colors"] = rgba
    small = trimesh.Trimesh(vertices=vertices, faces=faces, process=False, **kwargs)
    return small, report


def _trimesh_attributes(mesh, trimesh):
    """The per-vertex attributes of a trimesh that qem can carry, as simplify() takes
    them: texture coordinates, vertex colours (0-1) and normals the mesh already has."""
    import numpy as np

    attributes = {}
    visual = mesh.visual
    n = len(mesh.vertices)
    if isinstance(visual, trimesh.visual.TextureVisuals):
        uv = getattr(visual, "uv", None)
        if uv is not None and len(uv) == n:
            attributes["uv"] = np.asarray(uv, dtype=np.float64)[:, :2]
    elif getattr(visual, "kind", None) == "vertex":
        colours = np.asarray(visual.vertex_colors)
        if colours.shape[0] == n:
            attributes["colour"] = colours.astype(np.float64) / 255.0
    # Normals only when they are there (read from the file, or computed by the
    # caller): mesh.vertex_normals would otherwise compute them, and qem would weigh
    # normals the user never asked for.
    cache = getattr(mesh, "_cache", None)
    if cache is not None and "vertex_normals" in cache:
        normals = np.asarray(mesh.vertex_normals, dtype=np.float64)
        if normals.shape == (n, 3):
            attributes["normal"] = normals
    return attributes
