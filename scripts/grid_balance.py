#!/usr/bin/env python3
"""Triangle counts per cell of a regular grid over an OBJ's bounding box (each triangle in
the cell of its centroid), for comparison with the k-d cut of `qem tiles split`.

usage: scripts/grid_balance.py MESH.obj N...   (about N cells, as cubic as possible)
"""
import sys, math, collections
vs = []; fs = []
for line in open(sys.argv[1]):
    if line.startswith('v '):
        vs.append(tuple(map(float, line.split()[1:4])))
    elif line.startswith('f '):
        idx = [int(t.split('/')[0]) - 1 for t in line.split()[1:]]
        for i in range(1, len(idx) - 1):
            fs.append((idx[0], idx[i], idx[i + 1]))
lo = [min(v[k] for v in vs) for k in range(3)]; hi = [max(v[k] for v in vs) for k in range(3)]
ext = [hi[k] - lo[k] for k in range(3)]
cent = [[(vs[a][k] + vs[b][k] + vs[c][k]) / 3 for k in range(3)] for a, b, c in fs]
for n in map(int, sys.argv[2:]):
    # cells as cubic as possible, about n of them
    s = (ext[0] * ext[1] * ext[2] / n) ** (1 / 3)
    dims = [max(1, round(e / s)) for e in ext]
    cnt = collections.Counter()
    for p in cent:
        cell = tuple(min(dims[k] - 1, int((p[k] - lo[k]) / ext[k] * dims[k])) for k in range(3))
        cnt[cell] += 1
    c = sorted(cnt.values())
    print(f"n={n} grid {dims} ({dims[0]*dims[1]*dims[2]} cells): {len(c)} non-empty, min {c[0]}, max {c[-1]}, mean {len(fs)/len(c):.0f}, max/mean {c[-1]/(len(fs)/len(c)):.2f}")
