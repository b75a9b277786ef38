#!/bin/sh
# svgcrop.sh MAP.svg OUT.png X0 Y0 X1 Y1 [WIDTH_PX]
# Renders the part X0..X1, Y0..Y1 (metres, the map's frame) of an SVG that
# polyc wrote, WIDTH_PX wide (default 600), with rsvg-convert. The map's
# scale and position come from the comment polyc puts on its third line:
#   <!-- polyc map: ..., S px/m, x X m at px L, y Y m at px T -->
set -eu
[ $# -ge 6 ] || { echo "usage: svgcrop.sh MAP.svg OUT.png X0 Y0 X1 Y1 [WIDTH_PX]" >&2; exit 2; }
svg=$1 out=$2 x0=$3 y0=$4 x1=$5 y1=$6 width=${7:-600}
head=$(sed -n '3p' "$svg")
case $head in
*"px/m, x "*) ;;
*) echo "svgcrop.sh: $svg: no polyc map comment on line 3" >&2; exit 1 ;;
esac
# S px/m, x XA m at px L, y YA m at px T
set -- $(printf '%s\n' "$head" |
    sed 's/.*, \([0-9.]*\) px\/m, x \([-0-9.]*\) m at px \([-0-9.]*\), y \([-0-9.]*\) m at px \([-0-9.]*\) .*/\1 \2 \3 \4 \5/')
scale=$1 xa=$2 left=$3 ya=$4 top=$5
# the region in the SVG's pixels, then zoomed to WIDTH_PX
eval "$(awk -v s="$scale" -v xa="$xa" -v l="$left" -v ya="$ya" -v t="$top" \
    -v x0="$x0" -v y0="$y0" -v x1="$x1" -v y1="$y1" -v w="$width" 'BEGIN {
    px = l + (x0 - xa) * s; py = t + (ya - y1) * s;
    pw = (x1 - x0) * s; ph = (y1 - y0) * s; z = w / pw;
    printf "zoom=%.6f left=%.2f top=%.2f pagew=%.0f pageh=%.0f\n", z, -px * z, -py * z, w, ph * z }')"
rsvg-convert -z "$zoom" --left="$left" --top="$top" --page-width "$pagew" \
    --page-height "$pageh" -b white -o "$out" "$svg"
