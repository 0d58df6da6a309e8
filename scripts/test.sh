#!/usr/bin/env bash
# Every test of the project: formatting and lints, Rust unit/integration tests
# (SQLite and PostgreSQL), the WebAssembly decoder against the native one in
# Node, the viewer in headless Chromium, and a short fuzzing pass.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cargo fmt --all -- --check
cargo clippy --workspace --all-targets -- -D warnings
cargo clippy -p vitrine --no-deps --all-targets --features dev-tools -- -D warnings # vitrine-dev's tools
bash scripts/check-layout.sh # wasm32 core, crate and module DAGs
bash scripts/build.sh
cargo test --workspace
cargo test -p vitrine --features dev-tools --lib # the tools' unit tests (bench's Draco peer)
(cd web && npm run --silent typecheck && npm test && npm run test:e2e)
bash scripts/load.sh --short && bash scripts/faults.sh --short # crowd, faults, hostile HTTP (~3 min)
if [ -x scripts/fuzz.sh ] || [ -f scripts/fuzz.sh ]; then
    bash scripts/fuzz.sh "${FUZZ_SECONDS:-20}"
fi
