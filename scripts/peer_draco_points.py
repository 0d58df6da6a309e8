#!/usr/bin/env python3
"""Google Draco's point-cloud coder on the positions the Rust example wrote.

    pip install dracopy numpy
    python3 scripts/peer_draco_points.py BITS DIR [STEM ...]

For each DIR/STEM.f32 (x y z little-endian float32, from
`cargo run --release -p vitrine-points --example stream_size -- BITS --write DIR …`)
writes DIR/STEM.drc: DracoPy, no faces (Draco's point-cloud coder; kd-tree at
compression level 10), BITS quantization bits. Prints the sizes.
"""
import pathlib
import sys

import DracoPy
import numpy as np


def main() -> None:
    bits = int(sys.argv[1])
    folder = pathlib.Path(sys.argv[2])
    stems = sys.argv[3:] or [p.stem for p in sorted(folder.glob("*.f32"))]
    for stem in stems:
        points = np.fromfile(folder / f"{stem}.f32", dtype="<f4").reshape(-1, 3)
        encoded = DracoPy.encode(points, quantization_bits=bits, compression_level=10)
        (folder / f"{stem}.drc").write_bytes(encoded)
        print(f"{stem}\t{len(points)}\t{len(encoded)}")


if __name__ == "__main__":
    main()
