# pdt — helpers for shell tests (source this file).
#   ok NAME / fail NAME MSG / expect NAME CMD... / summary
# BIN (the programs' folder) and ROOT (the repository) come from tests/run.sh.
: "${ROOT:=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)}"
: "${BIN:=$ROOT/bin}"
PDT=$BIN/pdt
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
T_PASS=0; T_FAIL=0
TMP=$(mktemp -d "${TMPDIR:-/tmp}/pdt-test.XXXXXX")
trap 'rm -rf "$TMP"' EXIT
ok()   { echo "ok - $1"; T_PASS=$((T_PASS + 1)); }
fail() { echo "not ok - $1"; shift; [ $# -gt 0 ] && echo "#   $*"; T_FAIL=$((T_FAIL + 1)); }
# check NAME COMMAND... : passes when the command exits 0
check() { local n=$1; shift; if "$@"; then ok "$n"; else fail "$n" "command failed: $*"; fi; }
summary() { echo "# $T_PASS passed, $T_FAIL failed"; [ "$T_FAIL" -eq 0 ]; }
