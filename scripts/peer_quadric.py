#!/usr/bin/env python3
"""A quadric-error simplifier from the registries (fast-simplification, after
Garland & Heckbert), as the peer of `vitrine-simplify`'s bench.

    pip install fast-simplification plyfile numpy
    python3 scripts/peer_quadric.py IN.ply OUT.ply FRACTION

Keeps FRACTION of IN's faces; prints the simplification's wall time in ms.
"""
import sys
import time

import fast_simplification
import numpy as np
from plyfile import PlyData, PlyElement


def main():
    src, dst, fraction = sys.argv[1], sys.argv[2], float(sys.argv[3])
    ply = PlyData.read(src)
    v = ply["vertex"]
    points = np.column_stack([v["x"], v["y"], v["z"]]).astype(np.float32)
    faces = np.vstack(ply["face"]["vertex_indices"]).astype(np.int64)
    start = time.perf_counter()
    out_points, out_faces = fast_simplification.simplify(points, faces, target_reduction=1.0 - fraction)
    ms = 1000.0 * (time.perf_counter() - start)
    vertices = np.array([tuple(p) for p in out_points], dtype=[("x", "f4"), ("y", "f4"), ("z", "f4")])
    face_rows = np.array([(list(f),) for f in out_faces], dtype=[("vertex_indices", "i4", (3,))])
    PlyData([PlyElement.describe(vertices, "vertex"), PlyElement.describe(face_rows, "face")]).write(dst)
    print(f"{ms:.1f}")


if __name__ == "__main__":
    main()
