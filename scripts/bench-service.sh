#!/usr/bin/env bash
# Service benchmark for BENCHMARKS.md: refinement-batch requests/s and latency
# with wrk, payload cache on and off, SQLite and PostgreSQL.
#
#   scripts/bench-service.sh [mesh]        (default: shared/data/meshes/igea.ply)
#
# Environment: BIN (default target/release/vitrine, built with `cargo build --release -p vitrine`), CONNS (256), THREADS (2),
# DURATION (15s), RUNS (3, the median is reported), BATCHES ("5 13"),
# PG_ADMIN (postgres://postgres@127.0.0.1:5432/postgres), BACKENDS ("sqlite postgres"),
# LOAD_CAPS (off: thresholds out of reach, so every request is served and the
# table measures serving; on: the defaults, and batches above the good-enough
# level turn into 429s as the machine saturates), NGINX (on: with the payload
# cache on, each run also times nginx serving the same batch as a static file
# — 2 workers, sendfile, the proxy's listen options — just before Vitrine, and
# the table gives Vitrine's requests/s over nginx's; off: skip it).
# Needs wrk (apt-get install wrk) and, for PostgreSQL, scripts/start-postgres.sh.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
mesh=${1:-$root/../shared/data/meshes/igea.ply}
bin=${BIN:-$root/target/release/vitrine}
conns=${CONNS:-256}
threads=${THREADS:-2}
duration=${DURATION:-15s}
runs=${RUNS:-3}
batches=${BATCHES:-"5 13"}
pg_admin=${PG_ADMIN:-postgres://postgres@127.0.0.1:5432/postgres}
backends=${BACKENDS:-"sqlite postgres"}
port=${PORT:-18080}
load_caps=${LOAD_CAPS:-off}
peer_nginx=${NGINX:-on}
work=$(mktemp -d)
server=""
nginx_pid=""
pg_name="vitrine_bench_$$"

cleanup() {
    if [ -n "$server" ]; then kill "$server" 2>/dev/null || true; wait "$server" 2>/dev/null || true; fi
    [ -z "$nginx_pid" ] || kill "$nginx_pid" 2>/dev/null || true
    case " $backends " in
        *" postgres "*) psql "$pg_admin" -qc "DROP DATABASE IF EXISTS $pg_name WITH (FORCE)" >/dev/null 2>&1 || true ;;
    esac
    rm -rf "$work"
}
trap cleanup EXIT

command -v wrk >/dev/null || { echo "wrk is missing: apt-get install -y wrk" >&2; exit 1; }
"$bin" serve --help >/dev/null 2>&1 || { echo "$bin has no serve command (set BIN)" >&2; exit 1; }

# wrk prints latencies as 812.00us, 13.40ms or 1.02s: milliseconds out.
to_ms() {
    awk '{ v = $1; if (v ~ /us$/) { sub(/us$/, "", v); v /= 1000 } else if (v ~ /ms$/) { sub(/ms$/, "", v) } else if (v ~ /s$/) { sub(/s$/, "", v); v *= 1000 } printf "%.2f", v }'
}

median() { sort -n | awk '{ a[NR] = $1 } END { print a[int((NR + 1) / 2)] }'; }

start_server() { # db-url cache-bytes
    local caps=()
    if [ "$load_caps" = off ]; then
        caps=(--load-high-inflight 1000000000 --load-high-latency-ms 1000000000 --load-high-queue-ms 1000000000)
    fi
    RUST_LOG=warn "$bin" serve --db "$1" --listen "127.0.0.1:$port" --cache-bytes "$2" \
        --web-dir "$work/none" "${caps[@]}" >"$work/serve.log" 2>&1 &
    server=$!
    for _ in $(seq 1 100); do
        curl -fs "http://127.0.0.1:$port/readyz" >/dev/null 2>&1 && return 0
        sleep 0.1
    done
    cat "$work/serve.log" >&2
    return 1
}

# nginx serving $work/static on port+1, as deploy/nginx.conf's workers would.
start_nginx() {
    mkdir -p "$work/static" "$work/nginx/logs" "$work/nginx/tmp"
    cat >"$work/nginx/nginx.conf" <<EOF
worker_processes auto;
pid $work/nginx/nginx.pid;
error_log $work/nginx/logs/error.log warn;
events { worker_connections 16384; }
http {
    client_body_temp_path $work/nginx/tmp/body;
    proxy_temp_path $work/nginx/tmp/proxy;
    fastcgi_temp_path $work/nginx/tmp/fastcgi;
    uwsgi_temp_path $work/nginx/tmp/uwsgi;
    scgi_temp_path $work/nginx/tmp/scgi;
    access_log off;
    sendfile on;
    tcp_nopush on;
    keepalive_requests 100000;
    open_file_cache max=64;
    server {
        listen 127.0.0.1:$((port + 1)) backlog=4096 reuseport;
        root $work/static;
        default_type application/octet-stream;
    }
}
EOF
    chmod -R a+rX "$work"
    nginx -p "$work/nginx" -c "$work/nginx/nginx.conf" -g "daemon off; user $(id -un);" &
    nginx_pid=$!
    for _ in $(seq 1 100); do
        [ "$(curl -s -o /dev/null -w '%{http_code}' "http://127.0.0.1:$((port + 1))/")" != 000 ] && return 0
        sleep 0.1
    done
    return 1
}

# CPU time (user + system, in clock ticks) of some processes so far.
cpu_ticks() { # pid…
    local p
    for p in "$@"; do awk '{ print $14 + $15 }' "/proc/$p/stat" 2>/dev/null || echo 0; done | awk '{ s += $1 } END { print s + 0 }'
}

# One wrk run: "requests/s p50_ms p99_ms non-2xx cpu_us_per_request", the
# last over the processes serving (robust where other jobs share the cores).
wrk_run() { # url pid…
    local url=$1 out rps p50 p99 bad c0 c1 requests
    shift
    c0=$(cpu_ticks "$@")
    out=$(wrk -t"$threads" -c"$conns" -d"$duration" --latency "$url")
    c1=$(cpu_ticks "$@")
    requests=$(echo "$out" | awk '/requests in/ { print $1 }')
    rps=$(echo "$out" | awk '/Requests\/sec/ { print $2 }')
    p50=$(echo "$out" | awk '$1 == "50%" { print $2 }' | to_ms)
    p99=$(echo "$out" | awk '$1 == "99%" { print $2 }' | to_ms)
    bad=$(echo "$out" | awk '/Non-2xx/ { print $5 }')
    echo "$rps $p50 $p99 ${bad:-0} $(awk -v t=$((c1 - c0)) -v n="$requests" -v hz="$(getconf CLK_TCK)" 'BEGIN { printf "%.1f", n ? t / hz * 1e6 / n : 0 }')"
}

stop_server() {
    kill "$server"
    wait "$server" 2>/dev/null || true
    server=""
}

echo "machine: $(nproc) cores, $(uname -r); load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
echo "mesh: $(basename "$mesh"); wrk -t$threads -c$conns -d$duration --latency; median of $runs runs; load caps $load_caps"
echo
if [ "$peer_nginx" = on ]; then
    command -v nginx >/dev/null || { echo "nginx is missing: apt-get install -y nginx-light (or NGINX=off)" >&2; exit 1; }
    start_nginx
fi
echo "| backend | payload cache | batch (bytes) | requests/s | p50 ms | p99 ms | non-2xx | CPU µs a request | nginx static, same runs: requests/s, p50, p99 ms, CPU µs a request | Vitrine / nginx requests/s |"
echo "|---|---|---|---:|---:|---:|---:|---:|---|---:|"
for backend in $backends; do
    case $backend in
        sqlite) db="sqlite:$work/bench.db" ;;
        postgres)
            psql "$pg_admin" -qc "CREATE DATABASE $pg_name" >/dev/null
            db="${pg_admin%/*}/$pg_name"
            ;;
    esac
    "$bin" ingest "$mesh" --db "$db" --slug bench --title Bench --policy open >/dev/null
    for cache in on off; do
        bytes=$([ "$cache" = on ] && echo 268435456 || echo 0)
        start_server "$db" "$bytes"
        id=$(curl -fs "http://127.0.0.1:$port/api/models/bench" | sed -E 's/.*"compression_id":([0-9]+).*/\1/')
        for batch in $batches; do
            url="http://127.0.0.1:$port/api/compressions/$id/batches/$batch"
            size=$(curl -s "$url" | wc -c)
            peer=""
            if [ "$peer_nginx" = on ] && [ "$cache" = on ]; then
                curl -s -o "$work/static/batch-$batch" "$url"
                chmod a+r "$work/static/batch-$batch"
                peer="http://127.0.0.1:$((port + 1))/batch-$batch"
            fi
            : >"$work/runs"
            : >"$work/peer"
            for _ in $(seq 1 "$runs"); do
                # shellcheck disable=SC2046
                [ -z "$peer" ] || wrk_run "$peer" $(pgrep -P "$nginx_pid") >>"$work/peer"
                wrk_run "$url" "$server" >>"$work/runs"
            done
            rps=$(cut -d' ' -f1 "$work/runs" | median)
            versus="– | –"
            if [ -n "$peer" ]; then
                peer_rps=$(cut -d' ' -f1 "$work/peer" | median)
                versus="$peer_rps, $(cut -d' ' -f2 "$work/peer" | median), $(cut -d' ' -f3 "$work/peer" | median), $(cut -d' ' -f5 "$work/peer" | median) | $(awk "BEGIN { printf \"%.2f\", $rps / $peer_rps }")"
            fi
            echo "| $backend | $cache | $batch ($size) | $rps |" \
                "$(cut -d' ' -f2 "$work/runs" | median) | $(cut -d' ' -f3 "$work/runs" | median) |" \
                "$(cut -d' ' -f4 "$work/runs" | median) | $(cut -d' ' -f5 "$work/runs" | median) | $versus |"
        done
        stop_server
    done
done
echo
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
