#!/bin/sh
# Install the Debian packages named as arguments that are not installed yet:
# `apt-get update` once, then `apt-get install -y`.  Silent when nothing is
# missing.  Needs root (or sudo) only when something has to be installed.
missing=""
for p in "$@"; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
        # A program of that name already on PATH counts as present (npm comes
        # inside NodeSource's nodejs, which conflicts with Debian's npm).
        case "$p" in npm|node|hyperfine) command -v "$p" >/dev/null 2>&1 && continue ;; esac
        missing="$missing $p"
    fi
done
[ -z "$missing" ] && exit 0
echo "deps: installing missing Debian packages:$missing"
SUDO=""
if [ "$(id -u)" != 0 ]; then
    if command -v sudo >/dev/null 2>&1; then SUDO=sudo; else
        echo "deps: not root and no sudo: install these yourself:$missing" >&2; exit 1
    fi
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -q || exit 1
# shellcheck disable=SC2086
$SUDO apt-get install -y -q $missing || exit 1
