"""test_threads.py - one Context or OnlineMap shared by threads (run by `make test-python`).

Four threads share one OnlineMap, then one Context, and make 1,000 calls
each on it (scans in, updates or stages, results out): no crash (the
threads run in a child interpreter, so that a crash is a failed test, not
the end of the suite), no error but the library's own for a call out of
order, and the scan ids the threads got are 0..n-1, each once, n the
scans the map holds. A second thread's call waits while the first runs
(here: while the first is inside its progress callback) and then runs; a
call on the object from inside its own progress callback still raises
POLYC_ERR_BUSY at once, also while other threads wait. Environment as for
test_polyc.py (POLYC_LIB).
"""
import json
import os
import subprocess
import sys
import threading
import time
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
os.environ.setdefault("POLYC_LIB", os.path.join(REPO, "build", "py", "libpolyc.so"))
import polyc  # noqa: E402
from test_online import new_map, room_scans  # noqa: E402
from test_polyc import polyc_grid_cells, scene  # noqa: E402

THREADS, CALLS = 4, 1000


def hammer_online():
    """THREADS threads, CALLS calls each on one OnlineMap; what they saw."""
    scans = room_scans(24)
    m = new_map()
    m.add_scan(*scans[0])                     # so that an update is never before any scan
    ids, errors, start = [[0]], [], threading.Barrier(THREADS)

    def run(k):
        mine = []
        ids.append(mine)
        start.wait()
        for i in range(CALLS):
            op = (i + k) % 7
            try:
                if op == 0:
                    mine.append(m.add_scan(*scans[(i + k) % len(scans)]))
                elif op == 1:
                    m.update(work=2000)
                elif op == 2:
                    m.polylines
                elif op == 3:
                    m.stats
                elif op == 4:
                    m.changes_since(max(m.version - 1, 0))
                elif op == 5:
                    m.polyline_ids
                else:
                    m.version
            except Exception as e:            # none expected
                errors.append(repr(e))

    run_threads(run)
    m.finish()
    return {"ids": sorted(i for mine in ids for i in mine), "scans": m.stats["scans"],
            "polylines": len(m.polylines), "errors": errors}


def run_threads(run):
    """run(k) on THREADS threads at once, k = 0 .. THREADS - 1; returns
    when all have ended"""
    workers = [threading.Thread(target=run, args=(k,)) for k in range(THREADS)]
    for w in workers:
        w.start()
    for w in workers:
        w.join()


def hammer_context():
    """THREADS threads, CALLS calls each on one Context, the stages in any
    order: the only errors allowed are the library's for a stage out of
    order (POLYC_ERR_STATE) and for more scans than max_scans
    (POLYC_ERR_LIMIT)."""
    scans = scene()
    ctx = polyc.Context((8, 8 * 181, polyc_grid_cells(scans, 0.05), 0), cell_m=0.05,
                        max_iterations=2)
    errors, statuses, start = [], {}, threading.Barrier(THREADS)

    def run(k):
        start.wait()
        for i in range(CALLS):
            op = (i + k) % 8
            try:
                if op == 0:
                    ctx.add_scan(*scans[(i + k) % len(scans)])
                elif op == 1:
                    ctx.build_grid()
                elif op == 2:
                    ctx.extract_contour()
                elif op == 3:
                    ctx.trace()
                elif op == 4:
                    ctx.optimize()
                elif op == 5:
                    ctx.polylines()
                elif op == 6:
                    ctx.stats()
                else:
                    ctx.score()
            except polyc.PolycError as e:
                statuses[e.name] = statuses.get(e.name, 0) + 1
                if e.status not in (polyc.ERR_STATE, polyc.ERR_LIMIT):
                    errors.append(repr(e))
            except Exception as e:
                errors.append(repr(e))

    run_threads(run)
    ctx.build()
    return {"scans": ctx.stats()["scans"], "polylines": len(ctx.polylines()),
            "errors": errors, "statuses": statuses}


def in_child(name):
    """hammer_<name>() in a child interpreter: (its result, its exit status,
    its stderr)."""
    code = "import sys, json, test_threads; print(json.dumps(test_threads.hammer_%s()))" % name
    try:
        got = subprocess.run([sys.executable, "-X", "faulthandler", "-c", code], cwd=HERE,
                             capture_output=True, text=True, timeout=60)
    except subprocess.TimeoutExpired as e:   # a library stuck in a loop
        return None, "no end after 60 s", (e.stderr or b"")[-3000:]
    lines = got.stdout.strip().splitlines()
    return (json.loads(lines[-1]) if got.returncode == 0 and lines else None,
            got.returncode, got.stderr[-3000:])


class Threads(unittest.TestCase):
    def test_one_online_map_four_threads(self):
        result, status, stderr = in_child("online")
        self.assertEqual(status, 0, "the child ended with status %s:\n%s" % (status, stderr))
        self.assertEqual(result["errors"], [])
        n = result["scans"]
        self.assertGreater(n, THREADS * CALLS // 7)
        self.assertEqual(result["ids"], list(range(n)))     # each id once, none lost
        self.assertGreater(result["polylines"], 0)

    def test_one_context_four_threads(self):
        result, status, stderr = in_child("context")
        self.assertEqual(status, 0, "the child ended with status %s:\n%s" % (status, stderr))
        self.assertEqual(result["errors"], [])
        self.assertEqual(result["scans"], 8)                 # max_scans, then POLYC_ERR_LIMIT
        self.assertGreater(result["polylines"], 0)

    def test_a_second_thread_waits(self):
        # while finish runs (here: inside its progress callback) another
        # thread's call waits for it, then runs; the callback's own call on
        # the map is POLYC_ERR_BUSY at once, never a deadlock
        m = new_map()
        for s in room_scans(6):
            m.add_scan(*s)
        seen = {}
        waiter_done = threading.Event()

        def waiter():
            try:
                seen["waiter"] = m.version
            except Exception as e:
                seen["waiter"] = e
            waiter_done.set()

        def progress(it):
            if "started" in seen:
                return False
            seen["started"] = True
            other = threading.Thread(target=waiter)
            other.start()
            seen["waited"] = not waiter_done.wait(0.3)     # still waiting for finish
            try:
                m.update()
            except polyc.PolycError as e:
                seen["reentry"] = e.status
            seen["other"] = other
            return False

        t0 = time.monotonic()
        r = m.finish(progress=progress)
        self.assertLess(time.monotonic() - t0, 30.0)
        seen["other"].join(10.0)
        self.assertTrue(seen["waited"], "the second thread's call did not wait: %r"
                        % (seen.get("waiter"),))
        self.assertEqual(seen["reentry"], polyc.ERR_BUSY)
        self.assertEqual(seen["waiter"], r.version)          # it ran after finish
        self.assertGreater(r.polylines, 0)

    def test_a_context_waits_too(self):
        ctx = polyc.Context((4, 4 * 181, polyc_grid_cells(scene(), 0.05), 0), cell_m=0.05)
        for s in scene():
            ctx.add_scan(*s)
        seen = {}

        def progress(it):
            if "other" in seen:
                return False
            other = threading.Thread(target=lambda: seen.setdefault("count",
                                                                    len(ctx.polylines())))
            seen["other"] = other
            other.start()
            other.join(0.3)
            seen["waited"] = other.is_alive()
            try:
                ctx.stats()
            except polyc.PolycError as e:
                seen["reentry"] = e.status
            return False

        ctx.build(progress=progress)
        seen["other"].join(10.0)
        self.assertTrue(seen["waited"])
        self.assertEqual(seen["reentry"], polyc.ERR_BUSY)
        self.assertEqual(seen["count"], len(ctx.polylines()))


if __name__ == "__main__":
    unittest.main(verbosity=2)
