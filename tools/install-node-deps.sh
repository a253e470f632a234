#!/bin/sh
# Installs the npm packages of package.json (the page's three.js, the API
# and browser test tools) into node_modules, from package-lock.json; quiet
# when node_modules is already up to date.  Installs Node.js itself from
# Debian when it is missing.
set -eu
cd "$(dirname "$0")/.."
if ! command -v npm >/dev/null 2>&1; then
    if [ "$(id -u)" -ne 0 ]; then
        echo "install-node-deps: need root to install nodejs and npm" >&2
        exit 1
    fi
    echo "installing: nodejs npm"
    DEBIAN_FRONTEND=noninteractive apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends nodejs npm >/dev/null
fi
stamp=node_modules/.package-lock.json
if [ -f "$stamp" ] && [ ! package-lock.json -nt "$stamp" ]; then
    exit 0
fi
echo "installing npm packages (npm ci)"
npm ci --no-audit --no-fund --loglevel=error
