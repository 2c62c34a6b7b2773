#!/usr/bin/env python3
"""Fails unless the PNG given is a real rendering: decodes it (8-bit RGB/RGBA, no
interlace, as Chromium writes them), and requires at least 2 % of the pixels to be
non-white and at least 16 distinct colours. Standard library only."""
import struct
import sys
import zlib


def pixels(path):
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        sys.exit(f"{path}: not a PNG")
    pos, idat, header = 8, b"", None
    while pos < len(data):
        (n,) = struct.unpack(">I", data[pos : pos + 4])
        kind, body = data[pos + 4 : pos + 8], data[pos + 8 : pos + 8 + n]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    w, h, depth, colour, _, _, interlace = header
    if depth != 8 or colour not in (2, 6) or interlace:
        sys.exit(f"{path}: unexpected PNG kind (depth {depth}, colour {colour})")
    bpp = 3 if colour == 2 else 4
    raw, stride, prev, out = zlib.decompress(idat), w * bpp, bytearray(w * bpp), []
    for y in range(h):
        f, row = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1 : (y + 1) * (stride + 1)])
        for i in range(stride):
            a = row[i - bpp] if i >= bpp else 0
            b, c = prev[i], prev[i - bpp] if i >= bpp else 0
            if f == 1:
                row[i] = (row[i] + a) & 255
            elif f == 2:
                row[i] = (row[i] + b) & 255
            elif f == 3:
                row[i] = (row[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                row[i] = (row[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        out.append(bytes(row))
        prev = row
    return w, h, bpp, out


w, h, bpp, rows = pixels(sys.argv[1])
colours, inked = set(), 0
for row in rows:
    for x in range(0, w * bpp, bpp):
        px = row[x : x + 3]
        colours.add(px)
        inked += px != b"\xff\xff\xff"
share = inked / (w * h)
print(f"{sys.argv[1]}: {w}x{h}, {100 * share:.1f} % non-white, {len(colours)} colours")
if share < 0.02 or len(colours) < 16:
    sys.exit("the page did not render (blank or nearly blank screenshot)")
