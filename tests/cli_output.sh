#!/bin/sh
# cli_output.sh - where polyc writes (docs/formats.md, "Writing"): a file
# replaced atomically with its mode and owner kept, a symlink's target
# replaced, a device, a FIFO and stdout written in place, names refused
# before any work (an output that is an input, a symlink refused by the
# fs.protected_symlinks rule, a missing folder, an extension polyc does not
# write), the format from -o's extension, and no temporary file left after
# an error, a closed pipe, `ulimit -f` or a signal (SIGKILL too, where the
# system has O_TMPFILE).
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

. "$(dirname "$SELF")/cli_lib.sh"
cli_scratch out
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

# ---- an output that is an input: refused before any work, the input kept ----
# every output (-o, convert -o, --trace, grid's PREFIX.pgm and PREFIX.yaml,
# --frames' frames, stdout) against every input (the log by name, through a
# link, a hard link or stdin; a map YAML and its image)
cp "$LOG" in.log
cp in.log in.keep
ln -s in.log in-link.log
ln in.log in-hard.log
cp in.log gl.pgm
cp in.log gl.yaml
mkdir frl frn
ln -s ../in.log frl/frame-00050.svg
cp in.log frn/frame-00100.svg
run grid -o mp in.log
cp mp.pgm mp.keep
cp mp.yaml mpy.keep
ln -s mp.pgm mp-link.svg
kept() { cmp -s in.log in.keep && cmp -s mp.pgm mp.keep && cmp -s mp.yaml mpy.keep; }
# is_input NAME ARGS...: exit 2, 'the same file', no input changed
is_input() {
    name=input-$1
    shift
    run "$@"
    [ $rc -eq 2 ] && grep -q '(the same file' err.txt || bad "exit $rc, expected 2 and 'the same file'"
    kept || { bad "an input was changed"; cp in.keep in.log; cp mp.keep mp.pgm; cp mpy.keep mp.yaml; }
}
is_input o-name -o in.log in.log
is_input o-link -o in-link.log in.log
is_input o-hard -o in-hard.log in.log
is_input o-via-input-link -o in.log in-link.log
is_input o-json --format json -o in.log in.log
is_input convert convert -o in.log in.log
is_input convert-hard convert -o in-hard.log in-link.log
is_input trace --iterations 2 --trace in.log -o t.svg in.log
is_input trace-link --iterations 2 --trace in-link.log -o t.svg in.log
is_input online-o --online -o in.log in.log
is_input grid-pgm grid -o gl gl.pgm
is_input grid-yaml grid -o gl.yaml gl.yaml
is_input frames-link --online --frames frl -o t.svg in.log
is_input frames-file --online --frames frn frn/frame-00100.svg
is_input map-yaml -o mp.yaml mp.yaml
is_input map-image --format svg -o mp.pgm mp.yaml
is_input map-image-link -o mp-link.svg mp.yaml
is_input map-image-trace --iterations 2 --trace mp.pgm -o t.svg mp.yaml
name=input-stdin
count=$((count + 1))
"$POLYC" -o in.log - < in.log > out.txt 2> err.txt
rc=$?
[ $rc -eq 2 ] && grep -q "is the input 'stdin'" err.txt && kept || bad "exit $rc for -o the file on stdin"
name=input-stdout
count=$((count + 1))
"$POLYC" in.log >> in.log 2> err.txt
rc=$?
[ $rc -eq 2 ] && grep -q "^polyc: stdout is the input 'in.log'" err.txt && kept \
    || bad "exit $rc for stdout appended to the input"
cp in.keep in.log
name=input-not-a-copy
run --iterations 2 -o in.keep.svg --trace frn.txt in.log
[ $rc -eq 0 ] && is_svg in.keep.svg || bad "exit $rc: a copy of the input is not the input"
name=input-frames-other
run --online --frames frl --every 7 --format txt -o t.txt in.log
[ $rc -eq 0 ] && [ -L frl/frame-00050.svg ] && [ -s frl/frame-00007.svg ] \
    || bad "exit $rc: frames that are not the input refused"
rm -rf frl frn in-link.log in-hard.log gl.pgm gl.yaml mp-link.svg t.svg t.txt

# ---- a folder that is missing, or one the user may not write ----
pattern="-o 'nodir/x.svg' is in a folder that does not exist"
refused missing-folder -o nodir/x.svg "$LOG"
ln -s nodir/x.svg dangle.svg
pattern="-o 'dangle.svg' is in a folder that does not exist"
refused dangling-link-folder -o dangle.svg "$LOG"
pattern="-o PREFIX 'nodir/g' is in a folder that does not exist"
refused grid-missing-folder grid -o nodir/g "$LOG"
[ -e nodir ] && bad "nodir made"
if [ "$uid" != 0 ]; then
    mkdir rodir
    chmod 555 rodir
    pattern="-o 'rodir/x.svg' is in a folder that you may not write"
    refused unwritable-folder -o rodir/x.svg "$LOG"
    pattern="--trace 'rodir/t.txt' is in a folder that you may not write"
    refused unwritable-trace --trace rodir/t.txt -o t.svg "$LOG"
    [ -e t.svg ] && bad "t.svg written"
    rm -f t.svg
fi

# ---- symlinks in a sticky, world-writable folder: the kernel's
# fs.protected_symlinks rule (followed only if the caller or the folder's
# owner owns the link), whatever the system's setting ----
mkdir shared
chmod 1777 shared
name=sticky-own-link
ln -s ../own.svg shared/own.svg
run -o shared/own.svg "$LOG"
[ $rc -eq 0 ] && [ -L shared/own.svg ] && is_svg own.svg || bad "exit $rc: the caller's own link not followed"
if [ "$uid" = 0 ]; then
    mkdir private
    echo secret > private/secret
    chmod 600 private/secret
    ln -s ../private/secret shared/evil.svg
    chown -h 65534:65534 shared/evil.svg
    for args in "-o shared/evil.svg" "--trace shared/evil.svg -o t.svg" "convert -o shared/evil.svg"; do
        name="sticky-other-link ($args)"
        # shellcheck disable=SC2086
        run $args "$LOG"
        [ $rc -eq 2 ] && grep -q "fs.protected_symlinks" err.txt && [ "$(cat private/secret)" = secret ] \
            && [ "$(mode_of private/secret)" = 600 ] && [ ! -e t.svg ] \
            || bad "exit $rc, or the link's target was replaced"
    done
    name=sticky-grid-link
    ln -s ../private/secret shared/g.yaml
    chown -h 65534:65534 shared/g.yaml
    run grid -o shared/g "$LOG"
    [ $rc -eq 2 ] && grep -q "fs.protected_symlinks" err.txt && [ "$(cat private/secret)" = secret ] \
        && [ ! -e shared/g.pgm ] || bad "exit $rc, or a grid file written through the link"
    name=sticky-link-in-chain
    ln -s shared/evil.svg chain.svg
    run -o chain.svg "$LOG"
    [ $rc -eq 2 ] && [ "$(cat private/secret)" = secret ] || bad "exit $rc, a chain through the link followed"
    name=sticky-folder-owner-link
    mkdir owned
    chown 65534:65534 owned
    chmod 1777 owned
    ln -s ../by-owner.svg owned/l.svg
    chown -h 65534:65534 owned/l.svg
    run -o owned/l.svg "$LOG"
    [ $rc -eq 0 ] && [ -L owned/l.svg ] && is_svg by-owner.svg || bad "exit $rc: the folder owner's link not followed"
    name=not-sticky-other-link
    mkdir open
    chmod 777 open
    ln -s ../by-other.svg open/l.svg
    chown -h 65534:65534 open/l.svg
    run -o open/l.svg "$LOG"
    [ $rc -eq 0 ] && is_svg by-other.svg || bad "exit $rc: a link in a folder without the sticky bit not followed"
fi

# ---- the format follows -o's extension ----
name=format-json
run -o m.json "$LOG"
[ $rc -eq 0 ] && head -c 14 m.json | grep -q '^{"polylines": ' || bad "exit $rc, m.json is not JSON"
name=format-txt
run -o m.TXT "$LOG"
[ $rc -eq 0 ] && grep -qE '^(open|closed) [0-9]+ ' m.TXT || bad "exit $rc, m.TXT is not TXT"
name=format-none
run -o m "$LOG"
[ $rc -eq 0 ] && is_svg m || bad "exit $rc, m (no extension) is not the default SVG"
name=format-other
run --format json -o m2.map "$LOG"
[ $rc -eq 0 ] && head -c 1 m2.map | grep -q '{' || bad "exit $rc, --format json not followed"
pattern="-o 'clash.png': polyc writes .svg, .json or .txt, not .png"
refused format-png -o clash.png "$LOG"
[ -e clash.png ] && bad "clash.png written"
pattern="-o 'clash.map': polyc writes .svg, .json or .txt, not .map"
refused format-unknown -o clash.map "$LOG"
[ -e clash.map ] && bad "clash.map written"
pattern="polyc grid writes PREFIX.pgm and PREFIX.yaml .*not a .png file"
refused grid-png grid -o clash.png "$LOG"
[ -e clash.png.pgm ] && bad "clash.png.pgm written"

# ---- polyc grid: -o office, office.pgm or office.yaml give the same pair ----
for prefix in gp.pgm gy.yaml; do
    name=grid-ext-$prefix
    run grid -o $prefix "$LOG"
    base=${prefix%.*}
    [ $rc -eq 0 ] && [ -s $base.pgm ] && grep -q "^image: $base.pgm\$" $base.yaml \
        && [ ! -e $prefix.pgm ] && [ ! -e $prefix.yaml ] || bad "exit $rc, or not $base.pgm + $base.yaml"
done

# ---- a closed pipe: an error, no temporary file ----
name=closed-pipe
count=$((count + 1))
{ "$POLYC" --points --trace bic.txt "$LOG" 2> err.txt; echo $? > rc.txt; } | head -c 100 > /dev/null
rc=$(cat rc.txt)
[ "$rc" = 1 ] && grep -q '^polyc: writing stdout: Broken pipe$' err.txt && [ ! -e bic.txt ] \
    || bad "exit $rc, or bic.txt written without the map"
no_temps

# ---- signals: the temporary files go, the process dies of the signal ----
# wait_temp PID: until the run has written a file it has not named yet: an
# unnamed one (O_TMPFILE, open in /proc/PID/fd as '... (deleted)') or a
# temporary .polyc-XXXXXX (named is set to 1 then); the run is blocked after it
wait_temp() {
    i=0
    named=0
    while [ $i -lt 200 ]; do
        ls -A | grep -q '^\.polyc-' && { named=1; return; }
        ls -l "/proc/$1/fd" 2> /dev/null | grep -q '(deleted)' && return
        sleep 0.05
        i=$((i + 1))
    done
    bad "no prepared output seen in 10 s"
}
# a background job of a script ignores SIGINT and SIGQUIT, and so would polyc
# (it keeps a signal ignored, as nohup wants): env --default-signal gives them back
if env --default-signal=INT,QUIT true 2> /dev/null; then
    bg="env --default-signal=INT,QUIT"
    sigs="INT QUIT TERM HUP USR1 USR2 ALRM VTALRM XCPU"
else
    bg=
    sigs="TERM HUP USR1 USR2 ALRM VTALRM XCPU"
    echo "cli_output: SIGINT and SIGQUIT not tested (env --default-signal is missing)"
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
echo old > t4old.txt
for sig in $sigs; do
    # the map waits for a reader of the FIFO, the traces are written, unnamed
    name=signal-$sig-fifo
    count=$((count + 1))
    $bg "$POLYC" --iterations 2 --trace t4.txt -o blocked "$LOG" 2> err.txt &
    pid=$!
    wait_temp $pid
    stop $sig $pid
    [ $rc -gt 128 ] && [ ! -e t4.txt ] || bad "exit $rc after SIG$sig"
    no_temps
done
# SIGKILL: no handler runs; an unnamed file goes with the process (where
# the folder's file system has O_TMPFILE: asked of python3 if there is one)
tmpfile=unknown
if command -v python3 > /dev/null 2>&1; then
    python3 -c 'import os; os.close(os.open(".", os.O_TMPFILE | os.O_WRONLY, 0o600))' 2> /dev/null \
        && tmpfile=yes || tmpfile=no
fi
for trace in t4.txt t4old.txt; do
    name=signal-KILL-$trace
    count=$((count + 1))
    "$POLYC" --iterations 2 --trace $trace -o blocked "$LOG" 2> err.txt &
    pid=$!
    wait_temp $pid
    stop KILL $pid
    [ $rc -gt 128 ] && [ ! -e t4.txt ] && [ "$(cat t4old.txt)" = old ] || bad "exit $rc, or $trace changed"
    if [ $tmpfile = no ] || { [ $tmpfile = unknown ] && [ $named = 1 ]; }; then
        echo "cli_output: SIGKILL leaves a temporary file here (no O_TMPFILE in $T)"
        rm -f .polyc-*
    else
        no_temps
    fi
done
sig=${sigs%% *}
name=signal-$sig-full-pipe
count=$((count + 1))
mkfifo slow
sleep 30 < slow &
sleeper=$!
$bg "$POLYC" --points --iterations 2 --trace t5.txt "$LOG" > slow 2> err.txt &
pid=$!
wait_temp $pid
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
wait_temp $pid
stop $sig $pid
[ $rc -gt 128 ] && [ ! -e g.pgm ] || bad "exit $rc, or g.pgm written after SIG$sig"
no_temps

# ---- past ulimit -f (SIGXFSZ is ignored: the write fails, reported) ----
name=ulimit-f-new
count=$((count + 1))
(ulimit -f 2 && exec "$POLYC" -o big.svg "$LOG") > out.txt 2> err.txt
rc=$?
[ $rc -eq 1 ] && [ ! -e big.svg ] && grep -q '^polyc: big.svg: File too large$' err.txt \
    || bad "exit $rc, or big.svg written past ulimit -f"
no_temps
name=ulimit-f-old
echo old > big.svg
count=$((count + 1))
(ulimit -f 2 && exec "$POLYC" --iterations 2 --trace bt.txt -o big.svg "$LOG") > out.txt 2> err.txt
rc=$?
[ $rc -eq 1 ] && [ "$(cat big.svg)" = old ] && [ ! -e bt.txt ] || bad "exit $rc, or big.svg changed"
no_temps

echo "cli_output ($who): $count runs, $failed failures"
[ $failed -eq 0 ] || exit 1

# ---- as root: again as an ordinary user ----
if [ "$uid" = 0 ]; then
    U=$(mktemp -d "${TMPDIR:-/tmp}/polyc_user.XXXXXX") || exit 1
    cp "$POLYC" "$U/polyc" && cp "$LOG" "$U/in.log" && cp "$SELF" "$U/cli_output.sh" \
        && cp "$(dirname "$SELF")/cli_lib.sh" "$U/cli_lib.sh" && chmod 755 "$U" \
        && chmod 644 "$U/in.log" "$U/cli_lib.sh" || exit 1
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
