#!/bin/bash
# The picture of lesson 10: where the simulated time goes as P grows.
#
#   scripts/plot-phases.sh TABLE.md OUT.png [TITLE]
#
# TABLE.md is the output of scripts/simulate-scaling.sh (make simulate); its
# first table (one size, strong scaling) becomes one stacked bar per P: the
# simulated seconds of each phase (read, partition, local, merge, order,
# write: each the largest over the ranks), with the speedup (total of the first row / total) over the
# table's first row above each bar.  Needs gnuplot (gnuplot-nox).
# Exit status: 0, 1 when gnuplot fails, 2 for a usage error.
set -u
[ $# -ge 2 ] || { sed -n '2,/^# Exit status/s/^# \{0,1\}//p' "$0" >&2; exit 2; }
table=$1 out=$2 title=${3:-}
[ -r "$table" ] || { echo "plot-phases.sh: $table: cannot read" >&2; exit 2; }
command -v gnuplot > /dev/null || { echo "plot-phases.sh: gnuplot not found (apt-get install gnuplot-nox)" >&2; exit 2; }
[ -n "$title" ] || title=$(grep -m1 '^Strong scaling' "$table")
platform=$(grep -m1 '^Platform:' "$table" | sed 's/^Platform: //' | tr -d '"')
data=$(mktemp "${TMPDIR:-/tmp}/pdt-plot.XXXXXX")
trap 'rm -f "$data"' EXIT
# the first table's rows: P read partition local merge order write total speedup
awk -F'|' '/^\| P \|/ { t++; next } t == 1 && /^\| [0-9]/ {
        gsub(/ /, ""); print $2, $4, $5, $6, $7, $8, $9, $10, $11 } t == 1 && /^$/ && n++ { exit }' \
    "$table" > "$data"
[ -s "$data" ] || { echo "plot-phases.sh: $table: no table of simulate-scaling.sh" >&2; exit 2; }
gnuplot <<EOF || exit 1
set terminal pngcairo size 960,560 font "DejaVu Sans,11"
set output "$out"
set title "$title\n{/*0.8 simulated on $platform}"
set style data histograms
set style histogram rowstacked
set style fill solid 0.85 border -1
set boxwidth 0.7
set ylabel "simulated seconds"
set xlabel "ranks P"
set key outside right top vertical
set grid ytics
set yrange [0:*]
plot "$data" using 2:xtic(1) title "read" lc rgb "#9e9e9e", \
     "" using 3 title "partition" lc rgb "#1f77b4", \
     "" using 4 title "local" lc rgb "#2ca02c", \
     "" using 5 title "merge" lc rgb "#d62728", \
     "" using 6 title "order" lc rgb "#ff7f0e", \
     "" using 7 title "write" lc rgb "#9467bd", \
     "" using 0:(\$2+\$3+\$4+\$5+\$6+\$7):(sprintf("%.1fx", \$9)) with labels offset 0,0.8 notitle
EOF
