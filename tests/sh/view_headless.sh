#!/bin/bash
# pdtview --headless: PNG/SVG/PDF pictures that other tools can read, frames,
# phases, errors.  (The pixel-level checks are in tests/unit/test_view_render.c.)
# san: yes
. "$(dirname "$0")/lib.sh"
V=$BIN/pdtview
RUN=synth:srm:12:6:4

if "$V" --headless "$RUN" --end -o "$TMP/end.png" --size 800x500 --quiet &&
   [ "$(python3 -c 'import struct,sys; d=open(sys.argv[1],"rb").read(24); print(*struct.unpack(">II", d[16:24]))' "$TMP/end.png")" = "800 500" ]; then
    ok png_size
else fail png_size "no 800x500 PNG"; fi

if "$V" --headless "$RUN" --phase merge -o "$TMP/m.svg" --quiet && xmllint --noout "$TMP/m.svg" 2>"$TMP/xl.err" &&
   grep -q '<svg' "$TMP/m.svg"; then ok svg_valid; else fail svg_valid "$(head -3 "$TMP/xl.err")"; fi

if command -v rsvg-convert >/dev/null && rsvg-convert -o "$TMP/m_svg.png" "$TMP/m.svg" 2>/dev/null && [ -s "$TMP/m_svg.png" ]; then
    ok svg_renders
else fail svg_renders "rsvg-convert could not render the SVG"; fi

if "$V" --headless "$RUN" --at 500 -o "$TMP/a.pdf" --quiet && pdftoppm -r 30 -png "$TMP/a.pdf" "$TMP/pdfpage" &&
   ls "$TMP"/pdfpage*.png >/dev/null 2>&1; then ok pdf_renders; else fail pdf_renders; fi

# frames: 0, K, 2K, ..., m
m=$("$V" --headless "$RUN" --end -o "$TMP/x.png" | sed -n 's/.*event \([0-9]*\) of.*/\1/p')
"$V" --headless "$RUN" --frames "$TMP/frames" --every 400 --size 320x200 --quiet
want=$(( (m + 399) / 400 + 1 ))
got=$(ls "$TMP/frames" | grep -c '^frame-.*\.png$')
if [ "$got" -eq "$want" ]; then ok frames_count; else fail frames_count "want $want frames, got $got (m=$m)"; fi

# the picture changes along the run
if ! cmp -s "$TMP/frames/frame-000000.png" "$TMP/frames/frame-000002.png"; then ok frames_differ; else fail frames_differ; fi

# a run folder written by the trace writer reads back with the same events
if "$V" --write-run "$TMP/run" "$RUN" --quiet && [ -f "$TMP/run/manifest" ] &&
   a=$("$V" --headless "$TMP/run" --end -o "$TMP/run.png" --size 640x400) &&
   b=$("$V" --headless "$RUN" --end -o "$TMP/syn.png" --size 640x400) &&
   [ "${a##*(}" = "${b##*(}" ] && [ -s "$TMP/run.png" ]; then ok run_folder_roundtrip
else fail run_folder_roundtrip "$a / $b"; fi
if "$V" --headless "$TMP/run" --phase merge:1 -o "$TMP/run_m1.png" --size 640x400 --quiet; then ok run_folder_phase
else fail run_folder_phase; fi

# errors: unknown phase, cursor out of range, bad extension, missing run
if ! "$V" --headless "$RUN" --phase nosuch -o "$TMP/n.png" 2>"$TMP/e1" && grep -q 'no phase named' "$TMP/e1"; then
    ok error_phase; else fail error_phase; fi
if ! "$V" --headless "$RUN" --at 99999999 -o "$TMP/n.png" 2>"$TMP/e2" && grep -q 'has [0-9]* events' "$TMP/e2"; then
    ok error_at; else fail error_at; fi
if ! "$V" --headless "$RUN" --end -o "$TMP/n.bmp" 2>"$TMP/e3" && grep -q 'unknown picture format' "$TMP/e3"; then
    ok error_format; else fail error_format; fi
if ! "$V" --headless "$TMP/no-such-run" --end -o "$TMP/n.png" 2>"$TMP/e4"; then ok error_run; else fail error_run; fi

# option errors: exit status 2, the message names the option and the value,
# nothing written (bad values are never silently replaced by defaults)
opt_error() { # NAME PATTERN ARGS...
    name=$1 pat=$2
    shift 2
    rm -f "$TMP/o.png"
    "$V" "$@" 2>"$TMP/oe"
    rc=$?
    if [ $rc -eq 2 ] && grep -q -- "$pat" "$TMP/oe" && [ ! -e "$TMP/o.png" ]; then ok "option_$name"
    else fail "option_$name" "rc $rc: $(head -1 "$TMP/oe")"; fi
}
opt_error speed_zero "--speed needs a positive number, not '0'" "$RUN" --speed 0
opt_error speed_text "--speed needs a positive number, not 'fast'" "$RUN" --speed=fast
opt_error every_zero "--every needs a whole number" --headless "$RUN" --frames "$TMP/fr0" --every 0
opt_error at_text "--at needs a whole number, not '12x'" --headless "$RUN" --at 12x -o "$TMP/o.png"
opt_error size "--size needs WxH" --headless "$RUN" --end --size 100 -o "$TMP/o.png"
opt_error panels "--panels needs a list" --headless "$RUN" --end --panels code,nope -o "$TMP/o.png"
opt_error hide "--hide needs rank numbers" --headless "$RUN" --end --hide 1,a -o "$TMP/o.png"
opt_error unknown "unknown option '--bogus'" --headless "$RUN" --end --bogus -o "$TMP/o.png"
opt_error missing_value "--speed needs a value" "$RUN" --speed
opt_error no_run "needs one RUN" --headless --end -o "$TMP/o.png"
if ! "$V" --headless "$RUN" --end --hide 9 -o "$TMP/o.png" 2>"$TMP/oe" && grep -q -- '--hide 9: the run has' "$TMP/oe" &&
   [ ! -e "$TMP/o.png" ]; then ok option_hide_range; else fail option_hide_range "$(head -1 "$TMP/oe")"; fi
if "$V" --help | grep -q '^usage: pdtview'; then ok option_help; else fail option_help; fi
summary
