#!/bin/sh
# embedded_test.sh - runs the embedded examples (host builds) and checks
# each one's map of the 5 m x 4 m room: status ok, the block of at most
# 128 KiB was enough (memory_size <= block, memory used <= memory_size), a
# handful of polylines with a plausible number of vertices, and every vertex
# inside the room (one 0.1 m grid cell of slack).
# usage: tests/embedded_test.sh build/embedded_scan [build/embedded_online ...]
set -eu
for prog in "$@"; do
    out=$("$prog") || { printf '%s\n' "$out"; echo "embedded_test: FAIL: $prog failed"; exit 1; }
    printf '%s\n' "$out"
    printf '%s\n' "$out" | awk -v prog="$prog" '
        $1 == "status" { status = $2 }
        $1 == "block" { block = $2; need = $5 }
        $1 == "memory_used" { used = $2 }
        $1 == "open" || $1 == "closed" {
            lines++
            for (i = 3; i < NF; i += 2) {
                verts++
                x = $i; y = $(i + 1)
                if (x < -0.1 || x > 5.1 || y < -0.1 || y > 4.1) {
                    printf "embedded_test: %s: FAIL: vertex (%s, %s) outside the room\n", prog, x, y
                    bad = 1
                }
            }
        }
        END {
            if (status != "ok") { print "embedded_test: " prog ": FAIL: status " status; bad = 1 }
            if (block == "" || block > 131072 || need > block || used == "" || used > need) {
                print "embedded_test: " prog ": FAIL: memory: block " block ", need " need ", used " used; bad = 1
            }
            if (lines < 2 || lines > 10) { print "embedded_test: " prog ": FAIL: " lines " polylines"; bad = 1 }
            if (verts < 6 || verts > 40) { print "embedded_test: " prog ": FAIL: " verts " vertices"; bad = 1 }
            if (!bad) print "embedded_test: " prog ": ok: " lines " polylines, " verts " vertices, " used " of " block " bytes used"
            exit bad
        }'
done
