#!/bin/sh
# svgstrip.sh OUT.png WIDTH_PX A.svg B.svg ...
# Places SVGs that polyc wrote side by side, tops aligned, in one SVG (each
# as a nested <svg> of its own size) and renders that WIDTH_PX wide with
# rsvg-convert, on white: a strip of frames without an image tool. polyc's
# SVGs have the XML declaration on line 1 and the root element, with its
# width and height, on line 2.
set -eu
[ $# -ge 3 ] || { echo "usage: svgstrip.sh OUT.png WIDTH_PX A.svg B.svg ..." >&2; exit 2; }
out=$1 width=$2
shift 2
strip=$(mktemp "${TMPDIR:-/tmp}/svgstrip.XXXXXX")
trap 'rm -f "$strip" "$strip.body"' EXIT
x=0 height=0
for f; do
    size=$(sed -n '2s/^<svg [^>]*width="\([0-9.]*\)" height="\([0-9.]*\)".*/\1 \2/p' "$f")
    [ -n "$size" ] || { echo "svgstrip.sh: $f: no polyc <svg> element on line 2" >&2; exit 1; }
    w=${size% *} h=${size#* }
    printf '<svg x="%s" y="0" width="%s" height="%s" viewBox="0 0 %s %s">\n' "$x" "$w" "$h" "$w" "$h"
    sed '1,2d' "$f"                # its content and its closing </svg>
    x=$(awk -v a="$x" -v b="$w" 'BEGIN { print a + b }')
    height=$(awk -v a="$height" -v b="$h" 'BEGIN { print (a > b ? a : b) }')
done > "$strip.body"
{
    printf '<?xml version="1.0" encoding="UTF-8"?>\n'
    printf '<svg xmlns="http://www.w3.org/2000/svg" width="%s" height="%s" viewBox="0 0 %s %s">\n' \
        "$x" "$height" "$x" "$height"
    cat "$strip.body"
    printf '</svg>\n'
} > "$strip"
rsvg-convert -w "$width" -b white -o "$out" "$strip"
