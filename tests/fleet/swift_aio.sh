#!/usr/bin/env bash
# A throwaway one-replica OpenStack Swift with the s3api middleware on 127.0.0.1, for the fleet tests: rings
# with one device, account/container/object servers, a proxy (s3api + tempauth) and memcached, all under DIR.
# Swift keeps object metadata in extended attributes, so DIR must be on a disk filesystem (not tmpfs).
# Usage: swift_aio.sh DIR BASE_PORT   (uses BASE_PORT..BASE_PORT+4; proxy = BASE_PORT)
# Runs in the foreground until killed (the test kills its process group). S3 key "test:tester", secret "testing".
set -euo pipefail
dir=$1
base=$2
proxy=$base account=$((base + 1)) container=$((base + 2)) object=$((base + 3)) memcache=$((base + 4))
user=$(id -un)
for tool in swift-ring-builder swift-proxy-server swift-object-server swift-container-server swift-account-server memcached; do
  command -v "$tool" >/dev/null || { echo "swift_aio: $tool is missing (scripts/setup.sh installs swift, swift-proxy, swift-object, swift-container, swift-account, memcached)" >&2; exit 127; }
done
mkdir -p "$dir/etc" "$dir/srv/d1" "$dir/run" "$dir/cache"
touch "$dir/srv/d1/.xattr-probe"
if ! python3 -c 'import os,sys; os.setxattr(sys.argv[1], "user.colorlab", b"1")' "$dir/srv/d1/.xattr-probe" 2>/dev/null; then
  echo "swift_aio: $dir has no extended attributes (tmpfs?); Swift needs them" >&2; exit 1
fi
cd "$dir/etc"
for kind in account container object; do
  port_var=$kind
  swift-ring-builder $kind.builder create 4 1 1 >/dev/null
  swift-ring-builder $kind.builder add r1z1-127.0.0.1:${!port_var}/d1 100 >/dev/null
  swift-ring-builder $kind.builder rebalance >/dev/null 2>&1 || true
done
common="[DEFAULT]
swift_dir = $dir/etc
devices = $dir/srv
mount_check = false
bind_ip = 127.0.0.1
user = $user
workers = 0
log_facility = LOG_LOCAL2
log_level = WARNING
"
printf '%s\nbind_port = %s\n[pipeline:main]\npipeline = account-server\n[app:account-server]\nuse = egg:swift#account\n' "$common" "$account" > account-server.conf
printf '%s\nbind_port = %s\n[pipeline:main]\npipeline = container-server\n[app:container-server]\nuse = egg:swift#container\n' "$common" "$container" > container-server.conf
printf '%s\nbind_port = %s\n[pipeline:main]\npipeline = object-server\n[app:object-server]\nuse = egg:swift#object\n' "$common" "$object" > object-server.conf
cat > proxy-server.conf <<CONF
$common
bind_port = $proxy
[pipeline:main]
pipeline = catch_errors gatekeeper healthcheck proxy-logging cache listing_formats s3api tempauth copy slo dlo proxy-logging proxy-server
[app:proxy-server]
use = egg:swift#proxy
account_autocreate = true
[filter:catch_errors]
use = egg:swift#catch_errors
[filter:gatekeeper]
use = egg:swift#gatekeeper
[filter:healthcheck]
use = egg:swift#healthcheck
[filter:proxy-logging]
use = egg:swift#proxy_logging
[filter:cache]
use = egg:swift#memcache
memcache_servers = 127.0.0.1:$memcache
[filter:listing_formats]
use = egg:swift#listing_formats
[filter:s3api]
use = egg:swift#s3api
location = us-east-1
[filter:tempauth]
use = egg:swift#tempauth
user_test_tester = testing .admin
[filter:copy]
use = egg:swift#copy
[filter:slo]
use = egg:swift#slo
[filter:dlo]
use = egg:swift#dlo
CONF
pids=()
trap 'kill "${pids[@]}" 2>/dev/null; wait' EXIT TERM INT
memcached -l 127.0.0.1 -p "$memcache" -U 0 -u "$user" & pids+=($!)
swift-account-server account-server.conf & pids+=($!)
swift-container-server container-server.conf & pids+=($!)
swift-object-server object-server.conf & pids+=($!)
swift-proxy-server proxy-server.conf & pids+=($!)
wait -n
echo "swift_aio: a server exited" >&2
exit 1
