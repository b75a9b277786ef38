"""test_polyc.py - the Python binding (run by `make test`).

A synthetic room mapped through Python must give the polylines the `polyc`
tool gives for the same scans written in its plain format (to the tool's 4
decimals); too small a block, bad configuration and bad scans raise
PolycError with the library's message; the ctypes structs match the library.
Environment: POLYC_LIB (libpolyc.so) and POLYC_TOOL (the polyc binary),
defaulting to the repository's build/.
"""
import ctypes
import json
import math
import os
import random
import struct
import subprocess
import tempfile
import unittest
from array import array

import polyc

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
TOOL = os.environ.get("POLYC_TOOL", os.path.join(REPO, "build", "polyc"))

# A 6 m x 4 m room with a cabinet and a pillar: wall segments (x0, y0, x1, y1).
WALLS = [(0, 0, 6, 0), (6, 0, 6, 4), (6, 4, 0, 4), (0, 4, 0, 0),
         (4.0, 2.8, 5.0, 2.8), (5.0, 2.8, 5.0, 3.4), (5.0, 3.4, 4.0, 3.4), (4.0, 3.4, 4.0, 2.8),
         (2.0, 1.0, 2.3, 1.0), (2.3, 1.0, 2.3, 1.3), (2.3, 1.3, 2.0, 1.3), (2.0, 1.3, 2.0, 1.0)]
POSES = [(1.0, 2.0, 0.0), (3.0, 2.2, 0.4), (4.8, 1.5, 2.5), (2.5, 3.0, -2.0)]


def f32(v):
    """v rounded to float32, as the library stores it."""
    return struct.unpack("f", struct.pack("f", v))[0]


def cast(x, y, a, max_range):
    dx, dy = math.cos(a), math.sin(a)
    best = max_range
    for ax, ay, bx, by in WALLS:
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
            self.assertEqual([(float("%.4f" % x), float("%.4f" % y)) for x, y in mine.points],
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
