#!/usr/bin/env bash
# Runs every fuzz target of vitrine-codec (codec/fuzz) for N seconds each.
#
#   scripts/fuzz.sh [SECONDS] [TARGET...]     default: 30 seconds, all targets
#
# Needs the nightly toolchain (rustup toolchain install nightly; without it
# the script skips, see below); not cargo-fuzz (see the build below). Corpora grow in codec/fuzz/corpus/<target>,
# crashes land in codec/fuzz/artifacts/<target>; both are git-ignored. Turn a
# crash into a regression test in codec/mesh/tests/hostile.rs. Exits non-zero if
# any target found a crash.
set -euo pipefail
# meshoptimizer's vendored C++ (the meshopt crate, behind glTF's
# EXT_meshopt_compression) defines a file-level global `edges` in two
# translation units; AddressSanitizer reports that one-definition-rule
# violation at start-up and aborts before any input is read. It is not in
# our code and not reachable from input, so only that check is turned off.
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_odr_violation=0"

secs="${1:-30}"
shift || true
case "$secs" in
    '' | *[!0-9]*) echo "usage: $0 [SECONDS] [TARGET...]" >&2; exit 2 ;;
esac

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root/codec/fuzz"

# libFuzzer's instrumentation needs nightly. A machine without it skips
# fuzzing with a notice rather than failing the whole test run;
# FUZZ_REQUIRED=1 makes that an error.
skip() {
    echo "fuzzing SKIPPED: $1" >&2
    [ "${FUZZ_REQUIRED:-0}" = 1 ] && exit 1
    exit 0
}
cargo +nightly --version >/dev/null 2>&1 ||
    skip "no nightly toolchain (rustup toolchain install nightly)"

all=(decode_stream decode_points decode_batch import_ply import_obj import_off import_gltf import_md2 repair)
if [ "$#" -gt 0 ]; then
    targets=("$@")
else
    targets=("${all[@]}")
fi

# One build for every target (and the seed writer), with the flags
# `cargo fuzz build` passes (coverage for libFuzzer, AddressSanitizer,
# debug assertions, overflow checks; `--target` keeps them off build
# scripts). Built directly, so CI need not compile cargo-fuzz itself each
# run (minutes of a short CI); `cargo fuzz run <target>` works on the same
# crate for longer sessions by hand.
triple=x86_64-unknown-linux-gnu
RUSTFLAGS="-Cpasses=sancov-module -Cllvm-args=-sanitizer-coverage-level=4 \
-Cllvm-args=-sanitizer-coverage-inline-8bit-counters -Cllvm-args=-sanitizer-coverage-pc-table \
-Cllvm-args=-sanitizer-coverage-trace-compares --cfg fuzzing -Zsanitizer=address \
-Cdebug-assertions -Coverflow-checks -Cforce-frame-pointers=yes" \
    cargo +nightly build --manifest-path "$root/codec/fuzz/Cargo.toml" --target "$triple" \
    --target-dir "$root/codec/fuzz/target" --release --bins
bins="target/$triple/release"
# Seeds from the current encoder and exporters, kept apart from the corpora.
seeds="target/seeds"
rm -rf "$seeds"
"$bins/make_seeds" "$seeds"

failed=()
for t in "${targets[@]}"; do
    mkdir -p "corpus/$t" "$seeds/$t" "artifacts/$t"
    echo "=== $t: ${secs}s"
    if ! "$bins/$t" -artifact_prefix="artifacts/$t/" "corpus/$t" "$seeds/$t" \
        -max_total_time="$secs" -rss_limit_mb=2048 -timeout=10 -print_final_stats=1 2>&1 |
        tee "target/fuzz-$t.log" | grep -E '^(#[0-9]+\s+(INITED|DONE)|stat::number_of_executed_units|stat::average_exec_per_sec|stat::peak_rss_mb|==[0-9]+==|SUMMARY|Test unit written|thread .* panicked)'; then
        :
    fi
    if grep -qE 'Test unit written|SUMMARY: |deadly signal' "target/fuzz-$t.log"; then
        failed+=("$t")
    fi
done

if [ "${#failed[@]}" -gt 0 ]; then
    echo "crashes in: ${failed[*]} (inputs under codec/fuzz/artifacts/, logs under codec/fuzz/target/fuzz-*.log)" >&2
    exit 1
fi
echo "all targets ran ${secs}s without a crash"
