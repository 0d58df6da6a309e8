#!/usr/bin/env bash
# Fault injection against the release `vitrine` binary: each case
# prints PASS/FAIL/SKIP and a detail line; the script exits non-zero if any
# case FAILs. Results also land in $WORK/faults.md (RELIABILITY.md quotes them).
#
#   scripts/faults.sh            every case, longer crowds
#   scripts/faults.sh --short    CI: the same cases with smaller crowds (~2 minutes)
#   scripts/faults.sh CASE...    only these (pg_restart slow_db sqlite_locked
#                                sqlite_readonly kill9_ingest disk_full
#                                disconnects shutdown hostile)
#
# PostgreSQL cases run on a throw-away cluster of their own (initdb into a
# temporary directory, port $FAULT_PG_PORT, default 25433) so that stopping
# it never disturbs the shared server on 5432; they SKIP when no PostgreSQL
# binaries are installed (apt-get install postgresql). The read-only and
# disk-full cases use a read-only bind mount and a tiny tmpfs, which need
# root (CAP_SYS_ADMIN); without it the disk-full case falls back to
# RLIMIT_FSIZE (prlimit) and the read-only case SKIPs.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
short=0
cases=()
for a in "$@"; do
    case $a in
        --short) short=1 ;;
        -*) echo "unknown flag $a" >&2; exit 2 ;;
        *) cases+=("$a") ;;
    esac
done
[ ${#cases[@]} -gt 0 ] || cases=(pg_restart slow_db sqlite_locked sqlite_readonly kill9_ingest disk_full disconnects shutdown hostile)

export RUST_BACKTRACE=0 RUST_LOG=${RUST_LOG:-warn}
bin=$root/target/release/vitrine
load=$root/target/release/vitrine-load
if [ -z "${NO_BUILD:-}" ]; then
    # One build of both, as scripts/build.sh makes it: built apart, the two
    # unify their dependencies' features differently and the second build
    # recompiles tokio, hyper, sqlx and the service.
    cargo build --release -p vitrine -p vitrine-load
fi
ulimit -n "$(ulimit -Hn)" 2>/dev/null || true
mesh=${MESH:-$root/../shared/data/meshes/igea.ply}
[ -f "$mesh" ] || mesh=""
work=$(mktemp -d /tmp/vitrine-faults.XXXXXX)
chmod 755 "$work"
port=${FAULT_PORT:-18191}
url=http://127.0.0.1:$port
# Below the kernel's ephemeral range (32768–60999): a client socket that
# happened to take 55434 once kept the delay line from listening.
pg_port=${FAULT_PG_PORT:-25433}
proxy_port=$((pg_port + 1))
pids=()
mounts=()
pg_data=""
pg_bin=""
results=$work/faults.md

cleanup() {
    for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
    for m in "${mounts[@]}"; do umount "$m" 2>/dev/null || true; done
    if [ -n "$pg_data" ]; then runuser -u postgres -- "$pg_bin/pg_ctl" -D "$pg_data" -m immediate stop >/dev/null 2>&1 || true; fi
    if [ -n "${KEEP_WORK:-}" ]; then echo "work dir kept: $work"; else rm -rf "$work"; fi
}
trap cleanup EXIT

failed=0
report() { # PASS|FAIL|SKIP case detail
    printf '%-4s %-16s %s\n' "$1" "$2" "$3"
    printf '| %s | %s | %s |\n' "$2" "$1" "$(echo "$3" | tr '\n|' ' /')" >>"$results"
    [ "$1" != FAIL ] || failed=1
}
printf '| case | result | detail |\n|---|---|---|\n' >"$results"

# A sample model: igea.ply when the shared meshes are there, else a torus.
sample() {
    if [ -z "$mesh" ]; then
        mesh=$work/torus.ply
        "$bin" sample torus --kilo-vertices 100 -o "$mesh" >/dev/null
    fi
    echo "$mesh"
}

ingest() { # db slug [extra...]
    local db=$1 slug=$2
    shift 2
    "$bin" ingest "$(sample)" --db "$db" --slug "$slug" --title "$slug" "$@" >/dev/null
}

server=""
proxy_pid=""
serve() { # db [extra flags...]
    local db=$1
    shift
    "$bin" serve --db "$db" --listen "127.0.0.1:$port" --web-dir /nonexistent "$@" 2>>"$work/serve.log" &
    server=$!
    pids+=("$server")
    # Up to 30 s: through a delay line every query of the migrations costs a
    # round trip or more, and a busy CI machine stretches that further.
    for _ in $(seq 1 300); do
        curl -fs "$url/readyz" >/dev/null 2>&1 && return 0
        sleep 0.1
    done
    echo "server did not become ready within 30 s:" >&2
    tail -20 "$work/serve.log" >&2
    return 1
}

stop_proxy() {
    [ -z "$proxy_pid" ] || kill "$proxy_pid" 2>/dev/null || true
    proxy_pid=""
}

give_up() { # case detail: a FAIL that ends the case, its server and delay line with it
    report FAIL "$1" "$2"
    stop_server
    stop_proxy
}

proxy() { # delay-ms: a TCP delay line in front of the throw-away cluster, once it listens
    "$load" proxy --listen "127.0.0.1:$proxy_port" --to "127.0.0.1:$pg_port" --delay-ms "$1" 2>>"$work/proxy.log" &
    pids+=("$!")
    proxy_pid=$!
    for _ in $(seq 1 100); do
        (exec 3<>"/dev/tcp/127.0.0.1/$proxy_port") 2>/dev/null && return 0
        sleep 0.1
    done
    echo "the delay line did not listen on $proxy_port:" >&2
    tail -5 "$work/proxy.log" >&2
    return 1
}

stop_server() {
    [ -n "$server" ] || return 0
    kill "$server" 2>/dev/null || true
    wait "$server" 2>/dev/null || true
    server=""
}

code() { curl -s -o /dev/null -w '%{http_code}' "$@"; }

profile=$work/profile.json
make_profile() { # once: the decode time of each level of the sample model
    [ -f "$profile" ] && return 0
    local db=sqlite:$work/profile.db
    ingest "$db" sample --policy open
    serve "$db"
    "$load" profile --url "$url" --slug sample -o "$profile" 2>/dev/null
    stop_server
}

pg_start() {
    runuser -u postgres -- "$pg_bin/pg_ctl" -D "$pg_data" -w -l "$work/pg/log" \
        -o "-p $pg_port -k $work/pg -c listen_addresses=127.0.0.1 -c fsync=off" start >/dev/null || {
        # The work directory goes with the exit trap: show why here.
        echo "PostgreSQL did not start on port $pg_port; its log:" >&2
        tail -n 30 "$work/pg/log" >&2 || true
        return 1
    }
}
pg_stop() { runuser -u postgres -- "$pg_bin/pg_ctl" -D "$pg_data" -m fast -w stop >/dev/null; }

# A PostgreSQL cluster of our own, created on first use.
pg_db=""
pg_setup() {
    [ -n "$pg_db" ] && return 0
    pg_bin=$(ls -d /usr/lib/postgresql/*/bin 2>/dev/null | sort -V | tail -n 1)
    if [ -z "$pg_bin" ] || ! id postgres >/dev/null 2>&1; then
        return 1
    fi
    mkdir -p "$work/pg"
    chown postgres "$work/pg"
    runuser -u postgres -- "$pg_bin/initdb" -D "$work/pg/data" -A trust -U postgres >/dev/null
    pg_data=$work/pg/data
    pg_start
    pg_db=postgres://postgres@127.0.0.1:$pg_port/postgres
    ingest "$pg_db" sample --policy open
    make_profile
}

if [ $short = 1 ]; then crowd_n=120 crowd_s=16; else crowd_n=400 crowd_s=30; fi

case_pg_restart() {
    pg_setup || { report SKIP pg_restart "no PostgreSQL binaries (apt-get install postgresql)"; return; }
    # Caches short, so that every request needs the database.
    serve "$pg_db" --cache-bytes 0 --record-ttl-ms 200 --db-timeout-ms 1000
    local stop_at=4 down=4
    local clean_after=$((stop_at + down + 4))
    "$load" crowd --url "$url" --slug sample --profile "$profile" --visitors "$crowd_n" \
        --pattern "steady:$crowd_s" --require 503 --clean-after-s "$clean_after" \
        --json "$work/pg_restart.json" >"$work/pg_restart.out" 2>&1 &
    local crowd=$!
    sleep "$stop_at"
    pg_stop
    sleep "$down"
    pg_start
    local t1
    t1=$(date +%s.%N)
    until [ "$(code "$url/readyz")" = 200 ]; do sleep 0.05; done
    local recovered
    recovered=$(awk "BEGIN { printf \"%.2f\", $(date +%s.%N) - $t1 }")
    if wait "$crowd"; then
        report PASS pg_restart "PostgreSQL stopped ${down} s at t=${stop_at} s under a crowd of $crowd_n: $(grep -c '503' "$work/pg_restart.out") timeline buckets with 503 (all with Retry-After); /readyz 200 again ${recovered} s after PostgreSQL was back, without restarting Vitrine; every request from t=${clean_after} s answered 200. $(tail -n 3 "$work/pg_restart.out" | head -n 1)"
    else
        report FAIL pg_restart "$(tail -n 5 "$work/pg_restart.out")"
    fi
    cat "$work/pg_restart.out"
    stop_server
}

case_slow_db() {
    pg_setup || { report SKIP slow_db "no PostgreSQL binaries"; return; }
    proxy 50 || { report FAIL slow_db "the delay line did not start"; return; }
    local out=""
    for caps in on off; do
        local flags=(--cache-bytes 0)
        [ $caps = off ] && flags+=(--admit-rate 0 --load-high-inflight 1000000000 --load-high-latency-ms 1000000000 --load-high-queue-ms 1000000000)
        serve "postgres://postgres@127.0.0.1:$proxy_port/postgres" "${flags[@]}" || {
            give_up slow_db "caps $caps: the server did not become ready through the delay line (see above)"
            return
        }
        if "$load" crowd --url "$url" --slug sample --profile "$profile" --visitors "$crowd_n" \
            --pattern burst >"$work/slow_db_$caps.out" 2>&1; then
            out+="caps $caps: $(tail -n 2 "$work/slow_db_$caps.out" | head -n 1). "
        else
            give_up slow_db "caps $caps: $(tail -n 4 "$work/slow_db_$caps.out")"
            return
        fi
        stop_server
    done
    stop_proxy
    report PASS slow_db "+50 ms on every PostgreSQL answer (TCP delay line), payload cache off, $crowd_n visitors at once. $out"
}

case_sqlite_locked() {
    local db=$work/locked.db
    ingest "sqlite:$db" sample --policy open
    serve "sqlite:$db" --cache-bytes 0 --record-ttl-ms 200
    # Another process holds SQLite's write lock (BEGIN IMMEDIATE) until the
    # second ingest has given up, however long its encoding takes on a busy
    # machine (at most 120 s): a fixed hold let a slow encode outlast it.
    local release=$work/locked.release held=$work/locked.held
    python3 -c "
import os, sqlite3, time
c = sqlite3.connect('$db', isolation_level=None)
c.execute('BEGIN IMMEDIATE'); c.execute('UPDATE model SET title = title')
open('$held', 'w').close()
t0 = time.time()
while not os.path.exists('$release') and time.time() - t0 < 120: time.sleep(0.05)
c.execute('ROLLBACK')
print(round(time.time() - t0, 1))" >"$work/locked.seconds" &
    local locker=$!
    while [ ! -e "$held" ]; do
        kill -0 "$locker" 2>/dev/null || { report FAIL sqlite_locked "the locking process could not take the write lock"; stop_server; return; }
        sleep 0.05
    done
    "$load" crowd --url "$url" --slug sample --profile "$profile" --visitors 60 --pattern steady:5 \
        --allow "" >"$work/locked_crowd.out" 2>&1 &
    local crowd=$!
    local t0=$SECONDS
    local ingest_out
    if ingest_out=$("$bin" ingest "$(sample)" --db "sqlite:$db" --slug second --title second 2>&1); then
        touch "$release"
        wait "$locker" || true
        report FAIL sqlite_locked "ingest succeeded while another process held the write lock"
    else
        local waited=$((SECONDS - t0))
        touch "$release"
        wait "$locker"
        if wait "$crowd" && ingest "sqlite:$db" second && [ "$(code "$url/api/models/second")" = 200 ]; then
            report PASS sqlite_locked "write lock held $(cat "$work/locked.seconds") s by another process: readers unaffected (WAL), $(grep -o '[0-9]* requests, p50 [^,]*, p99 [^,]*' "$work/locked_crowd.out"), no error; an ingest gave up after ${waited} s with: $(echo "$ingest_out" | grep -m1 -o 'database.*locked' || echo "$ingest_out" | head -n 3); the same ingest succeeded after the lock was released"
        else
            report FAIL sqlite_locked "$(tail -n 4 "$work/locked_crowd.out")"
        fi
    fi
    stop_server
}

case_sqlite_readonly() {
    local dir=$work/ro
    mkdir -p "$dir"
    ingest "sqlite:$dir/ro.db" sample --policy open
    serve "sqlite:$dir/ro.db" --cache-bytes 0 --record-ttl-ms 200
    [ "$(code "$url/api/models/sample")" = 200 ] || { report FAIL sqlite_readonly "not serving before"; stop_server; return; }
    if ! { mount --bind "$dir" "$dir" && mount -o remount,ro,bind "$dir"; } 2>/dev/null; then
        report SKIP sqlite_readonly "cannot mount read-only here (needs CAP_SYS_ADMIN); root ignores file modes"
        stop_server
        return
    fi
    mounts+=("$dir")
    touch "$dir/probe" 2>/dev/null && { report FAIL sqlite_readonly "mount is writable"; return; }
    local serving ingest_out reads
    serving=$("$load" crowd --url "$url" --slug sample --profile "$profile" --visitors 40 --pattern steady:3 --allow "" 2>&1 | grep -o '[0-9]* requests, p50 [^,]*, p99 [^,]*' || true)
    reads=$?
    stop_server
    # A fresh start on the read-only volume serves too.
    serve "sqlite:$dir/ro.db" --cache-bytes 0
    local fresh
    fresh=$(code "$url/api/models/sample")
    stop_server
    if ingest_out=$("$bin" ingest "$(sample)" --db "sqlite:$dir/ro.db" --slug other --title other 2>&1); then
        report FAIL sqlite_readonly "ingest into a read-only database succeeded?"
    elif [ -n "$serving" ] && [ "$fresh" = 200 ]; then
        report PASS sqlite_readonly "database volume remounted read-only while serving: reads go on ($serving, no error); a fresh start on it serves ($fresh); ingest fails with: $(echo "$ingest_out" | grep -m1 -o 'attempt to write a readonly database' || echo "$ingest_out" | head -n 2)"
    else
        report FAIL sqlite_readonly "serving on read-only volume: crowd '$serving' ($reads), fresh start $fresh"
    fi
    umount "$dir"
    mounts=()
}

kill9_one() { # db label
    local db=$1 label=$2
    local log=$work/kill9_$label.log
    VITRINE_TEST_PAUSE_BEFORE_COMMIT_MS=60000 "$bin" ingest "$(sample)" --db "$db" --slug killed --title killed >/dev/null 2>"$log" &
    local child=$!
    for _ in $(seq 1 600); do
        grep -q 'pausing' "$log" 2>/dev/null && break
        sleep 0.1
    done
    grep -q 'pausing' "$log" || { echo "ingest never reached its commit"; return 1; }
    local during
    during=$(code "$url/api/models/killed")
    kill -9 "$child"
    wait "$child" 2>/dev/null || true
    sleep 0.3
    local after
    after=$(code "$url/api/models/killed")
    ingest "$db" killed
    sleep 0.3
    local version
    version=$(curl -s "$url/api/models/killed" | sed -E 's/.*"version":([0-9]+).*/\1/')
    echo "$label: before kill $during, after kill $after, re-ingest → version $version"
    [ "$during" = 404 ] && [ "$after" = 404 ] && [ "$version" = 1 ]
}

case_kill9_ingest() {
    local detail="" ok=1
    local db=sqlite:$work/kill.db
    ingest "$db" sample --policy open
    serve "$db" --record-ttl-ms 100
    detail+=$(kill9_one "$db" sqlite) || ok=0
    stop_server
    if pg_setup; then
        serve "$pg_db" --record-ttl-ms 100
        detail+="; $(kill9_one "$pg_db" postgres)" || ok=0
        stop_server
    fi
    [ $ok = 1 ] && report PASS kill9_ingest "SIGKILL while the ingest's transaction held every row, uncommitted (VITRINE_TEST_PAUSE_BEFORE_COMMIT_MS): $detail" \
        || report FAIL kill9_ingest "$detail"
}

case_disk_full() {
    local dir=$work/full how
    mkdir -p "$dir"
    local db=sqlite:$dir/full.db
    if mount -t tmpfs -o size=160k tmpfs "$dir" 2>/dev/null; then
        mounts+=("$dir")
        how="a 160 KiB tmpfs"
        "$bin" ingest "$(sample)" --db "$db" --slug first --title first >"$work/full.out" 2>&1 && true
    else
        how="RLIMIT_FSIZE 160 KiB (prlimit), SIGXFSZ ignored"
        (trap '' XFSZ; exec prlimit --fsize=163840 "$bin" ingest "$(sample)" --db "$db" --slug first --title first) >"$work/full.out" 2>&1 && true
    fi
    local status=$?
    local msg
    msg=$(grep -m1 -oE 'database or disk is full|disk I/O error|No space left on device|File too large' "$work/full.out" || true)
    if [ $status = 0 ]; then
        report FAIL disk_full "ingest succeeded on $how"
        return
    fi
    # Nothing partial is visible; with room again the same ingest works.
    local visible
    visible=$(sqlite3 "$dir/full.db" "SELECT count(*) FROM model" 2>/dev/null || echo "no database")
    if [ -n "${mounts[*]}" ]; then mount -o remount,size=64m "$dir"; fi
    if [ -n "$msg" ] && [ "$visible" != 1 ] && ingest "$db" first; then
        report PASS disk_full "ingest on $how failed (exit $status) with '$msg'; models stored afterwards: $visible; with room again the same ingest succeeded"
    else
        report FAIL disk_full "exit $status, message '$(tail -n 3 "$work/full.out")', models visible: $visible"
    fi
    if [ -n "${mounts[*]}" ]; then umount "$dir"; mounts=(); fi
}

case_disconnects() {
    local db=sqlite:$work/disc.db
    ingest "$db" sample --policy open
    serve "$db"
    local id last
    id=$(curl -s "$url/api/models/sample" | sed -E 's/.*"compression_id":([0-9]+).*/\1/')
    last=$(curl -s "$url/api/models/sample" | sed -E 's/.*"last_level":([0-9]+).*/\1/')
    local a b
    if a=$("$load" disconnects --url "$url" --path "/api/compressions/$id/batches/$last" --clients 300 --read-bytes 4096 2>&1) &&
        b=$("$load" disconnects --url "$url" --path "/api/compressions/$id/batches/$last" --clients 300 --read-bytes 0 2>&1) &&
        kill -0 "$server"; then
        report PASS disconnects "largest batch ($last): $a. Before reading: $b"
    else
        report FAIL disconnects "$a $b"
    fi
    stop_server
}

case_shutdown() {
    pg_setup || { report SKIP shutdown "no PostgreSQL binaries (requests need a slow database to be in flight)"; return; }
    proxy 200 || { report FAIL shutdown "the delay line did not start"; return; }
    # Opening a connection through the 200 ms line takes several round trips:
    # on a busy machine that outlasted the default 3 s acquire timeout, and the
    # server retried its migrations until the readiness wait ran out (a CI
    # failure). This case is about shutdown, not the database: give it 10 s.
    serve "postgres://postgres@127.0.0.1:$proxy_port/postgres" --db-timeout-ms 10000 \
        --cache-bytes 0 --record-ttl-ms 100 --db-max-connections 64 \
        --load-high-inflight 1000000000 --load-high-latency-ms 1000000000 --load-high-queue-ms 1000000000 || {
        give_up shutdown "the server did not become ready through the delay line (see above)"
        return
    }
    local pid=$server t0=$SECONDS
    if "$load" crowd --url "$url" --slug sample --profile "$profile" --visitors 80 --pattern steady:4 \
        --sigterm-pid "$pid" --sigterm-after-s 3 >"$work/shutdown.out" 2>&1; then
        wait "$pid"
        local status=$?
        server=""
        report PASS shutdown "SIGTERM at 3 s into a crowd of 80 arriving over 4 s (database +200 ms, payload cache off): $(grep -m1 '^SIGTERM' "$work/shutdown.out"); server exit status $status after $((SECONDS - t0)) s"
    else
        give_up shutdown "$(tail -n 4 "$work/shutdown.out")"
        return
    fi
    stop_proxy
}

case_hostile() {
    local db=sqlite:$work/hostile.db
    ingest "$db" sample --policy exhibition
    local token
    token=$("$bin" token --db "$db" --label hostile 2>/dev/null)
    serve "$db"
    if "$load" hostile --url "$url" --slug sample --token "$token" --slow >"$work/hostile.out" 2>&1; then
        report PASS hostile "$(tail -n 1 "$work/hostile.out")"
    else
        report FAIL hostile "$(grep -F 'FAIL' "$work/hostile.out" | head -n 5)"
    fi
    cat "$work/hostile.out"
    stop_server
}

for c in "${cases[@]}"; do
    make_profile
    echo "=== $c"
    "case_$c" || report FAIL "$c" "the case itself failed (see above)"
done
echo
cat "$results"
[ -n "${FAULTS_OUT:-}" ] && cp "$results" "$FAULTS_OUT"
exit $failed
