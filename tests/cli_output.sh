#!/bin/sh
# cli_output.sh - where polyc writes (docs/formats.md, "Writing"): a file
# replaced atomically with its mode and owner kept, a symlink's target
# replaced, a device, a FIFO and stdout written in place, names refused
# before any work, the format from -o's extension, and no temporary file
# left after an error, a closed pipe or SIGINT, SIGTERM, SIGHUP.
#   tests/cli_output.sh POLYC [LOG]
# LOG defaults to examples/office.log. Run as root, it runs again as user
# 65534 (setpriv, or su) where the machine allows it.
set -u
[ $# -ge 1 ] || { echo "usage: $0 POLYC [LOG]" >&2; exit 2; }
case $1 in /*) POLYC=$1 ;; *) POLYC=$(pwd)/$1 ;; esac
ROOT=$(cd "$(dirname "$0")/.." && pwd)
SELF=$(cd "$(dirname "$0")" && pwd)/$(basename "$0")
LOG=${2:-$ROOT/examples/office.log}
case $LOG in /*) ;; *) LOG=$(pwd)/$LOG ;; esac
[ -x "$POLYC" ] && [ -r "$LOG" ] || { echo "$0: cannot run $POLYC on $LOG" >&2; exit 2; }
uid=$(id -u)
who=$([ "$uid" = 0 ] && echo root || echo "user $uid")

T=$(mktemp -d "${TMPDIR:-/tmp}/polyc_out.XXXXXX") || exit 2
trap 'rm -rf "$T"' EXIT
cd "$T" || exit 2
failed=0
count=0
bad() {
    echo "FAIL $name ($who): $*"
    sed 's/^/    stderr: /' err.txt 2> /dev/null | head -3
    failed=$((failed + 1))
}
# no temporary file (.polyc-XXXXXX) in the folder after a run
no_temps() {
    left=$(ls -A | grep '^\.polyc-')
    [ -z "$left" ] || { bad "temporary files left: $left"; rm -f .polyc-*; }
}
# run ARGS...: polyc with a time limit; rc, stdout in out.txt, stderr in err.txt
run() {
    count=$((count + 1))
    timeout 60 "$POLYC" "$@" > out.txt 2> err.txt
    rc=$?
    no_temps
}
is_svg() { tail -c 7 "$1" | grep -q '</svg>'; }
mode_of() { stat -c %a "$1"; }
owner_of() { stat -c %u:%g "$1"; }

# ---- regular files: replaced atomically, mode and owner kept ----
name=new-file
run -o new.svg "$LOG"
[ $rc -eq 0 ] && is_svg new.svg || bad "exit $rc, no SVG"
name=keeps-mode
echo old > ro.svg
chmod 444 ro.svg
run -o ro.svg "$LOG"
[ $rc -eq 0 ] && is_svg ro.svg && [ "$(mode_of ro.svg)" = 444 ] \
    || bad "exit $rc, or mode $(mode_of ro.svg) instead of 444"
chmod 640 ro.svg
run -o ro.svg "$LOG"
[ "$(mode_of ro.svg)" = 640 ] || bad "mode $(mode_of ro.svg) instead of 640"
if [ "$uid" = 0 ]; then
    name=keeps-owner
    chown 65534:65534 ro.svg
    run -o ro.svg "$LOG"
    [ $rc -eq 0 ] && [ "$(owner_of ro.svg)" = 65534:65534 ] || bad "owner $(owner_of ro.svg)"
fi
name=long-name
long=$(printf '%0250d' 0 | tr 0 n).svg
run -o "$long" "$LOG"
[ $rc -eq 0 ] && is_svg "$long" || bad "exit $rc for a 254-character name"
rm -f "$long"
name=failed-run-keeps-file
printf 'SCAN 0 0 0 0 0.1 0.02 8 1 x\n' > bad.log
echo old > kept.svg
run -o kept.svg bad.log
[ $rc -eq 1 ] && [ "$(cat kept.svg)" = old ] || bad "exit $rc, or kept.svg changed"

# ---- a symlink: its target is replaced, the link stays ----
name=symlink
echo old > target.svg
ln -s target.svg link.svg
run -o link.svg "$LOG"
[ $rc -eq 0 ] && [ -L link.svg ] && is_svg target.svg || bad "exit $rc, or the link was replaced"
name=symlink-chain
mkdir real
ln -s real/t.svg link2.svg
ln -s link2.svg link3.svg
run -o link3.svg "$LOG"
[ $rc -eq 0 ] && [ -L link3.svg ] && [ -L link2.svg ] && is_svg real/t.svg \
    || bad "exit $rc, or a dangling link chain not followed to real/t.svg"

# ---- written in place: a FIFO, devices, stdout ----
name=fifo
mkfifo fifo
cat fifo > from_fifo.svg &
reader=$!
run -o fifo "$LOG"
wait $reader
[ $rc -eq 0 ] && [ -p fifo ] && is_svg from_fifo.svg || bad "exit $rc, or the FIFO was replaced"
name=dev-null
run -o /dev/null "$LOG"
[ $rc -eq 0 ] && [ -c /dev/null ] || bad "exit $rc for /dev/null"
# root tries a node of its own (a broken polyc would replace the system's)
full=/dev/full
if [ "$uid" = 0 ]; then
    full=
    mknod full c 1 7 2> /dev/null && full=full
fi
if [ -n "$full" ]; then
    name=dev-full
    run -o $full "$LOG"
    [ $rc -eq 1 ] && [ -c $full ] && grep -q "^polyc: $full: No space left on device\$" err.txt \
        || bad "exit $rc for $full, or it was replaced"
else
    echo "cli_output: -o /dev/full left to the ordinary user (root cannot mknod here)"
fi
name=dev-stdout
run -o /dev/stdout "$LOG"
[ $rc -eq 0 ] && is_svg out.txt || bad "exit $rc for /dev/stdout into a file"
count=$((count + 1))
"$POLYC" -o /dev/stdout "$LOG" 2> err.txt | cat > piped.svg
is_svg piped.svg || bad "-o /dev/stdout into a pipe"
name=dev-stdout-append
echo first > all.txt
count=$((count + 1))
"$POLYC" --format txt -o /dev/stdout "$LOG" >> all.txt 2> err.txt
[ "$(head -n 1 all.txt)" = first ] && grep -qE '^(open|closed) ' all.txt \
    || bad "-o /dev/stdout did not append to a file opened with >>"
name=dev-fd
count=$((count + 1))
"$POLYC" -o /dev/fd/3 "$LOG" 3> fd3.svg 2> err.txt
is_svg fd3.svg || bad "-o /dev/fd/3 did not write descriptor 3"
name=trace-dev-null
run --iterations 2 --trace /dev/null -o t.svg "$LOG"
[ $rc -eq 0 ] && is_svg t.svg || bad "exit $rc for --trace /dev/null"

# ---- refused before any work (usage, exit 2), nothing written ----
refused() {
    name=$1
    shift
    run "$@"
    [ $rc -eq 2 ] && grep -q "^polyc: .*$pattern" err.txt || bad "exit $rc, expected 2 and '$pattern'"
    [ -e clash.svg ] && bad "clash.svg written"
    rm -f clash.svg
}
mkdir adir
pattern="-o '' is empty"; refused empty-name -o '' "$LOG"
pattern="names a directory"; refused trailing-slash -o adir/x/ "$LOG"
refused directory -o adir "$LOG"
refused grid-trailing-slash grid -o adir/ "$LOG"
refused grid-directory grid -o adir "$LOG"
pattern="name the same file"; refused same-name -o clash.svg --trace clash.svg "$LOG"
refused same-new-file -o clash.svg --trace ./clash.svg "$LOG"
refused same-via-link -o link.svg --trace target.svg "$LOG"
ln target.svg hard.svg
refused same-inode -o hard.svg --trace target.svg "$LOG"
refused both-stdout --trace - "$LOG"
pattern="--format svg contradicts -o clash.json"; refused format-clash --format svg -o clash.json "$LOG"

# ---- the format follows -o's extension ----
name=format-json
run -o m.json "$LOG"
[ $rc -eq 0 ] && head -c 14 m.json | grep -q '^{"polylines": ' || bad "exit $rc, m.json is not JSON"
name=format-txt
run -o m.TXT "$LOG"
[ $rc -eq 0 ] && grep -qE '^(open|closed) [0-9]+ ' m.TXT || bad "exit $rc, m.TXT is not TXT"
name=format-other
run -o m.map "$LOG"
[ $rc -eq 0 ] && is_svg m.map || bad "exit $rc, m.map is not the default SVG"
run --format json -o m2.map "$LOG"
[ $rc -eq 0 ] && head -c 1 m2.map | grep -q '{' || bad "exit $rc, --format json not followed"

# ---- a closed pipe: an error, no temporary file ----
name=closed-pipe
count=$((count + 1))
{ "$POLYC" --points --trace bic.txt "$LOG" 2> err.txt; echo $? > rc.txt; } | head -c 100 > /dev/null
rc=$(cat rc.txt)
[ "$rc" = 1 ] && grep -q '^polyc: writing stdout: Broken pipe$' err.txt && [ ! -e bic.txt ] \
    || bad "exit $rc, or bic.txt written without the map"
no_temps

# ---- signals: the temporary files go, the process dies of the signal ----
# wait_temp: until a temporary file exists (the run is blocked after it)
wait_temp() {
    i=0
    while [ $i -lt 200 ] && ! ls -A | grep -q '^\.polyc-'; do sleep 0.05; i=$((i + 1)); done
}
# a background job of a script ignores SIGINT, and so would polyc (it keeps
# a signal ignored, as nohup wants): env --default-signal gives it back
if env --default-signal=INT true 2> /dev/null; then
    bg="env --default-signal=INT"
    sigs="INT TERM HUP"
else
    bg=
    sigs="TERM HUP"
    echo "cli_output: SIGINT not tested (env --default-signal is missing)"
fi
# stop SIG PID: sends SIG, then SIGKILL if the run outlives it by 5 s; rc
stop() {
    kill -s "$1" "$2"
    i=0
    while [ $i -lt 100 ] && kill -0 "$2" 2> /dev/null; do sleep 0.05; i=$((i + 1)); done
    kill -0 "$2" 2> /dev/null && { bad "still running 5 s after SIG$1"; kill -s KILL "$2"; }
    wait "$2"
    rc=$?
}
mkfifo blocked
for sig in $sigs; do
    # the map waits for a reader of the FIFO, the trace's temporary file is written
    name=signal-$sig-fifo
    count=$((count + 1))
    $bg "$POLYC" --iterations 2 --trace t4.txt -o blocked "$LOG" 2> err.txt &
    pid=$!
    wait_temp
    stop $sig $pid
    [ $rc -gt 128 ] && [ ! -e t4.txt ] || bad "exit $rc after SIG$sig"
    no_temps
done
sig=${sigs%% *}
name=signal-$sig-full-pipe
count=$((count + 1))
mkfifo slow
sleep 30 < slow &
sleeper=$!
$bg "$POLYC" --points --iterations 2 --trace t5.txt "$LOG" > slow 2> err.txt &
pid=$!
wait_temp
sleep 0.2
stop $sig $pid
kill $sleeper 2> /dev/null
wait $sleeper 2> /dev/null
[ $rc -gt 128 ] && [ ! -e t5.txt ] || bad "exit $rc after SIG$sig on a full pipe"
no_temps
name=signal-grid
count=$((count + 1))
mkfifo g.yaml
$bg "$POLYC" grid -o g "$LOG" 2> err.txt &
pid=$!
wait_temp
stop $sig $pid
[ $rc -gt 128 ] && [ ! -e g.pgm ] || bad "exit $rc, or g.pgm written after SIG$sig"
no_temps

echo "cli_output ($who): $count runs, $failed failures"
[ $failed -eq 0 ] || exit 1

# ---- as root: again as an ordinary user ----
if [ "$uid" = 0 ]; then
    U=$(mktemp -d "${TMPDIR:-/tmp}/polyc_user.XXXXXX") || exit 1
    cp "$POLYC" "$U/polyc" && cp "$LOG" "$U/in.log" && cp "$SELF" "$U/cli_output.sh" && chmod 755 "$U" \
        && chmod 644 "$U/in.log" || exit 1
    if command -v setpriv > /dev/null 2>&1; then
        setpriv --reuid=65534 --regid=65534 --clear-groups sh "$U/cli_output.sh" "$U/polyc" "$U/in.log"
        rc=$?
    elif command -v su > /dev/null 2>&1 && su nobody -s /bin/sh -c true 2> /dev/null; then
        su nobody -s /bin/sh -c "sh '$U/cli_output.sh' '$U/polyc' '$U/in.log'"
        rc=$?
    else
        echo "cli_output: skipped as an ordinary user (neither setpriv nor su nobody works)"
        rc=0
    fi
    rm -rf "$U"
    exit $rc
fi
