#!/usr/bin/env bash
# The supported multi-instance topology, on loopback: a PostgreSQL cluster of
# its own, two `vitrine serve` instances on it, nginx in front as the caching
# reverse proxy (deploy/nginx.conf, rendered with this run's ports and paths),
# and the crowd harness (vitrine-load) through nginx. Each check prints
# PASS/FAIL and a detail line; the script exits non-zero when one FAILs.
# Results also land in $work/topology.md (RELIABILITY.md quotes them).
#
#   scripts/topology.sh           5,000 visitors at once, longer event crowds
#   scripts/topology.sh --short   CI: a few hundred visitors (≤ 2.5 minutes)
#
# Checks: crowd (p50/p99 over every request, statuses, nginx cache hit ratio,
# each instance's share, nginx's own p99, where the CPU went: time on a CPU
# and time waiting for one of nginx's workers, the harness and the instances,
# and the kernel's listen-queue drops and retransmissions over the crowd), kill (SIGKILL one instance mid-crowd: nobody fails,
# it rejoins), ingest (a new version mid-crowd reaches both instances within
# the bound, nobody mixes versions), rolling (SIGTERM, restart, next, under a
# crowd: no request lost), pg_restart (cached batches flow, uncached answers
# 503 + Retry-After, recovery without restarting Vitrine), leak (a
# researcher's manifest never reaches a public visitor through the cache),
# versus (the same crowds against nginx serving the same bytes as static
# files, alternated: what Vitrine adds to the proxy's cost).
#
# Environment: VISITORS (5000; short 300), TOPO_PG_PORT (25533), TOPO_PORT
# (18200: nginx; +1, +2 the instances), NO_BUILD (use the built binaries),
# KEEP_WORK (keep the work directory), TOPO_CHECKS (the checks to run, by
# name: "versus_static" alone for issue 46's benchmark), COHERENCE_BOUND_S (5), BIN_DIR
# (target/release: where vitrine and vitrine-load are).
# Never touches the shared PostgreSQL on 5432. Needs root for runuser
# (PostgreSQL refuses to run as root) and installs nginx with apt-get when
# it is missing. Check 8 (versus) and its environment are in
# scripts/topology-versus-static.sh.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
short=0
[ "${1:-}" = --short ] && short=1

export RUST_BACKTRACE=0 RUST_LOG=${RUST_LOG:-warn}
bin_dir=${BIN_DIR:-$root/target/release}
bin=$bin_dir/vitrine
load=$bin_dir/vitrine-load
if [ -z "${NO_BUILD:-}" ]; then
    cargo build --release -p vitrine -p vitrine-load
fi
ulimit -n "$(ulimit -Hn)" 2>/dev/null || true
if ! command -v nginx >/dev/null 2>&1; then
    echo "installing nginx"
    export DEBIAN_FRONTEND=noninteractive
    apt-get install -y -qq nginx-light >/dev/null 2>&1 || {
        apt-get update -qq
        apt-get install -y -qq nginx-light >/dev/null 2>&1 || apt-get install -y -qq nginx >/dev/null
    }
fi
nginx_bin=$(command -v nginx)
pg_bin=$(ls -d /usr/lib/postgresql/*/bin 2>/dev/null | sort -V | tail -n 1)
[ -n "$pg_bin" ] || { echo "no PostgreSQL binaries (apt-get install postgresql)" >&2; exit 1; }

if [ $short = 1 ]; then
    visitors=${VISITORS:-300} event_n=120 event_s=10
else
    visitors=${VISITORS:-5000} event_n=400 event_s=20
fi
bound=${COHERENCE_BOUND_S:-5}
work=$(mktemp -d /tmp/vitrine-topology.XXXXXX)
chmod 755 "$work"
port=${TOPO_PORT:-18200}
# Below the kernel's ephemeral range (32768–60999): stop 49's CI could not
# start PostgreSQL on 55432, most likely because a client socket of an
# earlier step held that port (faults.sh met the same on 55434).
pg_port=${TOPO_PG_PORT:-25533}
ports=($((port + 1)) $((port + 2)))
proxy=http://127.0.0.1:$port
results=$work/topology.md
pids=()
inst=("" "")
nginx_pid=""
pg_data=$work/pg/data

cleanup() {
    for p in "${inst[@]}" "${pids[@]}"; do [ -z "$p" ] || kill "$p" 2>/dev/null || true; done
    [ -z "$nginx_pid" ] || kill "$nginx_pid" 2>/dev/null || true
    runuser -u postgres -- "$pg_bin/pg_ctl" -D "$pg_data" -m immediate stop >/dev/null 2>&1 || true
    if [ -n "${KEEP_WORK:-}" ]; then echo "work dir kept: $work"; else rm -rf "$work"; fi
}
trap cleanup EXIT

failed=0
report() { # PASS|FAIL check detail
    printf '%-4s %-11s %s\n' "$1" "$2" "$3"
    printf '| %s | %s | %s |\n' "$2" "$1" "$(echo "$3" | tr '\n|' ' /')" >>"$results"
    [ "$1" != FAIL ] || failed=1
}
printf '| check | result | detail |\n|---|---|---|\n' >"$results"
now() { date +%s.%N; }
since() { awk "BEGIN { printf \"%.2f\", $(now) - $1 }"; }
code() { curl -s -o /dev/null -w '%{http_code}' "$@"; }

# PostgreSQL of our own.
pg_start() {
    runuser -u postgres -- "$pg_bin/pg_ctl" -D "$pg_data" -w -l "$work/pg/log" \
        -o "-p $pg_port -k $work/pg -c listen_addresses=127.0.0.1 -c fsync=off -c max_connections=200" start >/dev/null || {
        # The work directory goes with the exit trap: show why here.
        echo "PostgreSQL did not start on port $pg_port; its log:" >&2
        tail -n 30 "$work/pg/log" >&2 || true
        return 1
    }
}
pg_stop() { runuser -u postgres -- "$pg_bin/pg_ctl" -D "$pg_data" -m fast -w stop >/dev/null; }
mkdir -p "$work/pg"
chown postgres "$work/pg"
runuser -u postgres -- "$pg_bin/initdb" -D "$pg_data" -A trust -U postgres >/dev/null
pg_start
db=postgres://postgres@127.0.0.1:$pg_port/postgres

# Two versions of one model that differ in every payload size.
"$bin" sample torus --kilo-vertices 60 -o "$work/v1.ply" >/dev/null
"$bin" sample torus --kilo-vertices 80 -o "$work/v2.ply" >/dev/null
"$bin" ingest "$work/v1.ply" --db "$db" --slug topo --title Topology --policy exhibition >/dev/null
# A model nobody asks for until PostgreSQL is down (check_pg_restart).
"$bin" ingest "$work/v1.ply" --db "$db" --slug untouched --title Untouched --policy open >/dev/null
token=$("$bin" token --db "$db" --label topology)

start_instance() { # index
    local i=$1
    "$bin" serve --db "$db" --listen "127.0.0.1:${ports[$i]}" --web-dir /nonexistent \
        --trusted-proxies 127.0.0.1/32 --shutdown-delay-ms 300 --coherence-poll-ms 2000 \
        --db-max-connections 16 2>>"$work/serve$i.log" &
    inst[$i]=$!
    for _ in $(seq 1 300); do
        [ "$(code "http://127.0.0.1:${ports[$i]}/readyz")" = 200 ] && return 0
        sleep 0.1
    done
    echo "instance $i did not become ready:" >&2
    tail -20 "$work/serve$i.log" >&2
    return 1
}
start_instance 0
start_instance 1

# nginx from deploy/nginx.conf with this run's ports, paths and no root.
mkdir -p "$work/nginx/cache" "$work/nginx/logs" "$work/nginx/tmp"
sed -e "s|^pid .*|pid $work/nginx/nginx.pid;|" \
    -e "s|^error_log .*|error_log $work/nginx/logs/error.log warn;|" \
    -e "s|/var/log/nginx/vitrine-access.log|$work/nginx/logs/access.log|" \
    -e "s|/var/cache/nginx/vitrine|$work/nginx/cache|" \
    -e "s|127.0.0.1:8081|127.0.0.1:${ports[0]}|" \
    -e "s|127.0.0.1:8082|127.0.0.1:${ports[1]}|" \
    -e "s|listen 80 |listen 127.0.0.1:$port |" \
    -e "s|^worker_processes .*|worker_processes 2;|" \
    -e "s|^http {|http {\n    client_body_temp_path $work/nginx/tmp/body;\n    proxy_temp_path $work/nginx/tmp/proxy;\n    fastcgi_temp_path $work/nginx/tmp/fastcgi;\n    uwsgi_temp_path $work/nginx/tmp/uwsgi;\n    scgi_temp_path $work/nginx/tmp/scgi;|" \
    "$root/deploy/nginx.conf" >"$work/nginx/rendered.conf"
# Check 8's static server block in the same nginx, before the last `}`.
# shellcheck source=scripts/topology-versus-static.sh
source "$root/scripts/topology-versus-static.sh"
{ sed '$d' "$work/nginx/rendered.conf"; versus_static_server; } >"$work/nginx/nginx.conf"
# As root nginx's workers would run as nobody; keep them ours.
"$nginx_bin" -p "$work/nginx" -c "$work/nginx/nginx.conf" -t -q -g "user $(id -un);"
start_nginx() {
    "$nginx_bin" -p "$work/nginx" -c "$work/nginx/nginx.conf" -g "daemon off; user $(id -un);" 2>>"$work/nginx/logs/stderr.log" &
    nginx_pid=$!
    for _ in $(seq 1 100); do [ "$(code "$proxy/nginx-healthz")" = 200 ] && break; sleep 0.1; done
}
start_nginx
access=$work/nginx/logs/access.log

profile=$work/profile.json
"$load" profile --url "http://127.0.0.1:${ports[0]}" --slug topo -o "$profile" 2>/dev/null

# Requests in the access log between two times (epoch seconds): the nginx
# cache hit ratio, each instance's share, statuses.
log_stats() { # from to
    sleep 1.2 # the access log is flushed every second
    awk -v from="$1" -v to="$2" -v a="127.0.0.1:${ports[0]}" -v b="127.0.0.1:${ports[1]}" '
        $1 >= from && $1 <= to && $4 ~ /^"\/api\// {
            n++; s[$2]++
            c = substr($7, 7); cache[c]++
            # The instance that answered: the last one tried.
            k = split(substr($0, index($0, "upstream=") + 9), tried, ", ")
            if (tried[k] == a) ua++
            if (tried[k] == b) ub++
        }
        END {
            hits = cache["HIT"] + cache["STALE"] + cache["UPDATING"] + cache["REVALIDATED"]
            printf "%d API requests through nginx, cache hit ratio %.1f %% (", n, n ? 100 * hits / n : 0
            sep = ""; for (k in cache) { printf "%s%s %d", sep, k, cache[k]; sep = ", " }
            printf "); to the instances: A %d, B %d (A %.0f %%); statuses", ua, ub, (ua + ub) ? 100 * ua / (ua + ub) : 0
            for (k in s) printf " %s: %d", k, s[k]
        }' "$access"
}

crowd_line() { grep -E '^[0-9]+ visitors' "$1" | tail -n 1; }
no_failed() { grep -qE '\(([0-9]+) completed, 0 failed' "$1"; }

# Where a crowd's time goes (issue 24). Time on a CPU and time runnable but
# waiting for one, in ns, summed over the threads of some processes
# (/proc/PID/task/*/schedstat: run time, run-queue wait, slices).
sched() { # pid… → "run_ns wait_ns"
    local p f files=()
    for p in "$@"; do
        for f in /proc/"$p"/task/*/schedstat; do [ -r "$f" ] && files+=("$f"); done
    done
    [ ${#files[@]} -gt 0 ] || { echo "0 0"; return 0; }
    # A thread may exit between the glob and the read.
    { cat "${files[@]}" 2>/dev/null || true; } | awk '{ r += $1; w += $2 } END { printf "%d %d\n", r, w }'
}
# The kernel's listen-queue counters (a dropped SYN or handshake costs its
# visitor a 1 s retransmission) and TCP retransmissions, as "name value".
tcp_counters() {
    awk '/^TcpExt:/ { if (!h) { for (i = 2; i <= NF; i++) n[i] = $i; h = 1 }
                      else for (i = 2; i <= NF; i++)
                          if (n[i] ~ /^(ListenOverflows|ListenDrops|TCPReqQFullDrop|TCPReqQFullDoCookies)$/) print n[i], $i }' \
        /proc/net/netstat 2>/dev/null
    awk '/^Tcp:/ { if (!t) { for (i = 2; i <= NF; i++) n[i] = $i; t = 1 }
                   else for (i = 2; i <= NF; i++) if (n[i] == "RetransSegs") print n[i], $i }' \
        /proc/net/snmp 2>/dev/null
}
counter_delta() { # before after → "name +delta, …"
    awk 'NR == FNR { b[$1] = $2; next } { printf "%s%s +%d", sep, $1, $2 - b[$1]; sep = ", " }' "$1" "$2"
}
cpu_ticks() { awk '/^cpu / { print $2 + $3 + $4 + $7 + $8, $2 + $3 + $4 + $5 + $6 + $7 + $8 }' /proc/stat; }
# nginx's own view: p99 of $request_time (from reading a request to its
# last byte) over the API requests logged between two times.
nginx_p99() { # from to
    awk -v from="$1" -v to="$2" '$1 >= from && $1 <= to && $4 ~ /^"\/api\// { print $6 * 1000 }' "$access" |
        sort -n | awk '{ v[NR] = $1 } END { if (!NR) { printf "-"; exit } k = int(NR * 0.99 + 0.5); if (k < 1) k = 1; printf "%.0f", v[k] }'
}

# 1. The crowd: every visitor at once, through nginx.
check_crowd() {
    local t0 out=$work/crowd.out
    local workers
    workers=$(ps -o pid= --ppid "$nginx_pid" | tr '\n' ' ')
    local n0 i0 c0 m0 h=0 hs="0 0" x rc=0
    # shellcheck disable=SC2086
    n0=$(sched $workers)
    i0=$(sched "${inst[@]}")
    m0=$(cpu_ticks)
    tcp_counters >"$work/tcp.before"
    t0=$(now)
    "$load" crowd --url "$proxy" --slug topo --profile "$profile" --visitors "$visitors" \
        --pattern burst --token "$token" --stay-s 0 --allow 429,503 \
        --json "$work/crowd.json" >"$out" 2>&1 &
    h=$!
    # The harness's threads are gone once it exits: sampled while it runs,
    # keeping the largest sample (as it exits, only its main thread is left).
    while kill -0 "$h" 2>/dev/null; do
        x=$(sched "$h")
        [ "${x%% *}" -le "${hs%% *}" ] || hs=$x
        sleep 0.2
    done
    wait "$h" || rc=$?
    local t1 n1 i1 m1
    t1=$(now)
    # shellcheck disable=SC2086
    n1=$(sched $workers)
    i1=$(sched "${inst[@]}")
    m1=$(cpu_ticks)
    tcp_counters >"$work/tcp.after"
    local tck
    tck=$(getconf CLK_TCK 2>/dev/null || echo 100)
    local cpu
    cpu=$(awk -v n0="$n0" -v n1="$n1" -v i0="$i0" -v i1="$i1" -v h="$hs" -v m0="$m0" -v m1="$m1" \
        -v tck="$tck" -v wall="$(awk "BEGIN { print $t1 - $t0 }")" -v cores="$(nproc)" 'BEGIN {
            split(n0, a); split(n1, b); split(i0, c); split(i1, d); split(h, e); split(m0, f); split(m1, g)
            busy = (g[1] - f[1]) / tck; total = (g[2] - f[2]) / tck
            nr = (b[1] - a[1]) / 1e9; nw = (b[2] - a[2]) / 1e9
            ir = (d[1] - c[1]) / 1e9; iw = (d[2] - c[2]) / 1e9
            hr = e[1] / 1e9; hw = e[2] / 1e9
            other = busy - nr - ir - hr; if (other < 0) other = 0
            printf "CPU over the crowd (%.1f s, %d cores): busy %.1f of %.1f CPU-s; on a CPU / runnable but waiting for one: nginx workers %.2f / %.2f s, the harness %.2f / %.2f s, the instances %.2f / %.2f s; everything else (PostgreSQL, other work on the machine) %.2f CPU-s",
                wall, cores, busy, total, nr, nw, hr, hw, ir, iw, other }')
    local detail
    detail="$visitors visitors at once through nginx: $(crowd_line "$out"). $(log_stats "$t0" "$t1"); nginx-side p99 $(nginx_p99 "$t0" "$t1") ms. $cpu. Kernel: $(counter_delta "$work/tcp.before" "$work/tcp.after") (somaxconn $(cat /proc/sys/net/core/somaxconn 2>/dev/null), tcp_max_syn_backlog $(cat /proc/sys/net/ipv4/tcp_max_syn_backlog 2>/dev/null))"
    if [ $rc = 0 ]; then
        report PASS crowd "$detail"
    else
        report FAIL crowd "$(tail -n 6 "$out")"
    fi
}

# 2. SIGKILL one instance mid-crowd, start it again.
check_kill() {
    local out=$work/kill.out
    "$load" crowd --url "$proxy" --slug topo --profile "$profile" --visitors "$event_n" \
        --pattern "steady:$event_s" --token "$token" --stay-s 0 --allow 429 >"$out" 2>&1 &
    local crowd=$!
    sleep 3
    kill -9 "${inst[0]}"
    wait "${inst[0]}" 2>/dev/null || true
    local killed_at
    killed_at=$(now)
    sleep 3
    start_instance 0
    local back_at
    back_at=$(now)
    local ok=1
    wait "$crowd" || ok=0
    no_failed "$out" || ok=0
    # Rejoined: uncached requests spread over both again.
    sleep 6 # fail_timeout: nginx tries the instance again
    local t1
    t1=$(now)
    for i in $(seq 1 20); do curl -s -o /dev/null "$proxy/api/models/topo?device=desktop&probe=kill$i"; done
    local share
    share=$(log_stats "$t1" "$(now)")
    echo "$share" | grep -qE 'A [1-9][0-9]*, B' || ok=0
    local detail="instance A killed (SIGKILL) under $event_n visitors over $event_s s, restarted $(awk "BEGIN { printf \"%.1f\", $back_at - $killed_at }") s later: $(crowd_line "$out"). After restart, 20 uncached requests: $share"
    if [ $ok = 1 ]; then report PASS kill "$detail"; else report FAIL kill "$detail $(tail -n 4 "$out")"; fi
}

# 3. A new version ingested mid-crowd.
check_ingest() {
    local out=$work/ingest.out
    "$load" crowd --url "$proxy" --slug topo --profile "$profile" --visitors "$event_n" \
        --pattern "steady:$event_s" --token "$token" --stay-s 5 --allow 429 \
        --require-versions 2 >"$out" 2>&1 &
    local crowd=$!
    sleep 3
    "$bin" ingest "$work/v2.ply" --db "$db" --slug topo --title Topology --policy exhibition --new-version >/dev/null
    local t0 seen=() ok=1
    t0=$(now)
    for i in 0 1; do
        local took=""
        for _ in $(seq 1 $((bound * 20))); do
            if curl -s "http://127.0.0.1:${ports[$i]}/api/models/topo" | grep -q '"version":2'; then
                took=$(since "$t0")
                break
            fi
            sleep 0.05
        done
        [ -n "$took" ] || { ok=0; took="not within $bound"; }
        seen+=("$took")
    done
    local through=""
    for _ in $(seq 1 $((bound * 20))); do
        if curl -s "$proxy/api/models/topo" | grep -q '"version":2'; then through=$(since "$t0"); break; fi
        sleep 0.05
    done
    [ -n "$through" ] || { ok=0; through="not within $bound"; }
    wait "$crowd" || ok=0
    no_failed "$out" || ok=0
    local detail="version 2 ingested by the CLI at t=3 s: instance A served it after ${seen[0]} s, B after ${seen[1]} s, nginx (max-age 2 s) after $through s (bound $bound s). $(grep '^versions' "$out"). $(crowd_line "$out")"
    if [ $ok = 1 ]; then report PASS ingest "$detail"; else report FAIL ingest "$detail $(tail -n 4 "$out")"; fi
}

# 4. Rolling restart: SIGTERM, wait, start, next.
check_rolling() {
    local out=$work/rolling.out
    "$load" crowd --url "$proxy" --slug topo --profile "$profile" --visitors "$event_n" \
        --pattern "steady:$((event_s + 12))" --token "$token" --stay-s 0 --allow 429 >"$out" 2>&1 &
    local crowd=$!
    sleep 2
    local i took=()
    for i in 0 1; do
        local t0
        t0=$(now)
        kill -TERM "${inst[$i]}"
        wait "${inst[$i]}" 2>/dev/null || true
        start_instance "$i"
        took+=("$(since "$t0")")
        # nginx tries an instance it took out again after fail_timeout (5 s).
        sleep 6
    done
    local ok=1
    wait "$crowd" || ok=0
    no_failed "$out" || ok=0
    local detail="A then B: SIGTERM, drained and exited, started again (${took[0]} s, ${took[1]} s) under $event_n visitors: $(crowd_line "$out")"
    if [ $ok = 1 ]; then report PASS rolling "$detail"; else report FAIL rolling "$detail $(tail -n 4 "$out")"; fi
}

# 5. PostgreSQL restarted mid-crowd.
check_pg_restart() {
    local out=$work/pg.out down=4
    # The cache is warm (earlier checks); the crowd asks what nginx holds.
    "$load" crowd --url "$proxy" --slug topo --profile "$profile" --visitors "$event_n" \
        --pattern "steady:$((event_s + 6))" --stay-s 0 --allow 429,503 >"$out" 2>&1 &
    local crowd=$!
    sleep 3
    pg_stop
    local t_down
    t_down=$(now)
    sleep 1.5
    # Uncached anywhere (a model nobody asked for yet): 503 with Retry-After.
    local probe
    probe=$(curl -s -D - -o /dev/null "$proxy/api/models/untouched")
    sleep "$((down - 1))"
    local t_up
    t_up=$(now)
    pg_start
    local recovered="" t1
    t1=$(now)
    for _ in $(seq 1 300); do
        if [ "$(code "http://127.0.0.1:${ports[0]}/readyz")" = 200 ] &&
            [ "$(code "http://127.0.0.1:${ports[1]}/readyz")" = 200 ] &&
            [ "$(code "$proxy/api/models/untouched?probe=up$RANDOM")" = 200 ]; then
            recovered=$(since "$t1")
            break
        fi
        sleep 0.1
    done
    local ok=1
    wait "$crowd" || ok=0
    no_failed "$out" || ok=0
    echo "$probe" | head -n 1 | grep -q ' 503' || ok=0
    echo "$probe" | grep -qi '^retry-after:' || ok=0
    [ -n "$recovered" ] || ok=0
    local during
    during=$(log_stats "$t_down" "$t_up")
    local hits
    hits=$(awk -v from="$t_down" -v to="$t_up" '$1 >= from && $1 <= to && $2 == 200 && $4 ~ /batches/ && /cache=(HIT|STALE|UPDATING)/' "$access" | wc -l)
    [ "$hits" -gt 0 ] || ok=0
    local detail="PostgreSQL stopped ${down} s under $event_n visitors: $hits batches answered 200 from the nginx cache meanwhile; an uncached manifest got '$(echo "$probe" | head -n 1 | tr -d '\r')' with $(echo "$probe" | grep -i '^retry-after:' | tr -d '\r'); both instances ready and an uncached request 200 again ${recovered:-never} s after PostgreSQL was back, no restart of Vitrine. During the outage: $during. $(crowd_line "$out")"
    if [ $ok = 1 ]; then report PASS pg_restart "$detail"; else report FAIL pg_restart "$detail $(tail -n 4 "$out")"; fi
}

# 6. A researcher's manifest never reaches a public visitor through nginx.
check_leak() {
    local ok=1 url="$proxy/api/models/topo?device=desktop&probe=leak"
    local researcher public public2 reused
    researcher=$(curl -s -H "Authorization: Bearer $token" "$url")
    public=$(curl -s "$url")
    # Cached for the public now; a token request must not get that copy…
    reused=$(curl -s -D - -o /dev/null -H "Authorization: Bearer $token" "$url" | grep -i '^x-cache-status' | tr -d '\r')
    # …and ?token= is personal as well.
    curl -s -o /dev/null "$url&token=$token"
    public2=$(curl -s "$url")
    echo "$researcher" | grep -q '"audience":"researcher"' || ok=0
    for p in "$public" "$public2"; do
        echo "$p" | grep -q '"audience":"public"' || ok=0
        echo "$p" | grep -q '"audience":"researcher"' && ok=0
    done
    # A payload only researchers may fetch: never stored, so the public
    # asking the same URL next is refused by an instance, not served a copy.
    local private_url private_r private_p
    private_url=$(echo "$public" | grep -o '"url":"[^"]*","allowed":false' | tail -n 1 | cut -d'"' -f4)
    if [ -n "$private_url" ]; then
        private_r=$(code -H "Authorization: Bearer $token" "$proxy$private_url")
        private_p=$(code "$proxy$private_url")
        [ "$private_r" = 200 ] && [ "$private_p" != 200 ] || ok=0
    else
        ok=0 private_r="no level above the public cap" private_p="-"
    fi
    local detail="token, then the same URL without: researcher / $(echo "$public" | grep -o '"audience":"[a-z]*"' | head -1); the token request after a public one: ${reused:-no X-Cache-Status}; a researcher-only batch ($private_url): researcher $private_r, then the public $private_p"
    if [ $ok = 1 ]; then report PASS leak "$detail"; else report FAIL leak "$detail"; fi
}

# 7. nginx keys the cache on the device class by Vitrine's own rule
# (deploy/nginx.conf's $vitrine_device, visitor.rs's guess_device): for each
# User-Agent (and Sec-CH-UA-Mobile) the class nginx keyed on is the class
# the answering instance guessed, and a cached tablet manifest never
# answers a desktop.
check_device() {
    local ok=1 detail="" n=0 line hint ua origin keyed
    while IFS='|' read -r hint ua; do
        n=$((n + 1))
        local url="$proxy/api/models/topo?probe=device-$n"
        local args=(-s -D "$work/device.h" -A "$ua")
        [ -n "$hint" ] && args+=(-H "Sec-CH-UA-Mobile: $hint")
        origin=$(curl "${args[@]}" "$url" | grep -o '"device":"[a-z]*"' | head -1 | cut -d'"' -f4)
        keyed=$(grep -i '^x-vitrine-device:' "$work/device.h" | awk '{print $2}' | tr -d '\r')
        [ "$origin" = "$keyed" ] || { ok=0; detail="$detail [$ua: nginx $keyed, Vitrine $origin]"; }
    done <<'AGENTS'
|Mozilla/5.0 (X11; Linux x86_64) AppleWebKit/537.36 Chrome/120.0 Safari/537.36
|Mozilla/5.0 (iPad; CPU OS 17_0 like Mac OS X) AppleWebKit/605.1.15 Mobile/15E148
|Mozilla/5.0 (iPhone; CPU iPhone OS 17_0 like Mac OS X) Mobile/15E148
|Mozilla/5.0 (Linux; Android 14; Pixel 8) Chrome/120.0 Mobile Safari/537.36
|Mozilla/5.0 (Linux; Android 14; SM-X710) Chrome/120.0 Safari/537.36
|Mozilla/5.0 (Windows NT 10.0; Win64; x64; Tablet PC 2.0) Chrome/120.0
?1|Mozilla/5.0 (Linux; Android 10; K) Chrome/120.0 Safari/537.36
?0|Mozilla/5.0 (Linux; Android 10; K) Chrome/120.0 Safari/537.36
?1|Mozilla/5.0 (iPad; CPU OS 17_0 like Mac OS X) Mobile/15E148
|curl/8.0
AGENTS
    # One URL, a tablet first, then a desktop: the desktop is not served
    # the tablet's cached copy.
    local url="$proxy/api/models/topo?probe=device-shared" tablet desktop
    tablet=$(curl -s -A "Mozilla/5.0 (iPad; CPU OS 17_0) Mobile/15E148" "$url" | grep -o '"device":"[a-z]*"' | head -1)
    desktop=$(curl -s -A "Mozilla/5.0 (X11; Linux x86_64) Chrome/120.0" "$url" | grep -o '"device":"[a-z]*"' | head -1)
    [ "$tablet" = '"device":"tablet"' ] && [ "$desktop" = '"device":"desktop"' ] || { ok=0; detail="$detail [shared URL: tablet $tablet, then desktop $desktop]"; }
    detail="$n User-Agents: nginx's class = Vitrine's${detail:+; mismatches:$detail}; one URL asked by a tablet then a desktop: $tablet, $desktop"
    if [ $ok = 1 ]; then report PASS device "$detail"; else report FAIL device "$detail"; fi
}

started=$(now)
for check in ${TOPO_CHECKS:-leak device crowd kill ingest rolling pg_restart versus_static}; do
    [ "$check" != versus_static ] || versus_fill_static_root
    "check_$check"
done
echo
echo "topology checks took $(since "$started") s (after setup); results: $results"
cat "$results"
exit $failed
