#!/usr/bin/env python3
"""Convert a triangle OBJ to OFF, ASCII PLY and ASCII STL, for the text readers' figures.

usage: scripts/obj_to_text.py IN.obj OUT_PREFIX

Writes OUT_PREFIX.off, OUT_PREFIX_ascii.ply (`float x y z`, `list uchar int
vertex_indices`) and OUT_PREFIX_ascii.stl (three vertices per facet, normal 0 0 0).
Coordinates are copied as the OBJ writes them (so the same digits in every format);
only `v` and triangular `f` lines (`f a b c`, `a/..` forms too) are read. BENCHMARKS.md
"Loading": `scripts/make_uv_sphere.py 1415 /tmp/sphere4m.obj`, then this with
`/tmp/sphere4m`, then `gzip -6 -k` of each.
"""
import sys


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    src, out = sys.argv[1], sys.argv[2]
    verts, faces = [], []
    with open(src) as f:
        for line in f:
            if line.startswith("v "):
                verts.append(" ".join(line.split()[1:4]))
            elif line.startswith("f "):
                idx = [int(w.split("/")[0]) - 1 for w in line.split()[1:]]
                if len(idx) != 3:
                    sys.exit(f"not a triangle: {line.strip()}")
                faces.append(idx)
    with open(out + ".off", "w") as f:
        f.write(f"OFF\n{len(verts)} {len(faces)} 0\n")
        f.writelines(v + "\n" for v in verts)
        f.writelines(f"3 {a} {b} {c}\n" for a, b, c in faces)
    with open(out + "_ascii.ply", "w") as f:
        f.write(
            "ply\nformat ascii 1.0\n"
            f"element vertex {len(verts)}\nproperty float x\nproperty float y\nproperty float z\n"
            f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n"
        )
        f.writelines(v + "\n" for v in verts)
        f.writelines(f"3 {a} {b} {c}\n" for a, b, c in faces)
    with open(out + "_ascii.stl", "w") as f:
        f.write("solid sphere\n")
        for a, b, c in faces:
            f.write(
                " facet normal 0 0 0\n  outer loop\n"
                f"   vertex {verts[a]}\n   vertex {verts[b]}\n   vertex {verts[c]}\n"
                "  endloop\n endfacet\n"
            )
        f.write("endsolid sphere\n")


if __name__ == "__main__":
    main()
