#!/bin/bash
# Man pages list every option: the options each program's --help shows (for
# pdt, also every command's and trace subcommand's --help) and the options
# man/pdt.1, man/pdtview.1 name (as mandoc renders them) are the same sets,
# both ways; every missing or extra option is named.
. "$(dirname "$0")/lib.sh"
command -v mandoc >/dev/null || { fail have_mandoc "mandoc is not installed (DEB_TEST)"; summary; exit 1; }
# options in a text: --word or -x, not inside a word (non-negative, x-axis)
opts_of() { grep -oE '(^|[^A-Za-z0-9_-])--?[a-z][a-z0-9-]*' | sed 's/^[^-]*//' | sort -u; }
# (EXAMPLES left out: they show other programs' options, mpirun -np)
man_opts() { mandoc -T ascii "$ROOT/man/$1" | col -b |
             awk '/^[A-Z]/ { skip = ($0 == "EXAMPLES") } !skip' | opts_of; }
# compare NAME HELP_OPTS_FILE MAN_OPTS_FILE
compare() {
    local missing extra
    missing=$(comm -23 "$2" "$3" | tr '\n' ' ')
    extra=$(comm -13 "$2" "$3" | tr '\n' ' ')
    if [ -z "$missing$extra" ]; then ok "$1"
    else fail "$1" "in --help, not in the man page: ${missing:-none}; in the man page, not in --help: ${extra:-none}"; fi
}

# ---- pdt: the program, every command, every trace subcommand ---------------------------------
{
    "$PDT" --help
    for c in triangulate hull check gen trace; do "$PDT" $c --help; done
    for s in info dump check export; do "$PDT" trace $s --help; done
} 2>&1 | opts_of >"$TMP/pdt.help"
# -h is --help's other name: say so in the man page too
man_opts pdt.1 >"$TMP/pdt.man"
compare pdt_man_lists_every_help_option "$TMP/pdt.help" "$TMP/pdt.man"
# each command's own options are in the man page (not only somewhere in --help)
for c in triangulate hull check gen; do
    "$PDT" $c --help 2>&1 | opts_of >"$TMP/c.help"
    m=$(comm -23 "$TMP/c.help" "$TMP/pdt.man" | tr '\n' ' ')
    if [ -z "$m" ]; then ok "pdt_${c}_options_in_man"; else fail "pdt_${c}_options_in_man" "missing: $m"; fi
done

# ---- pdtview -------------------------------------------------------------------------------
if [ -x "$BIN/pdtview" ]; then
    "$BIN/pdtview" --help 2>&1 | opts_of >"$TMP/view.help"
    # pdtview.1 says how a run is recorded (pdt triangulate --trace): pdt's option
    man_opts pdtview.1 | grep -vxF -- --trace >"$TMP/view.man"
    compare pdtview_man_lists_every_help_option "$TMP/view.help" "$TMP/view.man"
else
    ok "pdtview_man_lists_every_help_option # SKIP pdtview is not built"
fi
for m in pdt.1 pdtview.1; do
    if mandoc -T lint -W warning "$ROOT/man/$m" >"$TMP/lint" 2>&1; then ok "${m}_mandoc_lint"
    else fail "${m}_mandoc_lint" "$(head -5 "$TMP/lint")"; fi
done
summary
