#!/usr/bin/env bash
# Every test of the project: formatting and lints, Rust unit/integration tests
# (SQLite and PostgreSQL), the WebAssembly decoder against the native one in
# Node, the viewer in headless Chromium, and a short fuzzing pass. Each step
# prints its wall time, so CI's budget (45 minutes) can be watched.
set -euo pipefail
cd "$(dirname "$0")/.."

start=$SECONDS
step() {
    local t0=$SECONDS
    echo "::: $* (at $((t0 - start)) s)"
    "$@"
    echo "::: done in $((SECONDS - t0)) s: $*"
}

step bash scripts/setup.sh
step cargo fmt --all -- --check
step cargo clippy --workspace --all-targets -- -D warnings
step cargo clippy -p vitrine --no-deps --all-targets --features dev-tools -- -D warnings # vitrine-dev's tools
step bash scripts/check-layout.sh # wasm32 core, crate and module DAGs
step bash scripts/build.sh
step cargo test --workspace
step cargo test -p vitrine --features dev-tools --lib # the tools' unit tests (bench's Draco peer)
step bash -c 'cd web && npm run --silent typecheck && npm test && npm run test:e2e'
step bash -c 'bash scripts/load.sh --short && bash scripts/faults.sh --short' # crowd, faults, hostile HTTP (~3 min)
step bash scripts/topology.sh --short # two instances on one PostgreSQL behind nginx
if [ -f scripts/fuzz.sh ]; then
    step bash scripts/fuzz.sh "${FUZZ_SECONDS:-10}"
fi
echo "::: all tests passed in $((SECONDS - start)) s"
