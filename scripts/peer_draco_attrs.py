#!/usr/bin/env python3
"""Google Draco's point-cloud coder on the clouds `point_attrs` wrote, with
and without each attribute, so that its attribute bytes are known.

    pip install numpy   # and Draco's draco_encoder on PATH (1.5)
    python3 scripts/peer_draco_attrs.py BITS NORMAL_BITS DIR [STEM ...]

For each DIR/STEM.f32 (positions, x y z little-endian float32), with
DIR/STEM.nrm.f32 (normals) and DIR/STEM.rgb (colours, u8 RGB) when present
(`cargo run --release -p vitrine-points --example point_attrs -- DATA --write DIR`):
writes binary PLYs with positions only, with normals, with colours and with
both, and encodes each with `draco_encoder -point_cloud -cl 10 -qp BITS -qn
NORMAL_BITS` (Draco's point-cloud coder, kd-tree positions; colours are
8-bit and not quantized further). DracoPy 2.2.0's `encode(normals=...)` is
not used: it drops normals for a cloud without faces (the stream is the same
size with and without them). Prints positions-only bytes and the bytes
normals and colours add, and their bits per point.
"""
import pathlib
import subprocess
import sys
import tempfile

import numpy as np


def ply(path: pathlib.Path, points, normals, colours) -> None:
    fields = [("x", "<f4"), ("y", "<f4"), ("z", "<f4")]
    if normals is not None:
        fields += [("nx", "<f4"), ("ny", "<f4"), ("nz", "<f4")]
    if colours is not None:
        fields += [("red", "u1"), ("green", "u1"), ("blue", "u1")]
    rows = np.zeros(len(points), dtype=fields)
    for k, a in enumerate("xyz"):
        rows[a] = points[:, k]
        if normals is not None:
            rows["n" + a] = normals[:, k]
    if colours is not None:
        for k, c in enumerate(["red", "green", "blue"]):
            rows[c] = colours[:, k]
    kinds = {"<f4": "float", "u1": "uchar"}
    header = "ply\nformat binary_little_endian 1.0\n"
    header += f"element vertex {len(points)}\n"
    header += "".join(f"property {kinds[t]} {name}\n" for name, t in fields)
    header += "end_header\n"
    path.write_bytes(header.encode() + rows.tobytes())


def draco_size(tmp: pathlib.Path, bits: int, normal_bits: int, points, normals, colours) -> int:
    src, out = tmp / "in.ply", tmp / "out.drc"
    ply(src, points, normals, colours)
    subprocess.run(
        ["draco_encoder", "-point_cloud", "-i", str(src), "-o", str(out),
         "-cl", "10", "-qp", str(bits), "-qn", str(normal_bits)],
        check=True, capture_output=True,
    )
    return out.stat().st_size


def main() -> None:
    bits = int(sys.argv[1])
    normal_bits = int(sys.argv[2])
    folder = pathlib.Path(sys.argv[3])
    stems = sys.argv[4:] or [
        p.name[: -len(".f32")] for p in sorted(folder.glob("*.f32")) if not p.name.endswith(".nrm.f32")
    ]
    print("cloud\tpoints\tbits\tpos_bytes\tnormal_bytes\tcolour_bytes\tboth_bytes\tnormal_b/p\tcolour_b/p")
    with tempfile.TemporaryDirectory() as t:
        tmp = pathlib.Path(t)
        for stem in stems:
            points = np.fromfile(folder / f"{stem}.f32", dtype="<f4").reshape(-1, 3)
            n = len(points)
            nrm_path = folder / f"{stem}.nrm.f32"
            rgb_path = folder / f"{stem}.rgb"
            normals = np.fromfile(nrm_path, dtype="<f4").reshape(-1, 3) if nrm_path.exists() else None
            colours = np.fromfile(rgb_path, dtype=np.uint8).reshape(-1, 3) if rgb_path.exists() else None
            size = lambda nr, co: draco_size(tmp, bits, normal_bits, points, nr, co)  # noqa: E731
            pos = size(None, None)
            nb = size(normals, None) - pos if normals is not None else 0
            cb = size(None, colours) - pos if colours is not None else 0
            both = size(normals, colours) - pos
            print(f"{stem}\t{n}\t{bits}\t{pos}\t{nb}\t{cb}\t{both}\t{nb * 8 / n:.2f}\t{cb * 8 / n:.2f}")


if __name__ == "__main__":
    main()
