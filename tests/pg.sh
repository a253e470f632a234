#!/bin/sh
# A PostgreSQL server of the tests' own, in a directory of its own, reached
# by its Unix socket there (no port to collide with), run as the postgres
# user since the server refuses root, trusting local connections.
#   pg.sh start DIR   initdb into DIR and start; prints the URI to use
#   pg.sh stop DIR    stop it and remove DIR
# Exit status 3 (and a reason on stderr) when PostgreSQL is not installed.
set -eu
cmd=$1
dir=$2
bin=$(ls -d /usr/lib/postgresql/*/bin 2>/dev/null | sort -V | tail -n 1)
if [ -z "$bin" ] || [ ! -x "$bin/initdb" ]; then
    echo "pg.sh: PostgreSQL's server is not installed (Debian package postgresql)" >&2
    exit 3
fi
# as the postgres user when root; as oneself otherwise
as_owner() {
    if [ "$(id -u)" -eq 0 ]; then
        runuser -u postgres -- "$@"
    else
        "$@"
    fi
}
case $cmd in
start)
    mkdir -p "$dir"
    [ "$(id -u)" -ne 0 ] || chown postgres "$dir"
    if ! as_owner test -w "$dir"; then
        echo "pg.sh: the postgres user cannot reach $dir (its parents must be open to it: chmod 755)" >&2
        exit 1
    fi
    as_owner "$bin/initdb" -D "$dir/data" -A trust -U postgres -E UTF8 --locale=C.UTF-8 \
        >"$dir/initdb.log" 2>&1 || { cat "$dir/initdb.log" >&2; exit 1; }
    # fsync off: a test server that need not survive a power cut
    as_owner "$bin/pg_ctl" -D "$dir/data" -l "$dir/server.log" -w -t 60 \
        -o "-c listen_addresses='' -k $dir -c fsync=off -c max_connections=300" start \
        >/dev/null || { cat "$dir/server.log" >&2; exit 1; }
    echo "postgresql://postgres@$(echo "$dir" | sed 's|/|%2F|g')/postgres"
    ;;
stop)
    [ ! -d "$dir/data" ] || as_owner "$bin/pg_ctl" -D "$dir/data" -m fast -w stop >/dev/null || true
    rm -rf "$dir"
    ;;
*)
    echo "usage: pg.sh start|stop DIR" >&2
    exit 2
    ;;
esac
