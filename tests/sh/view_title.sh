#!/bin/bash
# The window title reaches X11 in UTF-8 whatever the locale: "pdtview — RUN"
# in _NET_WM_NAME (and WM_NAME), not "pdtview â" (SDL converts the title
# through the C library's character type; under LANG=C the em dash was lost).
. "$(dirname "$0")/lib.sh"
for t in Xvfb xprop xwininfo; do
    command -v $t >/dev/null || { ok "title_utf8 # SKIP no $t"; summary; exit 0; }
done
[ -x "$BIN/pdtview" ] || { ok "title_utf8 # SKIP pdtview is not built"; summary; exit 0; }
Xvfb -displayfd 3 -screen 0 800x600x24 -nolisten tcp 3>"$TMP/xvfb.num" >/dev/null 2>&1 &
xpid=$!
for _ in $(seq 100); do [ -s "$TMP/xvfb.num" ] && break; sleep 0.1; done
dpy=:$(head -1 "$TMP/xvfb.num")
want='pdtview — synth:graham:10'
# (the viewer stays until it is killed once its title was read: a run of
# a few frames could end between two looks under a loaded machine)
for loc in C POSIX C.UTF-8; do
    env -u LC_ALL -u LC_CTYPE LANG=$loc DISPLAY=$dpy timeout 60 "$BIN/pdtview" synth:graham:10 \
        --size 320x200 --script "wait:1000000 q" >/dev/null 2>&1 &
    vpid=$!
    got=""
    for _ in $(seq 150); do
        for w in $(DISPLAY=$dpy xwininfo -root -children 2>/dev/null | sed -n 's/^ *\(0x[0-9a-f]*\) .*/\1/p'); do
            n=$(DISPLAY=$dpy xprop -id "$w" _NET_WM_NAME 2>/dev/null | sed -n 's/^_NET_WM_NAME(UTF8_STRING) = "\(.*\)"$/\1/p')
            [ -n "$n" ] && got=$n
        done
        [ -n "$got" ] && break
        sleep 0.1
    done
    kill "$vpid" 2>/dev/null; wait "$vpid" 2>/dev/null
    if [ "$got" = "$want" ]; then ok "title_utf8_LANG_$loc"
    else fail "title_utf8_LANG_$loc" "_NET_WM_NAME is '${got:-not set}'"; fi
done
kill "$xpid" 2>/dev/null; wait "$xpid" 2>/dev/null
summary
