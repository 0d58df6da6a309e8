#!/usr/bin/env bash
# Builds everything the service ships: the release binary, the WebAssembly
# decoder and the viewer's assets in web/dist (and the crowd harness).
set -euo pipefail
cd "$(dirname "$0")/.."
# With the crowd harness in the same build: the load, fault and topology
# scripts build both at once, and built apart the two would unify their
# dependencies' features differently (a second release build of tokio,
# hyper, sqlx and the service).
cargo build --release -p vitrine -p vitrine-load
cargo build -p vitrine-wasm --target wasm32-unknown-unknown --profile wasm
(cd web && npm run --silent build)
