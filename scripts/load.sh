#!/usr/bin/env bash
# Crowd load test: simulated viewer visitors against the release
# `vitrine serve`, load caps off and on. See tests/README.md.
#
#   scripts/load.sh            the full run for BENCHMARKS.md: the 2.15 M-vertex
#                              upsampled igea, 1/50/100/1000/5000 visitors at once,
#                              caps off and on, RUNS runs each (median), then 1,000
#                              visitors ramping and steady; writes target/load/ and
#                              docs/load.svg. "caps on" is the default service:
#                              load caps and admission control of new visitors
#                              (503 busy + Retry-After past --admit-burst, which
#                              visitors retry with jitter); "caps off" turns both off
#   scripts/load.sh --short    CI (≤ 5 minutes with scripts/faults.sh --short): igea.ply
#                              (134 k vertices), 1 and 200 visitors with caps on;
#                              fails on any answer but 200/304/429/503, a 429/503
#                              without Retry-After, or a p99 over SHORT_P99_MS; then
#                              the same crowd against load thresholds it exceeds:
#                              fails unless load caps engage and every visitor they
#                              held refines on after re-reading the manifest
#
# Environment: RUNS (3), VISITORS ("1,50,100,1000,5000"), PATTERNS ("ramp:10 steady:20",
# extra 1,000-visitor runs), LOAD_MESH (a mesh instead of the upsampled igea),
# SHORT_VISITORS (200), SHORT_P99_MS (100), OUT (target/load), SVG (docs/load.svg).
# The full run needs numpy, trimesh and plyfile for ../shared/tools/upsample.py.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
short=0
[ "${1:-}" = --short ] && short=1

export RUST_BACKTRACE=0
# One build of both, as scripts/build.sh makes it: built apart, the two
# unify their dependencies' features differently and the second build
# recompiles tokio, hyper, sqlx and the service.
cargo build --release -p vitrine -p vitrine-load
bin=$root/target/release/vitrine
load=$root/target/release/vitrine-load
# Each visitor holds a connection in the harness and one in the server.
ulimit -n "$(ulimit -Hn)" 2>/dev/null || true
echo "open files: $(ulimit -n); $(nproc) cores; load average $(cut -d' ' -f1-3 /proc/loadavg)"

if [ $short = 1 ]; then
    work=$(mktemp -d /tmp/vitrine-load.XXXXXX)
    trap 'rm -rf "$work"' EXIT
    mesh=$root/../shared/data/meshes/igea.ply
    if [ ! -f "$mesh" ]; then
        mesh=$work/torus.ply
        "$bin" sample torus --kilo-vertices 150 -o "$mesh" >/dev/null
    fi
    db=sqlite:$work/load.db
    # The exhibition policy: public visitors stop one level short, researchers
    # (5 % of the crowd, with a token) reach the last level.
    "$bin" ingest "$mesh" --db "$db" --slug short --title Short --policy exhibition >/dev/null
    token=$("$bin" token --db "$db" --label load)
    n=${SHORT_VISITORS:-200}
    "$load" run --db "$db" --slug short --token "$token" --visitors "1,$n" --caps on \
        --listen 127.0.0.1:18190 --out "$work/out" \
        --check-visitors "$n" --max-p99-ms "${SHORT_P99_MS:-100}"
    # Load caps that engage and lift: thresholds this crowd exceeds, sampled
    # every 50 ms so that they engage within the burst on any machine, no
    # admission control, a 2 s Retry-After. Every visitor a load cap held
    # must read the manifest again and refine on once the pressure falls.
    "$load" run --db "$db" --slug short --token "$token" --visitors "1,$n" --caps on \
        --listen 127.0.0.1:18190 --out "$work/resume" --stay-s 30 \
        --serve-arg=--load-high-inflight --serve-arg=10 --serve-arg=--load-low-inflight --serve-arg=3 \
        --serve-arg=--load-sample-ms --serve-arg=50 \
        --serve-arg=--admit-rate --serve-arg=0 --serve-arg=--load-retry-after-s --serve-arg=2 \
        --check-visitors "$n" --check-resume
    exit 0
fi

out=${OUT:-$root/target/load}
mkdir -p "$out"
if [ -n "${LOAD_MESH:-}" ]; then
    mesh=$LOAD_MESH
else
    mesh=$out/igea2m.ply
    if [ ! -f "$mesh" ]; then
        python3 -c 'import numpy, trimesh, plyfile' 2>/dev/null || pip install numpy trimesh plyfile
        python3 "$root/../shared/tools/upsample.py" "$root/../shared/data/meshes/igea.ply" "$mesh" --levels 2
    fi
fi
slug=$(basename "${mesh%.*}" | tr 'A-Z_.' 'a-z--')
db=sqlite:$out/$slug.db
if [ ! -f "$out/$slug.db" ]; then
    # The open policy: every visitor may reconstruct the whole model (the worst case).
    "$bin" ingest "$mesh" --db "$db" --slug "$slug" --title "$slug" --policy open
fi
token=$("$bin" token --db "$db" --label load)
"$load" run --db "$db" --slug "$slug" --token "$token" \
    --visitors "${VISITORS:-1,50,100,1000,5000}" --caps off,on --runs "${RUNS:-3}" \
    --out "$out" --svg "${SVG:-$root/docs/load.svg}"
for pattern in ${PATTERNS-ramp:10 steady:20}; do
    "$load" run --db "$db" --slug "$slug" --token "$token" --visitors 1000 --caps off,on \
        --pattern "$pattern" --profile "$out/profile.json" --out "$out/${pattern%%:*}"
done
