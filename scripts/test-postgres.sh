#!/usr/bin/env bash
# A PostgreSQL server of the tests' own, which ctest starts before the
# daemon's tests and stops after them (a fixture, CMakeLists.txt):
#   scripts/test-postgres.sh start DIR   a new cluster in DIR/data, started on
#                                        a free loopback port; its URI in DIR/uri
#   scripts/test-postgres.sh stop DIR    stopped, and its data removed
# PostgreSQL refuses to run as root: under root (as CI runs) the server runs
# as the `postgres` user that Debian's package makes, in a folder of /tmp
# when that user cannot write under DIR.
set -euo pipefail
action=${1:-}
dir=$(realpath -m "${2:-}")
[[ ($action == start || $action == stop) && -n ${2:-} ]] || { echo "usage: $0 start|stop DIR" >&2; exit 2; }
bin=$(pg_config --bindir 2>/dev/null || true)
[[ -x $bin/pg_ctl ]] || bin=/usr/lib/postgresql/15/bin
if [[ ! -x $bin/pg_ctl ]]; then
  echo "test-postgres: no PostgreSQL server ($bin/pg_ctl); scripts/setup.sh installs it (postgresql-15)" >&2
  exit 1
fi

as_server() {
  if [[ $(id -u) -eq 0 ]]; then runuser -u postgres -- "$@"; else "$@"; fi
}

data_of() { if [[ -f $dir/datadir ]]; then cat "$dir/datadir"; else echo "$dir/data"; fi; }

stop() {
  local data
  data=$(data_of)
  if [[ -f $data/postmaster.pid ]]; then
    as_server "$bin/pg_ctl" -D "$data" -m fast -w stop >/dev/null 2>&1 ||
      as_server "$bin/pg_ctl" -D "$data" -m immediate -w stop >/dev/null 2>&1 || true
  fi
  rm -rf "$data" "$dir/uri" "$dir/datadir"
}

if [[ $action == stop ]]; then
  stop
  exit 0
fi

mkdir -p "$dir"
stop  # a server a killed run left
data=$dir/data
if [[ $(id -u) -eq 0 ]]; then
  chown postgres "$dir"
  if ! runuser -u postgres -- test -w "$dir"; then
    data=$(mktemp -d /tmp/rotafab-test-postgres.XXXXXX)
    chown postgres "$data"
    echo "$data" >"$dir/datadir"
  fi
fi

# A free port on loopback: the first from 54320 that nothing answers on.
port=
for candidate in $(seq 54320 54420); do
  if ! (exec 3<>"/dev/tcp/127.0.0.1/$candidate") 2>/dev/null; then
    port=$candidate
    break
  fi
done
[[ -n $port ]] || { echo "test-postgres: no free port in 54320-54420 on 127.0.0.1" >&2; exit 1; }

as_server "$bin/initdb" -D "$data" -U rotafab --auth=trust --encoding=UTF8 --no-instructions >"$dir/initdb.log" 2>&1 ||
  { cat "$dir/initdb.log" >&2; exit 1; }
as_server "$bin/pg_ctl" -D "$data" -l "$data/server.log" -w -t 60 \
  -o "-c listen_addresses=127.0.0.1 -p $port -c unix_socket_directories='' -c max_connections=200" start >/dev/null ||
  { cat "$data/server.log" >&2; exit 1; }
echo "postgresql://rotafab@127.0.0.1:$port/postgres" >"$dir/uri"
echo "test-postgres: $(cat "$dir/uri") (data in $data)"
