#!/usr/bin/env bash
# The quality study's cap under a crowd (issue 17; thesis §6.5–6.6): scripted
# answers become a model's good-enough level (`vitrine study import`,
# `report --apply`), then 1 and 100 simultaneous visitors reconstruct the
# model in full (load caps off) and held at the study's level
# (`vitrine serve --load-pin`), on the same machine, one after the other.
# Prints both medians and writes $OUT/study-load.json. See BENCHMARKS.md.
#
#   scripts/study-load.sh            igea (134 k vertices) from ../shared, or a
#                                    generated 150 k-vertex torus without it
#   LOAD_MESH=mesh.ply scripts/study-load.sh
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
export RUST_BACKTRACE=0 RUST_LOG=${RUST_LOG:-warn}
cargo build --release -q -p vitrine -p vitrine-load
bin=$root/target/release/vitrine
load=$root/target/release/vitrine-load
out=${OUT:-$root/target/study-load}
rm -rf "$out" && mkdir -p "$out"
mesh=${LOAD_MESH:-$root/../shared/data/meshes/igea.ply}
if [ ! -f "$mesh" ]; then
    mesh=$out/torus.ply
    "$bin" sample torus --kilo-vertices 150 -o "$mesh" >/dev/null
fi
db=sqlite:$out/study.db
"$bin" ingest "$mesh" --db "$db" --slug scan --title Scan --policy open >/dev/null

# Twelve scripted participants who find the level sufficient from the first
# level with a fifth of the vertices (where the thesis' Habacuc study landed,
# level 8 of 12), two of them one level later; one control step each.
python3 - "$db" "$out/answers.csv" <<'PY'
import json, sqlite3, sys
db = sqlite3.connect(sys.argv[1].removeprefix("sqlite:"))
counts = [v for (v,) in db.execute(
    "SELECT vertices FROM base_mesh UNION ALL SELECT vertices FROM refinement_batch "
    "WHERE compression_id = (SELECT MAX(id) FROM compression) ORDER BY 1")]
last = len(counts) - 1
fifth = next(k for k, v in enumerate(counts) if v >= 0.2 * counts[-1])
rows = ["participant,step,from_level,to_level,control,improvement,sufficient"]
for p in range(12):
    good = min(last, fifth + (1 if p < 2 else 0))
    step = 1
    for b in range(1, last + 1):
        rows.append(f"p{p:02},{step},{b-1},{b},false,{'a-little' if b <= good else 'none'},{'yes' if b >= good else 'no'}")
        step += 1
        if b == 1:
            rows.append(f"p{p:02},{step},1,1,true,none,{'yes' if 1 >= good else 'no'}")
            step += 1
open(sys.argv[2], "w").write("\n".join(rows) + "\n")
PY
"$bin" study import --db "$db" --slug scan "$out/answers.csv" >/dev/null
"$bin" study report --db "$db" --slug scan --json --apply > "$out/report.json"
level=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["good_enough_level"])' "$out/report.json")
echo "study: good-enough level $level"

"$load" run --db "$db" --slug scan --visitors 1,100 --caps off --runs "${RUNS:-3}" \
    --listen 127.0.0.1:18290 --out "$out/full" >/dev/null
"$load" run --db "$db" --slug scan --visitors 1,100 --caps on --runs "${RUNS:-3}" \
    --listen 127.0.0.1:18290 --out "$out/capped" --stay-s 0 \
    --serve-arg=--load-pin --serve-arg=--admit-rate --serve-arg=0 >/dev/null
python3 - "$out" "$level" <<'PY'
import json, pathlib, sys
out, level = pathlib.Path(sys.argv[1]), int(sys.argv[2])
def medians(folder):
    rows = json.loads((out / folder / "results.json").read_text())["medians"]
    return {r["visitors"]: r["recon_median_s"] for r in rows}
full, capped = medians("full"), medians("capped")
result = {"good_enough_level": level, "full_s": full, "capped_s": capped,
          "capped_over_full_at_100": capped[100] / full[100]}
(out / "study-load.json").write_text(json.dumps(result, indent=2) + "\n")
print(f"visitors  full reconstruction (s)  to the study's level {level} (s)  ratio")
for v in sorted(full):
    print(f"{v:>8}  {full[v]:>24.2f}  {capped[v]:>29.2f}  {capped[v] / full[v]:.2f}")
PY
