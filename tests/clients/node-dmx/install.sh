#!/bin/sh
# The node-dmx client's setup: installs npm dmx exactly as package-lock.json pins it (`npm ci`, from the
# npm registry) into DEST in the build tree, with drive.js beside it. Skips npm when DEST already holds
# this lockfile's install. Scripts stay off: serialport's native binding ships prebuilt for linux-x64
# and node-gyp-build picks it at run time, so nothing is compiled or downloaded besides the packages.
set -eu
src=$(cd "$(dirname "$0")" && pwd)
dest=${1:?usage: install.sh DEST}
mkdir -p "$dest"
cp "$src/drive.js" "$dest/drive.js"
if cmp -s "$src/package-lock.json" "$dest/package-lock.json" && [ -f "$dest/node_modules/.package-lock.json" ]; then
  exit 0
fi
cp "$src/package.json" "$src/package-lock.json" "$dest/"
cd "$dest"
npm ci --ignore-scripts --no-audit --no-fund --loglevel=error
