#!/bin/sh
# cli_bad_input.sh - every bad input of issue 6 through the polyc tool.
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

T=$(mktemp -d "${TMPDIR:-/tmp}/polyc_cli.XXXXXX") || exit 2
trap 'rm -rf "$T"' EXIT INT TERM
cd "$T" || exit 2
failed=0
count=0
LIMIT_S=120               # seconds per run: a hang fails
LIMIT_KB=3000000          # address space per run (plain builds): 3 GB

bad() {
    echo "FAIL $name: $*"
    sed 's/^/    stderr: /' err.txt | head -5
    failed=$((failed + 1))
}

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
    if ls map.svg.tmp* > /dev/null 2>&1; then
        bad "a temporary output file is left behind"
        rm -f map.svg.tmp*
    fi
    return 0
}

# refused NAME FILE LINE PATTERN: exit 1, `polyc: FILE:LINE: ...` matching
# PATTERN (grep -E, after the prefix) as the only stderr line, no output file.
refused() {
    name=$1 file=$2 line=$3 pattern=$4
    rm -f map.svg
    run -o map.svg "$file" || return
    prefix="polyc: $file:$line: "
    [ "$line" = - ] && prefix="polyc: $file: "
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
refused empty empty.log - 'no scans found \(0 lines read\)$'
printf '\n\n  \n# nothing\nODOM 1 2 3\n' > blank.log
refused blank blank.log - 'no scans found \(5 lines read\)$'
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
name=missing-dir
run -o nodir/map.svg lf.log
[ $rc -eq 1 ] && grep -q '^polyc: nodir/map.svg: cannot create a temporary file' err.txt \
    || bad "exit $rc for an unwritable output"
name=trace-unwritable
run --iterations 2 --trace nodir/trace.txt -o map.svg lf.log
[ $rc -eq 1 ] && [ ! -e map.svg ] && grep -q '^polyc: nodir/trace.txt: cannot create' err.txt \
    || bad "exit $rc, or the map written although --trace failed"
name=both-outputs
run --iterations 2 --trace trace.txt -o map.svg lf.log
[ $rc -eq 0 ] && [ -s map.svg ] && [ -s trace.txt ] || bad "exit $rc, map and trace not both written"
rm -f map.svg trace.txt
name=memory-budget
run --memory-mb 0.01 -o map.svg lf.log
[ $rc -eq 3 ] && [ ! -e map.svg ] && grep -q '^polyc: memory budget too small: need [0-9]* bytes$' err.txt \
    || bad "exit $rc for a too small --memory-mb"
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
[ $rc -eq 1 ] && grep -q '^polyc: adir:1: read error: Is a directory$' err.txt \
    || bad "exit $rc for a directory as input"
[ -e map.svg ] && bad "map.svg exists after a failure"

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
fi

echo "cli_bad_input: $count runs, $failed failures"
[ $failed -eq 0 ]
