"""test_polyc.py - the Python binding (run by `make test`).

A synthetic room mapped through Python must give the polylines the `polyc`
tool gives for the same scans written in its plain format (to the tool's 4
decimals); too small a block, bad configuration and bad scans raise
PolycError with the library's message; the ctypes structs match the library.
The package loads only its own library or $POLYC_LIB; `pip install` of
bindings/python (and of the repository root) into a fresh venv gives a
package that runs the README's example from another folder; logs and maps
read through the tool's readers give the tool's maps; points are N x 2
float64 buffers of shortest float32 decimals; exceptions in the progress
callback (KeyboardInterrupt too) reach the caller; integers out of range are
refused; a scan too large for the sized limits is retried as the tool does.
Environment: POLYC_LIB (the package's libpolyc.so, `make build/py/libpolyc.so`),
POLYC_TOOL (the polyc binary), defaulting to the repository's build/;
POLYC_WHEELS, a folder with setuptools and wheel wheels for an offline pip
install (else pip goes online). numpy is optional: its tests skip without it.
"""
import ctypes
import errno
import inspect
import json
import math
import os
import random
import re
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import threading
import time
import unittest
import zlib
from array import array

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
os.environ.setdefault("POLYC_LIB", os.path.join(REPO, "build", "py", "libpolyc.so"))
import polyc  # noqa: E402

TOOL = os.environ.get("POLYC_TOOL", os.path.join(REPO, "build", "polyc"))
try:
    import numpy
except ImportError:
    numpy = None
NO_NUMPY = "numpy is not installed (make test-python installs it in build/pyvenv if pip can)"

# A 6 m x 4 m room with a cabinet and a pillar: wall segments (x0, y0, x1, y1).
WALLS = [(0, 0, 6, 0), (6, 0, 6, 4), (6, 4, 0, 4), (0, 4, 0, 0),
         (4.0, 2.8, 5.0, 2.8), (5.0, 2.8, 5.0, 3.4), (5.0, 3.4, 4.0, 3.4), (4.0, 3.4, 4.0, 2.8),
         (2.0, 1.0, 2.3, 1.0), (2.3, 1.0, 2.3, 1.3), (2.3, 1.3, 2.0, 1.3), (2.0, 1.3, 2.0, 1.0)]
POSES = [(1.0, 2.0, 0.0), (3.0, 2.2, 0.4), (4.8, 1.5, 2.5), (2.5, 3.0, -2.0)]


def f32(v):
    """v rounded to float32, as the library stores it."""
    return struct.unpack("f", struct.pack("f", v))[0]


def cast(x, y, a, max_range, walls=None):
    """Range from (x, y) along angle a to the nearest of walls (the room's)."""
    dx, dy = math.cos(a), math.sin(a)
    best = max_range
    for ax, ay, bx, by in WALLS if walls is None else walls:
        ex, ey = bx - ax, by - ay
        den = dx * ey - dy * ex
        if abs(den) < 1e-12:
            continue
        t = ((ax - x) * ey - (ay - y) * ex) / den
        u = ((ax - x) * dy - (ay - y) * dx) / den
        if 0 < t < best and 0 <= u <= 1:
            best = t
    return best


def scene(beams=181, seed=5):
    """Scans of the room: 181 beams over 180 degrees, 1 cm noise, float32 values."""
    rng = random.Random(seed)
    start, step = f32(-math.pi / 2), f32(math.pi / (beams - 1))
    scans = []
    for x, y, th in POSES:
        ranges = [f32(cast(x, y, th + start + i * step, 30.0) + rng.gauss(0, 0.01))
                  for i in range(beams)]
        scans.append(polyc.Scan((x, y, th), start, step, f32(0.02), f32(30.0), ranges))
    return scans


def write_plain(path, scans):
    """polyc's plain format (docs/formats.md); repr() round-trips every value."""
    with open(path, "w") as f:
        f.write("# polyc-scans 1\n")
        for s in scans:
            fields = list(s.pose) + [s.start_angle_rad, s.angle_step_rad, s.min_range_m,
                                     s.max_range_m]
            f.write("SCAN %s %d %s\n" % (" ".join(repr(float(v)) for v in fields),
                                         len(s.ranges_m),
                                         " ".join(repr(float(r)) for r in s.ranges_m)))


class Binding(unittest.TestCase):
    def test_struct_sizes(self):
        for name, cls in polyc._STRUCTS.items():
            self.assertEqual(polyc._lib.polyc_struct_size(name.encode()), ctypes.sizeof(cls), name)
        self.assertEqual(polyc._lib.polyc_struct_size(b"no_such_struct"), 0)

    def test_version(self):
        with open(os.path.join(REPO, "include", "polyc.h")) as f:
            header = f.read()
        want = ".".join(re.search(r"#define POLYC_VERSION_%s (\d+)" % part, header).group(1)
                        for part in ("MAJOR", "MINOR", "PATCH"))
        self.assertEqual(polyc.__version__, want)
        self.assertEqual(polyc.__version__, "%d.%d.%d" % polyc.version())

    def test_every_public_call_has_a_docstring(self):
        names = [n for n in polyc.__all__ if callable(getattr(polyc, n))]
        for cls in (polyc.Context, polyc.OnlineMap):
            names += ["%s.%s" % (cls.__name__, n) for n in vars(cls) if not n.startswith("_")]
        self.assertIn("Context.build_grid", names)
        for name in names:
            obj = polyc
            for part in name.split("."):
                obj = getattr(obj, part)
            doc = inspect.getdoc(obj.fget if isinstance(obj, property) else obj)
            self.assertTrue(doc and doc.strip(), "%s has no docstring" % name)

    def test_the_readme_gives_the_real_signatures(self):
        with open(os.path.join(HERE, "README.md")) as f:
            text = f.read()
        calls = {"build_map": polyc.build_map, "build_map_from_grid": polyc.build_map_from_grid,
                 "grid_image": polyc.grid_image, "read_log": polyc.read_log,
                 "read_map": polyc.read_map, "Context": polyc.Context,
                 "OnlineMap": polyc.OnlineMap, "add_scan": polyc.OnlineMap.add_scan,
                 "update": polyc.OnlineMap.update, "finish": polyc.OnlineMap.finish,
                 "changes_since": polyc.OnlineMap.changes_since}
        for name, fn in calls.items():
            found = re.search(r"`%s\(([^`]+)\)`" % name, text)   # not a call `f()`
            self.assertIsNotNone(found, "README: no `%s(...)`" % name)
            documented = [p.split("=")[0] for p in re.split(r",\s*(?![^()]*\))",
                                                             " ".join(found.group(1).split()))]
            real = [("**" if p.kind == p.VAR_KEYWORD else "") + p.name
                    for p in inspect.signature(fn).parameters.values() if p.name != "self"]
            self.assertEqual(documented, real, "README's %s" % name)
            for part in re.split(r",\s*(?![^()]*\))", " ".join(found.group(1).split())):
                if "=" in part:
                    key, value = part.split("=", 1)
                    want = inspect.signature(fn).parameters[key].default
                    self.assertEqual(eval(value, vars(polyc)), want, "README's %s" % part)

    def test_defaults_in_field_order(self):
        c = polyc.default_config()   # a field out of order would show a wrong value here
        self.assertAlmostEqual(c["cell_m"], 0.025, places=6)
        self.assertEqual(c["contour_threshold"], 0.5)
        self.assertEqual(c["alpha"], 500.0)
        self.assertAlmostEqual(c["merge_dist_m"], 0.15, places=6)
        self.assertAlmostEqual(c["split_gap_m"], 0.20, places=6)
        self.assertAlmostEqual(c["step_m"], 0.01, places=6)
        self.assertEqual((c["patience"], c["max_iterations"], c["flags"], c["seed"]), (5, 100, 0, 1))
        self.assertEqual(polyc.version()[0] * 10000 + polyc.version()[1] * 100 + polyc.version()[2],
                         polyc._lib.polyc_version())

    def test_same_map_as_the_tool(self):
        scans = scene()
        result = polyc.build_map(scans, cell_m=0.05)
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "room.scans")
            write_plain(path, scans)
            out = subprocess.run([TOOL, "--format", "json", "--cell", "0.05", path],
                                 capture_output=True, text=True, check=True).stdout
        tool = json.loads(out)
        self.assertGreater(len(result.polylines), 0)
        self.assertEqual(len(result.polylines), len(tool["polylines"]))
        for mine, theirs in zip(result.polylines, tool["polylines"]):
            self.assertEqual(mine.closed, theirs["closed"])
            self.assertEqual([(float("%.4f" % f32(x)), float("%.4f" % f32(y)))
                              for x, y in mine.points],
                             [tuple(p) for p in theirs["points"]])
        for key in ("scans", "beams", "hits", "data_points", "polylines", "vertices",
                    "iterations", "memory_size_bytes"):
            self.assertEqual(result.stats[key], tool["stats"][key], key)
        self.assertEqual(float("%.6f" % result.stats["bic"]), tool["stats"]["bic"])

    def test_too_small_block(self):
        scans = scene()
        with self.assertRaises(polyc.PolycError) as e:
            polyc.build_map(scans, memory_bytes=100000, cell_m=0.05)
        self.assertEqual(e.exception.status, polyc.ERR_NOMEM)
        self.assertEqual(e.exception.name, "POLYC_ERR_NOMEM")
        self.assertIn("memory block too small", str(e.exception))
        self.assertIn("100000 bytes given", str(e.exception))

    def test_config_errors(self):
        scans = scene()
        with self.assertRaises(polyc.PolycError) as e:
            polyc.build_map(scans, cell_m=-1.0)
        self.assertEqual(e.exception.status, polyc.ERR_CONFIG)
        self.assertIn("cell_m must be", str(e.exception))
        with self.assertRaises(polyc.PolycError) as e:
            polyc.build_map(scans, noise_decay=0.0)
        self.assertIn("noise_decay", e.exception.detail)
        with self.assertRaises(TypeError):
            polyc.build_map(scans, no_such_field=1)
        with self.assertRaises(TypeError):
            polyc.build_map(scans, reserved=1)

    def test_bad_scan(self):
        ctx = polyc.Context((2, 10, 4096, 0))
        with self.assertRaises(polyc.PolycError) as e:
            ctx.add_scan((float("nan"), 0.0, 0.0), -1.5, 0.1, 0.02, 10.0, [1.0] * 10)
        self.assertEqual(e.exception.status, polyc.ERR_SCAN)
        self.assertIn("scan pose is not finite", str(e.exception))
        ctx.add_scan((0.0, 0.0, 0.0), -1.5, 0.1, 0.02, 10.0, [1.0] * 10)
        with self.assertRaises(polyc.PolycError) as e:   # more beams than the limits allow
            ctx.add_scan((0.0, 0.0, 0.0), -1.5, 0.1, 0.02, 10.0, [1.0] * 10)
        self.assertEqual(e.exception.status, polyc.ERR_LIMIT)

    def test_stages_and_progress(self):
        scans = scene()
        whole = polyc.build_map(scans, cell_m=0.05)
        ctx = polyc.Context((whole.stats["scans"], whole.stats["beams"],
                             polyc_grid_cells(scans, 0.05), 0), cell_m=0.05)
        with self.assertRaises(polyc.PolycError) as e:
            ctx.score()
        self.assertEqual(e.exception.status, polyc.ERR_STATE)
        for s in scans:
            ctx.add_scan(*s)
        ctx.trace()
        initial = ctx.polylines()
        self.assertEqual(len(initial), whole.stats["initial_polylines"])
        seen = []
        ctx.optimize(progress=lambda it: seen.append(it["iteration"]) and False)
        self.assertEqual(ctx.polylines(), whole.polylines)
        self.assertEqual(len(seen), whole.stats["iterations"])    # one call per iteration
        self.assertEqual(seen, list(range(seen[0], seen[0] + len(seen))))
        with self.assertRaises(polyc.PolycError) as e:   # stop at the first iteration
            ctx.optimize(progress=lambda it: True)
        self.assertEqual(e.exception.status, polyc.ERR_STOPPED)

    def test_a_deadline_keeps_the_best_map(self):
        # progress stops after 2 iterations: POLYC_ERR_STOPPED with the best
        # map so far attached, the map a Context stopped the same way keeps
        scans = scene()

        def deadline(it):
            return it["iteration"] >= 1

        with self.assertRaises(polyc.PolycError) as e:
            polyc.build_map(scans, cell_m=0.05, progress=deadline)
        self.assertEqual(e.exception.status, polyc.ERR_STOPPED)
        got = e.exception.result
        self.assertIsInstance(got, polyc.Result)
        self.assertGreater(len(got.polylines), 0)
        self.assertEqual(got.stats["vertices"], sum(len(p.points) for p in got.polylines))
        whole = polyc.build_map(scans, cell_m=0.05)
        self.assertLess(got.stats["iterations"], whole.stats["iterations"])
        ctx = polyc.Context((whole.stats["scans"], whole.stats["beams"],
                             polyc_grid_cells(scans, 0.05), 0), cell_m=0.05)
        for s in scans:
            ctx.add_scan(*s)
        with self.assertRaises(polyc.PolycError):
            ctx.build(progress=deadline)
        self.assertEqual(ctx.polylines(), got.polylines)
        cells, width, height, origin = room_grid()
        with self.assertRaises(polyc.PolycError) as e:
            polyc.build_map_from_grid(cells, width, height, 0.05, origin=origin,
                                      progress=lambda it: True)
        self.assertEqual(e.exception.status, polyc.ERR_STOPPED)
        self.assertGreater(len(e.exception.result.polylines), 0)
        with self.assertRaises(polyc.PolycError) as e:     # other errors carry none
            polyc.Context((1, 1, 1024, 0)).score()
        self.assertIsNone(e.exception.result)


def room_grid(yaw=0.3, res=0.05):
    """The room of WALLS rasterised into an occupancy grid turned by yaw:
    cells within 0.6 cells of a wall occupied (100), the room's others free
    (0), the rest unknown (-1). Returns (cells as a list, width, height,
    origin)."""
    c, s = math.cos(yaw), math.sin(yaw)
    corners = [(0, 0), (6, 0), (6, 4), (0, 4)]
    gx = [c * x + s * y for x, y in corners]
    gy = [-s * x + c * y for x, y in corners]
    ax, ay = min(gx) - 0.5, min(gy) - 0.5
    origin = (c * ax - s * ay, s * ax + c * ay, yaw)
    width = int(math.ceil((max(gx) - min(gx) + 1.0) / res))
    height = int(math.ceil((max(gy) - min(gy) + 1.0) / res))
    cells = []
    for j in range(height):
        for i in range(width):
            u, v = (i + 0.5) * res, (j + 0.5) * res
            x, y = origin[0] + c * u - s * v, origin[1] + s * u + c * v
            near = min(seg_dist(w, x, y) for w in WALLS) <= 0.6 * res
            inside = 0 < x < 6 and 0 < y < 4 and not (4.0 < x < 5.0 and 2.8 < y < 3.4) \
                and not (2.0 < x < 2.3 and 1.0 < y < 1.3)
            cells.append(100 if near else (0 if inside else -1))
    return cells, width, height, origin


def seg_dist(w, x, y):
    ax, ay, bx, by = w
    dx, dy = bx - ax, by - ay
    t = max(0.0, min(1.0, ((x - ax) * dx + (y - ay) * dy) / (dx * dx + dy * dy)))
    return math.hypot(ax + t * dx - x, ay + t * dy - y)


def pillar_scans():
    """A 0.3 m round pillar at (1, 2) inside a 6 m x 5 m room, seen from 16
    poses round it (361 beams over 180 degrees, facing the pillar)."""
    cx, cy, r = 1.0, 2.0, 0.3
    room = (-2.0, -0.5, 4.0, 4.5)
    scans = []
    for k in range(16):
        a = 2 * math.pi * k / 16
        px, py = cx + 1.4 * math.cos(a), cy + 1.4 * math.sin(a)
        th = math.atan2(cy - py, cx - px)
        ranges = []
        for i in range(361):
            b = th - math.pi / 2 + i * math.pi / 360
            dx, dy = math.cos(b), math.sin(b)
            best = 20.0
            # the pillar
            ox, oy = px - cx, py - cy
            bb = dx * ox + dy * oy
            disc = bb * bb - (ox * ox + oy * oy - r * r)
            if disc >= 0 and -bb - math.sqrt(disc) > 0:
                best = -bb - math.sqrt(disc)
            # the room's walls
            for t in ((room[0] - px) / dx if dx < 0 else (room[2] - px) / dx if dx > 0 else 1e9,
                      (room[1] - py) / dy if dy < 0 else (room[3] - py) / dy if dy > 0 else 1e9):
                if 0 < t < best:
                    best = t
            ranges.append(round(best, 3))
        scans.append(((px, py, th), -math.pi / 2, math.pi / 360, 0.02, 20.0, ranges))
    return scans


class Circles(unittest.TestCase):
    def test_pillar_is_a_circle(self):
        scans = pillar_scans()
        for flags in (0, polyc.FLAG_NO_ARCS):
            ctx = polyc.Context((len(scans), 361 * len(scans), 1 << 20, 0), flags=flags)
            for s in scans:
                ctx.add_scan(*s)
            ctx.build()
            circles = ctx.circles()
            if flags:
                self.assertEqual(circles, [])
                continue
            self.assertEqual(len(circles), 1, circles)
            c = circles[0]
            self.assertLess(math.hypot(c.center[0] - 1.0, c.center[1] - 2.0), 0.01, c)
            self.assertLess(abs(c.radius - 0.3), 0.01, c)
            line = ctx.polylines()[c.index]
            self.assertTrue(all(abs(math.hypot(x - c.center[0], y - c.center[1]) - c.radius)
                                <= c.polyline_dev + 1e-6 for x, y in line.points))

    def test_arc_polylines(self):
        # a D-shaped room: a straight wall along y = 0 and a half circle of
        # 4 m radius about the origin, seen from poses along its middle
        scans, R = [], 4.0
        for k in range(12):
            px, py = -2.0 + 4.0 * k / 11, 1.5
            for th in (0.0, math.pi):
                ranges = []
                for i in range(361):
                    b = th - math.pi / 2 + i * math.pi / 360
                    dx, dy = math.cos(b), math.sin(b)
                    bb = dx * px + dy * py
                    t = -bb + math.sqrt(bb * bb - (px * px + py * py - R * R))
                    if py + t * dy < 0:            # the straight wall first
                        t = -py / dy
                    ranges.append(round(t, 3))
                scans.append(((px, py, th), -math.pi / 2, math.pi / 360, 0.02, 20.0, ranges))
        ctx = polyc.Context((len(scans), 361 * len(scans), 1 << 20, 0))
        for s in scans:
            ctx.add_scan(*s)
        ctx.build()
        bent = 0
        for a in ctx.arc_polylines():
            pts = a.points.tolist()
            for k, b in enumerate(a.bulges):
                if b == 0:
                    continue
                bent += 1
                # the arc's middle lies on the true half circle (within 1 cm)
                (x0, y0), (x1, y1) = pts[k], pts[(k + 1) % len(pts)]
                c = math.hypot(x1 - x0, y1 - y0)
                s = b * c / 2                      # the sagitta, to the right of the chord
                mx = (x0 + x1) / 2 + s * (y1 - y0) / c
                my = (y0 + y1) / 2 - s * (x1 - x0) / c
                self.assertLess(abs(math.hypot(mx, my) - R), 0.01, (pts[k], b))
        self.assertGreaterEqual(bent, 1)
        scans = pillar_scans()
        ctx = polyc.Context((len(scans), 361 * len(scans), 1 << 20, 0))
        for s in scans:
            ctx.add_scan(*s)
        ctx.build()
        lines, arcs = ctx.polylines(), ctx.arc_polylines()
        self.assertEqual(len(lines), len(arcs))
        for line, a in zip(lines, arcs):
            self.assertLessEqual(len(a.points), len(line.points))
            self.assertEqual(len(a.bulges), len(a.points) if a.closed else len(a.points) - 1)
            self.assertTrue(all(-1 < b < 1 for b in a.bulges))
            self.assertTrue(set(a.points.tolist()) <= set(line.points.tolist()))

    def test_online_pillar(self):
        scans = pillar_scans()
        m = polyc.OnlineMap(12.0, 361)
        for s in scans:
            m.add_scan(*s)
            m.update()
        m.finish()
        self.assertEqual(len(m.circles), 1)


class Grid(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.room = room_grid()

    def test_room_from_grid(self):
        cells, width, height, origin = self.room
        result = polyc.build_map_from_grid(cells, width, height, 0.05, origin=origin)
        # the room, the cabinet and the 30 cm pillar (6 cells wide): three
        # closed polygons, every corner of each within a cell of a vertex
        # (map frame)
        self.assertEqual(len(result.polylines), 3)
        self.assertTrue(all(line.closed for line in result.polylines))
        vertices = [p for line in result.polylines for p in line.points]
        self.assertLessEqual(len(vertices), 12)
        for w in WALLS[:8]:
            self.assertLess(min(math.hypot(x - w[0], y - w[1]) for x, y in vertices), 0.05, w)
        pillar = [line for line in result.polylines
                  if all(math.hypot(x - 2.15, y - 1.15) < 0.4 for x, y in line.points)]
        self.assertEqual(len(pillar), 1)
        for cx, cy in ((2.0, 1.0), (2.3, 1.0), (2.3, 1.3), (2.0, 1.3)):
            self.assertLess(min(math.hypot(x - cx, y - cy) for x, y in pillar[0].points), 0.05)
        # the data: the occupied cells that face free space (a free cell at
        # most 4 cells away along a row or a column, only unknown between)
        def at(i, j):
            return cells[j * width + i] if 0 <= i < width and 0 <= j < height else -1

        def faces(i, j, di, dj):
            for k in range(1, 5):
                v = at(i + k * di, j + k * dj)
                if v != -1:
                    return v == 0
            return False
        facing = sum(1 for j in range(height) for i in range(width) if at(i, j) == 100 and any(
            faces(i, j, di, dj) for di, dj in ((1, 0), (-1, 0), (0, 1), (0, -1))))
        self.assertEqual(result.stats["data_points"], facing)
        self.assertEqual(result.stats["scans"], 0)
        self.assertEqual(result.stats["grid_width"], width)
        self.assertEqual(result.stats["vertices"], len(vertices))

    def test_every_kind_of_buffer(self):
        cells, width, height, origin = self.room
        as_bytes = bytes(v & 0xff for v in cells)
        want = polyc.build_map_from_grid(cells, width, height, 0.05, origin=origin).polylines
        kinds = [as_bytes, bytearray(as_bytes), array("b", cells),
                 memoryview(as_bytes).cast("b"), memoryview(array("b", cells)).cast("B", (height, width))]
        try:
            import numpy
            kinds.append(numpy.array(cells, dtype=numpy.int8).reshape(height, width))
        except ImportError:
            pass
        for kind in kinds:
            got = polyc.build_map_from_grid(kind, width, height, 0.05, origin=origin)
            self.assertEqual(got.polylines, want, type(kind).__name__)

    def test_grid_errors(self):
        cells, width, height, origin = [0, 100, 0, -1], 2, 2, (0.0, 0.0, 0.0)
        for res in (0.0, -0.05, float("nan")):
            with self.assertRaises(polyc.PolycError) as e:
                polyc.build_map_from_grid(cells, width, height, res)
            self.assertEqual(e.exception.status, polyc.ERR_CONFIG)
        for bad in (101, -2):
            with self.assertRaises(polyc.PolycError) as e:
                polyc.build_map_from_grid([0, bad, 0, 0], 2, 2, 0.05)
            self.assertEqual(e.exception.status, polyc.ERR_CONFIG)
        with self.assertRaises(polyc.PolycError) as e:   # not even an int8
            polyc.build_map_from_grid([0, 200, 0, 0], 2, 2, 0.05)
        self.assertEqual(e.exception.status, polyc.ERR_CONFIG)
        with self.assertRaises(polyc.PolycError) as e:
            polyc.build_map_from_grid([], 0, 3, 0.05)
        self.assertEqual(e.exception.status, polyc.ERR_CONFIG)
        with self.assertRaises(ValueError):
            polyc.build_map_from_grid(cells, 3, 2, 0.05)
        with self.assertRaises(TypeError):
            polyc.build_map_from_grid(array("i", cells), 2, 2, 0.05)
        with self.assertRaises(polyc.PolycError) as e:
            polyc.build_map_from_grid(cells, 2, 2, 0.05, free_thresh=0.9)
        self.assertIn("free_thresh", e.exception.detail)
        # a context holding a grid refuses scans, with the library's message
        ctx = polyc.Context((0, 1, 1024, 0))
        ctx.add_grid(cells, width, height, 0.05, origin)
        with self.assertRaises(polyc.PolycError) as e:
            ctx.add_scan((0.0, 0.0, 0.0), -1.5, 0.1, 0.02, 10.0, [1.0] * 10)
        self.assertEqual(e.exception.status, polyc.ERR_STATE)
        self.assertIn("holds a grid", str(e.exception))
        with self.assertRaises(polyc.PolycError) as e:
            ctx.add_grid(cells, width, height, 0.05, origin)
        self.assertEqual(e.exception.status, polyc.ERR_STATE)

    def test_thresholds(self):
        c = polyc.default_config()
        self.assertAlmostEqual(c["occupied_thresh"], 0.65, places=6)
        self.assertAlmostEqual(c["free_thresh"], 0.196, places=6)
        # 60 is occupied only with a lower threshold
        cells = [0] * 100
        for i in range(2, 8):
            cells[5 * 10 + i] = 60
        plain = polyc.build_map_from_grid(cells, 10, 10, 0.1)
        self.assertEqual(plain.stats["data_points"], 0)
        low = polyc.build_map_from_grid(cells, 10, 10, 0.1, occupied_thresh=0.5)
        self.assertEqual(low.stats["data_points"], 6)
        self.assertEqual(len(low.polylines), 1)


def tool_json(*args):
    """The polyc tool's JSON map of args, polylines only (--no-arcs: build_map's
    Result holds the polylines as the library gives them)."""
    out = subprocess.run([TOOL, "--format", "json", "--no-arcs"] + list(args), capture_output=True,
                         text=True, check=True).stdout
    return json.loads(out)


def same_as_tool(test, result, tool):
    """The tool's polylines (4 decimals) and counts."""
    test.assertGreater(len(result.polylines), 0)
    test.assertEqual(len(result.polylines), len(tool["polylines"]))
    for mine, theirs in zip(result.polylines, tool["polylines"]):
        test.assertEqual(mine.closed, theirs["closed"])
        # the tool prints the float32 to 4 decimals (a shortest decimal such as
        # 11.32895 may round the other way)
        test.assertEqual([(float("%.4f" % f32(x)), float("%.4f" % f32(y)))
                          for x, y in mine.points],
                         [tuple(p) for p in theirs["points"]])
    for key in ("polylines", "vertices", "data_points", "iterations"):
        test.assertEqual(result.stats[key], tool["stats"][key], key)


def big_scan(beams, seed=1):
    """One scan of the room all round from the first pose."""
    rng = random.Random(seed)
    start, step = f32(-math.pi), f32(2 * math.pi / beams)
    x, y, th = POSES[0]
    ranges = [f32(cast(x, y, th + start + i * step, 30.0) + rng.gauss(0, 0.01))
              for i in range(beams)]
    return polyc.Scan((x, y, th), start, step, f32(0.02), f32(30.0), ranges)


class Package(unittest.TestCase):
    """What is loaded, and pip install."""

    def test_loads_only_its_own_library(self):
        # a copy of the package two folders below a build/libpolyc.so (where
        # the old binding looked) does not load it; next to it, it does
        with tempfile.TemporaryDirectory() as tmp:
            pkg = os.path.join(tmp, "bindings", "python", "polyc")
            os.makedirs(pkg)
            os.makedirs(os.path.join(tmp, "build"))
            shutil.copy(polyc.__file__, pkg)
            shutil.copy(os.environ["POLYC_LIB"], os.path.join(tmp, "build", "libpolyc.so"))
            env = {k: v for k, v in os.environ.items() if k != "POLYC_LIB"}
            run = [sys.executable, "-c", "import polyc; print(polyc._library_path())"]
            got = subprocess.run(run, cwd=os.path.dirname(pkg), env=env, capture_output=True,
                                 text=True)
            self.assertNotEqual(got.returncode, 0)
            self.assertIn("POLYC_LIB is not set", got.stderr)
            shutil.copy(os.environ["POLYC_LIB"], pkg)
            got = subprocess.run(run, cwd=os.path.dirname(pkg), env=env, capture_output=True,
                                 text=True, check=True)
            self.assertEqual(got.stdout.strip(), os.path.join(pkg, "libpolyc.so"))

    def test_pip_install_and_the_readme_example(self):
        text = open(os.path.join(HERE, "README.md")).read()
        example = re.search(r"```python\n(.*?)```", text, re.S).group(1)
        wheels = os.environ.get("POLYC_WHEELS", "")
        offline = ["--no-index", "--find-links", wheels] if wheels and os.listdir(wheels) else []
        env = {k: v for k, v in os.environ.items() if k not in ("POLYC_LIB", "PYTHONPATH")}
        # the example with the library under test, for comparison
        want = subprocess.run([sys.executable, "-c", example], capture_output=True, text=True,
                              check=True, cwd=HERE).stdout
        self.assertIn("vertices", want)
        for where in ("bindings/python", "."):  # pip install ./bindings/python, and . at the root
            with tempfile.TemporaryDirectory() as tmp:
                # a clean copy of the checkout (pip builds in place)
                clone = os.path.join(tmp, "libpolyc")
                shutil.copytree(REPO, clone, ignore=shutil.ignore_patterns(
                    "build", "build-*", "*.egg-info", "__pycache__", ".git", "*.o"))
                source = os.path.join(clone, where)
                subprocess.run([sys.executable, "-m", "venv", os.path.join(tmp, "venv")],
                               check=True, env=env)
                python = os.path.join(tmp, "venv", "bin", "python")
                pip = subprocess.run([python, "-m", "pip", "install", "-q"] + offline + [source],
                                     capture_output=True, text=True, env=env, cwd=tmp)
                if pip.returncode != 0 and not offline and re.search(
                        r"connection|resolve|No matching distribution|network", pip.stderr, re.I):
                    self.skipTest("pip could not reach an index for setuptools: %s"
                                  % pip.stderr.strip()[-300:])
                self.assertEqual(pip.returncode, 0, pip.stderr)
                folder = os.path.join(tmp, "elsewhere")
                os.makedirs(folder)
                with open(os.path.join(folder, "example.py"), "w") as f:
                    f.write(example)
                got = subprocess.run([python, "example.py"], capture_output=True, text=True,
                                     env=env, cwd=folder)
                self.assertEqual(got.returncode, 0, got.stderr)
                self.assertEqual(got.stdout, want)
                where = subprocess.run([python, "-c", "import polyc; print(polyc._library_path())"],
                                       capture_output=True, text=True, env=env, cwd=folder,
                                       check=True).stdout.strip()
                self.assertTrue(where.startswith(os.path.join(tmp, "venv")), where)
                self.assertTrue(where.endswith(os.path.join("polyc", "libpolyc.so")), where)


class Results(unittest.TestCase):
    def test_shortest_float32_decimals(self):
        self.assertEqual(polyc._shortest(f32(2.0)), 2.0)
        self.assertEqual(polyc._shortest(f32(0.1)), 0.1)
        self.assertEqual(polyc._shortest(1.999999761581421), 1.9999998)
        self.assertEqual(polyc._shortest(f32(-1234.5678)), -1234.5677)
        rng = random.Random(3)
        for _ in range(2000):
            v = f32(rng.uniform(-100, 100) * 10 ** rng.randint(-6, 6))
            short = polyc._shortest(v)
            self.assertEqual(f32(short), v)
            digits = len(("%.9e" % short).split("e")[0].replace("-", "").replace(".", "")
                         .rstrip("0"))
            if digits > 1:             # no shorter decimal rounds to the same float32
                self.assertNotEqual(f32(float("%.*g" % (digits - 1, v))), v, (v, short))

    def test_points_are_an_n_by_2_float64_buffer(self):
        result = polyc.build_map(scene(), cell_m=0.05)
        for line in result.polylines:
            pts = line.points
            n = len(pts)
            self.assertEqual(pts.view.shape, (n, 2))
            self.assertEqual(pts.view.format, "d")
            self.assertTrue(pts.view.readonly)
            self.assertEqual(pts.view.tolist(), [list(p) for p in pts])
            self.assertEqual(pts.tolist(), list(pts))
            self.assertEqual(pts[-1], pts.tolist()[-1])
            for x, y in pts:           # float32 values, as their shortest decimals
                for v in (x, y):
                    self.assertEqual(polyc._shortest(f32(v)), v)

    @unittest.skipIf(numpy is None, NO_NUMPY)
    def test_numpy_takes_points_without_a_copy(self):
        result = polyc.build_map(scene(), cell_m=0.05)
        for line in result.polylines:
            a = numpy.asarray(line.points)
            self.assertEqual(a.shape, (len(line.points), 2))
            self.assertEqual(a.dtype, numpy.float64)
            self.assertTrue(numpy.shares_memory(a, numpy.asarray(line.points.view)))
            self.assertEqual(a.tolist(), [list(p) for p in line.points])
            b = numpy.asarray(line.points.view)
            self.assertEqual(b.shape, a.shape)

    def test_ranges_in_any_buffer(self):
        scans = scene()
        want = polyc.build_map(scans, cell_m=0.05)
        kinds = [lambda r: array("f", r), lambda r: array("d", r), lambda r: list(r),
                 lambda r: tuple(r), lambda r: memoryview(array("f", r))]
        if numpy is not None:
            kinds += [lambda r: numpy.array(r, dtype=numpy.float32),
                      lambda r: numpy.array(r, dtype=numpy.float64),
                      lambda r: numpy.repeat(numpy.array(r, dtype=numpy.float32), 2)[::2]]
        for kind in kinds:
            got = polyc.build_map([s._replace(ranges_m=kind(s.ranges_m)) for s in scans],
                                  cell_m=0.05)
            self.assertEqual(got.polylines, want.polylines)
        with self.assertRaises(TypeError):
            polyc.build_map([scans[0]._replace(ranges_m=array("i", [1, 2, 3]))])
        if numpy is not None:          # not native byte order, or 2-D: refused, not misread
            swapped = ">f4" if sys.byteorder == "little" else "<f4"
            for bad in (numpy.array(scans[0].ranges_m, dtype=swapped),
                        numpy.zeros((2, 2), dtype=numpy.float32)):
                with self.assertRaises(TypeError):
                    polyc.build_map([scans[0]._replace(ranges_m=bad)])

    def test_clockwise_scans(self):
        # the same beams listed clockwise (negative step) give the same map
        scans = scene()
        turned = [s._replace(start_angle_rad=f32(s.start_angle_rad + 180 * s.angle_step_rad),
                             angle_step_rad=-s.angle_step_rad, ranges_m=s.ranges_m[::-1])
                  for s in scans]
        a = polyc.build_map(scans, cell_m=0.05)
        b = polyc.build_map(turned, cell_m=0.05)
        for key in ("hits", "data_points", "contour_cells", "polylines"):
            self.assertEqual(a.stats[key], b.stats[key], key)
        vertices_a = [p for line in a.polylines for p in line.points]
        for line in b.polylines:
            for xb, yb in line.points:
                self.assertLess(min(math.hypot(xa - xb, ya - yb) for xa, ya in vertices_a), 0.05)


class Files(unittest.TestCase):
    """Logs and maps read through the tool's own readers."""
    LOG = os.path.join(REPO, "examples", "office.log")

    def test_log_gives_the_tools_map(self):
        scans = polyc.read_log(self.LOG)
        self.assertGreater(len(scans), 10)
        self.assertIsInstance(scans[0].ranges_m, array)
        same_as_tool(self, polyc.build_map(scans), tool_json(self.LOG))
        short = polyc.read_log(self.LOG, max_range_m=4.0)
        self.assertTrue(all(s.max_range_m <= 4.0 for s in short))
        same_as_tool(self, polyc.build_map(short), tool_json("--max-range", "4", self.LOG))

    def test_plain_log_round_trip(self):
        scans = scene()
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "room.scans")
            write_plain(path, scans)
            back = polyc.read_log(path)
        self.assertEqual([tuple(s.ranges_m) for s in back], [tuple(s.ranges_m) for s in scans])
        self.assertEqual(polyc.build_map(back, cell_m=0.05), polyc.build_map(scans, cell_m=0.05))

    def test_bad_log_says_what_the_tool_says(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "bad.log")
            with open(path, "w") as f:
                f.write("SCAN 0 0 0 0 0.1 0.05 4 3 1 1 1\nSCAN 0 0 0 0 0.1 0.05 4 3 1 x 1\n")
            with self.assertRaises(ValueError) as e:
                polyc.read_log(path)
            tool = subprocess.run([TOOL, path], capture_output=True, text=True)
            self.assertEqual(tool.returncode, 1)
            self.assertEqual("polyc: " + str(e.exception), tool.stderr.strip())
            self.assertIn(path + ":2:", str(e.exception))

    def test_a_file_not_opened_is_an_os_error(self):
        # as open() raises it: the same class, errno, text and filename
        with tempfile.TemporaryDirectory() as tmp:
            missing = os.path.join(tmp, "missing.log")
            for read in (polyc.read_log, polyc.read_map):
                for path in (missing, tmp, os.fsencode(missing)):
                    with self.assertRaises(OSError) as want:
                        open(path, "rb")
                    with self.assertRaises(OSError) as e:
                        read(path)
                    self.assertIs(type(e.exception), type(want.exception))
                    self.assertEqual(str(e.exception), str(want.exception))
                    self.assertEqual(e.exception.filename, path)
                with self.assertRaises(IsADirectoryError):
                    read(tmp)
            with self.assertRaises(FileNotFoundError) as e:
                polyc.read_log("/nonexistent.log")
            self.assertEqual(e.exception.errno, errno.ENOENT)

    def test_a_path_with_a_nul_is_a_value_error(self):
        # as open() refuses it, not the file before the NUL
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "room.scans")
            write_plain(path, scene())
            subprocess.run([TOOL, "grid", "-o", os.path.join(tmp, "room"), path], check=True,
                           capture_output=True)
            yaml = os.path.join(tmp, "room.yaml")
            for read, good in ((polyc.read_log, path), (polyc.read_map, yaml)):
                read(good)
                for bad in (good + "\0", good + "\0.txt", os.fsencode(good) + b"\0"):
                    with self.assertRaises(ValueError) as want:
                        open(bad, "rb")
                    with self.assertRaises(ValueError) as e:
                        read(bad)
                    self.assertEqual(str(e.exception), str(want.exception))

    def test_grid_image_is_what_polyc_grid_writes(self):
        image = polyc.grid_image(polyc.read_log(self.LOG))
        with tempfile.TemporaryDirectory() as tmp:
            prefix = os.path.join(tmp, "office")
            subprocess.run([TOOL, "grid", "-o", prefix, self.LOG], check=True,
                           capture_output=True)
            with open(prefix + ".pgm", "rb") as f:
                data = f.read()
            grid = polyc.read_map(prefix + ".yaml")
        header = [w for w in data[:200].split(b"\n")[:4] if not w.startswith(b"#")]
        magic, width, height, maxval = b" ".join(header).split()[:4]
        self.assertEqual((magic, int(width), int(height), int(maxval)),
                         (b"P5", image.width, image.height, 255))
        self.assertEqual(image.pixels, data[-image.width * image.height:])
        self.assertEqual(set(image.pixels), {0, 205, 254})
        self.assertEqual(image.cell_m, grid.resolution)
        self.assertEqual(image.cell_m, 0.025)
        for a, b in zip(image.origin, grid.origin):
            self.assertAlmostEqual(a, b, places=6)
        ctx = polyc.Context((1, 10, 4096, 0))
        ctx.add_scan((0.0, 0.0, 0.0), -1.5, 0.1, 0.02, 10.0, [1.0] * 10)
        with self.assertRaises(polyc.PolycError) as e:     # before the grid
            ctx.grid_image()
        self.assertEqual(e.exception.status, polyc.ERR_STATE)
        ctx.build_grid()
        self.assertGreater(ctx.grid_image().width, 0)

    def test_map_gives_the_tools_map(self):
        with tempfile.TemporaryDirectory() as tmp:
            prefix = os.path.join(tmp, "office")
            subprocess.run([TOOL, "grid", "-o", prefix, self.LOG], check=True,
                           capture_output=True)
            grid = polyc.read_map(prefix + ".yaml")
            self.assertEqual(grid.image_path, prefix + ".pgm")
            self.assertEqual(len(grid.cells), grid.width * grid.height)
            self.assertEqual(set(grid.cells) - {0, 100, 255}, set())   # 255: -1 unknown
            result = polyc.build_map_from_grid(grid.cells, grid.width, grid.height,
                                               grid.resolution, origin=grid.origin)
            same_as_tool(self, result, tool_json(prefix + ".yaml"))
            # a bad map: the YAML's line, as the tool says it
            with open(prefix + ".yaml") as f:
                text = f.read()
            with open(prefix + ".yaml", "w") as f:
                f.write(re.sub(r"resolution: .*", "resolution: -1", text))
            with self.assertRaises(ValueError) as e:
                polyc.read_map(prefix + ".yaml")
            tool = subprocess.run([TOOL, prefix + ".yaml"], capture_output=True, text=True)
            self.assertEqual("polyc: " + str(e.exception), tool.stderr.strip())
            os.remove(prefix + ".pgm")
            with open(prefix + ".yaml", "w") as f:
                f.write(text)
            with self.assertRaises(ValueError) as e:
                polyc.read_map(prefix + ".yaml")
            self.assertIn("image", str(e.exception))

    def test_map_from_png(self):
        """The grid's image as an RGBA PNG in scale mode (the unknown cells
        transparent, as nav2's map_saver writes it): the same cells as the
        PGM, and the tool's map; a damaged PNG gives the tool's message."""
        with tempfile.TemporaryDirectory() as tmp:
            prefix = os.path.join(tmp, "office")
            subprocess.run([TOOL, "grid", "-o", prefix, self.LOG], check=True,
                           capture_output=True)
            pgm = polyc.read_map(prefix + ".yaml")
            image = polyc.grid_image(polyc.read_log(self.LOG))
            rows = b"".join(b"\0" + bytes(c for v in image.pixels[r * image.width:
                                                                   (r + 1) * image.width]
                                           for c in (v, v, v, 0 if v == 205 else 255))
                            for r in range(image.height))

            def chunk(kind, data):
                return (struct.pack(">I", len(data)) + kind + data +
                        struct.pack(">I", zlib.crc32(kind + data)))
            png = (b"\x89PNG\r\n\x1a\n" +
                   chunk(b"IHDR", struct.pack(">IIBBBBB", image.width, image.height, 8, 6,
                                              0, 0, 0)) +
                   chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))
            with open(prefix + ".png", "wb") as f:
                f.write(png)
            with open(prefix + ".yaml") as f:
                text = f.read().replace("office.pgm", "office.png")
            with open(prefix + "_png.yaml", "w") as f:
                f.write("mode: scale\n" + text)
            grid = polyc.read_map(prefix + "_png.yaml")
            self.assertEqual(grid.image_path, prefix + ".png")
            self.assertEqual((grid.width, grid.height), (pgm.width, pgm.height))
            self.assertEqual(bytes(grid.cells), bytes(pgm.cells))
            result = polyc.build_map_from_grid(grid.cells, grid.width, grid.height,
                                               grid.resolution, origin=grid.origin)
            same_as_tool(self, result, tool_json(prefix + "_png.yaml"))
            with open(prefix + ".png", "wb") as f:
                f.write(png[:-4] + b"\0" * 4)               # IEND's CRC damaged
            with self.assertRaises(ValueError) as e:
                polyc.read_map(prefix + "_png.yaml")
            tool = subprocess.run([TOOL, prefix + "_png.yaml"], capture_output=True, text=True)
            self.assertEqual("polyc: " + str(e.exception), tool.stderr.strip())
            self.assertIn("byte", str(e.exception))


class Calls(unittest.TestCase):
    """Arguments, the callback, the retry."""

    def test_integers_out_of_range(self):
        scans = scene()
        for bad in ({"max_iterations": -1}, {"flags": 2 ** 32 + 1}, {"seed": -1},
                    {"seed": 2 ** 64}, {"patience": 2 ** 32}):
            with self.assertRaises(ValueError) as e:
                polyc.build_map(scans, **bad)
            self.assertIn(list(bad)[0], str(e.exception))
        for bad in ({"max_iterations": 2.5}, {"seed": "1"}, {"cell_m": "0.05"},
                    {"flags": True}):
            with self.assertRaises(TypeError):
                polyc.build_map(scans, **bad)
        with self.assertRaises(TypeError) as e:
            polyc.build_map(scans, cell=0.05)
        for name in ("cell_m", "max_iterations", "seed", "free_thresh"):
            self.assertIn(name, str(e.exception))
        with self.assertRaises(ValueError):
            polyc.Context((1, -1, 4096, 0))
        with self.assertRaises(ValueError):
            polyc.Context({"max_scans": 2 ** 32, "max_beams": 1, "max_grid_cells": 1,
                           "max_vertices": 0})
        with self.assertRaises(TypeError):
            polyc.Context({"max_scan": 1})
        with self.assertRaises(ValueError):
            polyc.build_map_from_grid([0] * 4, -2, -2, 0.05)
        with self.assertRaises(ValueError):
            polyc.build_map(scans, max_vertices=-1)
        # the limits still work at the top of their range
        self.assertEqual(polyc.build_map(scans, cell_m=0.05, seed=2 ** 64 - 1).stats["scans"], 4)

    def test_exception_in_the_callback_reaches_the_caller(self):
        class Mine(Exception):
            pass

        calls = []

        def bad(it):
            calls.append(it["iteration"])
            raise Mine("from the callback")

        with self.assertRaises(Mine) as e:
            polyc.build_map(scene(), cell_m=0.05, progress=bad)
        self.assertEqual(str(e.exception), "from the callback")
        self.assertEqual(len(calls), 1)              # stopped at once
        ctx = polyc.Context((4, 4 * 181, polyc_grid_cells(scene(), 0.05), 0), cell_m=0.05)
        for s in scene():
            ctx.add_scan(*s)
        with self.assertRaises(Mine):
            ctx.build(progress=bad)
        self.assertGreater(len(ctx.polylines()), 0)  # the best map so far is kept
        ctx.optimize()                               # and the context still works

    def test_keyboard_interrupt_in_the_callback(self):
        def ctrl_c(it):
            signal.raise_signal(signal.SIGINT)

        def raises(it):
            raise KeyboardInterrupt

        for fn in (ctrl_c, raises):
            with self.assertRaises(KeyboardInterrupt):
                polyc.build_map(scene(), cell_m=0.05, progress=fn)
        self.assertIs(signal.getsignal(signal.SIGINT), signal.default_int_handler)

    def test_ctrl_c_during_the_optimiser(self):
        # a Ctrl-C while the library runs, without a callback of the caller's:
        # a long optimisation stops at the next iteration with KeyboardInterrupt
        scans = scene(beams=721)
        timer = threading.Timer(0.3, os.kill, (os.getpid(), signal.SIGINT))
        t0 = time.monotonic()
        timer.start()
        try:
            with self.assertRaises(KeyboardInterrupt):
                polyc.build_map(scans, cell_m=0.02, max_iterations=10 ** 6, patience=10 ** 6,
                                noise_decay=1.0)
        finally:
            timer.cancel()
        self.assertLess(time.monotonic() - t0, 20.0)

    def test_progress_must_be_callable(self):
        for call in (lambda: polyc.build_map(scene(), progress=5),
                     lambda: polyc.build_map_from_grid([0, 100, 0, 0], 2, 2, 0.05, progress="x")):
            with self.assertRaises(TypeError) as e:
                call()
            self.assertIn("progress must be callable", str(e.exception))
        ctx = polyc.Context((4, 4 * 181, polyc_grid_cells(scene(), 0.05), 0), cell_m=0.05)
        with self.assertRaises(TypeError):
            ctx.build(progress=5)

    def test_the_callback_may_not_call_its_context(self):
        ctx = polyc.Context((4, 4 * 181, polyc_grid_cells(scene(), 0.05), 0), cell_m=0.05)
        for s in scene():
            ctx.add_scan(*s)
        seen = {}

        def reenter(it):
            # the library refuses it too, whatever the binding lets through
            seen["trace"] = polyc._lib.polyc_trace(ctx._ctx)
            seen["count"] = polyc._lib.polyc_polyline_count(ctx._ctx)
            seen["error"] = polyc._lib.polyc_last_error(ctx._ctx).decode()
            other = polyc.build_map(scene()[:1], cell_m=0.05, max_iterations=1)
            seen["other"] = len(other.polylines)    # another context works
            ctx.polylines()

        with self.assertRaises(polyc.PolycError) as e:
            ctx.build(progress=reenter)
        self.assertEqual(e.exception.status, polyc.ERR_BUSY)
        self.assertIn("progress callback", str(e.exception))
        self.assertEqual(seen["trace"], polyc.ERR_BUSY)
        self.assertEqual(seen["count"], 0)
        self.assertEqual(seen["error"], "called from inside the progress callback")
        self.assertGreater(seen["other"], 0)
        self.assertGreater(len(ctx.polylines()), 0)    # usable again afterwards
        self.assertEqual(polyc.STATUS[polyc.ERR_BUSY], "POLYC_ERR_BUSY")

    def test_no_scans_is_refused_as_the_tool_refuses_it(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "empty.scans")
            write_plain(path, [])
            tool = subprocess.run([TOOL, path], capture_output=True, text=True)
        self.assertEqual(tool.returncode, 1)
        self.assertIn("no scans found", tool.stderr)
        for call in (lambda: polyc.build_map([]), lambda: polyc.build_map(iter(())),
                     lambda: polyc.build_map((), cell_m=0.05, progress=print),
                     lambda: polyc.grid_image([])):
            with self.assertRaises(ValueError) as e:
                call()
            self.assertIn("no scans found", str(e.exception))

    def test_one_large_scan_fits_its_limits(self):
        scan = big_scan(8000)
        # the limits sized for it hold it (a scan with more returns than
        # data points has them summed by cell)...
        cfg = polyc._config({})
        held = polyc._scan(scan)
        lim = polyc._Limits()
        self.assertEqual(polyc._lib.polyc_limits_for_scans(
            ctypes.byref(cfg), ctypes.byref(held[0]), 1, ctypes.byref(lim)), polyc.OK)
        ctx = polyc.Context((lim.max_scans, lim.max_beams, lim.max_grid_cells,
                             lim.max_vertices, lim.max_points))
        ctx.add_scan(*scan)
        ctx.build()
        self.assertGreater(len(ctx.polylines()), 0)
        # ...and build_map gives the tool's map
        result = polyc.build_map([scan])
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "big.scans")
            write_plain(path, [scan])
            same_as_tool(self, result, tool_json(path))


def polyc_grid_cells(scans, cell_m):
    """max_grid_cells as polyc_limits_for_scans computes it."""
    cfg = polyc._config({"cell_m": cell_m})
    held = [polyc._scan(s) for s in scans]
    arr = (polyc._Scan * len(held))(*[s for s, _ in held])
    lim = polyc._Limits()
    polyc._lib.polyc_limits_for_scans(ctypes.byref(cfg), arr, len(held), ctypes.byref(lim))
    return lim.max_grid_cells


if __name__ == "__main__":
    unittest.main(verbosity=2)
