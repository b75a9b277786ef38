#!/usr/bin/env python3
"""check.py - judges an embedded example's map from the emulated Cortex-M4F
against the room's true walls and against the same example's map on the host,
and prints the instructions of each library call.

usage: check.py --room examples/embedded_room.h --name NAME
                [--min-length M] [--host-tolerance M] TARGET.out HOST.out

TARGET.out: the target run's output (status, polylines in polyc's TXT form,
"instructions WHAT INDEX N" lines, "calibration EXPECTED MEASURED").
HOST.out: the host build's output (status and polylines).

Checks (exit 1 on any failure, each named):
- the status is ok on both, and the harness's clock counted its calibration
  loop exactly;
- every target vertex lies within --wall-tolerance (4 cm) of a true wall;
- the target map is at least --min-length metres long;
- the two maps lie within --host-tolerance of each other: every vertex of
  each within that distance of the other map's segments.
"""
import argparse
import math
import re
import sys


def parse(path):
    status, lines, counts, calib = None, [], [], None
    with open(path) as f:
        for raw in f:
            w = raw.split()
            if not w:
                continue
            if w[0] == "status":
                status = w[1]
            elif w[0] in ("open", "closed"):
                v = [float(x) for x in w[2:]]
                pts = list(zip(v[0::2], v[1::2]))
                if w[0] == "closed":
                    pts.append(pts[0])
                lines.append(pts)
            elif w[0] == "instructions" and w[1] != "total":
                counts.append((w[1], int(w[2]), int(w[3])))
            elif w[0] == "calibration":
                calib = (int(w[1]), int(w[2]))
    return status, lines, counts, calib


def walls_of(header):
    text = open(header).read()
    m = re.search(r"walls\[\]\[4\]\s*=\s*\{(.*?)\};", text, re.S)
    if not m:
        sys.exit("check.py: no walls[][4] in " + header)
    body = re.sub(r"/\*.*?\*/", "", m.group(1), flags=re.S)
    quads = re.findall(r"\{([^{}]*)\}", body)
    return [[(float(q.split(",")[0].strip().rstrip("f")), float(q.split(",")[1].strip().rstrip("f"))),
             (float(q.split(",")[2].strip().rstrip("f")), float(q.split(",")[3].strip().rstrip("f")))]
            for q in quads]


def seg_dist(p, a, b):
    ax, ay = a
    dx, dy = b[0] - ax, b[1] - ay
    L = dx * dx + dy * dy
    t = 0.0 if L == 0 else max(0.0, min(1.0, ((p[0] - ax) * dx + (p[1] - ay) * dy) / L))
    return math.hypot(p[0] - ax - t * dx, p[1] - ay - t * dy)


def dist_to(p, polylines):
    return min(seg_dist(p, pl[i], pl[i + 1]) for pl in polylines for i in range(len(pl) - 1))


def length(polylines):
    return sum(math.dist(pl[i], pl[i + 1]) for pl in polylines for i in range(len(pl) - 1))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--room", required=True)
    ap.add_argument("--name", required=True)
    ap.add_argument("--wall-tolerance", type=float, default=0.04)
    ap.add_argument("--min-length", type=float, default=0.0)
    ap.add_argument("--host-tolerance", type=float, default=0.02)
    ap.add_argument("target")
    ap.add_argument("host")
    a = ap.parse_args()
    walls = walls_of(a.room)
    st, tl, counts, calib = parse(a.target)
    hst, hl, _, _ = parse(a.host)
    fails = []
    if st != "ok" or hst != "ok":
        fails.append("status: target %s, host %s" % (st, hst))
    if not calib or calib[0] != calib[1]:
        fails.append("the clock counted %s for its calibration loop" % (calib,))
    tv = [p for pl in tl for p in pl]
    hv = [p for pl in hl for p in pl]
    if not tv or not hv:
        fails.append("an empty map: target %d vertices, host %d" % (len(tv), len(hv)))
    else:
        wall_err = max(dist_to(p, walls) for p in tv)
        if wall_err > a.wall_tolerance:
            fails.append("a vertex %.4f m off the walls (at most %.3f)" % (wall_err, a.wall_tolerance))
        if length(tl) < a.min_length:
            fails.append("the map is %.2f m long (at least %.2f)" % (length(tl), a.min_length))
        host_err = max(max(dist_to(p, hl) for p in tv), max(dist_to(p, tl) for p in hv))
        if host_err > a.host_tolerance:
            fails.append("target and host maps %.4f m apart (at most %.3f)" % (host_err, a.host_tolerance))
        print("target %s: %d polylines, %d vertices, %.2f m long; host %d polylines, %d vertices,"
              " %.2f m; vertices within %.4f m of the walls, maps %.4f m apart"
              % (a.name, len(tl), sum(len(pl) for pl in tl) - sum(pl[0] == pl[-1] for pl in tl),
                 length(tl), len(hl), sum(len(pl) for pl in hl) - sum(pl[0] == pl[-1] for pl in hl),
                 length(hl), wall_err, host_err))
    for what, i, n in counts:
        if what != "scan":
            print("target %s: %-7s %2d %12d instructions" % (a.name, what, i, n))
    lib = sum(n for what, _, n in counts if what != "scan")
    print("target %s: library  total %12d instructions" % (a.name, lib))
    adds = {}
    for what, i, n in counts:
        if what in ("add", "update"):
            adds[i] = adds.get(i, 0) + n
    if any(what == "update" for what, _, _ in counts):
        i = max(adds, key=adds.get)
        print("target %s: largest add + update (scan %d) %d instructions" % (a.name, i, adds[i]))
    for f in fails:
        print("target %s: FAIL: %s" % (a.name, f))
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
