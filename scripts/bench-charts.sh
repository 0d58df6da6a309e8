#!/usr/bin/env bash
# Issue 23's measurements of the charted stream (format 5), in one run:
# native size and decode time on 1, 2 and 4 threads against format 4
# (`charts_bench`, every charted stream checked lossless), DracoPy on the
# same meshes (size, native decode), then WebAssembly decode in Node:
# format 4, format 5 decoded serially and by the viewer's decode pool of 2
# and 4 workers, and draco3d, and each pool member's share decoded alone
# (a pool's critical path with a core per member); last, the viewer in headless Chromium on the
# last mesh (time to the first and the last level, format 4 and format 5 on
# 1, 2 and 4 decode workers; VIEWER=0 skips it).
#
#   bash scripts/bench-charts.sh MESH…     (RUNS=7, OUT=target/bench-charts,
#                                           PEER_DRACO=../shared/tools/peer_draco.py)
# Needs: pip install dracopy trimesh numpy plyfile pillow; npm (draco3d is
# installed under /tmp/draco3d).
set -euo pipefail
cd "$(dirname "$0")/.."
[ $# -gt 0 ] || { echo "usage: bash scripts/bench-charts.sh MESH…" >&2; exit 2; }
runs=${RUNS:-7}
out=${OUT:-target/bench-charts}
peer=${PEER_DRACO:-../shared/tools/peer_draco.py}
mkdir -p "$out"
cargo build --release -p vitrine
cargo build --release -p vitrine-mesh --example charts_bench
cargo build -p vitrine-wasm --target wasm32-unknown-unknown --profile wasm
[ -d /tmp/draco3d/node_modules/draco3d ] || npm install --silent --prefix /tmp/draco3d draco3d

echo "# $(date -u '+%Y-%m-%d %H:%M UTC'), $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg), commit $(git rev-parse --short HEAD)"
echo
echo "## Native: format 5 against format 4 (median of $runs)"
target/release/examples/charts_bench --runs "$runs" --per 0 --count 2 --count 4 "$@"
echo
echo "## DracoPy on the same meshes (12 bits, level 10, positions only)"
python3 "$peer" --bits 12 "$@"
echo
stems=()
for mesh in "$@"; do
    stem=$out/$(basename "${mesh%.*}")
    target/release/vitrine encode "$mesh" -o "$stem.vtr" >/dev/null 2>&1
    target/release/vitrine encode "$mesh" -o "$stem.v5.vtr" --charts auto >/dev/null 2>&1
    python3 - "$peer" "$mesh" "$stem.drc" <<'PY'
import os, sys
sys.path.insert(0, os.path.dirname(os.path.abspath(sys.argv[1])))
import numpy as np, DracoPy
from upsample import load
v, f, _, _ = load(sys.argv[2])
with open(sys.argv[3], "wb") as out:
    out.write(DracoPy.encode(v.astype(np.float32), f.astype(np.uint32), quantization_bits=12, compression_level=10))
PY
    case $stem in
        /*) stems+=("$stem") ;;
        *) stems+=("$PWD/$stem") ;;
    esac
done
echo "## WebAssembly in Node: one thread, and pools whose helpers run on worker threads (median of $runs)"
(cd web && node bench/mesh-decode.mjs --draco3d /tmp/draco3d/node_modules/draco3d --runs "$runs" --workers 2,4 --members 2,4 "${stems[@]}")
if [ "${VIEWER:-1}" != 0 ]; then
    echo
    echo "## The viewer in headless Chromium (SwiftShader), ${*: -1}"
    (cd web && node build.mjs >/dev/null && node bench/pool-viewer.mjs --mesh "$(realpath "${*: -1}")" --runs 3 --workers 1,2,4)
fi
