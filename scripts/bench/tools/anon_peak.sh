#!/bin/bash
# anon_peak.sh OUT CMD...: run CMD (its output to the file OUT) and print the
# largest RssAnon (KiB) seen in /proc/PID/status, sampled every 10 ms: the
# command's own memory (GNU time's maxrss counts its mapped file pages too).
# Exits with CMD's status.  Used by bench/45-replay.sh and
# tests/sh/trace_check_bounded.sh.  A sample can miss a short peak, never
# make one up.
out=$1; shift
"$@" >"$out" 2>&1 &
pid=$! peak=0
while kill -0 $pid 2>/dev/null; do
    a=$(awk '/^RssAnon/ {print $2}' /proc/$pid/status 2>/dev/null)
    [ -n "$a" ] && [ "$a" -gt "$peak" ] && peak=$a
    sleep 0.01
done
wait $pid
rc=$?
echo "$peak"
exit $rc
