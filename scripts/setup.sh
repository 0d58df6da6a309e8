#!/usr/bin/env bash
# Installs what building and testing Vitrine needs on a fresh Debian machine
# with the Rust toolchain: the wasm32 target, Node packages, Debian's Chromium
# (browser tests) and a running PostgreSQL (storage tests). Idempotent.
set -euo pipefail
cd "$(dirname "$0")/.."

rustup target list --installed | grep -q '^wasm32-unknown-unknown$' || rustup target add wasm32-unknown-unknown

need_apt=()
command -v node >/dev/null 2>&1 || need_apt+=(nodejs npm)
[ -x /usr/bin/chromium ] || need_apt+=(chromium)
# The caching proxy of scripts/topology.sh (CI runs its --short version).
command -v nginx >/dev/null 2>&1 || need_apt+=(nginx-light)
# The meshopt crate (glTF's EXT_meshopt_compression) builds meshoptimizer's C++.
command -v c++ >/dev/null 2>&1 || need_apt+=(g++)
if [ ${#need_apt[@]} -gt 0 ]; then
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq "${need_apt[@]}" >/dev/null
fi

(cd web && npm ci --no-audit --no-fund --loglevel=error)

bash scripts/start-postgres.sh
