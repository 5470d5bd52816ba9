#!/usr/bin/env python3
"""png_colour_count.py PNG RRGGBB [TOLERANCE]: prints the number of pixels of a PNG within TOLERANCE
(per channel, default 8) of the colour, as `pixels=N width=W height=H`. Reads 8-bit RGB or RGBA,
non-interlaced PNGs (what headless Chromium's --screenshot writes) with the standard library only."""
import struct
import sys
import zlib


def read_png(path):
    data = open(path, 'rb').read()
    if data[:8] != b'\x89PNG\r\n\x1a\n':
        raise ValueError(f'{path}: not a PNG')
    pos, idat, ihdr = 8, b'', None
    while pos < len(data):
        length, kind = struct.unpack('>I4s', data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b'IHDR':
            ihdr = struct.unpack('>IIBBBBB', body)
        elif kind == b'IDAT':
            idat += body
        pos += 12 + length
    width, height, depth, colour, _, _, interlace = ihdr
    if depth != 8 or colour not in (2, 6) or interlace:
        raise ValueError(f'{path}: only 8-bit RGB/RGBA non-interlaced PNGs are read (depth {depth}, colour {colour})')
    bpp = 3 if colour == 2 else 4
    raw = zlib.decompress(idat)
    stride = width * bpp
    rows, prev = [], bytearray(stride)
    for y in range(height):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b = prev[i]
            c = prev[i - bpp] if i >= bpp else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(line)
        prev = line
    return width, height, bpp, rows


def main():
    path, hexcolour = sys.argv[1], sys.argv[2]
    tol = int(sys.argv[3]) if len(sys.argv) > 3 else 8
    want = [int(hexcolour[i:i + 2], 16) for i in (0, 2, 4)]
    width, height, bpp, rows = read_png(path)
    n = 0
    for line in rows:
        for x in range(0, width * bpp, bpp):
            if abs(line[x] - want[0]) <= tol and abs(line[x + 1] - want[1]) <= tol and abs(line[x + 2] - want[2]) <= tol:
                n += 1
    print(f'pixels={n} width={width} height={height}')


if __name__ == '__main__':
    main()
