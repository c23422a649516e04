#!/bin/bash
# pdtview's real window on a projector-sized screen (Xvfb 1024x768) and a
# large one (1920x1080), without and with a window manager (openbox): the
# window fits the screen's usable area, F11 fills the screen and gives the
# window back, and the layout report of the frame shown (the status row
# included) passes scripts/layout-check.py at font scales 1, 1.5 and 2:
# nothing overlaps or is cut, no text under 16 px, code and event line at
# least 18 px, a status text present.
. "$(dirname "$0")/lib.sh"
V=$BIN/pdtview
CHECK="python3 $ROOT/scripts/layout-check.py"
for t in Xvfb xdotool openbox; do
    command -v $t >/dev/null || { fail "have_$t" "$t is not installed (DEB_TEST)"; summary; exit 1; }
done
XPID=; WMPID=
cleanup() {
    [ -n "$WMPID" ] && kill "$WMPID" 2>/dev/null
    [ -n "$XPID" ] && kill "$XPID" 2>/dev/null
    rm -rf "$TMP"
}
trap cleanup EXIT

# screen WxH [wm]: a fresh Xvfb (and openbox) on a free display
screen() {
    [ -n "$WMPID" ] && kill "$WMPID" 2>/dev/null && wait "$WMPID" 2>/dev/null
    [ -n "$XPID" ] && kill "$XPID" 2>/dev/null && wait "$XPID" 2>/dev/null
    WMPID=
    local d=90
    while [ -e /tmp/.X$d-lock ] || [ -e /tmp/.X11-unix/X$d ]; do d=$((d + 1)); done
    Xvfb :$d -screen 0 "$1"x24 -nolisten tcp >"$TMP/xvfb.log" 2>&1 &
    XPID=$!
    export DISPLAY=:$d
    for i in $(seq 50); do xdotool getdisplaygeometry >/dev/null 2>&1 && break; sleep 0.1; done
    if [ "${2:-}" = wm ]; then
        openbox >"$TMP/wm.log" 2>&1 &
        WMPID=$!
        for i in $(seq 50); do xprop -root _NET_SUPPORTING_WM_CHECK 2>/dev/null | grep -q window && break; sleep 0.1; done
        sleep 1 # (a window mapped while openbox starts may never be: SDL would wait for it)
    fi
}

# the size the window's screenshot reports ("(WxH, event"): the drawable
shot_size() { sed -n 's/.*screenshot .* (\([0-9]*x[0-9]*\), event.*/\1/p' "$1" | tail -1; }
fits() { # WxH within SWxSH
    local w=${1%x*} h=${1#*x} sw=${2%x*} sh=${2#*x}
    [ -n "$1" ] && [ "$w" -le "$sw" ] && [ "$h" -le "$sh" ]
}

for wm in nowm wm; do
    for scr in 1024x768 1920x1080; do
        screen $scr $wm
        # the default window (1600x1000 asked): within the screen
        timeout -k 5 40 "$V" synth:srm:8:8:4 --screenshot "$TMP/d.png" --script "wait:5 q" 2>"$TMP/d.err"
        sz=$(shot_size "$TMP/d.err")
        if fits "$sz" $scr; then ok "window_fits_${wm}_$scr"; else fail "window_fits_${wm}_$scr" "window $sz on $scr"; fi
        # F11: the whole screen, then the window's own size back
        timeout -k 5 40 "$V" synth:srm:8:8:4 --size 800x600 --screenshot "$TMP/f.png" \
            --script "wait:3 f11 wait:15 s f11 wait:15 s wait:2 q" 2>"$TMP/f.err"
        set -- $(sed -n 's/.*screenshot .* (\([0-9]*x[0-9]*\), event.*/\1/p' "$TMP/f.err")
        if [ "${1:-}" = $scr ] && [ "${2:-}" = 800x600 ]; then ok "f11_full_and_back_${wm}_$scr"
        else fail "f11_full_and_back_${wm}_$scr" "sizes: $*"; fi
        # (one run a scale: the headless test has both runs at every scale)
        for fs in 1 1.5 2; do
            for spec in "synth:srm:8:8:4 --at 465" "synth:graham:40 --at 60"; do
                [ "$fs" = 1.5 ] && [ "${spec#synth:srm}" != "$spec" ] && continue
                [ "$fs" != 1.5 ] && [ "${spec#synth:graham}" != "$spec" ] && continue
                n=$(echo "${spec}_${scr}_${fs}_$wm" | tr -c 'a-z0-9\n' _)
                # m and s show their result in the status row of the frame reported
                timeout -k 5 40 "$V" $spec --font-scale $fs --layout-report "$TMP/$n.json" \
                    --screenshot "$TMP/$n.png" --script "m wait:5 s wait:2 q" 2>"$TMP/$n.err"
                if $CHECK --min-px 16 --min-big 18 --status "$TMP/$n.json" >"$TMP/$n.out" &&
                   grep -Eq '"(mark at|saved) ' "$TMP/$n.json"; then ok "window_readable_$n"
                else fail "window_readable_$n" "$(head -3 "$TMP/$n.out" "$TMP/$n.err")"; fi
            done
        done
    done
done
summary
