# shellcheck shell=bash
# Sourced by every step deb_package_test.sh runs inside the chroot (copied to /tmp/colorlab-test.sh there):
# the installed programs, run as the colorlab user, and bounded waits for the daemon.
set -euo pipefail
fail() { echo "FAIL (in the chroot): $*" >&2; exit 1; }
state=/var/lib/colorlabd
socket=$state/colorlabd.sock
cli() { setpriv --reuid=colorlab --regid=colorlab --init-groups colorlab --socket "$socket" --json "$@"; }
json() { python3 -c "import json, sys; d = json.load(sys.stdin); print($1)"; }
start_daemon() {
  rm -f /tmp/colorlabd.log
  setpriv --reuid=colorlab --regid=colorlab --init-groups colorlabd --config /etc/colorlab/colorlabd.toml \
    >/tmp/colorlabd.log 2>&1 &
  daemon=$!
  for _ in $(seq 600); do
    [[ -S $socket && -s $state/colorlabd.endpoint ]] && return 0
    kill -0 "$daemon" 2>/dev/null || { cat /tmp/colorlabd.log; fail "colorlabd exited while starting"; }
    sleep 0.1
  done
  cat /tmp/colorlabd.log
  fail "colorlabd did not write its endpoint within 60 s"
}
stop_daemon() {
  kill -TERM "$daemon"
  for _ in $(seq 600); do
    kill -0 "$daemon" 2>/dev/null || break
    sleep 0.1
  done
  kill -0 "$daemon" 2>/dev/null && { cat /tmp/colorlabd.log; fail "colorlabd did not stop within 60 s of SIGTERM"; }
  wait "$daemon" || { cat /tmp/colorlabd.log; fail "colorlabd exited with $? on SIGTERM"; }
}
# comm holds 15 characters: colorlab-central is colorlab-centra there.
daemons_running() {
  grep -lx -e colorlabd -e colorlab-sim -e colorlab-ship -e colorlab-centra /proc/[0-9]*/comm 2>/dev/null || true
}
