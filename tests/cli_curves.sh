#!/bin/sh
# cli_curves.sh - round things in the tool's outputs (docs/formats.md): a
# pillar hall and a room of curved walls simulated by gen_example, mapped
# batch and --online; pillars come out as JSON "circles", TXT `circle` lines
# and SVG <circle> elements, curved walls as "bulges", TXT `bulges` and SVG
# arcs; --no-arcs and --max-chord-error E write polylines only (the latter
# each curve as a polyline within E of it); a bad E is a usage error.
#   tests/cli_curves.sh POLYC GEN_EXAMPLE
set -u
[ $# -eq 2 ] || { echo "usage: $0 POLYC GEN_EXAMPLE" >&2; exit 2; }
case $1 in /*) POLYC=$1 ;; *) POLYC=$(pwd)/$1 ;; esac
case $2 in /*) GEN=$2 ;; *) GEN=$(pwd)/$2 ;; esac
. "$(dirname "$0")/cli_lib.sh"
cli_scratch circles
run() {
    count=$((count + 1))
    timeout 120 "$POLYC" --quiet "$@" > out.txt 2> err.txt
    rc=$?
}
"$GEN" hall.log hall.gt.txt pillars 1 > /dev/null || { echo "cli_curves: gen_example failed"; exit 1; }

# JSON: the circles beside the polylines, none of them also a polyline
name=json
run --format json -o map.json hall.log
[ $rc -eq 0 ] && python3 - map.json <<'PY' || bad "exit $rc, or the JSON's circles are wrong"
import json, sys
d = json.load(open(sys.argv[1]))
c = d["circles"]
assert len(c) >= 3, c
for x in c:
    assert len(x["center"]) == 2 and 0.05 < x["radius"] < 0.7, x
n = len(d["polylines"])
assert d["stats"]["polylines"] == n + len(c), (d["stats"]["polylines"], n, len(c))
PY
circles=$(python3 -c 'import json; print(len(json.load(open("map.json"))["circles"]))' 2>/dev/null)

# TXT: one `circle X Y R` line each, the same count
name=txt
run --format txt -o map.txt hall.log
[ $rc -eq 0 ] && [ "$(grep -c '^circle -\{0,1\}[0-9]*\.[0-9]\{4\} -\{0,1\}[0-9]*\.[0-9]\{4\} [0-9]*\.[0-9]\{4\}$' map.txt)" = "$circles" ] ||
    bad "exit $rc, or not $circles circle lines"

# SVG: a <circle> each, in the polylines' group
name=svg
run -o map.svg hall.log
[ $rc -eq 0 ] && [ "$(grep -c '^<circle stroke=' map.svg)" = "$circles" ] && grep -q "$circles circles" map.svg ||
    bad "exit $rc, or not $circles <circle> elements"

# --stats: the circles and arcs
name=stats
run --stats -o stats.svg hall.log
[ $rc -eq 0 ] && grep -q "^curves         $circles circles, [0-9]* arcs\$" err.txt ||
    bad "exit $rc, or no line 'curves $circles circles, N arcs'"

# arcs: a room of curved walls; JSON "bulges" one a segment, TXT `bulges`,
# SVG arcs; --max-chord-error: none, each arc within E of the polyline
"$GEN" arcs.log arcs.gt.txt arcwalls 1 > /dev/null || { echo "cli_curves: gen_example failed"; exit 1; }
name=arcs-json
run --format json -o arcs.json arcs.log
[ $rc -eq 0 ] && python3 - arcs.json <<'PY' || bad "exit $rc, or the JSON's bulges are wrong"
import json, sys
d = json.load(open(sys.argv[1]))
with_arcs = [p for p in d["polylines"] if "bulges" in p]
assert with_arcs, "no arc"
for p in with_arcs:
    n = len(p["points"])
    assert len(p["bulges"]) == (n if p["closed"] else n - 1), p
    assert all(-1.0 < b < 1.0 for b in p["bulges"]) and any(b != 0 for b in p["bulges"])
PY
name=arcs-txt
run --format txt -o arcs.txt arcs.log
[ $rc -eq 0 ] && grep -q '^\(open\|closed\) [0-9]* .* bulges -\{0,1\}[0-9]\.[0-9]\{6\}' arcs.txt ||
    bad "exit $rc, or no TXT line with bulges"
name=arcs-svg
run -o arcs.svg arcs.log
[ $rc -eq 0 ] && grep -q '^<path stroke=[^>]* A[0-9.]* [0-9.]* 0 [01] [01] ' arcs.svg && grep -q ' arcs, ' arcs.svg ||
    bad "exit $rc, or no SVG arc"
name=arcs-max-chord-error
run --max-chord-error 0.001 --format json -o arcs-lines.json arcs.log
[ $rc -eq 0 ] && python3 - arcs-lines.json arcs.json <<'PY' || bad "exit $rc, or an arc not within 1 mm"
import json, math, sys
a, b = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
assert all("bulges" not in p for p in a["polylines"]) and "circles" not in a
assert len(a["polylines"]) == len(b["polylines"]) + len(b.get("circles", []))
def arc(p, q, bulge):
    dx, dy = q[0] - p[0], q[1] - p[1]
    c = math.hypot(dx, dy)
    half = 2 * math.atan(abs(bulge))
    r = c / (2 * math.sin(half))
    s = 1 if bulge >= 0 else -1
    d = r * math.cos(half)
    return (p[0] + q[0]) / 2 + s * d * (-dy / c), (p[1] + q[1]) / 2 + s * d * (dx / c), r
flat = [pt for p in a["polylines"] for pt in p["points"]]
for p in b["polylines"]:
    for k, bulge in enumerate(p.get("bulges", [])):
        if bulge == 0:
            continue
        u, v = p["points"][k], p["points"][(k + 1) % len(p["points"])]
        cx, cy, r = arc(u, v, bulge)
        # the flattened polyline has points on the arc, its sides within 1 mm
        on = [q for q in flat if abs(math.hypot(q[0] - cx, q[1] - cy) - r) < 2e-4 and
              min(math.hypot(q[0] - u[0], q[1] - u[1]), math.hypot(q[0] - v[0], q[1] - v[1])) > 1e-3]
        assert on, (u, v, bulge)
PY

# --online: the finished map's circles too
name=online
run --online --format json -o online.json hall.log
[ $rc -eq 0 ] && python3 -c 'import json; assert len(json.load(open("online.json"))["circles"]) >= 3' ||
    bad "exit $rc, or fewer than 3 circles online"

# --no-arcs: polylines only, as many as the map with circles has in all
name=no-arcs
run --no-arcs --format json -o lines.json hall.log
[ $rc -eq 0 ] && python3 - lines.json map.json <<'PY' || bad "exit $rc, or circles with --no-arcs"
import json, sys
a, b = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
assert "circles" not in a
assert len(a["polylines"]) == len(b["polylines"]) + len(b["circles"])
PY

# --max-chord-error: each circle a closed polyline within E of it
name=max-chord-error
run --max-chord-error 0.002 --format json -o chord.json hall.log
[ $rc -eq 0 ] && python3 - chord.json map.json <<'PY' || bad "exit $rc, or a circle not within 2 mm"
import json, math, sys
a, b = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
assert "circles" not in a
for c in b["circles"]:
    (cx, cy), r = c["center"], c["radius"]
    near = [p for p in a["polylines"] if p["closed"] and len(p["points"]) >= 8 and
            all(abs(math.hypot(x - cx, y - cy) - r) < 2e-4 for x, y in p["points"])]
    assert len(near) == 1, c
    pts = near[0]["points"]
    for (x0, y0), (x1, y1) in zip(pts, pts[1:] + pts[:1]):
        mx, my = (x0 + x1) / 2, (y0 + y1) / 2
        assert r - math.hypot(mx - cx, my - cy) <= 0.002 + 2e-4, (c, x0, y0)
PY
for e in 0 -1 2 x 0.00001; do
    name="max-chord-error $e"
    run --max-chord-error "$e" -o bad.svg hall.log
    [ $rc -eq 2 ] && [ ! -e bad.svg ] || bad "exit $rc, not 2"
done
name="no-arcs on polyc grid"
run grid --no-arcs -o g hall.log
[ $rc -eq 2 ] || bad "exit $rc, not 2"

echo "cli_curves: $count runs, $failed failed"
[ $failed -eq 0 ]
