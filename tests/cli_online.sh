#!/bin/sh
# cli_online.sh - polyc --online (docs/formats.md, "Online"): the bundled
# log replayed as a stream gives a valid map, the same one twice; --stats
# shows the latencies, --trace the finish's iterations, --memory-mb caps the
# block; --frames writes one SVG every --every scans into a
# folder it makes, as -o writes (a symlink's target replaced); --work 0,
# --frames without --online and --online with a map are refused.
#   tests/cli_online.sh POLYC [LOG]
# LOG defaults to examples/office.log (195 scans).
set -u
[ $# -ge 1 ] || { echo "usage: $0 POLYC [LOG]" >&2; exit 2; }
case $1 in /*) POLYC=$1 ;; *) POLYC=$(pwd)/$1 ;; esac
ROOT=$(cd "$(dirname "$0")/.." && pwd)
LOG=${2:-$ROOT/examples/office.log}
case $LOG in /*) ;; *) LOG=$(pwd)/$LOG ;; esac
[ -x "$POLYC" ] && [ -r "$LOG" ] || { echo "$0: cannot run $POLYC on $LOG" >&2; exit 2; }

. "$ROOT/tests/cli_lib.sh"
cli_scratch online
# run ARGS...: polyc with a time limit; rc, stdout in out.txt, stderr in err.txt
run() {
    count=$((count + 1))
    timeout 120 "$POLYC" "$@" > out.txt 2> err.txt
    rc=$?
}
is_svg() { head -c 200 "$1" | grep -q '<svg' && tail -c 7 "$1" | grep -q '</svg>'; }
# refused NAME PATTERN ARGS...: exit 2, one line matching PATTERN, then the hint
refused() {
    name=$1 pattern=$2
    shift 2
    run "$@"
    [ $rc -eq 2 ] || bad "exit $rc, expected 2"
    head -n 1 err.txt | grep -qE -- "$pattern" || bad "stderr does not match '$pattern'"
    [ -s out.txt ] && bad "stdout is not empty"
}
scans=$(grep -c '^ROBOTLASER1\|^FLASER\|^SCAN' "$LOG")

name=online-svg
run --online -o map.svg "$LOG"
[ $rc -eq 0 ] && is_svg map.svg || bad "exit $rc, or no SVG"
grep -q '<g id="polylines"' map.svg && grep -q '<path stroke=' map.svg || bad "no polyline drawn"

name=online-json
run --online -o map.json "$LOG"
[ $rc -eq 0 ] || bad "exit $rc"
python3 - map.json "$scans" << 'EOF' || bad "not a map of the log's scans"
import json, sys
m = json.load(open(sys.argv[1]))
lines = m["polylines"]
assert lines and all(len(p["points"]) >= 2 for p in lines), "no polyline"
assert m["stats"]["scans"] == int(sys.argv[2]), m["stats"]["scans"]
assert m["stats"]["vertices"] == sum(len(p["points"]) for p in lines)
EOF

name=online-same-twice
run --online --format txt -o a.txt "$LOG"
run --online --format txt -o b.txt "$LOG"
[ $rc -eq 0 ] && [ -s a.txt ] && cmp -s a.txt b.txt || bad "two runs differ"

name=online-stats
run --online --stats -o map.svg "$LOG"
[ $rc -eq 0 ] || bad "exit $rc"
for what in '^online +[0-9]+ scans, --work 8000' '^add ms +median [0-9.]+, p99 [0-9.]+, max' \
            '^add\+update ms +median [0-9.]+, p99 [0-9.]+, max' \
            '^online ms +adds and updates [0-9.]+ in all, finish [0-9.]+' \
            '^backlog +at most [0-9]+ tiles' '^final +[0-9]+ polylines'; do
    grep -qE -- "$what" err.txt || bad "no line '$what' in --stats"
done

name=online-work
run --online --work 1 --format txt -o w1.txt "$LOG"
[ $rc -eq 0 ] && [ -s w1.txt ] || bad "--work 1: exit $rc"
refused work-zero '^polyc: --work needs a budget of 1 or more' --online --work 0 "$LOG"
refused work-junk '^polyc: --work needs' --online --work x "$LOG"

name=online-trace
run --online --trace tr.txt -o map.svg "$LOG"
[ $rc -eq 0 ] && [ "$(head -n 1 tr.txt)" = "# iteration bic best_bic vertices polylines noise_m" ] \
    && [ "$(wc -l < tr.txt)" -ge 2 ] || bad "exit $rc, or no finish iterations in the trace"

name=online-memory-cap
run --online --memory-mb 1 -o capped.svg "$LOG"
[ $rc -eq 3 ] && grep -q '^polyc: memory budget too small: need [0-9]* bytes' err.txt \
    && [ ! -e capped.svg ] || bad "exit $rc, expected 3 and no output"

name=frames
run --online --frames fr --every 50 -o map.svg "$LOG"
want=$((scans / 50))
got=$(ls fr 2> /dev/null | grep -c '^frame-[0-9]\{5\}\.svg$')
[ $rc -eq 0 ] && [ "$got" -eq "$want" ] || bad "exit $rc, $got frames, expected $want"
[ -e fr/frame-00050.svg ] && is_svg fr/frame-00050.svg || bad "no frame-00050.svg"
[ -e fr/frame-00100.svg ] || bad "no frame-00100.svg"
grep -q '<g id="path"' fr/frame-00050.svg || bad "no robot path in the frame"
grep -q "50 of $scans scans" fr/frame-00050.svg || bad "the frame's title does not count its scans"
[ "$(ls -A fr | grep -c '^\.polyc-')" -eq 0 ] || bad "temporary files left in fr"

name=frames-leave-map
run --online --frames fr7 --every 7 --format txt -o framed.txt "$LOG"
[ $rc -eq 0 ] && cmp -s a.txt framed.txt || bad "exit $rc, or the map differs with frames"

name=frames-default-every
rm -rf fr
run --online --frames fr -o map.svg "$LOG"
got=$(ls fr 2> /dev/null | wc -l)
[ $rc -eq 0 ] && [ "$got" -eq "$want" ] || bad "exit $rc, $got frames, expected $want (every 50)"

name=frames-symlink
rm -rf fr && mkdir fr && echo old > kept.svg && ln -s ../kept.svg fr/frame-00050.svg
run --online --frames fr --every 50 -o map.svg "$LOG"
[ $rc -eq 0 ] && [ -L fr/frame-00050.svg ] && is_svg kept.svg \
    || bad "exit $rc, or the link replaced instead of its target"

name=frames-more-than-scans
rm -rf fr
run --online --frames fr --every 100000 -o map.svg "$LOG"
[ $rc -eq 0 ] && [ -d fr ] && [ -z "$(ls -A fr)" ] || bad "exit $rc, or frames written"

refused frames-batch '^polyc: --frames does not apply to a batch run' --frames fr "$LOG"
refused every-batch '^polyc: --every does not apply to a batch run' --every 5 "$LOG"
refused every-alone '^polyc: --every needs --frames' --online --every 5 "$LOG"
refused every-zero '^polyc: --every needs 1\.\.' --online --frames fr --every 0 "$LOG"
echo x > plain.txt
refused frames-file "^polyc: --frames 'plain.txt' is not a folder" --online --frames plain.txt "$LOG"
refused frames-empty "^polyc: --frames '' is empty" --online --frames '' "$LOG"
refused online-no-optimize '^polyc: --no-optimize does not apply to --online' \
    --online --no-optimize "$LOG"
refused online-grid-cmd '^polyc: --online does not apply to polyc grid' --online grid -o g "$LOG"

name=frames-no-parent
run --online --frames no/such/dir -o map.svg "$LOG"
[ $rc -eq 1 ] && grep -q '^polyc: --frames no/such/dir: ' err.txt || bad "exit $rc"

# a map: made by polyc grid, refused with --online
name=online-map
run grid -o room "$LOG"
[ $rc -eq 0 ] && [ -s room.yaml ] || bad "polyc grid: exit $rc"
refused online-map '^polyc: --online does not apply to a map YAML' --online -o m.svg room.yaml
[ -e m.svg ] && bad "m.svg written"

# a log whose only scan has no beam: an empty map, as a batch run gives
name=online-no-beams
printf 'SCAN 0 0 0 0 0.1 0.02 30 0\n' > nobeam.log
run --online --format json -o nobeam.json nobeam.log
[ $rc -eq 0 ] && grep -q '"polylines": \[\]' nobeam.json || bad "exit $rc, or not an empty map"
run --format json -o nobeam-batch.json nobeam.log
[ $rc -eq 0 ] && grep -q '"polylines": \[\]' nobeam-batch.json || bad "batch: exit $rc"

# scans 1e4 to 1e6 m apart: too wide for the grid, said with the file and the reach
for far in 1e4 1e5 5e5 1e6; do
    name=online-far-$far
    printf 'SCAN 0 0 0 0 0.1 0.02 30 3 1 1 1\nSCAN %s 0 0 0 0.1 0.02 30 3 1 1 1\n' $far > far.log
    run --online -o far.svg far.log
    [ $rc -eq 1 ] && [ "$(wc -l < err.txt)" -eq 1 ] &&
        grep -qE '^polyc: far\.log: the log reaches [0-9]+ m from its first pose: an online map of [0-9]+ m square is more than the grid.s limit of 2000 m$' err.txt ||
        bad "exit $rc, or not the extent message"
    [ -e far.svg ] && bad "far.svg written"
done

# a log whose returns fall in more tiles than a usual building's: posts seen
# from 900 poses over a 96 m square (about 2,000 tiles against the area's
# estimate of 1,024): sized from the log, mapped in one replay
name=online-sized-from-log
awk 'BEGIN {
    for (i = 0; i < 30; i++) for (j = 0; j < 30; j++) {
        printf "SCAN %d %d 0 -3.14159 0.0872665 0.02 30 72", 3.3 * i, 3.3 * j
        for (k = 0; k < 72; k++) printf " %.2f", 0.5 + 0.3 * (k % 2)
        printf "\n"
    } }' > posts.log
run --online --stats -o posts.svg posts.log
[ $rc -eq 0 ] && is_svg posts.svg && grep -q '^online .* block [0-9]* bytes$' err.txt ||
    bad "exit $rc, or the replay ran again with a larger block: $(grep '^online ' err.txt)"

echo "cli_online: $count runs, $failed failed"
[ $failed -eq 0 ]
