#!/bin/bash
# The viewer's speed (issue 5): open a run of about 10^7 events, seek
# anywhere (median), step back, and draw 10^5 edges (frames per second,
# headless, 1600x1000).  Goals: open < 1 s, seek < 50 ms, 60 frames/s.
# The 10^7-event run is a synthetic one (pdtview --write-run: a 1000 x 1100
# grid on 8 ranks, level 2) written through the trace writer and read back
# through the reader library, so "open" covers pdt_run_open + pdt_run_merged
# + the replay index.  Prints figures; never fails on a time.
set -u
cd "$(dirname "$0")/../.."
V=bin/pdtview
OUT=build/bench/view
mkdir -p "$OUT"
RUN=$OUT/run-1e7
if [ ! -f "$RUN/manifest" ]; then
    echo "writing the 10^7-event run (once) ..."
    "$V" --write-run "$RUN" synth:srm:1000:1100:8 || exit 1
fi
echo "-- a run of ~10^7 events (cpu = process CPU time: the machine may be shared)"
"$V" --bench "$RUN" --size 1600x1000 | grep -v '^draw'
echo "-- drawing 10^5 edges (130 x 130 grid, 4 ranks, end state)"
"$V" --bench synth:srm:130:130:4 --size 1600x1000 | grep '^draw'
