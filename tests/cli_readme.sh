#!/bin/sh
# cli_readme.sh - the README's C example ("As a library"), as written: its
# code block is taken from README.md, compiled against the library with a
# main that reads a plain scan log, and run on a log made here whose map
# needs more data points than polyc_limits_for_scans gives (the example's
# retry with the worst-case limits): it must print the map the polyc tool
# makes (the same polylines and vertices), and an error for a log the
# library refuses.
#   tests/cli_readme.sh "CC FLAGS" POLYC     (libpolyc.a next to POLYC)
set -u
[ $# -eq 2 ] || { echo "usage: $0 \"CC FLAGS\" POLYC" >&2; exit 2; }
CCF=$1
case $2 in /*) POLYC=$2 ;; *) POLYC=$(pwd)/$2 ;; esac
ROOT=$(cd "$(dirname "$0")/.." && pwd)
LIB=$(dirname "$POLYC")/libpolyc.a
[ -x "$POLYC" ] && [ -r "$LIB" ] || { echo "$0: no $POLYC or $LIB" >&2; exit 2; }

. "$ROOT/tests/cli_lib.sh"
cli_scratch readme

# the first C block of the section "As a library", unchanged
awk '/^## As a library/ { in_section = 1; next }
     /^## / { in_section = 0 }
     in_section && /^```c$/ && !done { block = 1; next }
     block && /^```$/ { block = 0; done = 1; next }
     block { print }' "$ROOT/README.md" > example.c
cat >> example.c << 'EOF'

/* the test's main: a log in polyc's plain format (`polyc convert`'s: a few
 * comment lines, then SCAN lines) */
int main(int argc, char **argv)
{
    FILE *f = argc == 2 ? fopen(argv[1], "r") : NULL;
    polyc_scan *scans = NULL;
    float *ranges = NULL;
    uint32_t n = 0, cap = 0;
    size_t used = 0, room = 0;
    double x, y, th;
    float start, step, lo, hi;
    unsigned beams;
    if (!f)
        return 2;
    for (int k = 1; k > 0;) {                           /* # comment lines */
        k = 0;
        if (fscanf(f, " #%*[^\n]%n", &k) == EOF)
            break;
    }
    while (fscanf(f, " SCAN %lf %lf %lf %f %f %f %f %u", &x, &y, &th, &start, &step, &lo, &hi,
                  &beams) == 8) {
        if (n == cap && !(scans = realloc(scans, (cap = 2 * cap + 16) * sizeof *scans)))
            return 2;
        if (used + beams > room && !(ranges = realloc(ranges, (room = 2 * (used + beams)) *
                                                                  sizeof *ranges)))
            return 2;
        for (unsigned i = 0; i < beams; i++)
            if (fscanf(f, "%f", &ranges[used + i]) != 1)
                return 2;
        polyc_scan s = {0};
        s.pose_x_m = x, s.pose_y_m = y, s.pose_theta_rad = th;
        s.start_angle_rad = start, s.angle_step_rad = step;
        s.min_range_m = lo, s.max_range_m = hi, s.beam_count = beams;
        s.range_m = (const float *)(uintptr_t)used;     /* an offset until the pool is whole */
        scans[n++] = s;
        used += beams;
    }
    fclose(f);
    for (uint32_t i = 0; i < n; i++)
        scans[i].range_m = ranges + (uintptr_t)scans[i].range_m;
    int rc = print_map(scans, n);
    free(scans);
    free(ranges);
    return rc;
}
EOF

name=compile
count=$((count + 1))
# shellcheck disable=SC2086
$CCF -std=c99 -Wall -Wextra -Wpedantic -Werror -I"$ROOT/include" example.c "$LIB" -lm \
    -o example 2> err.txt || bad "the README's example does not compile"

# 100 scans, 5 m apart on a 10 x 10 grid, each of a round room of 2 m
# radius: every beam's endpoint in a cell of its own (18,100 data points),
# more than polyc_limits_for_scans gives (10,776)
awk 'BEGIN { for (s = 0; s < 100; s++) {
    printf "SCAN %d %d 0 -1.5707964 0.017453292 0.02 30 181", 5 * (s % 10), 5 * int(s / 10)
    for (i = 0; i < 181; i++) printf " 2"
    printf "\n" } }' > rooms.log

name=example-on-rooms
count=$((count + 1))
if [ -x example ]; then
    "$POLYC" convert -o rooms.txt rooms.log             # with its comment lines
    timeout 120 ./example rooms.txt > out.txt 2> err.txt
    rc=$?
    lines=$(grep -c '^closed\|^open' out.txt)
    points=$(awk '{ n += $2 } END { print n + 0 }' out.txt)
    timeout 120 "$POLYC" --stats -o map.svg rooms.log 2> stats.txt
    want=$(awk '/^final / { print $2, $4 }' stats.txt)
    [ $rc -eq 0 ] && [ "$lines" -gt 0 ] && [ "$lines $points" = "$want" ] ||
        bad "exit $rc, $lines polylines of $points points; the tool: $want"
fi

name=example-error
count=$((count + 1))
if [ -x example ]; then
    printf 'SCAN 0 0 0 0 0.1 0.02 30 3 1 1 1\nSCAN 5000 0 0 0 0.1 0.02 30 3 1 1 1\n' > far.log
    ./example far.log > out.txt 2> err.txt
    rc=$?
    [ $rc -eq 1 ] && [ ! -s out.txt ] && grep -q '^polyc: data extent' err.txt ||
        bad "exit $rc: no error printed for data wider than the grid"
fi

echo "cli_readme: $count runs, $failed failed"
[ $failed -eq 0 ]
