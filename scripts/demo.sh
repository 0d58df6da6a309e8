#!/usr/bin/env bash
# The main job: set up, build, encode generated samples into SQLite and serve
# them with the viewer on http://127.0.0.1:${PORT:-8080}/ (Ctrl-C stops it).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh
mkdir -p data
db=data/vitrine.db
vitrine=target/release/vitrine
[ -f data/torus.ply ] || $vitrine sample torus --colour --noise 0.002 --kilo-vertices 300 -o data/torus.ply
[ -f data/plate.ply ] || $vitrine sample plate --kilo-vertices 120 -o data/plate.ply
rm -f "$db" "$db-wal" "$db-shm"
$vitrine ingest data/torus.ply --db "sqlite:$db" --slug painted-torus --policy open \
    --title "Painted torus" --description "A generated, painted torus with scan-like noise (300k vertices)."
$vitrine ingest data/plate.ply --db "sqlite:$db" --slug tunnel-plate --policy open \
    --title "Tunnel plate" --description "A genus-3 plate with sharp edges and tunnels."
echo "Vitrine: open http://127.0.0.1:${PORT:-8080}/"
exec $vitrine serve --db "sqlite:$db" --listen "127.0.0.1:${PORT:-8080}" --web-dir web/dist
