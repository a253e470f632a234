#!/bin/sh
# Assembles the page served by `tightknotd --web DIR`: the files of web/ and
# the three.js modules it imports, taken from node_modules (installed by
# `npm install`), so that the browser needs nothing beyond the daemon.
#
# usage: tools/build-web.sh OUT_DIR
set -eu
if [ $# -ne 1 ]; then
    echo "usage: $0 OUT_DIR" >&2
    exit 2
fi
out=$1
root=$(cd "$(dirname "$0")/.." && pwd)
three="$root/node_modules/three"
if [ ! -f "$three/build/three.module.js" ] ||
   [ ! -f "$three/examples/jsm/controls/OrbitControls.js" ]; then
    echo "build-web: $three is missing (or incomplete): run 'npm install' in $root first" >&2
    exit 1
fi

# Start from an empty vendor directory so that files of an older three.js
# do not linger next to the new ones.
rm -rf "$out/vendor"
mkdir -p "$out/vendor/three/build" "$out/vendor/three/examples/jsm/controls"
cp -R "$root/web/." "$out/"

# The layout under vendor/three mirrors the package, so the relative imports
# inside it (three.module.js -> ./three.core.js) keep working; the page's
# import map resolves the bare "three" and "three/addons/" specifiers.
cp "$three/build/three.module.js" "$out/vendor/three/build/"
# Releases since r170 split the core out of three.module.js.
if [ -f "$three/build/three.core.js" ]; then
    cp "$three/build/three.core.js" "$out/vendor/three/build/"
fi
cp "$three/examples/jsm/controls/OrbitControls.js" "$out/vendor/three/examples/jsm/controls/"
cp "$three/LICENSE" "$out/vendor/three/LICENSE"
echo "build-web: $out (three.js $(sed -n 's/.*"version": *"\([^"]*\)".*/\1/p' "$three/package.json"))"
