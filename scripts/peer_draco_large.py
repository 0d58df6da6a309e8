#!/usr/bin/env python3
"""Google Draco (compression level 10) on a binary PLY too large for
../shared/tools/peer_draco.py's loader (plyfile and Python lists: a
25.6 M-vertex mesh took it past 22 GiB here). Reads the upsampler's layout
(float x, y, z, optional uchar r, g, b; faces as `list uchar int` of 3) with
numpy views of the file, then encodes positions and faces as peer_draco.py
does, and decodes once. Same columns as peer_draco.py.

  python3 scripts/peer_draco_large.py MESH.ply [--bits 12]
"""
import argparse
import os
import time

import numpy as np


def header(path):
    with open(path, "rb") as f:
        lines = []
        while True:
            line = f.readline().decode("ascii").strip()
            lines.append(line)
            if line == "end_header":
                return lines, f.tell()


def load(path):
    lines, offset = header(path)
    if "format binary_little_endian 1.0" not in lines:
        raise SystemExit(f"{path}: only binary little-endian PLY")
    counts, props, element = {}, {"vertex": [], "face": []}, None
    for line in lines:
        parts = line.split()
        if parts[0] == "element":
            element = parts[1]
            counts[element] = int(parts[2])
        elif parts[0] == "property" and element in props:
            props[element].append(parts[1:])
    kinds = {"float": "<f4", "uchar": "u1"}
    vertex = np.dtype([(p[-1], kinds[p[0]]) for p in props["vertex"]])
    if props["face"] != [["list", "uchar", "int", "vertex_indices"]]:
        raise SystemExit(f"{path}: faces must be `list uchar int vertex_indices`")
    face = np.dtype([("n", "u1"), ("i", "<i4", (3,))])
    data = np.memmap(path, dtype=np.uint8, mode="r", offset=offset)
    nv, nf = counts["vertex"], counts["face"]
    v = np.frombuffer(data, dtype=vertex, count=nv)
    f = np.frombuffer(data, dtype=face, count=nf, offset=nv * vertex.itemsize)
    if not (f["n"] == 3).all():
        raise SystemExit(f"{path}: triangles only")
    positions = np.stack([v[k] for k in ("x", "y", "z")], axis=1).astype(np.float32)
    return positions, np.ascontiguousarray(f["i"], dtype=np.uint32)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("meshes", nargs="+")
    ap.add_argument("--bits", type=int, default=12)
    a = ap.parse_args()
    import DracoPy
    print("mesh\tvertices\tfaces\tbits\tbytes\tbpv\tencode_ms\tdecode_ms\tdecode_Mv_s")
    for path in a.meshes:
        v, f = load(path)
        nf = len(f)
        t = time.perf_counter()
        buf = DracoPy.encode(v, f, quantization_bits=a.bits, compression_level=10)
        enc = (time.perf_counter() - t) * 1e3
        del f
        t = time.perf_counter()
        DracoPy.decode(buf)
        dec = time.perf_counter() - t
        print(f"{os.path.basename(path)}\t{len(v)}\t{nf}\t{a.bits}\t{len(buf)}"
              f"\t{8 * len(buf) / len(v):.2f}\t{enc:.1f}\t{dec * 1e3:.1f}\t{len(v) / dec / 1e6:.2f}", flush=True)


if __name__ == "__main__":
    main()
