"""qem: quadric error metric mesh simplification for messy real-world meshes.

Garland and Heckbert's pair contraction (SIGGRAPH 97) on any triangle input: CAD
exports and STL soups, scans with holes and several parts, non-manifold fins,
duplicate and degenerate faces. Never a crash on bad input (a ``QemError`` instead),
always a valid mesh out, the error it made reported.

Meshes are NumPy arrays: ``vertices`` of shape (n, 3) (float32 or float64) and
``faces`` of shape (m, 3) (int32, int64, uint32 or uint64). Where a function takes a
whole mesh it accepts a ``(vertices, faces)`` pair or any object with ``.vertices`` and
``.faces`` (such as a ``trimesh.Trimesh``).

- :func:`simplify` -- simplify arrays, with every option of the Rust library.
- :func:`simplify_trimesh` -- the same for a ``trimesh.Trimesh``.
- :func:`measure` -- Metro-style distances between two meshes.
- :func:`load` / :func:`save` -- OBJ, PLY, STL and OFF files (optionally gzipped).
- :func:`default_options` -- the defaults of :func:`simplify`'s options.
- :class:`QemError` -- raised for everything qem refuses (a ``ValueError``).

The type stubs (``__init__.pyi``) document every option.
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

__all__ = [
    "QemError",
    "__version__",
    "default_options",
    "load",
    "measure",
    "save",
    "simplify",
    "simplify_trimesh",
]


def simplify_trimesh(mesh, *, progress=None, **options):
    """Simplifies a ``trimesh.Trimesh``; returns ``(new_mesh, report)``.

    Takes the same keyword options as :func:`simplify`. The new mesh is built with
    ``process=False``, so trimesh does not merge or reorder what qem wrote; its vertices
    and faces have the input's dtypes. Needs trimesh (``pip install trimesh``), which is
    imported only when this function is called.
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
    vertices, faces, report = simplify(
        mesh.vertices, mesh.faces, progress=progress, **options
    )
    return trimesh.Trimesh(vertices=vertices, faces=faces, process=False), report
