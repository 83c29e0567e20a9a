#!/usr/bin/env python3
"""Put PNG images side by side in one PNG (the README's scene strips).

    scripts/compare/montage.py OUT.png IN.png [IN.png ...] [--gap PIXELS] [--columns N]

Reads 8-bit RGB or RGBA PNGs (as candela writes them; alpha is dropped), all of
the same height within a row, and lays them out left to right in rows of
`columns` images (all in one row by default) with `gap` pixels of white
between them. Standard library only."""

import argparse
import struct
import sys
import zlib


def read_png(path):
    """(width, height, rows of RGB bytes) of an 8-bit RGB/RGBA, non-interlaced PNG."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        sys.exit("montage: %s is not a PNG" % path)
    pos, idat, header = 8, b"", None
    while pos < len(data):
        length, tag = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        pos += 12 + length
        if tag == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif tag == b"IDAT":
            idat += body
        elif tag == b"IEND":
            break
    width, height, depth, colour, _, _, interlace = header
    if depth != 8 or colour not in (2, 6) or interlace:
        sys.exit("montage: %s: only 8-bit RGB/RGBA, non-interlaced PNGs" % path)
    bpp = 3 if colour == 2 else 4
    raw = zlib.decompress(idat)
    stride = width * bpp
    rows, prev = [], bytearray(stride)
    for y in range(height):
        kind = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b = prev[i]
            c = prev[i - bpp] if i >= bpp else 0
            if kind == 1:
                line[i] = (line[i] + a) & 255
            elif kind == 2:
                line[i] = (line[i] + b) & 255
            elif kind == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif kind == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        prev = line
        rows.append(bytes(line) if bpp == 3 else bytes(v for k, v in enumerate(line) if k % 4 != 3))
    return width, height, rows


def filtered(kind, line, prev):
    """Row `line` under PNG filter `kind` (0 none, 1 sub, 2 up, 3 average, 4 Paeth), 3 bytes a pixel."""
    out = bytearray(len(line))
    for i in range(len(line)):
        a = line[i - 3] if i >= 3 else 0
        b = prev[i]
        c = prev[i - 3] if i >= 3 else 0
        if kind == 0:
            pred = 0
        elif kind == 1:
            pred = a
        elif kind == 2:
            pred = b
        elif kind == 3:
            pred = (a + b) // 2
        else:
            p = a + b - c
            pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
            pred = a if pa <= pb and pa <= pc else b if pb <= pc else c
        out[i] = (line[i] - pred) & 255
    return bytes(out)


def write_png(path, width, rows):
    """An 8-bit RGB PNG, each row under the filter with the smallest sum of absolute
    (signed) residuals (the usual heuristic), deflated at level 9."""
    prev, raw = bytes(3 * width), bytearray()
    for line in rows:
        kind, best = min(((k, filtered(k, line, prev)) for k in range(5)),
                         key=lambda kf: sum(v if v < 128 else 256 - v for v in kf[1]))
        raw += bytes([kind]) + best
        prev = line

    def chunk(tag, body):
        return struct.pack(">I", len(body)) + tag + body + struct.pack(">I", zlib.crc32(tag + body))
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", width, len(rows), 8, 2, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(bytes(raw), 9)))
        f.write(chunk(b"IEND", b""))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("output")
    ap.add_argument("inputs", nargs="+")
    ap.add_argument("--gap", type=int, default=4)
    ap.add_argument("--columns", type=int, default=0)
    args = ap.parse_args()
    images = [read_png(p) for p in args.inputs]
    columns = args.columns or len(images)
    white = b"\xff\xff\xff"
    grid_rows = [images[k:k + columns] for k in range(0, len(images), columns)]
    width = max(sum(w for w, _, _ in row) + args.gap * (len(row) - 1) for row in grid_rows)
    out = []
    for r, row in enumerate(grid_rows):
        if r:
            out += [white * width] * args.gap
        height = row[0][1]
        if any(h != height for _, h, _ in row):
            sys.exit("montage: the images of a row differ in height")
        for y in range(height):
            line = (white * args.gap).join(rows[y] for _, _, rows in row)
            out.append(line + white * ((width * 3 - len(line)) // 3))
    write_png(args.output, width, out)
    print("wrote %s: %d x %d" % (args.output, width, len(out)))


if __name__ == "__main__":
    main()
