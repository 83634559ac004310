#!/usr/bin/env bash
# Installs colorlab's Debian 12 dependencies (as root, only what is missing), then configures and
# builds the chosen preset. Idempotent: a second run installs nothing and rebuilds incrementally.
set -euo pipefail
cd "$(dirname "$0")/.."

preset="${1:-dev}"

packages=(
  # toolchain
  g++ cmake ninja-build pkg-config git
  # libraries
  libboost-dev libsqlite3-dev libserialport-dev libhidapi-dev libusb-1.0-0-dev libraw-dev libaravis-dev
  libgphoto2-dev liblcms2-dev libeigen3-dev nlohmann-json3-dev libtomlplusplus-dev libcli11-dev liblua5.4-dev
  libtiff-dev libjpeg-dev libsystemd-dev libssl-dev libgtest-dev libgmock-dev libbenchmark-dev libopencv-dev
  # standard CIE data at run time
  colord-data
  # independent references and test tools
  argyll aravis-tools aravis-tools-cli libraw-bin dcraw python3-numpy hyperfine sqlite3 curl util-linux procps strace
  imagemagick
  # third-party clients of the simulated lab (tests/clients): OLA, whose olad runs in a network namespace of
  # its own (iproute2 brings its lo up); node-dmx comes from the npm registry with the machine's Node.js and
  # npm (not Debian's: the machine's are newer), installed by its test with npm ci
  ola iproute2
  # the data service: load benches against nginx, fuzzing with clang's libFuzzer, the Python client
  wrk nginx-light clang libfuzzer-14-dev python3-requests python3-pandas openssl
  # the daemon's webhook notifications ([notify] webhook)
  libcurl4-openssl-dev
  # reports (plots by matplotlib) and the web console, both tested in headless Chromium
  python3-matplotlib chromium chromium-driver python3-selenium
  # clang only recommends its fuzzer and sanitizer runtimes, and this script installs without recommends
  libclang-rt-14-dev
  # the system's CA bundle, which an https:// object store without s3_ca_file is verified against (tests/fleet/ship_https_test.cpp)
  ca-certificates
  # the Debian package (docs/packaging.md): cpack's dpkg-shlibdeps, lintian, and mmdebstrap's throwaway chroot
  dpkg-dev binutils lintian mmdebstrap debian-archive-keyring
  # the TLS listener checked by a tool colorlab did not write (tests/security/testssl_test.py)
  testssl.sh
  # the house's tools (scripts/format.sh, scripts/tidy.sh; docs/TESTING.md)
  clang-format clang-tidy
  # the wall clock stepped under colorlabd in tests (libfaketime, tests/integration/clock_step_test.cpp)
  faketime
  # colorlab-ship (fleet/): libpq for the central PostgreSQL; its tests start a throwaway PostgreSQL 15 and a
  # one-replica OpenStack Swift with s3api (the bookworm S3 server that checks SigV4 and payload hashes)
  libpq-dev postgresql-15 postgresql-client-15 swift swift-proxy swift-object swift-container swift-account memcached
  # the measured scene rendered by a renderer nobody here wrote (tests/verify/scene): Blender 3.4's Cycles, and
  # OpenImageIO's Python reader for its OpenEXR output
  blender python3-openimageio
  # renderings verified against the lab (verify/io, issue 23): OpenEXR 3.1, and OpenImageIO as the independent reader
  libopenexr-dev libimath-dev openimageio-tools python3-openimageio
  # colorlab-ship's fault tests (tests/fleet/ship_faults_test.cpp): the network cut by killing a socat TCP proxy
  socat
  # verify/io's own ZIP chunk decoder (docs/PERFORMANCE.md "Verifying a rendering"): libdeflate inflates them
  libdeflate-dev
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

# node-dmx's test uses the machine's Node.js and npm where they exist (newer than Debian's); Debian's only
# where the machine has none, so that test never lacks its runtime.
if ! command -v npm >/dev/null 2>&1; then
  missing+=(nodejs npm)
fi

if ((${#missing[@]})); then
  if [[ $(id -u) -ne 0 ]]; then
    echo "colorlab setup: missing Debian packages: ${missing[*]}" >&2
    echo "run this script as root, or: sudo apt-get install ${missing[*]}" >&2
    exit 1
  fi
  echo "colorlab setup: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

if [[ ! -f build/CMakeCache.txt && "$preset" == dev ]] || [[ "$preset" != dev && ! -d "build-$preset" ]]; then
  cmake --preset "$preset" >/dev/null
fi
cmake --build --preset "$preset" -j "$(nproc)"
