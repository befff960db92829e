#!/usr/bin/env python3
"""The ideal slice of bench/solid_quality.sh's bent box: the exemplar warped along
concentric arcs around the sketch's centre (the box corner x = y = -0.5), i.e. the slice
a perfectly field-following synthesis would show where the solved field is the arcs'
tangent. Pixel (col, row) of an N x N middle-z slice has its voxel centre at
x = -0.5 + (col + 0.5)/N, y = -0.5 + (row + 0.5)/N; with rho = N * |(x, y) - corner|
(pixels) and theta its angle, the exemplar is read (bilinear, toroidal) at
(rho * theta, +-rho): exemplar x along the arcs, exemplar y across them.

Usage: solid_ideal_slice.py EXEMPLAR.png N SIGN OUT.png  (SIGN = 1 or -1 mirrors y)
Standard library only (zlib PNG reader/writer for 8-bit RGB/RGBA, non-interlaced)."""
import math, struct, sys, zlib


def read_png(path):
    data = open(path, "rb").read()
    i, idat = 8, b""
    while i < len(data):
        n, = struct.unpack(">I", data[i:i + 4])
        kind, body = data[i + 4:i + 8], data[i + 8:i + 8 + n]
        i += 12 + n
        if kind == b"IHDR":
            w, h, depth, ctype = struct.unpack(">IIBB", body[:10])
            if depth != 8 or ctype not in (2, 6) or body[12] != 0:
                sys.exit(f"{path}: only 8-bit RGB/RGBA non-interlaced PNGs")
        elif kind == b"IDAT":
            idat += body
    ch = 3 if ctype == 2 else 4
    raw, stride, rows, prev, o = zlib.decompress(idat), w * ch, [], bytearray(w * ch), 0
    for _ in range(h):
        f, r = raw[o], bytearray(raw[o + 1:o + 1 + stride])
        o += 1 + stride
        for x in range(stride):
            a = r[x - ch] if x >= ch else 0
            b = prev[x]
            c = prev[x - ch] if x >= ch else 0
            if f == 1:
                r[x] = (r[x] + a) & 255
            elif f == 2:
                r[x] = (r[x] + b) & 255
            elif f == 3:
                r[x] = (r[x] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                r[x] = (r[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(r)
        prev = r
    return w, h, [[tuple(r[x * ch:x * ch + 3]) for x in range(w)] for r in rows]


def write_png(path, rows):
    h, w = len(rows), len(rows[0])
    raw = b"".join(b"\0" + bytes(v for px in r for v in px) for r in rows)

    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))

    head = struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)
    open(path, "wb").write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", head) + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


def main():
    ex, n, sign, out = sys.argv[1], int(sys.argv[2]), float(sys.argv[3]), sys.argv[4]
    w, h, px = read_png(ex)

    def sample(u, v):
        x0, y0 = math.floor(u), math.floor(v)
        fx, fy = u - x0, v - y0
        acc = [0.0, 0.0, 0.0]
        for dy, wy in ((0, 1 - fy), (1, fy)):
            for dx, wx in ((0, 1 - fx), (1, fx)):
                c = px[(y0 + dy) % h][(x0 + dx) % w]
                for k in range(3):
                    acc[k] += wx * wy * c[k]
        return tuple(min(255, max(0, int(round(a)))) for a in acc)

    rows = []
    for row in range(n):
        y = (row + 0.5) / n
        rows.append([sample(n * math.hypot((col + 0.5) / n, y) * math.atan2(y, (col + 0.5) / n),
                            sign * n * math.hypot((col + 0.5) / n, y)) for col in range(n)])
    write_png(out, rows)


main()
