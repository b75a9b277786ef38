#!/bin/sh
# golden.sh - the tool's output does not depend on how it was compiled:
# polyc built at -O0, -O2, -O3 and -Os -flto (each in its own build folder,
# the library and the tool only) must write the same bytes for the same
# input. Inputs: two simulated scenes (the simulator's hall and drift, seed
# 3, written by GEN, the repository's gen_example), examples/office.log,
# and the office's hit/miss grid as a ROS map (`polyc grid`, then the map
# YAML mapped). Compares cksum of `polyc --format txt` (and of the grid's
# PGM) across the builds; prints the table and fails on any difference.
# The drift scene's map changes under -ffast-math, so the test sees that.
# (x87 arithmetic, -mfpmath=387, gives other maps on every input: the
# library's results assume FLT_EVAL_METHOD 0, docs/api.md.)
# usage: tests/golden.sh MAKE GEN
set -eu
make=${1:-make}
gen=${2:-build/gen_example}
fail() { echo "golden: FAIL: $*"; exit 1; }
[ -x "$gen" ] || fail "$gen not built (make build/gen_example)"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for scene in hall drift; do
    "$gen" "$tmp/$scene.log" "$tmp/$scene.gt.txt" "$scene" 3 >/dev/null ||
        fail "gen_example $scene"
done

# the folders stay (build-golden-*), so that a rerun only relinks
sums=$tmp/sums
: >"$sums"
for name in O0 O2 O3 Os-flto; do
    case $name in
    O0) opt=-O0 ;;
    O2) opt=-O2 ;;
    O3) opt=-O3 ;;
    Os-flto) opt='-Os -flto' ;;
    esac
    build=build-golden-$name
    $make --no-print-directory BUILD="$build" OPT="$opt" "$build/polyc" >"$tmp/make-$name.log" 2>&1 ||
        { tail -n 20 "$tmp/make-$name.log"; fail "building with $opt"; }
    out=$tmp/$name
    mkdir -p "$out"
    for input in "$tmp/hall.log" "$tmp/drift.log" examples/office.log; do
        base=$(basename "$input" .log)
        "$build/polyc" --quiet --format txt -o "$out/$base.txt" "$input" ||
            fail "$name: polyc $input"
        echo "$base.txt $name $(cksum <"$out/$base.txt")" >>"$sums"
    done
    "$build/polyc" grid -o "$out/grid" examples/office.log || fail "$name: polyc grid"
    echo "grid.pgm $name $(cksum <"$out/grid.pgm")" >>"$sums"
    "$build/polyc" --quiet --format txt -o "$out/map.txt" "$out/grid.yaml" ||
        fail "$name: polyc grid.yaml"
    echo "map.txt $name $(cksum <"$out/map.txt")" >>"$sums"
done

# one checksum per output across every build
bad=0
for f in hall.txt drift.txt office.txt grid.pgm map.txt; do
    n=$(awk -v f="$f" '$1 == f {print $3, $4}' "$sums" | sort -u | wc -l)
    if [ "$n" -ne 1 ]; then
        bad=1
        echo "golden: $f differs across builds:"
        awk -v f="$f" '$1 == f {print "    " $2 ": cksum " $3 " " $4}' "$sums"
    fi
done
awk '{printf "%-11s %-8s %s %s\n", $1, $2, $3, $4}' "$sums"
[ $bad -eq 0 ] || fail "the output depends on the optimisation level"
echo "golden: the same bytes at -O0, -O2, -O3 and -Os -flto for all 5 outputs"
