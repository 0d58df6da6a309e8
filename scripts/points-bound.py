#!/usr/bin/env python3
"""Two prices for issue 42's position target, computed before building anything.

    pip install numpy scipy trimesh
    python3 scripts/points-bound.py floor MESH POINTS
    python3 scripts/points-bound.py direct DUMP BITS D0 BASE [--fit plane|quadric] [--k 16]
        [--uncoded-weight 0.05] [--oracle]

`floor`: the entropy of POINTS points drawn uniformly on MESH's triangles and
quantized to 2^bits cells over the bounding cube's largest side, for 12 and 14
bits, *with the surface known for free* — no coder of such a sample can go
below it. One point's cell has entropy H1 = log2(A / h^2) - E[log2 a], where a
is the area of the surface inside the point's cell in h^2; for a plane of unit
normal n through a random cell, a is the density of n.x for x uniform in the
cube, so E[log2 a] = E_x[log2 pdf(n.x)] (tabulated by Monte Carlo per normal
class). A set of N such points: N (H1 - log2 N + log2 e) bits.

`direct`: prices a "direct mode" for the deep octree levels. DUMP is the
quantized cloud (`cargo run --release -p vitrine-points --example point_depths
-- MESH POINTS BITS 3 --dump DUMP`); BASE is the stream's bytes at D0 bits (the
same example with BITS = D0), taken as the cost of the octree down to depth D0.
Below D0 a cell holding one point codes its remaining BITS - D0 bits per axis
at once: the two axes furthest from the local surface normal raw, the third as
a residual against a surface fitted to the point's K nearest D0-cell centres
(neighbours earlier in Morton order are already exact, weight 1; the others
are at their cell centres, weight --uncoded-weight; --oracle makes all exact).
The residual costs its empirical entropy given the fit's roughness class (what
an adaptive model per class approaches); a cell of several points pays 3 bits
a depth (the octree's rate there). Prints the estimated total.
"""
import argparse
import math

import numpy as np


def floor(args: argparse.Namespace) -> None:
    import trimesh

    mesh = trimesh.load(args.mesh, process=False, force="mesh")
    vertices, faces = mesh.vertices, mesh.faces
    side = (vertices.max(0) - vertices.min(0)).max()
    corners = vertices[faces]
    cross = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    double_area = np.linalg.norm(cross, axis=1)
    keep = double_area > 0
    area = 0.5 * double_area[keep]
    normals = np.abs(cross[keep] / double_area[keep, None])
    total_area = area.sum()
    rng = np.random.default_rng(1)
    grid = 24

    def mean_log_area(n: np.ndarray) -> float:
        x = rng.random((400_000, 3))
        d = x @ n
        hist, edges = np.histogram(d, bins=400, density=True)
        at = np.clip(np.searchsorted(edges, d) - 1, 0, 399)
        return float(np.mean(np.log2(np.maximum(hist[at], 1e-12))))

    # Normals folded into one octant and sorted, binned on two ratios.
    s = -np.sort(-normals, axis=1)
    keys = np.stack(
        [np.rint(s[:, 1] / s[:, 0] * grid), np.rint(s[:, 2] / np.maximum(s[:, 1], 1e-9) * grid)], 1
    ).astype(int)
    uniq, inverse = np.unique(keys, axis=0, return_inverse=True)
    values = np.empty(len(uniq))
    for i, (a, b) in enumerate(uniq):
        n = np.array([1.0, a / grid, a / grid * b / grid])
        values[i] = mean_log_area(n / np.linalg.norm(n))
    e_log_a = float((area * values[inverse.ravel()]).sum() / total_area)
    n_points = args.points
    for bits in (12, 14):
        h = side / (2**bits - 1)
        h1 = math.log2(total_area / h**2) - e_log_a
        per_point = h1 - math.log2(n_points) + math.log2(math.e)
        print(
            f"{args.mesh} {n_points} points, {bits} bits: A/h^2 {total_area / h**2:.4g}, "
            f"E[log2 a] {e_log_a:.3f}, floor {per_point:.3f} b/point = {per_point * n_points / 8:.0f} bytes"
        )


def entropy(values: np.ndarray) -> float:
    _, counts = np.unique(values, return_counts=True)
    p = counts / counts.sum()
    return float(-(p * np.log2(p)).sum())


def morton(cells: np.ndarray, depth: int) -> np.ndarray:
    code = np.zeros(len(cells), dtype=np.int64)
    for b in range(depth):
        for a in range(3):
            code |= ((cells[:, a] >> b) & 1) << (3 * b + a)
    return code


def direct(args: argparse.Namespace) -> None:
    from scipy.spatial import cKDTree

    q = np.fromfile(args.dump, dtype="<u4").reshape(-1, 3).astype(np.int64)
    n_points, shift = len(q), args.bits - args.d0
    side = 1 << shift
    cell = q >> shift
    keys = (cell[:, 0] << 42) | (cell[:, 1] << 21) | cell[:, 2]
    _, inverse, counts = np.unique(keys, return_inverse=True, return_counts=True)
    single = counts[inverse.ravel()] == 1
    rank = np.empty(n_points, dtype=np.int64)
    rank[np.lexsort((q[:, 2], q[:, 1], q[:, 0], morton(cell, args.d0)))] = np.arange(n_points)
    centre = cell * side + (side - 1) / 2.0
    _, near = cKDTree(centre).query(centre, k=args.k + 1)
    near = near[:, 1:]
    coded = np.ones_like(near, dtype=bool) if args.oracle else rank[near] < rank[:, None]
    p = np.where(coded[..., None], q[near].astype(float), centre[near])
    w = np.where(coded, 1.0, args.uncoded_weight)
    c = (p * w[..., None]).sum(1) / w.sum(1)[:, None]
    x = (p - c[:, None, :]) * np.sqrt(w)[..., None]
    eigenvalues, frames = np.linalg.eigh(np.einsum("nki,nkj->nij", x, x))
    normal, t1, t2 = frames[:, :, 0], frames[:, :, 2], frames[:, :, 1]
    roughness = np.sqrt(np.maximum(eigenvalues[:, 0], 0) / w.sum(1))
    rows = np.arange(n_points)
    axis = np.argmax(np.abs(normal), 1)
    n_axis = normal[rows, axis]
    guess = q.astype(float)
    other = ((q - c) * normal).sum(1) - (q[rows, axis] - c[rows, axis]) * n_axis
    guess[rows, axis] = c[rows, axis] - other / n_axis
    if args.fit == "quadric":
        rel = p - c[:, None, :]
        u, v = np.einsum("nki,ni->nk", rel, t1), np.einsum("nki,ni->nk", rel, t2)
        height = np.einsum("nki,ni->nk", rel, normal)
        sw = np.sqrt(w)
        design = np.stack([np.ones_like(u), u, v, u * u, u * v, v * v], -1) * sw[..., None]
        ridge = np.diag([1e-6, 1e-6, 1e-6, 1, 1, 1]) * 1e-3 * (np.mean(u * u, 1)[:, None, None] + 1)
        normal_eq = np.einsum("nki,nkj->nij", design, design) + ridge
        coef = np.linalg.solve(normal_eq, np.einsum("nki,nk->ni", design, height * sw)[..., None])[..., 0]
        for _ in range(3):  # Newton along the coded axis onto the height field
            d = guess - c
            uu, vv, hh = (d * t1).sum(1), (d * t2).sum(1), (d * normal).sum(1)
            f = coef[:, 0] + coef[:, 1] * uu + coef[:, 2] * vv + coef[:, 3] * uu * uu
            f += coef[:, 4] * uu * vv + coef[:, 5] * vv * vv
            fu = coef[:, 1] + 2 * coef[:, 3] * uu + coef[:, 4] * vv
            fv = coef[:, 2] + coef[:, 4] * uu + 2 * coef[:, 5] * vv
            slope = n_axis - (fu * t1[rows, axis] + fv * t2[rows, axis])
            safe = np.abs(slope) > 0.2
            step = np.where(safe, (hh - f) / np.where(safe, slope, 1), 0)
            guess[rows, axis] -= np.clip(step, -side, side)
    low = cell[rows, axis] * side
    predicted = np.clip(np.rint(guess[rows, axis]), low, low + side - 1)
    residual = (q[rows, axis] - predicted).astype(np.int64)[single]
    context = np.clip(np.floor(np.log2(np.maximum(roughness, 1e-3)) * 2).astype(int), -4, 10)[single]
    h_ctx = sum((context == t).sum() * entropy(residual[context == t]) for t in np.unique(context))
    h_ctx /= len(residual)
    singles = int(single.sum())
    bits = singles * (2 * shift + h_ctx) + (n_points - singles) * 3.0 * shift
    print(
        f"{args.dump}: {args.bits} bits, direct below depth {args.d0} ({args.fit}, k {args.k}"
        f"{', oracle' if args.oracle else ''}): {100 * singles / n_points:.1f} % single; normal "
        f"residual {entropy(residual):.3f} b ({h_ctx:.3f} by roughness class) against {shift} raw; "
        f"estimated {args.base + bits / 8:.0f} bytes (3 bits a depth: {args.base + n_points * 3.0 * shift / 8:.0f})"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    f = sub.add_parser("floor")
    f.add_argument("mesh")
    f.add_argument("points", type=int)
    d = sub.add_parser("direct")
    d.add_argument("dump")
    d.add_argument("bits", type=int)
    d.add_argument("d0", type=int)
    d.add_argument("base", type=float)
    d.add_argument("--fit", choices=["plane", "quadric"], default="quadric")
    d.add_argument("--k", type=int, default=16)
    d.add_argument("--uncoded-weight", type=float, default=0.05)
    d.add_argument("--oracle", action="store_true")
    args = parser.parse_args()
    floor(args) if args.command == "floor" else direct(args)


if __name__ == "__main__":
    main()
