#!/usr/bin/env bash
# Makes sure a PostgreSQL server answers on 127.0.0.1:5432 for the service
# tests (user postgres, trust authentication on loopback). Starts the Debian
# cluster if one is installed but stopped; installs PostgreSQL with apt-get if
# it is missing. Does nothing when a server already answers.
set -euo pipefail

host=127.0.0.1
port=5432

ready() {
    command -v pg_isready >/dev/null 2>&1 && pg_isready -q -h "$host" -p "$port"
}

if ready; then
    echo "PostgreSQL already answers on $host:$port"
    exit 0
fi

if ! ls /etc/postgresql/*/main >/dev/null 2>&1; then
    echo "installing PostgreSQL"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq postgresql >/dev/null
fi

version=$(ls /etc/postgresql | sort -V | tail -n 1)
conf=/etc/postgresql/$version/main
# The tests connect as postgres over TCP without a password.
if ! grep -q "^host all all 127.0.0.1/32 trust" "$conf/pg_hba.conf"; then
    sed -i '/^host/d' "$conf/pg_hba.conf"
    printf 'host all all 127.0.0.1/32 trust\nhost all all ::1/128 trust\n' >>"$conf/pg_hba.conf"
fi
pg_ctlcluster --skip-systemctl-redirect "$version" main start || pg_ctlcluster --skip-systemctl-redirect "$version" main restart

for _ in $(seq 1 30); do
    if ready; then
        echo "PostgreSQL $version answers on $host:$port"
        exit 0
    fi
    sleep 1
done
echo "PostgreSQL did not come up on $host:$port" >&2
exit 1
