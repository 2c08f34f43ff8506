#!/usr/bin/env python3
"""Write a checker texture as PNG: the shipped cow's texture (`assets/spot_checker.png`).

usage: scripts/make_checker_png.py OUT.png [--size 256] [--squares 16]

Two colours in squares, so that a mesh's texture coordinates show on it: a seam drawn
across the squares, or squares stretched where UVs were moved badly, are plain to see.
Written with the standard library only (zlib and a hand-made PNG container).
"""
import argparse, struct, zlib


def chunk(kind, data):
    body = kind + data
    return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--squares", type=int, default=16)
    a = ap.parse_args()
    light, dark = bytes((236, 226, 205)), bytes((63, 92, 122))
    side = a.size // a.squares
    rows = []
    for y in range(a.size):
        row = bytearray([0])  # filter: none
        for x in range(a.size):
            row += light if (x // side + y // side) % 2 == 0 else dark
        rows.append(bytes(row))
    header = struct.pack(">IIBBBBB", a.size, a.size, 8, 2, 0, 0, 0)  # 8-bit RGB
    png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header)
           + chunk(b"IDAT", zlib.compress(b"".join(rows), 9)) + chunk(b"IEND", b""))
    with open(a.out, "wb") as f:
        f.write(png)


if __name__ == "__main__":
    main()
