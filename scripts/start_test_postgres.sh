#!/usr/bin/env bash
# Start a throwaway PostgreSQL server for the trace tests, on 127.0.0.1 only.
#
# Installs the server with apt-get if it is missing (needs root), creates a cluster in a
# temporary folder (trust authentication, loopback only), starts it and creates the database.
# The last line printed on stdout is the SQLAlchemy URL, e.g.
#   postgresql+psycopg://pycram@127.0.0.1:54329/pycram_test
# so callers can do:  export PYCRAM_TEST_POSTGRES_URL="$(scripts/start_test_postgres.sh | tail -n 1)"
# Progress goes to stderr. Exits non-zero (printing why) if no server can be started.
#
# Environment: PYCRAM_PG_PORT (default 54329), PYCRAM_PG_DIR (default /tmp/pycram-test-postgres).
# Stop it with:  scripts/start_test_postgres.sh stop
set -euo pipefail

PORT="${PYCRAM_PG_PORT:-54329}"
DIR="${PYCRAM_PG_DIR:-/tmp/pycram-test-postgres}"
USER_NAME=pycram
DB_NAME=pycram_test
URL="postgresql+psycopg://${USER_NAME}@127.0.0.1:${PORT}/${DB_NAME}"

say() { echo "start_test_postgres: $*" >&2; }

find_bin() {
    local name="$1" candidate
    for candidate in /usr/lib/postgresql/*/bin/"$name"; do
        if [ -x "$candidate" ]; then echo "$candidate"; fi
    done | sort -V | tail -n 1
}

PG_CTL="$(find_bin pg_ctl)"
if [ -z "$PG_CTL" ]; then
    if command -v apt-get >/dev/null 2>&1 && [ "$(id -u)" = 0 ]; then
        say "installing the PostgreSQL server with apt-get"
        export DEBIAN_FRONTEND=noninteractive
        apt-get update -qq >&2 && apt-get install -y -qq postgresql >&2 || true
        PG_CTL="$(find_bin pg_ctl)"
    fi
fi
if [ -z "$PG_CTL" ]; then
    say "no PostgreSQL server available (and it could not be installed)"
    exit 1
fi
BIN="$(dirname "$PG_CTL")"

# Run server commands as an unprivileged user: postgres refuses to run as root.
as_owner() {
    if [ "$(id -u)" = 0 ]; then
        runuser -u postgres -- "$@"
    else
        "$@"
    fi
}

if [ "${1:-}" = "stop" ]; then
    if [ -d "$DIR/data" ]; then as_owner "$BIN/pg_ctl" -D "$DIR/data" -m fast stop >&2 || true; fi
    exit 0
fi

if [ -d "$DIR/data" ] && as_owner "$BIN/pg_ctl" -D "$DIR/data" status >/dev/null 2>&1; then
    say "server already running in $DIR on port $PORT"
else
    rm -rf "$DIR"
    mkdir -p "$DIR"
    if [ "$(id -u)" = 0 ]; then chown postgres: "$DIR"; fi
    say "creating a cluster in $DIR"
    as_owner "$BIN/initdb" -D "$DIR/data" -U postgres --auth=trust --no-sync -E UTF8 >/dev/null
    say "starting the server on 127.0.0.1:$PORT"
    as_owner "$BIN/pg_ctl" -D "$DIR/data" -l "$DIR/server.log" -w -t 60 \
        -o "-c listen_addresses=127.0.0.1 -p $PORT -k $DIR -c fsync=off -c max_connections=100" start >&2
fi

PSQL="$BIN/psql"
[ -x "$PSQL" ] || PSQL="$(command -v psql)"
psql_admin() { "$PSQL" -X -q -h 127.0.0.1 -p "$PORT" -U postgres -d postgres -v ON_ERROR_STOP=1 "$@"; }
if ! psql_admin -tAc "SELECT 1 FROM pg_roles WHERE rolname='${USER_NAME}'" | grep -q 1; then
    psql_admin -c "CREATE ROLE ${USER_NAME} LOGIN CREATEDB" >&2
fi
if ! psql_admin -tAc "SELECT 1 FROM pg_database WHERE datname='${DB_NAME}'" | grep -q 1; then
    psql_admin -c "CREATE DATABASE ${DB_NAME} OWNER ${USER_NAME}" >&2
fi
say "ready"
echo "$URL"
