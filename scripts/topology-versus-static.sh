# shellcheck shell=bash
# Sourced by scripts/topology.sh (its variables and helpers): the check that
# measures what Vitrine adds to what the proxy costs (issue 46).
#
# The same nginx (one process, the same workers and listen options) gets a
# second server block that serves the crowd's bytes as static files: every
# manifest a visitor can be sent (device class × with or without a token,
# chosen by the same maps as the proxy's cache key) and every payload they
# list, fetched from an instance beforehand. The same harness then sends the
# same crowd, all at once, to three setups in turn, round after round:
#
#   static  nginx serving the files (no Vitrine at all);
#   warm    nginx's cache in front of the two instances, the cache warm,
#           instance A killed (SIGKILL) mid-crowd (at VERSUS_KILL_AT of the
#           static crowd's duration) and started again after;
#   cold    the same after nginx's cache was emptied and both instances
#           restarted (empty payload caches): a crowd arriving at a fresh
#           deployment, A killed mid-crowd as well.
#
# Each crowd's p99 over every request and its time-outs (no answer within
# VERSUS_TIMEOUT_S, 2 s like wrk's default) are kept, with the time until
# its last visitor was done and how many visitors Vitrine's admission control
# asked to come back (503 `busy`, Retry-After): a token bypasses nginx's
# cache, so the researchers' manifests meet admission. The result is the
# median over rounds and Vitrine's over static's. On a machine where the
# harness shares the cores with nginx, this ratio is what can be shown; the
# absolute figure needs the harness on cores of its own.
#
# Environment: VERSUS_VISITORS ("1000 5000"; short "300"), VERSUS_ROUNDS (3;
# short 1), VERSUS_TIMEOUT_S (2), VERSUS_KILL_AT (0.3), VERSUS_GOAL (1.2).

static_root=$work/static
static_port=$((port + 3))

# The files, under the URLs the crowd asks for.
versus_fill_static_root() {
    local origin="http://127.0.0.1:${ports[0]}" device personal ua url
    mkdir -p "$static_root/manifests"
    for device in desktop tablet phone; do
        case $device in
        desktop) ua="Mozilla/5.0 (X11; Linux x86_64) Chrome/120.0" ;;
        tablet) ua="Mozilla/5.0 (iPad; CPU OS 17_0 like Mac OS X) Mobile/15E148" ;;
        phone) ua="Mozilla/5.0 (iPhone; CPU iPhone OS 17_0 like Mac OS X) Mobile/15E148" ;;
        esac
        for personal in 0 1; do
            local auth=()
            [ $personal = 0 ] || auth=(-H "Authorization: Bearer $token")
            curl -sf -A "$ua" "${auth[@]}" "$origin/api/models/topo" \
                >"$static_root/manifests/topo.$device.$personal.json"
        done
    done
    # What each may fetch: the levels it is allowed and the textures.
    jq -r '(.levels[]? | select(.allowed) | .url), (.textures[]?.url) | select(. != null)' \
        "$static_root"/manifests/*.json | sort -u | while read -r url; do
        mkdir -p "$static_root$(dirname "$url")"
        curl -sf -H "Authorization: Bearer $token" -o "$static_root$url" "$origin$url"
    done
    chmod -R a+rX "$static_root"
}

# The server block, added to the rendered nginx.conf before its last `}`.
versus_static_server() {
    cat <<EOF
    server {
        listen 127.0.0.1:$static_port backlog=4096 reuseport;
        server_name _;
        root $static_root;
        location = /api/models/topo {
            default_type application/json;
            try_files /manifests/topo.\$vitrine_device.\$vitrine_personal.json =404;
        }
        location /api/ {
            default_type application/octet-stream;
        }
    }
}
EOF
}

# One crowd, all at once; appends "visitors setup round p99_ms time_outs
# failed requests wall_s refused_at_admission" to $1.
versus_crowd() { # rows url visitors setup round kill_after_s (or "")
    local rows=$1 url=$2 n=$3 setup=$4 round=$5 kill=$6
    local json=$work/versus-$setup-$n-$round.json
    "$load" crowd --url "$url" --slug topo --profile "$profile" --visitors "$n" \
        --pattern burst --token "$token" --stay-s 0 --allow 429,503 \
        --request-timeout-s "$versus_timeout" --json "$json" >"$work/versus.out" 2>&1 &
    local h=$!
    if [ -n "$kill" ]; then
        sleep "$kill"
        kill -9 "${inst[0]}"
        wait "${inst[0]}" 2>/dev/null || true
    fi
    # A crowd with time-outs exits non-zero; they are counted, not fatal.
    wait "$h" || true
    [ -z "$kill" ] || start_instance 0
    if [ -s "$json" ]; then
        jq -r --arg n "$n" --arg s "$setup" --arg r "$round" \
            '.summary | "\($n) \($s) \($r) \(.p99_ms) \(.errors["no answer"] // 0) \(.failed) \(.requests) \(.wall_s) \(.admission_refused)"' \
            "$json" >>"$rows"
    else
        echo "$n $setup $round - - - - - -" >>"$rows"
        tail -n 5 "$work/versus.out" >&2
    fi
}

# A deployment's first minute: nginx's cache emptied, both instances fresh.
versus_go_cold() {
    kill -QUIT "$nginx_pid"
    wait "$nginx_pid" 2>/dev/null || true
    rm -rf "${work:?}/nginx/cache"/*
    local i
    for i in 0 1; do
        kill -TERM "${inst[$i]}"
        wait "${inst[$i]}" 2>/dev/null || true
        start_instance "$i"
    done
    start_nginx
}

# 8. Vitrine against static files, alternated in one run.
check_versus_static() {
    local visitors_list rounds n r rows=$work/versus.rows
    if [ "$short" = 1 ]; then
        visitors_list=${VERSUS_VISITORS:-300} rounds=${VERSUS_ROUNDS:-1}
    else
        visitors_list=${VERSUS_VISITORS:-"1000 5000"} rounds=${VERSUS_ROUNDS:-3}
    fi
    versus_timeout=${VERSUS_TIMEOUT_S:-2}
    local kill_at=${VERSUS_KILL_AT:-0.3} kill_s
    local goal=${VERSUS_GOAL:-1.2}
    : >"$rows"
    for r in $(seq 1 "$rounds"); do
        for n in $visitors_list; do
            versus_crowd "$rows" "http://127.0.0.1:$static_port" "$n" static "$r" ""
            kill_s=$(jq -r --argjson f "$kill_at" '.summary.wall_s * $f' \
                "$work/versus-static-$n-$r.json" 2>/dev/null || echo 0.5)
            # Warm: what the cold crowd of the round before (or the earlier
            # checks) left in nginx's cache, topped up by a small crowd.
            "$load" crowd --url "$proxy" --slug topo --profile "$profile" --visitors 20 \
                --pattern burst --token "$token" --stay-s 0 --allow 429,503 >/dev/null 2>&1 || true
            versus_crowd "$rows" "$proxy" "$n" warm "$r" "$kill_s"
            versus_go_cold
            versus_crowd "$rows" "$proxy" "$n" cold "$r" "$kill_s"
        done
    done
    # Medians over rounds, and the ratios to static.
    local summary ok
    summary=$(awk -v goal="$goal" '
        function median(list,   a, k, i, j, t) {
            k = split(list, a, " ")
            for (i = 1; i <= k; i++) for (j = i + 1; j <= k; j++) if (a[j] < a[i]) { t = a[i]; a[i] = a[j]; a[j] = t }
            return k % 2 ? a[(k + 1) / 2] : (a[k / 2] + a[k / 2 + 1]) / 2
        }
        $4 == "-" { missing = 1; next }
        { k = $1 " " $2; p[k] = p[k] " " $4; t[k] += $5; f[k] += $6; w[k] = w[k] " " $8; a[k] += $9; seen[$1] = 1 }
        END {
            verdict = missing ? "FAIL" : "PASS"
            for (n in seen) {
                s = median(p[n " static"])
                printf "%d at once: p99 static %.0f ms, warm %.0f (×%.2f), cold %.0f (×%.2f); time-outs static %d, warm %d, cold %d; failed visitors static %d, warm %d, cold %d; last visitor done (median) static %.1f s, warm %.1f, cold %.1f; asked to come back by admission, all rounds: warm %d, cold %d. ", n, s, median(p[n " warm"]), median(p[n " warm"]) / s, median(p[n " cold"]), median(p[n " cold"]) / s, t[n " static"], t[n " warm"], t[n " cold"], f[n " static"], f[n " warm"], f[n " cold"], median(w[n " static"]), median(w[n " warm"]), median(w[n " cold"]), a[n " warm"], a[n " cold"]
                met = median(p[n " warm"]) <= goal * s && t[n " warm"] <= goal * t[n " static"]
                printf "Warm goal (≤ ×%s, time-outs too) %s. ", goal, met ? "met" : "not met"
            }
            print verdict
        }' "$rows")
    ok=${summary##* }
    local detail="$rounds round(s), burst crowds alternated static / warm / cold, A killed in warm and cold at $kill_at of the static crowd's time, time-out ${versus_timeout} s. ${summary% *} Rows (visitors setup round p99 time-outs failed requests wall refused): $(tr '\n' ';' <"$rows")"
    report "$ok" versus "$detail"
}
