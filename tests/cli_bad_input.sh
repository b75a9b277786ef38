#!/bin/sh
# cli_bad_input.sh - every bad input of issue 6 through the polyc tool, and
# bad ROS maps (a map YAML and its PGM or PNG) and `polyc grid`.
#   tests/cli_bad_input.sh [--quick] POLYC
# Each input must give either a map (exit 0, what was skipped counted in
# --stats) or one line `polyc: FILE:LINE: reason` on stderr with a non-zero
# exit; never a crash, a hang, unbounded memory or a partial output file.
# The rules are in docs/formats.md ("What is refused, skipped or counted").
# --quick (sanitizer builds): skips the multi-megabyte inputs and the
# address-space limit, which sanitizers cannot run under.
set -u
quick=0
if [ "${1:-}" = --quick ]; then
    quick=1
    shift
fi
[ $# -eq 1 ] || { echo "usage: $0 [--quick] POLYC" >&2; exit 2; }
case $1 in /*) POLYC=$1 ;; *) POLYC=$(pwd)/$1 ;; esac
[ -x "$POLYC" ] || { echo "$0: $POLYC is not executable" >&2; exit 2; }
ROOT=$(cd "$(dirname "$0")/.." && pwd)   # for examples/office.log

. "$ROOT/tests/cli_lib.sh"
CLI_ERR_LINES=5
cli_scratch cli
trap 'rm -rf "$T"' EXIT INT TERM
LIMIT_S=120               # seconds per run: a hang fails
LIMIT_KB=3000000          # address space per run (plain builds): 3 GB

# run ARGS...: polyc with a time limit (and a memory limit unless --quick);
# sets rc, leaves stdout in out.txt and stderr in err.txt.
run() {
    count=$((count + 1))
    if [ $quick = 1 ]; then
        timeout $LIMIT_S "$POLYC" "$@" > out.txt 2> err.txt
    else
        (ulimit -v $LIMIT_KB && exec timeout $LIMIT_S "$POLYC" "$@") > out.txt 2> err.txt
    fi
    rc=$?
    if [ $rc -ge 124 ]; then
        bad "exit $rc (timeout, crash or signal)"
        return 1
    fi
    if ls -A | grep -q '^\.polyc-'; then
        bad "a temporary output file is left behind"
        rm -f .polyc-*
    fi
    # stderr is a file here: no progress line (it would carry a carriage return)
    if grep -q "$(printf '\r')" err.txt; then bad "a progress line on stderr, which is not a terminal"; fi
    return 0
}

# refused NAME FILE LINE PATTERN: exit 1, `polyc: FILE:LINE: ...` matching
# PATTERN (grep -E, after the prefix) as the only stderr line, no output file.
refused() {
    prefix="polyc: $2:$3: "
    [ "$3" = - ] && prefix="polyc: $2: "
    refused_as "$1" "$2" "$prefix" "$4"
}

# refused_as NAME FILE PREFIX PATTERN: the same, with the message's prefix
# given whole (a PGM's is `polyc: IMAGE: byte N: `).
refused_as() {
    name=$1 file=$2 prefix=$3 pattern=$4
    rm -f map.svg
    run -o map.svg "$file" || return
    [ $rc -eq 1 ] || bad "exit $rc, expected 1"
    [ -e map.svg ] && bad "map.svg exists after a failure"
    [ -s out.txt ] && bad "stdout is not empty"
    [ "$(wc -l < err.txt)" -eq 1 ] || bad "stderr is not one line"
    head -n 1 err.txt | grep -qF -- "$prefix" || bad "stderr does not start with '$prefix'"
    head -n 1 err.txt | grep -qE -- "$pattern" || bad "stderr does not match '$pattern'"
    if LC_ALL=C grep -q '[^ -~]' err.txt; then bad "stderr holds raw bytes"; fi
}

# mapped NAME FILE PATTERN...: exit 0, a complete SVG, each PATTERN (grep -E)
# found in the --stats lines.
mapped() {
    name=$1 file=$2
    shift 2
    rm -f map.svg
    run --stats --iterations 5 -o map.svg "$file" || return
    [ $rc -eq 0 ] || { bad "exit $rc, expected 0"; return; }
    tail -c 7 map.svg | grep -q '</svg>' || bad "map.svg is not a complete SVG"
    for p in "$@"; do
        grep -qE -- "$p" err.txt || bad "--stats lacks '$p'"
    done
}

GOOD='SCAN 0 0 0 -1.5707963 0.0174532924 0.02 8 5 1.0 1.05 1.1 1.15 1.2'

# ---- empty, binary, truncated, line endings ----
: > empty.log
refused empty empty.log - 'no scans found \(0 lines read; polyc reads CARMEN FLASER and ROBOTLASER1 lines, .*\)$'
printf '\n\n  \n# nothing\nODOM 1 2 3\n' > blank.log
refused blank blank.log - 'no scans found \(5 lines read; '
printf '%s\n' "$GOOD" | gzip -c > gzip.log
refused gzip gzip.log 1 'binary data \(byte 0x1f at column 1\)$'
refused elf "$POLYC" 1 'binary data \(byte 0x7f at column 1\)$' 2> /dev/null
# high bytes only, no control byte: not a keyword, quoted without raw bytes
printf '%s\n\200\233[2J\377\376 1 2\n' "$GOOD" > high.log
refused high-bytes high.log 2 "not a log line: starts with '.x80.x9b\[2J.xff.xfe'$"
printf '%s\n\000%s\n' "$GOOD" "$GOOD" > nul.log
refused nul nul.log 2 'binary data \(byte 0x00 at column 1\)$'
printf '%s\n%s' "$GOOD" "$(echo "$GOOD" | cut -c 1-40)" > cut.log
refused truncated cut.log 2 'missing max range \(field 8\) \(the file ends inside this line: truncated\?\)$'
printf '%s\n%s' "$GOOD" "$GOOD" > nonl.log
mapped no-final-newline nonl.log '^scans +2 '
printf '%s\r\n# c\r\n\r\n%s\r\n' "$GOOD" "$GOOD" > crlf.log
printf '%s\n# c\n\n%s\n' "$GOOD" "$GOOD" > lf.log
mapped crlf crlf.log '^scans +2 ' 'blank 1'
run --format txt lf.log && cp out.txt lf.txt
run --format txt crlf.log
cmp -s out.txt lf.txt || { name=crlf-same-map; bad "CRLF and LF give different maps"; }
printf '%s\r%s\r' "$GOOD" "$GOOD" > cr.log
refused cr-only cr.log 1 'SCAN with 5 beams needs 5 fields after the count, found 19 '

# ---- counts ----
printf '%s\nSCAN 0 0 0 0 0.1 0.02 8 6 1 1 1\n' "$GOOD" > more.log
refused count-too-big more.log 2 'SCAN with 6 beams needs 6 fields after the count, found 3$'
printf '%s\nSCAN 0 0 0 0 0.1 0.02 8 2 1 1 1\n' "$GOOD" > fewer.log
refused count-too-small fewer.log 2 'needs 2 fields after the count, found 3$'
printf '%s\nSCAN 0 0 0 0 0.1 0.02 8 2147483648 1 1\n' "$GOOD" > huge.log
refused count-2^31 huge.log 2 'beam count 2147483648 out of range \(at most 1048576\)$'
printf 'FLASER 4294967296 1 2 3\n' > huge2.log
refused count-2^32-flaser huge2.log 1 'beam count 4294967296 out of range'
printf 'ROBOTLASER1 0 -1 3 0.01 8 0.01 0 18446744073709551616 1 2\n' > huge3.log
refused count-2^64-robotlaser1 huge3.log 1 'beam count 18446744073709551616 out of range'
printf 'SCAN 0 0 0 0 0.1 0.02 8 -3 1 1 1\n' > neg.log
refused count-negative neg.log 1 "beam count is not a count: '-3' \(field 9\)$"
printf 'FLASER 3 1 1 1 0 0 0 0 0 0 0 h 0\nFLASER 3 1 1 0 0 0 0 0 0 0 h 0\n' > flcount.log
refused flaser-count flcount.log 2 'FLASER with 3 beams needs 12 fields after the count, found 11$'

# ---- ranges: bad values are skipped and counted, text is refused ----
printf '%s\nSCAN 0 0 0 0 0.1 0.02 8 6 -1 nan inf -inf 1e39 1.5\n' "$GOOD" > ranges.log
mapped bad-ranges ranges.log 'bad ranges 5,' 'skipped by the library 5\)'
printf 'FLASER 4 1 0.01 nan 2 0 0 0 0 0 0 0 h 0\nFLASER 4 1 1.1 1.2 2 0 0 0 0 0 0 0 h 0\n' > short.log
mapped carmen-short-ranges short.log 'bad ranges 1, below min range 1\)'
printf '%s\nSCAN 0 0 0 0 0.1 0.02 8 3 1 one 1\n' "$GOOD" > text.log
refused range-text text.log 2 "range is not a number: 'one' \(field 11\)$"
printf '%s\nSCAN 0 0 0 0 0.1 0.02 8 1 0x\n' "$GOOD" > hex.log
refused range-bad-hex hex.log 2 "range is not a number: '0x' \(field 10\)$"

# ---- poses and geometry ----
printf '%s\nSCAN 1e30 0 0 0 0.1 0.02 8 1 1\n' "$GOOD" > pose1.log
refused pose-1e30 pose1.log 2 'pose x 1e\+30 beyond \+-1e\+06 m$'
printf '%s\nSCAN 0 NaN 0 0 0.1 0.02 8 1 1\n' "$GOOD" > pose2.log
refused pose-nan pose2.log 2 'pose y is not finite$'
printf '%s\nSCAN 0 0 -inf 0 0.1 0.02 8 1 1\n' "$GOOD" > pose3.log
refused theta-inf pose3.log 2 'pose theta is not finite$'
printf 'FLASER 1 1 0 1e30 0 0 0 0 0 h 0\n' > pose4.log
refused flaser-pose-1e30 pose4.log 1 'pose y 1e\+30 beyond'
printf 'ROBOTLASER1 0 -1 3 0.5 8 0.01 0 2 1 1 0 nan 0 0 0 0 0 0 0 0 0 0 0 h 0\n' > pose5.log
refused robotlaser1-pose-nan pose5.log 1 'laser pose x is not finite$'
printf '%s\nSCAN 0 0 0 150 0.1 0.02 8 1 1\n' "$GOOD" > start.log
refused start-angle start.log 2 'start angle 150 rad beyond \+-100 rad$'
printf '%s\nSCAN 0 0 0 0 0 0.02 8 1 1\n' "$GOOD" > step.log
refused zero-step step.log 2 'angle step 0 rad not in'
printf '%s\nSCAN 0 0 0 0 0.1 0.02 1e30 1 1\n' "$GOOD" > maxr.log
refused max-range maxr.log 2 'max range 1e\+30 m out of'

# ---- a scan far from all others: refused before any memory is sized ----
{ for i in 1 2 3 4 5; do echo "$GOOD"; done
  echo 'SCAN 5000 -20 0 0 0.1 0.02 8 1 1'
  echo "$GOOD"; } > far.log
refused far-scan far.log 6 'this scan \(pose 5000.00 -20.00\) reaches 50[0-9][0-9] m from the median pose.*more than the grid.s limit of 2000 m$'
{ echo "$GOOD"; echo 'SCAN 0 0 0 0 0.1 0.02 1e6 1 3000'; echo "$GOOD"; } > farhit.log
refused far-hit farhit.log 2 'reaches 300[0-9] m from the median pose'
{ echo "$GOOD"; echo 'SCAN 999999 999999 0 0 0.1 0.02 8 1 1'; echo "$GOOD"; } > farpose.log
refused far-pose-1e6 farpose.log 2 'more than the grid.s limit of 2000 m$'

# ---- line types ----
printf '%s\nODOM 1 2 3\nPARAM x 1\nODOM 4\nRLASER 1 2\nFOO_BAR9 x\n' "$GOOD" > kw.log
mapped keywords kw.log 'lines skipped +5 \(ODOM 2, PARAM 1, RLASER 1, FOO_BAR9 1\)'
printf '%s\n$$$ 1 2 3\n' "$GOOD" > dollar.log
refused not-a-keyword dollar.log 2 "not a log line: starts with '\\\$\\\$\\\$'$"
printf '%s\nSCAN-1 2\n' "$GOOD" > dash.log
refused keyword-with-dash dash.log 2 "not a log line: starts with 'SCAN-1'$"
printf '%s\n# polyc-scans 2\n' "$GOOD" > ver.log
refused plain-version ver.log 2 "unsupported polyc-scans version '2'"
{ echo "$GOOD"; i=0; while [ $i -lt 40 ]; do echo "KEY$i 1"; i=$((i + 1)); done; } > many.log
mapped many-keywords many.log 'lines skipped +40 '

# ---- output: nothing partial, an old file untouched ----
echo old > map.svg
run -o map.svg text.log
name=old-output-kept
[ $rc -eq 1 ] && [ "$(cat map.svg)" = old ] || bad "a failed run changed an existing map.svg"
rm -f map.svg
# a missing folder: refused before any work (exit 2), the folder named
name=missing-dir
run -o nodir/map.svg lf.log
[ $rc -eq 2 ] && grep -q "^polyc: -o 'nodir/map.svg' is in a folder that does not exist$" err.txt \
    || bad "exit $rc for an output in a missing folder"
name=trace-unwritable
run --iterations 2 --trace nodir/trace.txt -o map.svg lf.log
[ $rc -eq 2 ] && [ ! -e map.svg ] \
    && grep -q "^polyc: --trace 'nodir/trace.txt' is in a folder that does not exist$" err.txt \
    || bad "exit $rc, or the map written although --trace cannot be"
name=dangling-link-missing-dir
ln -s nodir/map.svg dangling.svg
run -o dangling.svg lf.log
[ $rc -eq 2 ] && grep -q "^polyc: -o 'dangling.svg' is in a folder that does not exist$" err.txt \
    || bad "exit $rc for a link into a missing folder"
rm -f dangling.svg
# file names from the command line are escaped in messages, as input bytes are
name=escaped-names
esc=$(printf '\033')
run "$(printf 'evil\033[31m.log')"
[ $rc -eq 1 ] && grep -q '^polyc: evil\\x1b\[31m\.log: No such file or directory$' err.txt \
    && ! grep -q "$esc" err.txt || bad "exit $rc, or an ESC byte on stderr"
run -o "$(printf 'out\033]0;x\007.png')" lf.log
[ $rc -eq 2 ] && ! grep -q "$esc" err.txt || bad "exit $rc, or an ESC byte on stderr"
run -o "$(printf 'nodir\033[2J/m.svg')" lf.log
[ $rc -eq 2 ] && grep -q "^polyc: -o 'nodir\\\\x1b\[2J/m.svg' is in a folder" err.txt \
    && ! grep -q "$esc" err.txt || bad "exit $rc, or an ESC byte on stderr"
name=both-outputs
run --iterations 2 --trace trace.txt -o map.svg lf.log
[ $rc -eq 0 ] && [ -s map.svg ] && [ -s trace.txt ] || bad "exit $rc, map and trace not both written"
rm -f map.svg trace.txt
name=memory-budget
run --memory-mb 0.01 -o map.svg lf.log
[ $rc -eq 3 ] && [ ! -e map.svg ] && grep -q '^polyc: memory budget too small: need [0-9]* bytes ([0-9.]* MiB), --memory-mb 0.01 allows 0.01 MiB: give --memory-mb [0-9]* or more$' err.txt \
    || bad "exit $rc for a too small --memory-mb"
# ---- messages name the options ----
usage() {   # usage NAME PATTERN ARGS...: exit 2 and the message
    name=$1 pattern=$2
    shift 2
    run "$@"
    [ $rc -eq 2 ] && head -n 1 err.txt | grep -qE -- "^polyc: $pattern" || bad "exit $rc, expected 2 and '$pattern'"
}
usage cell-0 'bad option value: --cell must be in \[0.001, 10\]$' --cell 0 lf.log
usage threshold-1 'bad option value: --threshold must be in \[0, 1\)$' --threshold 1 lf.log
usage memory-huge "--memory-mb needs MiB from 0.000001 to 1000000000, not '1e10'$" --memory-mb 1e10 lf.log
usage convert-format '--format does not apply to polyc convert$' convert --format json lf.log
usage convert-points '--points does not apply to polyc convert$' convert --points lf.log
usage convert-no-optimize '--no-optimize does not apply to polyc convert$' convert --no-optimize lf.log
name=version
run --version
[ $rc -eq 0 ] && grep -qx "polyc $(awk '/define POLYC_VERSION_(MAJOR|MINOR|PATCH) /{v = v s $3; s = "."} END {print v}' "$ROOT/include/polyc.h")" out.txt \
    || bad "--version is not the library's version: $(cat out.txt)"
name=junk
echo 'hello world' > junk.log
run junk.log
[ $rc -eq 1 ] && grep -q "no scans found (1 lines read; polyc reads CARMEN FLASER and ROBOTLASER1 lines, polyc's SCAN lines, or a map_server map YAML)$" err.txt \
    || bad "exit $rc, or the message does not say which formats are read"
name=extent-margin
{ echo 'SCAN 0 0 0 -1.57 0.0174 0.02 8 3 1 1 1'; echo 'SCAN 1998 0 0 -1.57 0.0174 0.02 8 3 1 1 1'; } > wide.log
run --cell 1 wide.log
[ $rc -eq 1 ] && grep -q "plus the grid's margin of 4 m), more than the grid's limit of 2000 m$" err.txt \
    || bad "exit $rc, or the message for a 1998 m span does not name the limit"
if grep -q -- '--cell' err.txt; then bad "a larger --cell cannot help a span at the limit"; fi
name=stdin
printf '%s\n%s\n' "$GOOD" "SCAN 0 0 0 0 0.1 0.02 8 1 x" | {
    run -o map.svg -
    [ $rc -eq 1 ] && grep -q "^polyc: <stdin>:2: range is not a number: 'x'" err.txt \
        || bad "exit $rc for bad stdin"; }
name=no-such-file
run -o map.svg nonexistent.log
[ $rc -eq 1 ] && grep -q '^polyc: nonexistent.log: No such file or directory$' err.txt \
    || bad "exit $rc for a missing input"
mkdir adir
name=directory
run -o map.svg adir
[ $rc -eq 1 ] && grep -q '^polyc: adir: Is a directory: give a log file$' err.txt \
    || bad "exit $rc for a directory as input"
[ -e map.svg ] && bad "map.svg exists after a failure"

# ---- ROS maps: a map YAML and its PGM image ----
# A room in the image's top half (PGM rows 2..10 of 16), so that a row order
# turned upside down shows: its walls are at cell centres x -0.875..-0.125,
# y 2.275..2.675 with the origin (-1, 2) and 5 cm cells.
awk 'BEGIN { w = 20; h = 16; printf "P2\n# a room\n%d %d\n255\n", w, h
    for (y = 0; y < h; y++) { for (x = 0; x < w; x++) {
        v = (x < 2 || y < 2 || x > w - 3 || y > 10) ? 205 : (x == 2 || y == 2 || x == w - 3 || y == 10) ? 0 : 254
        printf "%d ", v }; printf "\n" } }' > room.pgm
REST='origin: [-1.0, 2.0, 0.0]
negate: 0
occupied_thresh: 0.65
free_thresh: 0.196'
printf 'image: room.pgm\nresolution: 0.05\n%s\n' "$REST" > room.yaml
# inside BOX (x0 x1 y0 y1): every point of the TXT map in out.txt is
inside() {
    awk -v x0=$1 -v x1=$2 -v y0=$3 -v y1=$4 '{ for (i = 3; i < NF; i += 2)
        if ($i < x0 || $i > x1 || $(i + 1) < y0 || $(i + 1) > y1) bad++; n += $2 }
        END { exit !(n >= 4 && bad == 0) }' out.txt
}
name=map-room
run --format txt room.yaml
[ $rc -eq 0 ] && [ -s out.txt ] || bad "exit $rc, no map"
inside -0.9 -0.1 2.25 2.7 || bad "the room's polylines are not in the map's frame: $(head -c 300 out.txt)"
name=map-room-yaw
printf 'image: room.pgm\nresolution: 0.05\norigin: [1.0, 0.0, 1.5707963268]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n' > yaw.yaml
run --format txt yaw.yaml
# turned by 90 degrees about (1, 0): (x, y) in the grid -> (1 - y, x)
[ $rc -eq 0 ] && inside 0.3 0.75 0.1 0.9 || bad "exit $rc, or the yaw is not applied: $(head -c 300 out.txt)"
# --memory-mb bounds the image's decoding: a 255 KB PNG that unpacks to
# 16384 x 16383 pixels (512 MiB with its cells) is refused from its header,
# before anything is allocated (within 100 MB of address space)
if [ $quick = 0 ]; then
    name=map-png-memory-budget
    python3 - << 'EOF2'
import struct, zlib
w, h = 16384, 16383
def chunk(t, d):
    return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xffffffff)
c = zlib.compressobj(9)
row = bytes(w + 1)
z = b"".join(c.compress(row) for _ in range(h)) + c.flush()
with open("huge.png", "wb") as f:
    f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 0, 0, 0, 0))
            + chunk(b"IDAT", z) + chunk(b"IEND", b""))
EOF2
    printf 'image: huge.png\nresolution: 0.05\n%s\n' "$REST" > huge.yaml
    count=$((count + 1))
    (ulimit -v 100000 && exec timeout $LIMIT_S "$POLYC" --memory-mb 1 -o huge.svg huge.yaml) \
        > out.txt 2> err.txt
    rc=$?
    [ $rc -eq 3 ] && grep -qE '^polyc: memory budget too small: image huge.png needs 537[0-9]{6} bytes \(512.5 MiB\) to read \(16384 x 16383 pixels\), --memory-mb 1 allows 1 MiB: give --memory-mb 513 or more$' err.txt \
        || bad "exit $rc, or not refused by --memory-mb before decoding"
    [ -e huge.svg ] && bad "huge.svg written"
    rm -f huge.png huge.yaml huge.svg
fi
name=map-memory-budget-pgm
run --memory-mb 1 -o map.svg room.yaml
[ $rc -eq 0 ] || bad "exit $rc: a 20 x 16 map within --memory-mb 1"
printf 'P5\n1000 1000\n255\n' > wide.pgm
head -c 1000000 /dev/zero >> wide.pgm
printf 'image: wide.pgm\nresolution: 0.05\n%s\n' "$REST" > wide.yaml
run --memory-mb 1 -o map.svg wide.yaml
[ $rc -eq 3 ] && grep -q '^polyc: memory budget too small: image wide.pgm needs 4000017 bytes' err.txt \
    || bad "exit $rc: a 1000 x 1000 PGM read within --memory-mb 1"
rm -f map.svg wide.pgm wide.yaml
name=map-stats
run --stats -o map.svg room.yaml
[ $rc -eq 0 ] && tail -c 7 map.svg | grep -q '</svg>' || bad "exit $rc, no complete SVG"
grep -qE '^map +20 x 16 cells of 0.05 m, room.pgm \(P2, maxval 255\), mode trinary$' err.txt \
    || bad "--stats lacks the map line"
grep -qE '^cells +occupied 46, free 98, unknown 176$' err.txt || bad "--stats lacks the cell counts"
rm -f map.svg
# the same room as P5 (binary), in another folder: the image is found next
# to the YAML, or by its absolute path
mkdir -p sub/dir
{ printf 'P5\n20 16\n255\n'; awk 'NR > 4 { for (i = 1; i <= NF; i++) printf "%s\n", $i }' room.pgm |
    while read -r v; do case $v in 0) printf '\000' ;; 254) printf '\376' ;; *) printf '\315' ;; esac; done
} > sub/dir/room5.pgm
printf 'image: room5.pgm\nresolution: 0.05\n%s\n' "$REST" > sub/dir/m.yaml
printf 'image: "%s/sub/dir/room5.pgm"\nresolution: 0.05\n%s\n' "$T" "$REST" > abs.yaml
run --format txt room.yaml && cp out.txt p2.txt
for f in sub/dir/m.yaml abs.yaml; do
    name="map-path-$f"
    run --format txt "$f"
    [ $rc -eq 0 ] && cmp -s out.txt p2.txt || bad "exit $rc, or the P5 map differs from the P2 one"
done
# the same room as PNG: 8-bit gray, and 8-bit RGBA in scale mode with the
# unknown cells transparent (what nav2's map_saver writes in scale mode):
# the same cells, so the same map
printf '\211\120\116\107\015\012\032\012\000\000\000\015\111\110\104\122\000\000\000\024\000\000\000\020\010\000\000\000\000\063\163\000\307\000\000\000\040\111\104\101\124\170\332\143\070\213\005\060\340\020\144\100\003\020\301\177\050\140\120\010\142\163\047\361\336\244\104\020\000\035\300\356\055\117\046\130\374\000\000\000\000\111\105\116\104\256\102\140\202' > room_g.png
printf '\211\120\116\107\015\012\032\012\000\000\000\015\111\110\104\122\000\000\000\024\000\000\000\020\010\006\000\000\000\026\030\137\033\000\000\000\055\111\104\101\124\170\332\143\070\173\366\054\003\065\061\003\315\014\004\202\377\224\140\254\006\376\373\367\217\054\074\152\340\210\066\220\252\351\160\360\147\275\221\143\040\000\034\301\132\042\323\172\235\046\000\000\000\000\111\105\116\104\256\102\140\202' > room_c.png
printf 'image: room_g.png\nresolution: 0.05\n%s\n' "$REST" > png_g.yaml
printf 'image: room_c.png\nmode: scale\nresolution: 0.05\n%s\n' "$REST" > png_c.yaml
for f in png_g.yaml png_c.yaml; do
    name="map-png-$f"
    run --format txt "$f"
    [ $rc -eq 0 ] && cmp -s out.txt p2.txt || bad "exit $rc, or the PNG map differs from the PGM one"
done
name=map-png-stats
run --stats -o map.svg png_c.yaml
[ $rc -eq 0 ] && grep -qE '^map +20 x 16 cells of 0.05 m, room_c.png \(PNG, 8-bit RGBA\), mode scale$' err.txt \
    || bad "exit $rc, or --stats lacks the PNG's map line"
rm -f map.svg

# refused: the YAML's line, or the image's byte
cat > nonegate.yaml <<YAML
image: room.pgm
resolution: 0.05
origin: [-1.0, 2.0, 0.0]
occupied_thresh: 0.65
free_thresh: 0.196
YAML
refused map-missing-key nonegate.yaml 5 'no negate key \(map_server needs it\)$'
printf 'image: room.pgm\nresolution: 5cm\n%s\n' "$REST" > badnum.yaml
refused map-bad-number badnum.yaml 2 "resolution: '5cm' is not a number$"
printf 'image: room.pgm\nresolution: 0\n%s\n' "$REST" > res0.yaml
refused map-resolution-0 res0.yaml 2 'resolution 0 must be above 0 m$'
printf 'image: room.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.3\nfree_thresh: 0.4\n' > order.yaml
refused map-free-above-occupied order.yaml 6 'free_thresh 0.4 must be below occupied_thresh 0.3$'
printf 'image: room.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 1.2\nfree_thresh: 0.4\n' > over.yaml
refused map-threshold-over-1 over.yaml 5 'occupied_thresh 1.2 is outside \[0, 1\]$'
printf 'image: room.pgm\nresolution: 0.05\nmode: binary\n%s\n' "$REST" > mode.yaml
refused map-bad-mode mode.yaml 3 "mode must be trinary, scale or raw, not 'binary'$"
printf 'image: room.pgm\nresolution: 0.05\norigin: [0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n' > origin2.yaml
refused map-origin-2 origin2.yaml 3 'origin must have 3 elements \[x, y, yaw\], not 2$'
printf 'image: nothere.pgm\nresolution: 0.05\n%s\n' "$REST" > noimg.yaml
refused map-no-image noimg.yaml 1 'image nothere.pgm: No such file or directory$'
printf 'image: "\\e[2J.pgm"\nresolution: 0.05\n%s\n' "$REST" > esc.yaml
refused map-image-name-escaped esc.yaml 1 'image .x1b\[2J.pgm: No such file or directory$'
printf 'image: adir\nresolution: 0.05\n%s\n' "$REST" > dirimg.yaml
refused map-image-directory dirimg.yaml 1 'image adir: Is a directory$'
for dev in /dev/zero /dev/urandom; do
    printf 'image: %s\nresolution: 0.05\n%s\n' $dev "$REST" > dev.yaml
    refused "map-image-$dev" dev.yaml 1 "image $dev: not a regular file \(a device or a FIFO\): give a PGM or PNG file$"
done
mkfifo fifo.pgm
printf 'image: fifo.pgm\nresolution: 0.05\n%s\n' "$REST" > fifo.yaml
refused map-image-fifo fifo.yaml 1 'image fifo.pgm: not a regular file'
rm -f fifo.pgm
name=map-stats-escaped
cp room.pgm "$(printf '\033[2J.pgm')"
run --stats -o map.svg esc.yaml
[ $rc -eq 0 ] && grep -qF 'cells of 0.05 m, \x1b[2J.pgm (P2' err.txt || bad "exit $rc, or --stats lacks the escaped image name"
if LC_ALL=C grep -q '[^ -~]' err.txt; then bad "--stats prints raw bytes"; fi
rm -f map.svg "$(printf '\033[2J.pgm')"
printf '\211PNG\r\n\032\n\000\000\000\rIHDR' > png.pgm
printf 'image: png.pgm\nresolution: 0.05\n%s\n' "$REST" > png.yaml
refused_as map-png-truncated png.yaml 'polyc: png.pgm: byte 8: ' 'the file ends before its IEND chunk \(truncated\)$'
img() { printf 'image: %s\nresolution: 0.05\n%s\n' "$1" "$REST" > "$1.yaml"; }
printf 'P5\n4 2\n255\n\000\000\000' > cut.pgm; img cut.pgm
refused_as map-truncated cut.pgm.yaml 'polyc: cut.pgm: byte 14: ' 'truncated: 3 bytes of pixel data, 4 x 2 at 1 bytes a pixel need 8$'
printf 'P5\n4 2\n255\n\000\000\000\000\000\000\000\000\n' > long.pgm; img long.pgm
refused_as map-trailing long.pgm.yaml 'polyc: long.pgm: byte 19: ' '1 bytes after the pixel data \(trailing garbage, or the size does not match\)$'
printf 'P5\n4 2\n0\n\000\000\000\000\000\000\000\000' > max0.pgm; img max0.pgm
refused_as map-maxval-0 max0.pgm.yaml 'polyc: max0.pgm: byte 7: ' 'maxval is 0 \(must be 1..65535\)$'
printf 'P5\n4 2\n70000\n' > maxbig.pgm; img maxbig.pgm
refused_as map-maxval-70000 maxbig.pgm.yaml 'polyc: maxbig.pgm: byte 7: ' 'maxval above 65535$'
printf 'P5\n65536 65536\n255\n' > huge.pgm; img huge.pgm
refused_as map-huge huge.pgm.yaml 'polyc: huge.pgm: byte 9: ' '65536 x 65536 pixels: more than 268435456 cells$'
printf 'P2\n3 1\n255\n0 0\n' > p2cut.pgm; img p2cut.pgm
refused_as map-p2-truncated p2cut.pgm.yaml 'polyc: p2cut.pgm: byte 15: ' 'truncated: 2 of 3 pixel values \(3 x 1\)$'
printf 'P2\n21 1\n255\n' > wide.pgm; i=0; while [ $i -lt 21 ]; do printf '0 ' >> wide.pgm; i=$((i + 1)); done
printf 'image: wide.pgm\nresolution: 100\n%s\n' "$REST" > wide.yaml
refused map-too-wide wide.yaml 2 'the map spans 2100.0 x 100.0 m \(21 x 1 cells of 100 m\): more than the grid.s limit of 2000 m$'
refused map-image-given room.pgm - "an image: give the map's YAML file \(map_server's map.yaml\), which names the image$"
printf 'P5\n4 2\n255\n\000\000\000\000\000\000\000\000' > direct.pgm
refused map-p5-given direct.pgm - "an image: give the map's YAML file"
name=map-option-refused
run --cell 0.05 -o map.svg room.yaml
[ $rc -eq 2 ] && grep -q "^polyc: --cell does not apply to a map YAML" err.txt && [ ! -e map.svg ] \
    || bad "exit $rc for --cell on a map"
name=log-option-refused
run --occupied-thresh 0.5 -o map.svg lf.log
[ $rc -eq 2 ] && grep -q "^polyc: --occupied-thresh does not apply to a laser log$" err.txt \
    || bad "exit $rc for --occupied-thresh on a log"
name=map-grid-layer
run --grid --vertices --quiet -o map.svg room.yaml
[ $rc -eq 0 ] && grep -q '<path' map.svg || bad "exit $rc for --grid on a map"
rm -f map.svg
name=map-grid-layer-yaw
run --grid -o map.svg yaw.yaml
[ $rc -eq 2 ] && grep -q '^polyc: --grid draws the grid unrotated' err.txt && [ ! -e map.svg ] \
    || bad "exit $rc for --grid on a turned map"
name=map-thresholds
run --occupied-thresh 0.9 --free-thresh 0.1 --format txt room.yaml
[ $rc -eq 0 ] && inside -0.9 -0.1 2.25 2.7 || bad "exit $rc with --occupied-thresh and --free-thresh"
name=log-through-a-pipe
cat lf.log | { run --format txt /dev/stdin; cmp -s out.txt lf.txt || bad "exit $rc, or a log read through a pipe differs"; }
name=convert-map
run convert room.yaml
[ $rc -eq 1 ] && grep -q "^polyc: room.yaml: a map YAML: polyc convert takes a laser log$" err.txt \
    || bad "exit $rc for convert of a map"

# ---- polyc grid: the log's hit/miss grid as map_saver's two files ----
name=grid-needs-prefix
run grid lf.log
[ $rc -eq 2 ] && grep -q '^polyc: polyc grid needs -o PREFIX' err.txt || bad "exit $rc without -o"
name=grid-option-refused
run grid --alpha 5 -o g lf.log
[ $rc -eq 2 ] && grep -q '^polyc: --alpha does not apply to polyc grid$' err.txt && [ ! -e g.pgm ] \
    || bad "exit $rc for --alpha"
name=grid-files
run grid -o g lf.log
[ $rc -eq 0 ] && [ ! -s out.txt ] || bad "exit $rc, or output on stdout"
head -c 3 g.pgm | grep -q '^P5$' || bad "g.pgm is not a P5 image"
grep -qE '^image: g.pgm$' g.yaml && grep -qE '^resolution: 0.025000$' g.yaml &&
    grep -qE '^origin: \[-?[0-9]+\.[0-9]{6}, -?[0-9]+\.[0-9]{6}, 0\.000000\]$' g.yaml &&
    grep -qE '^negate: 0$' g.yaml && grep -qE '^occupied_thresh: 0.65$' g.yaml &&
    grep -qE '^free_thresh: 0.196$' g.yaml || bad "g.yaml is not map_saver's: $(cat g.yaml)"
name=grid-back-as-map
run --format txt g.yaml
[ $rc -eq 0 ] || bad "exit $rc reading polyc grid's map back"
mkdir -p out
name=grid-in-folder
run grid --cell 0.05 -o out/g lf.log
[ $rc -eq 0 ] && grep -q '^image: g.pgm$' out/g.yaml && grep -q '^resolution: 0.050000$' out/g.yaml \
    || bad "exit $rc, or out/g.yaml names its image by more than its file name"
name=grid-bad-log
cp g.yaml g.yaml.old
run grid -o g text.log
[ $rc -eq 1 ] && cmp -s g.yaml g.yaml.old || bad "exit $rc, or a failed run changed g.yaml"
rm -f g.pgm g.yaml
run grid -o g text.log
[ ! -e g.pgm ] && [ ! -e g.yaml ] || bad "a failed run left g.pgm or g.yaml"
name=grid-unwritable
run grid -o nodir/g lf.log
[ $rc -eq 2 ] && [ ! -e nodir ] \
    && grep -q "^polyc: -o PREFIX 'nodir/g' is in a folder that does not exist" err.txt \
    || bad "exit $rc for a prefix in a missing folder"

# ---- round trip: office.log -> polyc grid -> polyc PREFIX.yaml ----
# The map from the grid must lie on the map from the log, and cover it: the
# share of each map's length within 10 cm of the other (sampled every 2 cm).
NEAR='function d2(px, py, i,   dx, dy, l2, t, qx, qy) {
        dx = bx2[i] - bx1[i]; dy = by2[i] - by1[i]; l2 = dx * dx + dy * dy
        t = l2 > 0 ? ((px - bx1[i]) * dx + (py - by1[i]) * dy) / l2 : 0
        t = t < 0 ? 0 : t > 1 ? 1 : t
        qx = bx1[i] + t * dx; qy = by1[i] + t * dy
        return (px - qx) ^ 2 + (py - qy) ^ 2 }
    FNR == 1 { file++ }
    { n = $2; m = $1 == "closed" ? n : n - 1
      for (k = 0; k < n; k++) { x[k] = $(3 + 2 * k); y[k] = $(4 + 2 * k) }
      for (k = 0; k < m; k++) {
        x1 = x[k]; y1 = y[k]; x2 = x[(k + 1) % n]; y2 = y[(k + 1) % n]
        if (file == 1) { bx1[ns] = x1; by1[ns] = y1; bx2[ns] = x2; by2[ns] = y2; ns++; continue }
        L = sqrt((x2 - x1) ^ 2 + (y2 - y1) ^ 2); steps = int(L / 0.02) + 1
        for (s = 0; s < steps; s++) {
          t = (s + 0.5) / steps; px = x1 + t * (x2 - x1); py = y1 + t * (y2 - y1)
          best = 1e30; for (i = 0; i < ns; i++) { e = d2(px, py, i); if (e < best) best = e }
          total += L / steps; if (best <= 0.01) near += L / steps } } }
    END { printf "%.3f\n", (total > 0 ? near / total : 0) }'
name=round-trip-office
run --format txt "$ROOT/examples/office.log" && cp out.txt office_log.txt
run grid -o office "$ROOT/examples/office.log"
[ $rc -eq 0 ] || bad "polyc grid: exit $rc"
run --format txt office.yaml && cp out.txt office_map.txt
[ $rc -eq 0 ] && [ -s office_map.txt ] || bad "polyc office.yaml: exit $rc, or no polylines"
on=$(awk "$NEAR" office_log.txt office_map.txt)
covered=$(awk "$NEAR" office_map.txt office_log.txt)
echo "round trip office.log: $on of the grid map's length within 10 cm of the log map, $covered of the log map's within 10 cm of it"
awk -v a="$on" -v b="$covered" 'BEGIN { exit !(a >= 0.9 && b >= 0.9) }' \
    || bad "the map from polyc grid's files is not on the log's map ($on, $covered)"

# ---- big inputs: bounded time and memory ----
if [ $quick = 0 ]; then
    # a 10 MB line: 1048576 ranges, the most one scan may have
    awk -v g="$GOOD" 'BEGIN { printf "%s\nSCAN 0 0 0 0 0.000005 0.02 8 1048576", g;
        for (i = 0; i < 1048576; i++) printf " 1.%06d", i % 997; printf "\n" }' > long.log
    mapped 10MB-line long.log '^scans +2 ' 'input beams +1048581 '
    # 10 MB of a skipped line type
    awk -v g="$GOOD" 'BEGIN { printf "%s\nODOM", g; for (i = 0; i < 1000000; i++)
        printf " 1.234567890"; printf "\n" }' > longodom.log
    mapped 10MB-skipped-line longodom.log 'ODOM 1\)'
    # one beam more than allowed
    awk 'BEGIN { printf "SCAN 0 0 0 0 0.000005 0.02 8 1048577"; for (i = 0; i < 1048577; i++)
        printf " 1"; printf "\n" }' > toolong.log
    refused too-many-beams toolong.log 1 'beam count 1048577 out of range \(at most 1048576\)$'
    # a line past the 32 MiB line buffer
    { printf '%s\n# ' "$GOOD"; head -c 34000000 /dev/zero | tr '\0' 'x'; echo; } > huge.log
    refused line-over-32MiB huge.log 2 'line longer than 33554432 bytes$'
    # two million scans of one beam
    awk 'BEGIN { for (i = 0; i < 2000000; i++)
        printf "SCAN %.2f %.2f 0 0 0.1 0.02 8 1 1.5\n", (i % 2000) * 0.01, int(i / 2000) * 0.001 }' > two_million.log
    start=$(date +%s)
    mapped two-million-scans two_million.log '^scans +2000000 ' 'input beams +2000000 '
    took=$(( $(date +%s) - start ))
    [ $took -le 60 ] || bad "two million scans took $took s"
    rm -f long.log longodom.log toolong.log huge.log two_million.log
    # progress on a terminal (script(1) gives polyc a pty): the stage, the
    # iteration, vertices and BIC, on one line blanked at the end; nothing
    # with --quiet; the map the same either way. Needs a run over 2 s: 16
    # copies of office.log side by side, every endpoint kept (about 5 s).
    if command -v script > /dev/null 2>&1; then
        "$POLYC" convert "$ROOT/examples/office.log" | awk '/^#/ && NR < 3 { print; next }
            /^SCAN/ { line[n++] = $0 }
            END { for (c = 0; c < 16; c++) for (i = 0; i < n; i++) { k = split(line[i], f, " ")
                f[2] += (c % 4) * 20; f[3] += int(c / 4) * 16; s = f[1]
                for (j = 2; j <= k; j++) s = s " " f[j]; print s } }' > offices.log
        name=progress-on-a-terminal
        count=$((count + 1))
        start=$(date +%s)
        script -qefc "'$POLYC' --exact-points -o pty.svg offices.log" pty.txt > /dev/null 2>&1 < /dev/null
        took=$(( $(date +%s) - start ))
        if [ $took -lt 3 ] && ! grep -q 'polyc: optimize' pty.txt; then
            echo "progress-on-a-terminal: skipped (the run took under 3 s: too short for the progress line)"
        else
            grep -qE "$(printf '\r')polyc: optimize: iteration [0-9]+, [0-9]+ vertices, BIC -?[0-9.]+ \([0-9.]+ s\)" pty.txt \
                || bad "no progress line on a terminal: $(head -c 300 pty.txt)"
            grep -qE "$(printf '\r') +$(printf '\r')" pty.txt || bad "the progress line is not blanked at the end"
            count=$((count + 1))
            script -qefc "'$POLYC' --exact-points --quiet -o pty2.svg offices.log" pty2.txt > /dev/null 2>&1 < /dev/null
            if grep -q 'polyc: ' pty2.txt; then bad "a progress line with --quiet"; fi
            grep -v '<text id="time"' pty.svg > pty_a.svg
            grep -v '<text id="time"' pty2.svg > pty_b.svg
            cmp -s pty_a.svg pty_b.svg || bad "the map differs with and without the progress line"
        fi
        rm -f pty.svg pty2.svg pty_a.svg pty_b.svg pty.txt pty2.txt offices.log
    else
        echo "progress-on-a-terminal: skipped (needs script(1))"
    fi
fi

echo "cli_bad_input: $count runs, $failed failures"
[ $failed -eq 0 ]
