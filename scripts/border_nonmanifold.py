#!/usr/bin/env python3
"""Non-manifold edges (three or more faces) of a `qem tiles merge` output (binary PLY as
qem writes it), and how many of them join two tile-border vertices, which would mean
that the two sides of a border overlap.

usage: scripts/border_nonmanifold.py MERGED.ply TILE_DIR
"""
import struct, sys, json, collections
def read_ply(path):
    b = open(path, 'rb').read()
    h = b.index(b'end_header\n') + len(b'end_header\n')
    head = b[:h].decode()
    nv = int(head.split('element vertex ')[1].split()[0]); nf = int(head.split('element face ')[1].split()[0])
    pos = [struct.unpack_from('<3d', b, h + 24*i) for i in range(nv)]
    o = h + 24*nv; faces = []
    for i in range(nf):
        faces.append(struct.unpack_from('<3i', b, o + 1)); o += 13
    return pos, faces
pos, faces = read_ply(sys.argv[1])
# border positions of all tiles (from the simplified tiles with their statuses)
d = sys.argv[2]; m = json.load(open(d + '/tiles.json')); border = set()
for t in m['tiles']:
    s = json.load(open(d + '/tile-%05d.done.json' % t['index']))
    p, _ = read_ply(d + '/tile-%05d.simplified.ply' % t['index'])
    border.update(p[:s['border_vertices']])
e = collections.Counter()
for f in faces:
    for i in range(3):
        a, c = f[i], f[(i+1)%3]; e[(min(a,c), max(a,c))] += 1
nm = [k for k, v in e.items() if v > 2]
both = sum(1 for a, c in nm if pos[a] in border and pos[c] in border)
one = sum(1 for a, c in nm if (pos[a] in border) != (pos[c] in border))
print(f"{len(nm)} non-manifold edges: {both} between two border vertices, {one} with one")
