#!/usr/bin/env bash
# Builds everything the service ships: the release binary, the WebAssembly
# decoder and the viewer's assets in web/dist.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -p vitrine
cargo build -p vitrine-wasm --target wasm32-unknown-unknown --profile wasm
(cd web && npm run --silent build)
