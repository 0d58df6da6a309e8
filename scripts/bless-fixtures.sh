#!/usr/bin/env bash
# Re-records web/test/fixtures: small streams the Rust encoder writes from
# generated samples (never from shared data), and beside each NAME.vtr a
# NAME.json of what the native decoder makes of it: per level the vertex and
# face counts and the SHA-256 of its positions (f32), indices (u32) and
# colours (u8), little-endian, as `vitrine-dev dump-levels` writes them. The
# Node tests (web/test/wasm.test.mjs, reconstruction.test.mjs) decode the
# committed bytes with the WebAssembly decoder and compare.
#
# Run it when a test says the decoder's output changed and the change is
# meant (consider codec/core/FORMAT.md's version, as for
# codec/core/tests/golden.txt), or to add a fixture:
#
#   bash scripts/bless-fixtures.sh            # builds the release CLI and vitrine-dev first
#   VITRINE_BIN=path/to/vitrine VITRINE_DEV_BIN=path/to/vitrine-dev bash scripts/bless-fixtures.sh
set -euo pipefail
cd "$(dirname "$0")/.."

if [ -z "${VITRINE_BIN:-}" ]; then
    cargo build --release -p vitrine
    VITRINE_BIN=target/release/vitrine
fi
if [ -z "${VITRINE_DEV_BIN:-}" ]; then
    cargo build --release -p vitrine --features dev-tools --bin vitrine-dev
    VITRINE_DEV_BIN=target/release/vitrine-dev
fi
out=web/test/fixtures
mkdir -p "$out"
# A fixture dropped from the list below goes too (each stream with its
# sidecar; other JSON there, such as geodesic-torus.json, is not this
# script's: codec/wasm/tests/geodesic_fixture.rs writes it).
for stream in "$out"/*.vtr; do
    rm -f "$stream" "${stream%.vtr}.json"
done
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

sha() { if [ -f "$1" ]; then printf '"%s"' "$(sha256sum "$1" | cut -d' ' -f1)"; else printf 'null'; fi; }
size() { stat -c %s "$1"; }

# fixture NAME SAMPLE-ARGS...: `vitrine sample SAMPLE-ARGS`, then encode with
# the defaults and $encode_args.
encode_args=()
fixture() {
    local name=$1
    shift
    "$VITRINE_BIN" sample "$@" -o "$tmp/$name.ply" 2>/dev/null
    "$VITRINE_BIN" encode "$tmp/$name.ply" -o "$out/$name.vtr" "${encode_args[@]}" >/dev/null 2>&1
    "$VITRINE_DEV_BIN" dump-levels "$out/$name.vtr" "$tmp/$name"
    local levels
    levels=$(find "$tmp/$name" -name 'level-*.positions' | wc -l)
    {
        printf '{\n'
        printf '  "made_by": "vitrine sample %s; vitrine encode%s; bash scripts/bless-fixtures.sh",\n' "$*" "${encode_args[*]:+ ${encode_args[*]}}"
        printf '  "stream": { "bytes": %s, "sha256": %s },\n' "$(size "$out/$name.vtr")" "$(sha "$out/$name.vtr")"
        printf '  "levels": [\n'
        for ((k = 0; k < levels; k++)); do
            local at="$tmp/$name/level-$k"
            printf '    { "level": %d, "vertices": %d, "faces": %d, "positions": %s, "indices": %s, "colours": %s }' \
                "$k" $(($(size "$at.positions") / 12)) $(($(size "$at.indices") / 12)) \
                "$(sha "$at.positions")" "$(sha "$at.indices")" "$(sha "$at.colours")"
            if ((k + 1 < levels)); then printf ',\n'; else printf '\n'; fi
        done
        printf '  ]\n}\n'
    } >"$out/$name.json"
    printf '%-36s %6d bytes, %2d levels, %5d vertices\n' "$out/$name.vtr" "$(size "$out/$name.vtr")" "$levels" \
        $(($(size "$tmp/$name/level-$((levels - 1)).positions") / 12))
}

fixture torus torus --kilo-vertices 1
fixture painted-torus torus --kilo-vertices 1 --colour --noise 0.003
fixture plate plate --kilo-vertices 1
fixture sphere sphere --kilo-vertices 1 --noise 0.002
# A charted stream (format 5): four charts, each decoded on its own.
encode_args=(--charts 4)
fixture charted-torus torus --kilo-vertices 3 --colour --noise 0.003
# A nested stream (format 6): 2 top charts, each split in 2 twice (3 phases),
# for the viewer's nested refinement (web/test/nested-refinement.test.mjs).
encode_args=(--charts nested:2,2,3)
fixture nested-torus torus --kilo-vertices 2 --colour --noise 0.003
encode_args=()
