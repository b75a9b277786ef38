"""test_online.py - the Python binding's OnlineMap (run by `make test-python`).

A robot drives through a rectangular room (scans generated here, ray cast
against the walls with seeded noise); each scan is added and followed by an
update: the map fills up, its version grows, a copy of the map kept from
changes_since alone equals the map after every update, changes_since(0)
lists every current polyline as added and changes_since(version) nothing,
and finish() gives segments within a few cm of the walls. The errors (work
0, an update or finish before any scan, correcting a scan not kept, a scan
outside the area) raise PolycError with the library's status and message;
POLYC_ERR_RANGE from polyc_online_changes is a ResyncError (a substitute
function returns it: these scenes never outrun the library's memory of
removals). A kept scan given a wrong pose and corrected gives the walls
back; ranges in lists, array('f') and numpy arrays give the same map.
Environment as for test_polyc.py (POLYC_LIB).
"""
import contextlib
import ctypes
import io
import math
import os
import random
import re
import signal
import struct
import subprocess
import sys
import tempfile
import unittest
from array import array

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
os.environ.setdefault("POLYC_LIB", os.path.join(REPO, "build", "py", "libpolyc.so"))
import polyc  # noqa: E402
from test_polyc import cast as room_cast, f32, write_plain  # noqa: E402

try:
    import numpy
except ImportError:
    numpy = None

# The room: 8 m x 5 m, walls (x0, y0, x1, y1)
ROOM_W, ROOM_H = 8.0, 5.0
WALLS = [(0, 0, ROOM_W, 0), (ROOM_W, 0, ROOM_W, ROOM_H), (ROOM_W, ROOM_H, 0, ROOM_H),
         (0, ROOM_H, 0, 0)]
BEAMS = 361                                # all round, one degree apart
CELL_M = 0.05


def cast(x, y, a, max_range):
    """Range from (x, y) along angle a to the nearest wall of this room."""
    return room_cast(x, y, a, max_range, WALLS)


def poses(n=24):
    """A loop through the room: out along y = 1.8, back along y = 3.2."""
    out = []
    for i in range(n):
        s = i / max(n - 1, 1)
        if s < 0.5:
            x, y, th = 1.5 + 10.0 * s, 1.8, 0.1 * i
        else:
            x, y, th = 6.5 - 10.0 * (s - 0.5), 3.2, 0.1 * i
        out.append((x, y, math.remainder(th, 2 * math.pi)))
    return out


def room_scans(n=24, seed=7, noise_m=0.005):
    """polyc.Scan records of the room from poses(n): float32 ranges, seeded noise."""
    rng = random.Random(seed)
    start, step = f32(-math.pi), f32(2 * math.pi / (BEAMS - 1))
    scans = []
    for x, y, th in poses(n):
        ranges = [f32(cast(x, y, th + start + i * step, 30.0) + rng.gauss(0, noise_m))
                  for i in range(BEAMS)]
        scans.append(polyc.Scan((x, y, th), start, step, f32(0.02), f32(30.0), ranges))
    return scans


def wall_dist(x, y):
    best = math.inf
    for ax, ay, bx, by in WALLS:
        dx, dy = bx - ax, by - ay
        t = max(0.0, min(1.0, ((x - ax) * dx + (y - ay) * dy) / (dx * dx + dy * dy)))
        best = min(best, math.hypot(ax + t * dx - x, ay + t * dy - y))
    return best


def segments(polylines):
    for line in polylines:
        pts = line.points.tolist()
        pairs = list(zip(pts, pts[1:]))
        if line.closed and len(pts) > 2:
            pairs.append((pts[-1], pts[0]))
        yield from pairs


def new_map(area_m=16.0, **kw):
    kw.setdefault("config", {"cell_m": CELL_M})
    return polyc.OnlineMap(area_m, BEAMS, **kw)


def replay_with(scans):
    """A function of a ranges type: the scans replayed with their ranges of
    that type, an update after each; the map, its ids and its version."""
    def run(kind):
        m = new_map()
        for s in scans:
            m.add_scan(*s._replace(ranges_m=kind(s.ranges_m)))
            m.update()
        return m.polylines, m.polyline_ids, m.version
    return run


class Online(unittest.TestCase):
    def assert_on_walls(self, polylines, tol_m=0.05):
        """Every segment within tol_m of a wall (ends and eight points between),
        and every wall's middle within tol_m of a segment."""
        segs = list(segments(polylines))
        self.assertGreater(len(segs), 0)
        for (ax, ay), (bx, by) in segs:
            for k in range(10):
                t = k / 9
                d = wall_dist(ax + t * (bx - ax), ay + t * (by - ay))
                self.assertLess(d, tol_m, "segment (%.3f %.3f)-(%.3f %.3f) is %.3f m off the "
                                "walls" % (ax, ay, bx, by, d))
        for wx0, wy0, wx1, wy1 in WALLS:
            mx, my = (wx0 + wx1) / 2, (wy0 + wy1) / 2
            near = min(point_seg_dist(mx, my, a, b) for a, b in segs)
            self.assertLess(near, tol_m, "no segment near the wall's middle (%g, %g)" % (mx, my))

    def test_room_scan_by_scan(self):
        m = new_map()
        self.assertEqual(m.version, 0)
        self.assertEqual(m.polylines, [])
        self.assertEqual(m.changes_since(0), [])
        versions, sizes = [], []
        client, seen = {}, 0                # a copy of the map kept by the changes alone
        for i, s in enumerate(room_scans()):
            self.assertEqual(m.add_scan(*s), i)
            r = m.update()
            self.assertIsInstance(r, polyc.OnlineReport)
            self.assertEqual(r.scans, i + 1)
            self.assertEqual(r.version, m.version)
            self.assertEqual(r.polylines, len(m.polylines))
            versions.append(r.version)
            sizes.append(r.polylines)
            now = dict(zip(m.polyline_ids, m.polylines))
            changes = m.changes_since(seen)
            self.assertEqual(len(changes) > 0, r.version > seen)
            self.assertTrue(all(seen < c.version <= r.version for c in changes))
            for c in changes:
                if c.kind == "removed":
                    self.assertNotIn(c.id, now)
                    client.pop(c.id, None)
                else:
                    self.assertEqual(c.kind == "added", c.id not in client)
                    client[c.id] = now[c.id]
            self.assertEqual(client, now)
            seen = r.version
        self.assertEqual(versions, sorted(versions))         # never goes back
        self.assertGreater(versions[-1], versions[0])        # and grows
        self.assertGreater(min(sizes[4:]), 0)                # a map after a few scans
        ids = m.polyline_ids
        self.assertEqual(len(ids), len(m.polylines))
        self.assertEqual(len(set(ids)), len(ids))
        self.assertTrue(all(i >= 1 for i in ids))
        changes = m.changes_since(0)
        self.assertEqual([c.id for c in changes], sorted(c.id for c in changes))
        self.assertEqual({c.id for c in changes if c.kind == "added"}, set(ids))
        self.assertTrue(all(c.kind == "removed" for c in changes if c.id not in ids))
        self.assertTrue(all(1 <= c.version <= m.version for c in changes))
        self.assertTrue(all(isinstance(c, tuple) and len(c) == 3 for c in changes))
        self.assertEqual(m.changes_since(m.version), [])
        stats = m.stats
        self.assertEqual(stats["scans"], len(room_scans()))
        self.assertEqual(stats["polylines"], len(ids))
        before = m.version
        r = m.finish()
        self.assertIsInstance(r, polyc.OnlineReport)
        self.assertGreaterEqual(m.version, before)
        self.assertEqual(r.backlog_tiles, 0)
        self.assertEqual(r.polylines, len(m.polylines))
        self.assert_on_walls(m.polylines)
        # what finish changed is what changes_since says
        after = {c.id: c for c in m.changes_since(before)}
        self.assertTrue(set(m.polyline_ids) - set(ids) <= set(after))
        self.assertTrue(all(after[i].kind == "removed" for i in set(ids) - set(m.polyline_ids)))

    def test_the_same_scans_give_the_same_map(self):
        run = replay_with(room_scans(8))
        want = run(list)
        self.assertGreater(len(want[0]), 0)
        self.assertEqual(run(lambda r: array("f", r)), want)
        self.assertEqual(run(lambda r: array("d", r)), want)
        self.assertEqual(run(tuple), want)

    @unittest.skipIf(numpy is None, "numpy is not installed")
    def test_numpy_ranges(self):
        scans = room_scans(8)
        run = replay_with(scans)
        want = run(list)
        self.assertEqual(run(lambda r: numpy.array(r, dtype=numpy.float32)), want)
        self.assertEqual(run(lambda r: numpy.array(r, dtype=numpy.float64)), want)
        with self.assertRaises(TypeError):        # 2-D: refused, as for the batch API
            m = new_map()
            m.add_scan(*scans[0]._replace(ranges_m=numpy.zeros((2, 2), dtype=numpy.float32)))

    def test_errors(self):
        m = new_map()
        for call in (m.update, m.finish):                    # before any scan
            with self.assertRaises(polyc.PolycError) as e:
                call()
            self.assertEqual(e.exception.status, polyc.ERR_STATE)
            self.assertTrue(e.exception.detail)              # the library's message
        s = room_scans(2)
        first = m.add_scan(*s[0])
        with self.assertRaises(polyc.PolycError) as e:       # no work allowed
            m.update(work=0)
        self.assertEqual(e.exception.status, polyc.ERR_CONFIG)
        m.update()
        with self.assertRaises(polyc.PolycError) as e:       # not kept
            m.correct(first, (1.0, 1.0, 0.0))
        self.assertEqual(e.exception.status, polyc.ERR_RANGE)
        self.assertNotIsInstance(e.exception, polyc.ResyncError)
        with self.assertRaises(polyc.PolycError) as e:       # unknown
            m.correct(99, (1.0, 1.0, 0.0))
        self.assertEqual(e.exception.status, polyc.ERR_RANGE)
        with self.assertRaises(polyc.PolycError) as e:       # a pose outside the area
            m.add_scan((20.0, 2.5, 0.0), *s[1][1:])
        self.assertEqual(e.exception.status, polyc.ERR_EXTENT)
        with self.assertRaises(polyc.PolycError) as e:       # too many beams
            m.add_scan(s[1].pose, s[1].start_angle_rad, f32(0.001), 0.02, 30.0,
                       [1.0] * (BEAMS + 1))
        self.assertEqual(e.exception.status, polyc.ERR_LIMIT)
        with self.assertRaises(polyc.PolycError) as e:       # bad geometry
            m.add_scan((math.nan, 0.0, 0.0), *s[1][1:])
        self.assertEqual(e.exception.status, polyc.ERR_SCAN)
        self.assertEqual(m.stats["scans"], 1)                # none of them was added
        # bad arguments never reach the library
        for bad in (-1, 2 ** 64, 1.5, True):
            with self.assertRaises((TypeError, ValueError)):
                m.update(work=bad)
        with self.assertRaises(ValueError):
            m.changes_since(-1)
        with self.assertRaises(TypeError):
            m.correct("0", (0.0, 0.0, 0.0))
        with self.assertRaises(TypeError):
            m.finish(progress=5)

    def test_construction(self):
        m = new_map(keep_scans=3, keep_beams=3 * BEAMS, max_vertices=5000)
        self.assertEqual(m.limits["keep_scans"], 3)
        self.assertEqual(m.limits["keep_beams"], 3 * BEAMS)
        self.assertEqual(m.limits["max_vertices"], 5000)
        self.assertEqual(m.limits["max_scan_beams"], BEAMS)
        self.assertEqual(m.limits["area_m"], 16.0)
        self.assertGreater(m.memory_size, 0)
        self.assertEqual(len(m._block), m.memory_size)
        with self.assertRaises(TypeError):
            new_map(max_vertex=10)                           # not a limit
        with self.assertRaises(TypeError):
            new_map(config={"cell": 0.05})                   # not a config field
        with self.assertRaises(ValueError):
            new_map(keep_scans=-1)
        with self.assertRaises(polyc.PolycError) as e:
            new_map(config={"cell_m": -1.0})
        self.assertEqual(e.exception.status, polyc.ERR_CONFIG)
        with self.assertRaises(polyc.PolycError) as e:
            polyc.OnlineMap(-5.0, BEAMS)
        self.assertEqual(e.exception.status, polyc.ERR_CONFIG)
        self.assertIn("area_m must be", str(e.exception))
        with self.assertRaises(polyc.PolycError) as e:       # wider than max_extent_m allows
            polyc.OnlineMap(200.0, BEAMS, config={"max_extent_m": 50.0})
        self.assertEqual(e.exception.status, polyc.ERR_EXTENT)
        self.assertIn("max_extent_m", str(e.exception))

    def test_a_kept_scan_corrected(self):
        scans = room_scans(12)
        true_pose = scans[5].pose
        wrong = (true_pose[0] + 0.4, true_pose[1] - 0.3, true_pose[2] + 0.2)
        m = new_map(20.0, keep_scans=1, keep_beams=BEAMS)   # room for the wrong pose's walls
        for i, s in enumerate(scans):
            if i == 5:
                kept = m.add_scan(*s._replace(pose=wrong), keep=True)
            else:
                self.assertNotEqual(m.add_scan(*s), None)
            m.update()
        with self.assertRaises(polyc.PolycError) as e:       # keep_scans used up
            m.add_scan(*scans[0], keep=True)
        self.assertEqual(e.exception.status, polyc.ERR_LIMIT)
        self.assertEqual(m.stats["scans"], len(scans))       # that scan was not added
        # the wrong pose put a wall far from the room's
        self.assertGreater(max(wall_dist(x, y) for line in m.polylines for x, y in line.points),
                           0.2)
        before = m.version
        m.correct(kept, true_pose)
        r = m.update()
        self.assertGreater(r.version, before)                # the correction changed the map
        m.finish()
        self.assert_on_walls(m.polylines)
        m.correct(kept, true_pose)                           # again, the same pose: fine
        with self.assertRaises(polyc.PolycError) as e:       # a pose outside the area
            m.correct(kept, (true_pose[0] + 9.0, true_pose[1], true_pose[2]))
        self.assertEqual(e.exception.status, polyc.ERR_EXTENT)
        with self.assertRaises(polyc.PolycError) as e:
            m.correct(kept, (math.inf, 0.0, 0.0))
        self.assertEqual(e.exception.status, polyc.ERR_SCAN)

    def test_scans_after_finish(self):
        scans = room_scans(12)
        m = new_map()
        for s in scans[:6]:
            m.add_scan(*s)
            m.update()
        m.finish()
        for s in scans[6:]:
            m.add_scan(*s)
            m.update()
        self.assertEqual(m.finish().scans, len(scans))
        self.assert_on_walls(m.polylines)

    def test_finish_progress(self):
        class Mine(Exception):
            pass

        m = new_map()
        for s in room_scans(6):
            m.add_scan(*s)
        calls = []

        def bad(it):
            calls.append(it["iteration"])
            raise Mine("from the callback")

        with self.assertRaises(Mine):
            m.finish(progress=bad)
        self.assertEqual(len(calls), 1)

        def ctrl_c(it):
            signal.raise_signal(signal.SIGINT)

        with self.assertRaises(KeyboardInterrupt):            # Ctrl-C as for the batch build
            m.finish(progress=ctrl_c)
        self.assertIs(signal.getsignal(signal.SIGINT), signal.default_int_handler)
        seen = {}

        def reenter(it):
            try:
                m.update()
            except polyc.PolycError as e:
                seen["status"] = e.status
            return True                                      # and stop

        with self.assertRaises(polyc.PolycError) as e:
            m.finish(progress=reenter)
        self.assertEqual(e.exception.status, polyc.ERR_STOPPED)
        self.assertEqual(seen["status"], polyc.ERR_BUSY)
        r = m.finish(progress=lambda it: False)
        self.assertEqual(r.polylines, len(m.polylines))
        self.assertGreater(r.polylines, 0)

    def test_resync(self):
        # the library's POLYC_ERR_RANGE from polyc_online_changes is a ResyncError
        m = new_map()
        m.add_scan(*room_scans(1)[0])
        m.update()
        real = polyc._lib.polyc_online_changes

        def forgotten(ctx, since, out, cap, count):
            return polyc.ERR_RANGE

        polyc._lib.polyc_online_changes = forgotten
        try:
            with self.assertRaises(polyc.ResyncError) as e:
                m.changes_since(0)
        finally:
            polyc._lib.polyc_online_changes = real
        self.assertIsInstance(e.exception, polyc.PolycError)
        self.assertEqual(e.exception.status, polyc.ERR_RANGE)
        self.assertEqual(len(m.changes_since(0)), len(m.polyline_ids))

    def test_the_readme_example(self):
        # the README's online example as written, run on a log written here:
        # a 60 m corridor driven in 150 scans, wider than a 40 m square and
        # more scans than 100 kept, which a fixed area or keep_scans refuse
        with open(os.path.join(HERE, "README.md")) as f:
            text = f.read()
        examples = re.findall(r"```python\n(.*?)```", text, re.S)
        example = [e for e in examples if "OnlineMap" in e]
        self.assertEqual(len(example), 1)
        walls = [(0, 0, 60, 0), (60, 0, 60, 3), (60, 3, 0, 3), (0, 3, 0, 0)]
        rng = random.Random(3)
        start, step = f32(-math.pi / 2), f32(math.pi / 180)
        scans = []
        for k in range(150):
            x, y, th = 1.0 + 58.0 * k / 149, 1.5, 0.0 if k < 75 else math.pi
            ranges = [f32(room_cast(x, y, th + start + i * step, 30.0, walls) +
                          rng.gauss(0, 0.005)) for i in range(181)]
            scans.append(polyc.Scan((x, y, th), start, step, f32(0.02), f32(30.0), ranges))
        with tempfile.TemporaryDirectory() as tmp:
            log = os.path.join(tmp, "corridor.log")
            write_plain(log, scans)
            area_m, beams = polyc.online_area(polyc.read_log(log), {"cell_m": 0.05})
            self.assertGreater(area_m, 100.0)          # the corridor from its first pose
            self.assertEqual(beams, 181)
            env = dict(os.environ, PYTHONPATH=HERE)    # this package, POLYC_LIB's library
            got = subprocess.run([sys.executable, "-c", example[0], log], capture_output=True,
                                 text=True, timeout=600, env=env)
        self.assertEqual(got.returncode, 0, got.stderr)
        m = re.fullmatch(r"(\d+) polylines, (\d+) vertices, (\d+) changes sent\n", got.stdout)
        self.assertIsNotNone(m, got.stdout)
        self.assertGreater(int(m.group(1)), 0)
        self.assertGreater(int(m.group(3)), 0)

    def test_online_area(self):
        # the tool's sizing: the square round the first pose that holds every
        # pose and endpoint, 1 m of edge and 32 cells of air
        scans = room_scans(6)
        area_m, beams = polyc.online_area(scans, {"cell_m": CELL_M})
        self.assertEqual(beams, BEAMS)
        x0, y0, _ = scans[0].pose
        reach = max(max(abs(x0 - 0.0), abs(ROOM_W - x0)), max(abs(y0 - 0.0), abs(ROOM_H - y0)))
        self.assertAlmostEqual(area_m, 2 * (reach + 1.0 + 32 * f32(CELL_M)), delta=0.05)
        m = polyc.OnlineMap(area_m, beams, config={"cell_m": CELL_M})
        for s in scans:
            m.add_scan(*s)
        m.update()
        with self.assertRaises(ValueError):
            polyc.online_area([])
        nobeam = polyc.Scan((0.0, 0.0, 0.0), 0.0, 0.1, 0.02, 30.0, [])
        self.assertEqual(polyc.online_area([nobeam]).max_scan_beams, 1)

    def test_far_area_is_extent(self):
        # a side over twice max_extent_m is POLYC_ERR_EXTENT, even beyond 1e5 m
        for area in (5000.0, 2e5, 2e6, float("inf")):
            with self.assertRaises(polyc.PolycError) as e:
                polyc.OnlineMap(area, BEAMS)
            self.assertEqual(e.exception.status, polyc.ERR_EXTENT, area)
        with self.assertRaises(polyc.PolycError) as e:
            polyc.OnlineMap(float("nan"), BEAMS)
        self.assertEqual(e.exception.status, polyc.ERR_CONFIG)

    def test_struct_sizes(self):
        # in the import's check (test_polyc tests every struct of _STRUCTS)
        for name in ("polyc_online_limits", "polyc_online_report", "polyc_change"):
            cls = polyc._STRUCTS[name]
            self.assertEqual(polyc._lib.polyc_struct_size(name.encode()), ctypes.sizeof(cls),
                             name)
        with open(os.path.join(REPO, "include", "polyc.h")) as f:
            header = f.read()
        self.assertIn("#define POLYC_ONLINE_WORK_DEFAULT %du" % polyc.ONLINE_WORK_DEFAULT, header)
        for value, kind in polyc.CHANGE_KINDS.items():
            self.assertIn("#define POLYC_CHANGE_%s %du" % (kind.upper(), value), header)


def point_seg_dist(x, y, a, b):
    (ax, ay), (bx, by) = a, b
    dx, dy = bx - ax, by - ay
    den = dx * dx + dy * dy
    t = 0.0 if den == 0 else max(0.0, min(1.0, ((x - ax) * dx + (y - ay) * dy) / den))
    return math.hypot(ax + t * dx - x, ay + t * dy - y)


if __name__ == "__main__":
    unittest.main(verbosity=2)
