#!/usr/bin/env bash
# Set up, build and run every test. Hardware-labelled tests skip themselves with a printed reason.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh dev
ctest --preset dev "$@"
