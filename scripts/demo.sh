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
[ -f data/cloud.ply ] || $vitrine sample cloud --colour -o data/cloud.ply
rm -f "$db" "$db-wal" "$db-shm"
$vitrine ingest data/torus.ply --db "sqlite:$db" --slug painted-torus --policy open \
    --title "Painted torus" --description "A generated, painted torus with scan-like noise (300k vertices)."
# --quality: the model page plots its per-level quality curve (adds ~20 s here).
$vitrine ingest data/torus.ply --db "sqlite:$db" --slug painted-torus-ccc --policy open --colour ccc --quality \
    --title "Painted torus (cell-complex texture)" \
    --description "The same torus with its colour in a cubic-cell-complex texture shared by every level."
# A real textured scan, when the shared data folder is there (it is never committed).
mask=../shared/data/meshes/mask/mask-gltf-2.0_separated-valid.gltf
if [ -f "$mask" ]; then
    $vitrine ingest "$mask" --db "sqlite:$db" --slug bali-mask --policy open --colour ccc \
        --title "Bali mask" --description "Badisches Landesmuseum, CC BY-SA 4.0; photographic texture through a cubic cell complex."
fi
$vitrine ingest data/plate.ply --db "sqlite:$db" --slug tunnel-plate --policy open --guard features \
    --title "Tunnel plate" --description "A genus-3 plate with sharp edges and tunnels, kept sharp in the coarse levels by the feature guard; try Relief."
# A point cloud (a PLY without faces): streamed as points, drawn as splats.
$vitrine ingest data/cloud.ply --db "sqlite:$db" --slug jittered-cube --policy open \
    --title "Jittered cube (point cloud)" \
    --description "A generated point cloud with normals and colour, drawn as splats that keep the cube's edges sharp."
# A quality study of the torus (T = 5 s here; the thesis used 20): one invitation link.
base=http://127.0.0.1:${PORT:-8080}
$vitrine study create --db "sqlite:$db" --slug painted-torus --seconds 5 >/dev/null
study_link=$($vitrine study invite --db "sqlite:$db" --slug painted-torus --base-url "$base")
echo "Vitrine: open $base/"
echo "Quality study (one participant): $study_link"
exec $vitrine serve --db "sqlite:$db" --listen "127.0.0.1:${PORT:-8080}" --web-dir web/dist
