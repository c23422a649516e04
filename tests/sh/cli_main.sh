#!/bin/bash
# The pdt program itself: --version, --help, unknown commands, exit statuses.
source "$(dirname "$0")/lib.sh"
v=$("$PDT" --version); rc=$?
[ $rc -eq 0 ] && [[ "$v" =~ ^pdt\ [0-9]+\.[0-9]+\.[0-9]+$ ]] && ok version || fail version "$v"
"$PDT" --help > "$TMP/h" ; rc=$?
[ $rc -eq 0 ] && grep -q triangulate "$TMP/h" && grep -q hull "$TMP/h" && grep -q check "$TMP/h" \
    && grep -q gen "$TMP/h" && ok help_lists_commands || fail help_lists_commands
"$PDT" 2> /dev/null; [ $? -eq 2 ] && ok no_command_is_usage_error || fail no_command_is_usage_error
"$PDT" frobnicate 2> "$TMP/e"; [ $? -eq 2 ] && grep -q "unknown command 'frobnicate'" "$TMP/e" \
    && ok unknown_command || fail unknown_command
for c in triangulate hull check gen; do
    "$PDT" "$c" --help > "$TMP/c" 2>&1; rc=$?
    [ $rc -eq 0 ] && grep -q "^usage: pdt $c" "$TMP/c" && ok "help_$c" || fail "help_$c"
done
summary
