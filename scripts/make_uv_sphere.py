#!/usr/bin/env python3
"""Write a closed, noisy UV sphere as OBJ, for whole-process measurements on a large input.

usage: scripts/make_uv_sphere.py N OUT.obj

N rings of N vertices between the two poles (2·N·(N−1) triangles: N = 1415 gives
4,001,620), radius 1 with a deterministic ±0.001 radial noise (seed 1), so the quadrics
are not all zero. The poles are fans of N slivers, as in many exported UV spheres.
"""
import math
import random
import sys


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    n, out = int(sys.argv[1]), sys.argv[2]
    random.seed(1)
    with open(out, "w", buffering=1 << 22) as f:
        w = f.write
        w("v 0 0 1\n")
        for i in range(1, n):
            th = math.pi * i / n
            st, ct = math.sin(th), math.cos(th)
            for j in range(n):
                ph = 2 * math.pi * j / n
                r = 1 + 0.002 * (random.random() - 0.5)
                w(f"v {r * st * math.cos(ph):.7f} {r * st * math.sin(ph):.7f} {r * ct:.7f}\n")
        w("v 0 0 -1\n")
        south = 1 + (n - 1) * n + 1

        def vid(i, j):  # OBJ index of ring i (1..n-1), column j
            return 2 + (i - 1) * n + (j % n)

        for j in range(n):
            w(f"f 1 {vid(1, j)} {vid(1, j + 1)}\n")
        for i in range(1, n - 1):
            for j in range(n):
                a, b, c, d = vid(i, j), vid(i, j + 1), vid(i + 1, j), vid(i + 1, j + 1)
                w(f"f {a} {c} {b}\nf {b} {c} {d}\n")
        for j in range(n):
            w(f"f {south} {vid(n - 1, j + 1)} {vid(n - 1, j)}\n")


if __name__ == "__main__":
    main()
