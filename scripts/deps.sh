#!/bin/sh
# Install the Debian packages named as arguments that are not installed yet:
# `apt-get update` once, then `apt-get install -y`.  Silent when nothing is
# missing: presence is checked first, with one dpkg-query for all of them, and
# apt-get is not run at all then.  Needs root (or sudo) only when something
# has to be installed.  Not on Debian (no dpkg-query): says what to install by
# hand and goes on (exit 0), the build says what is really missing.
[ $# -gt 0 ] || exit 0
if ! command -v dpkg-query >/dev/null 2>&1; then
    echo "deps: no dpkg-query (not Debian): make sure these are installed: $*" >&2
    exit 0
fi
# one line per installed package: "NAME" (architecture qualifiers dropped)
installed=$(dpkg-query -W -f='${Package} ${Status}\n' "$@" 2>/dev/null |
            awk '/ install ok installed$/ { sub(/:.*/, "", $1); print $1 }')
installed=" $(echo $installed) "
missing=""
for p in "$@"; do
    case "$installed" in *" $p "*) continue ;; esac
    # A program of that name already on PATH counts as present (npm comes
    # inside NodeSource's nodejs, which conflicts with Debian's npm).
    case "$p" in npm|node|hyperfine) command -v "$p" >/dev/null 2>&1 && continue ;; esac
    missing="$missing $p"
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
