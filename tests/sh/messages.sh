#!/bin/bash
# Messages a user sees name the user's input (file:line, triangle, edge, rank
# and event), never a position in pdt's own sources (`check.c:424: ...`).
#
# 1. The error-path scripts of the suite run again with BIN pointing at
#    wrappers that tee every byte pdt and pdtview write to standard error into
#    one log; the log must hold no `NAME.c:LINE` (nor .h).
# 2. No source passes __FILE__ / __LINE__ or a literal "NAME.c:" into a message.
source "$(dirname "$0")/lib.sh"
SCRIPTS="cli_main cli_triangulate cli_hull cli_check cli_gen cli_csv exit_codes damage_cli
         limits_int32 trace_cli par_fail view_headless"
LOG=$TMP/stderr.log
W=$TMP/wbin
mkdir -p "$W"
: > "$LOG"
for prog in pdt pdtview; do
    [ -x "$BIN/$prog" ] || continue
    cat > "$W/$prog" <<EOF
#!/bin/bash
exec "$BIN/$prog" "\$@" 2> >(tee -a "$LOG" >&2)
EOF
    chmod +x "$W/$prog"
done

ran=0
for s in $SCRIPTS; do
    f=$ROOT/tests/sh/$s.sh
    [ -f "$f" ] || continue
    env BIN="$W" ROOT="$ROOT" bash "$f" > "$TMP/$s.out" 2>&1 || true
    ran=$((ran + 1))
done
sleep 1 # let the last tee finish writing
lines=$(grep -c . "$LOG")
[ "$ran" -ge 8 ] && [ "$lines" -ge 50 ] && ok "error_paths_ran ($ran scripts, $lines stderr lines)" \
    || fail error_paths_ran "only $ran scripts, $lines lines of stderr"
if grep -nE '\b[A-Za-z_][A-Za-z0-9_]*\.[ch]:[0-9]+' "$LOG" > "$TMP/hits"; then
    fail no_source_positions_in_messages "$(head -5 "$TMP/hits")"
else
    ok no_source_positions_in_messages
fi
# messages still say where in the user's input
grep -qE '\.txt:[0-9]+: ' "$LOG" && ok messages_name_file_and_line \
    || fail messages_name_file_and_line "no 'FILE.txt:LINE: ' message seen"

if grep -rnE '__FILE__|__LINE__|"[a-z_]+\.c:' "$ROOT/src" "$ROOT/include" > "$TMP/src"; then
    fail no_source_positions_in_code "$(head -5 "$TMP/src")"
else
    ok no_source_positions_in_code
fi
summary
