#!/bin/sh
# Installs the Debian packages tightknot needs, quietly when all are there;
# packages given as arguments are installed too (a bench's own).
set -eu
packages="$* build-essential pkg-config check clang libsuitesparse-dev liblapack-dev
libblas-dev libjansson-dev libmicrohttpd-dev libsqlite3-dev libcurl4-openssl-dev libgnutls28-dev libpq-dev postgresql
wrk sqlite3 curl openssl chromium firefox-esr xvfb"
missing=""
for p in $packages; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
        missing="$missing $p"
    fi
done
[ -z "$missing" ] && exit 0
echo "installing:$missing"
if [ "$(id -u)" -ne 0 ]; then
    echo "install-deps: need root to install:$missing" >&2
    exit 1
fi
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
# shellcheck disable=SC2086
apt-get install -y -qq --no-install-recommends $missing >/dev/null
