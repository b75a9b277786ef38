"""polyc.py - Python binding of libpolyc (ctypes, standard library only).

    import math, polyc
    scan = polyc.Scan(pose=(0.0, 0.0, 0.0), start_angle_rad=-math.pi / 2,
                      angle_step_rad=math.pi / 180, min_range_m=0.02,
                      max_range_m=30.0, ranges_m=ranges)
    result = polyc.build_map([scan], cell_m=0.05)     # config fields as keywords
    for line in result.polylines:
        print(line.closed, line.points)               # [(x, y), ...] in metres
    print(result.stats["memory_used_bytes"])

    # a ROS map (nav_msgs/OccupancyGrid data: int8, -1 unknown, 0..100)
    result = polyc.build_map_from_grid(msg.data, msg.info.width, msg.info.height,
                                       msg.info.resolution, origin=(x, y, yaw))

The library is loaded from $POLYC_LIB, else from build/libpolyc.so of the
repository this file lives in, else from the system (ctypes.util). At import
the ctypes structs are checked against polyc_struct_size(): a binding that
does not match the library raises PolycError instead of corrupting memory.

Memory: each Context owns its block (ctypes.create_string_buffer of
polyc_memory_size() bytes, or memory_bytes if given); results are copied out
into Python lists. Errors: every failing call raises PolycError with the
status, its polyc_status_str() and polyc_last_error().
"""
import ctypes
import ctypes.util
import os
from array import array
from typing import NamedTuple, Sequence, Tuple, List

__all__ = ["PolycError", "Scan", "Polyline", "Result", "Context", "build_map", "build_map_from_grid",
           "default_config", "version", "STATUS", "FLAG_EXACT_POINTS", "FLAG_NO_GRAZING",
           "FLAG_GRID_TRACE"]

# polyc_status, append-only like the C enum
STATUS = {0: "POLYC_OK", 1: "POLYC_ERR_NULL", 2: "POLYC_ERR_CONFIG", 3: "POLYC_ERR_NOMEM",
          4: "POLYC_ERR_SCAN", 5: "POLYC_ERR_STATE", 6: "POLYC_ERR_EXTENT", 7: "POLYC_ERR_LIMIT",
          8: "POLYC_ERR_RANGE", 9: "POLYC_ERR_STOPPED"}
OK, ERR_NULL, ERR_CONFIG, ERR_NOMEM, ERR_SCAN, ERR_STATE = 0, 1, 2, 3, 4, 5
ERR_EXTENT, ERR_LIMIT, ERR_RANGE, ERR_STOPPED = 6, 7, 8, 9
FLAG_EXACT_POINTS = 0x1
FLAG_NO_GRAZING = 0x2
FLAG_GRID_TRACE = 0x4

_f32, _f64, _u32, _u64 = ctypes.c_float, ctypes.c_double, ctypes.c_uint32, ctypes.c_uint64


class PolycError(Exception):
    """A libpolyc call failed: .status (int), .name ('POLYC_ERR_NOMEM'),
    .what (the operation), .detail (polyc_last_error, may be empty)."""

    def __init__(self, status, what, detail=""):
        self.status, self.what, self.detail = status, what, detail
        self.name = STATUS.get(status, "status %d" % status)
        text = _lib.polyc_status_str(status).decode() if _lib else self.name
        super().__init__("%s: %s%s (%s)" % (what, text, ": " + detail if detail else "", self.name))


# ---- the public structs of polyc.h, field for field ----

class _Config(ctypes.Structure):
    _fields_ = [(n, _f32) for n in (
        "cell_m", "contour_threshold", "data_min_m", "free_range_m", "grazing_cells",
        "max_extent_m", "alpha", "gamma", "merge_dist_m", "split_gap_m", "step_m", "noise_m",
        "noise_decay", "overlap_m", "search_radius_m")] + [
        ("patience", _u32), ("max_iterations", _u32), ("flags", _u32), ("reserved", _u32),
        ("seed", _u64), ("occupied_thresh", _f32), ("free_thresh", _f32)]


class _Limits(ctypes.Structure):
    _fields_ = [("max_scans", _u32), ("max_beams", _u32), ("max_grid_cells", _u32),
                ("max_vertices", _u32), ("max_points", _u32)]


class _Scan(ctypes.Structure):
    _fields_ = [("pose_x_m", _f64), ("pose_y_m", _f64), ("pose_theta_rad", _f64),
                ("start_angle_rad", _f32), ("angle_step_rad", _f32), ("min_range_m", _f32),
                ("max_range_m", _f32), ("beam_count", _u32), ("reserved", _u32),
                ("range_m", ctypes.POINTER(_f32))]


class _Box(ctypes.Structure):
    _fields_ = [("min_x_m", _f64), ("min_y_m", _f64), ("max_x_m", _f64), ("max_y_m", _f64)]


class _Polyline(ctypes.Structure):
    _fields_ = [("xy_m", ctypes.POINTER(_f32)), ("point_count", _u32), ("closed", _u32)]


class _Stats(ctypes.Structure):
    _fields_ = [(n, _u64) for n in (
        "beams", "beams_skipped", "hits", "data_points", "memory_used_bytes",
        "memory_size_bytes", "grid_bytes")] + [("bic", _f64), ("error_sq_m2", _f64)] + [
        (n, _u32) for n in (
            "scans", "grid_width", "grid_height", "grid_tiles", "contour_cells",
            "initial_polylines", "initial_vertices", "polylines", "vertices",
            "weighted_points", "iterations", "reserved")]


class _Iteration(ctypes.Structure):
    _fields_ = [("iteration", _u32), ("vertices", _u32), ("polylines", _u32),
                ("reserved", _u32), ("bic", _f64), ("best_bic", _f64), ("noise_m", _f64)]


class _OccupancyGrid(ctypes.Structure):
    _fields_ = [("width", _u32), ("height", _u32), ("resolution_m", _f32), ("reserved", _u32),
                ("origin_x_m", _f64), ("origin_y_m", _f64), ("origin_yaw_rad", _f64),
                ("cells", ctypes.POINTER(ctypes.c_int8))]


_STRUCTS = {"polyc_config": _Config, "polyc_limits": _Limits, "polyc_scan": _Scan,
            "polyc_box": _Box, "polyc_polyline": _Polyline, "polyc_stats": _Stats,
            "polyc_iteration": _Iteration, "polyc_occupancy_grid": _OccupancyGrid}
_PROGRESS = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.POINTER(_Iteration))


# ---- loading ----

def _library_path():
    env = os.environ.get("POLYC_LIB")
    if env:
        return env
    repo = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    local = os.path.join(repo, "build", "libpolyc.so")
    if os.path.exists(local):
        return local
    found = ctypes.util.find_library("polyc")
    if not found:
        raise OSError("libpolyc.so not found: set POLYC_LIB or run make in " + repo)
    return found


def _load():
    lib = ctypes.CDLL(_library_path())
    P, st, ctx, sz = ctypes.POINTER, ctypes.c_int, ctypes.c_void_p, ctypes.c_size_t
    signatures = {
        "polyc_version": (_u32, []),
        "polyc_status_str": (ctypes.c_char_p, [st]),
        "polyc_struct_size": (sz, [ctypes.c_char_p]),
        "polyc_config_default": (None, [P(_Config)]),
        "polyc_config_check": (st, [P(_Config), P(ctypes.c_char_p)]),
        "polyc_limits_for_scans": (st, [P(_Config), P(_Scan), _u32, P(_Limits)]),
        "polyc_limits_for_grid": (st, [P(_Config), P(_OccupancyGrid), P(_Limits)]),
        "polyc_memory_size": (sz, [P(_Config), P(_Limits)]),
        "polyc_init": (st, [ctypes.c_void_p, sz, P(_Config), P(_Limits), P(ctx)]),
        "polyc_reset": (st, [ctx]),
        "polyc_add_scan": (st, [ctx, P(_Scan)]),
        "polyc_add_grid": (st, [ctx, P(_OccupancyGrid)]),
        "polyc_build_grid": (st, [ctx]),
        "polyc_extract_contour": (st, [ctx]),
        "polyc_trace": (st, [ctx]),
        "polyc_optimize": (st, [ctx, _PROGRESS, ctypes.c_void_p]),
        "polyc_build": (st, [ctx, _PROGRESS, ctypes.c_void_p]),
        "polyc_polyline_count": (_u32, [ctx]),
        "polyc_get_polyline": (st, [ctx, _u32, P(_Polyline)]),
        "polyc_get_stats": (st, [ctx, P(_Stats)]),
        "polyc_score": (st, [ctx, P(_f64), P(_f64)]),
        "polyc_last_error": (ctypes.c_char_p, [ctx]),
    }
    for name, (res, args) in signatures.items():
        fn = getattr(lib, name)
        fn.restype, fn.argtypes = res, args
    return lib


_lib = None                                # PolycError works before the load
_lib = _load()
for _name, _cls in _STRUCTS.items():
    _size = _lib.polyc_struct_size(_name.encode())
    if _size != ctypes.sizeof(_cls):
        raise PolycError(ERR_CONFIG, "loading " + _library_path(),
                         "struct %s is %d bytes in the library but %d in polyc.py: the binding "
                         "does not match this libpolyc" % (_name, _size, ctypes.sizeof(_cls)))


# ---- Python side ----

class Scan(NamedTuple):
    """One scan: beam i points at theta + start_angle_rad + i * angle_step_rad; a
    range outside [min_range_m, max_range_m) is a beam with no return."""
    pose: Tuple[float, float, float]       # x_m, y_m, theta_rad
    start_angle_rad: float
    angle_step_rad: float
    min_range_m: float
    max_range_m: float
    ranges_m: Sequence[float]


class Polyline(NamedTuple):
    points: List[Tuple[float, float]]      # metres; a closed one does not repeat its start
    closed: bool


class Result(NamedTuple):
    polylines: List[Polyline]
    stats: dict                            # the fields of polyc_stats


def version():
    """(major, minor, patch) of the loaded library."""
    v = _lib.polyc_version()
    return (v // 10000, v // 100 % 100, v % 100)


def default_config():
    """The library's defaults (the paper's parameters) as a dict."""
    c = _Config()
    _lib.polyc_config_default(ctypes.byref(c))
    return {n: getattr(c, n) for n, _ in _Config._fields_ if n != "reserved"}


def _config(overrides):
    c = _Config()
    _lib.polyc_config_default(ctypes.byref(c))
    for name, value in overrides.items():
        if name == "reserved" or name not in dict(_Config._fields_):
            raise TypeError("unknown polyc_config field %r" % name)
        setattr(c, name, value)
    why = ctypes.c_char_p()
    status = _lib.polyc_config_check(ctypes.byref(c), ctypes.byref(why))
    if status != OK:
        raise PolycError(status, "config", (why.value or b"").decode())
    return c


def _scan(scan):
    """A _Scan and the float array it points to (keep both alive)."""
    pose, start, step, lo, hi, ranges = scan
    x, y, theta = pose
    if isinstance(ranges, array) and ranges.typecode == "f":
        buf = (_f32 * len(ranges)).from_buffer_copy(ranges)
    else:
        buf = (_f32 * len(ranges))(*ranges)
    s = _Scan(x, y, theta, start, step, lo, hi, len(ranges), 0,
              ctypes.cast(buf, ctypes.POINTER(_f32)))
    return s, buf


def _grid(cells, width, height, resolution, origin):
    """An _OccupancyGrid and the int8 array it points to (keep both alive).
    cells: any buffer of bytes (bytes, bytearray, array('b'), a numpy int8
    array; byte 255 is -1) or a sequence of ints, width * height of them,
    row-major from the origin's row."""
    width, height = int(width), int(height)
    if width < 0 or height < 0:
        raise ValueError("width and height must not be negative")
    try:
        view = memoryview(cells)
    except TypeError:
        view = None
    if view is not None:
        if view.itemsize != 1 or view.format not in ("b", "B", "c"):
            raise TypeError("cells must be a buffer of int8 (format 'b'), not format %r"
                            % view.format)
        data = view.tobytes()              # any layout, in C order
    else:
        try:
            data = array("b", cells).tobytes()
        except OverflowError:
            raise PolycError(ERR_CONFIG, "grid", "grid cell value outside -1..100") from None
    if len(data) != width * height:
        raise ValueError("%d cells given for a grid of %d x %d" % (len(data), width, height))
    buf = (ctypes.c_int8 * max(len(data), 1)).from_buffer_copy(data or b"\0")
    x, y, yaw = origin
    g = _OccupancyGrid(width, height, resolution, 0, x, y, yaw,
                       ctypes.cast(buf, ctypes.POINTER(ctypes.c_int8)))
    return g, buf


def _progress(fn):
    """A C callback calling fn(dict of polyc_iteration); a true result stops."""
    if fn is None:
        return ctypes.cast(None, _PROGRESS)

    def call(_user, it):
        i = it.contents
        return 1 if fn({n: getattr(i, n) for n, _ in _Iteration._fields_ if n != "reserved"}) else 0
    return _PROGRESS(call)


class Context:
    """A libpolyc context in a block this object owns.

    limits: dict or (max_scans, max_beams, max_grid_cells, max_vertices[, max_points]);
    memory_bytes: block size (default: polyc_memory_size); other keywords
    override polyc_config fields (cell_m=0.05, max_iterations=0, seed=3, ...)."""

    def __init__(self, limits, memory_bytes=None, **config):
        self._cfg = _config(config)
        if isinstance(limits, dict):
            self._lim = _Limits(**limits)
        else:
            self._lim = _Limits(*limits)
        need = _lib.polyc_memory_size(ctypes.byref(self._cfg), ctypes.byref(self._lim))
        if need == 0:
            raise PolycError(ERR_CONFIG, "memory size", "the limits are too large for size_t")
        size = need if memory_bytes is None else int(memory_bytes)
        if size < need:
            raise PolycError(ERR_NOMEM, "init", "%d bytes given, polyc_memory_size says %d "
                             "are needed" % (size, need))
        self.memory_size = need
        self._block = ctypes.create_string_buffer(size)
        self._ctx = ctypes.c_void_p()
        self._check(_lib.polyc_init(self._block, size, ctypes.byref(self._cfg),
                                    ctypes.byref(self._lim), ctypes.byref(self._ctx)), "init")

    def _check(self, status, what):
        if status != OK:
            detail = _lib.polyc_last_error(self._ctx).decode() if self._ctx else ""
            raise PolycError(status, what, detail)

    def add_scan(self, pose, start_angle_rad, angle_step_rad, min_range_m, max_range_m,
                 ranges_m):
        """Copies one scan in (see Scan for the fields)."""
        s, _buf = _scan((pose, start_angle_rad, angle_step_rad, min_range_m, max_range_m,
                         ranges_m))
        self._check(_lib.polyc_add_scan(self._ctx, ctypes.byref(s)), "add scan")

    def add_grid(self, cells, width, height, resolution, origin=(0.0, 0.0, 0.0)):
        """Takes an occupancy grid (see build_map_from_grid for the arguments);
        a context holds one grid or scans, not both."""
        g, _buf = _grid(cells, width, height, resolution, origin)
        self._check(_lib.polyc_add_grid(self._ctx, ctypes.byref(g)), "add grid")

    def build(self, progress=None):
        """Grid, contour, trace and (if max_iterations > 0) the optimiser.
        progress(iteration_dict) returning True stops (PolycError POLYC_ERR_STOPPED;
        the best map so far is kept)."""
        cb = _progress(progress)
        self._check(_lib.polyc_build(self._ctx, cb, None), "build")

    def build_grid(self):
        self._check(_lib.polyc_build_grid(self._ctx), "build grid")

    def extract_contour(self):
        self._check(_lib.polyc_extract_contour(self._ctx), "extract contour")

    def trace(self):
        self._check(_lib.polyc_trace(self._ctx), "trace")

    def optimize(self, progress=None):
        cb = _progress(progress)
        self._check(_lib.polyc_optimize(self._ctx, cb, None), "optimize")

    def score(self):
        """(bic, error_sq_m2) of the current polylines."""
        bic, err = _f64(), _f64()
        self._check(_lib.polyc_score(self._ctx, ctypes.byref(bic), ctypes.byref(err)), "score")
        return bic.value, err.value

    def polylines(self):
        """The current map, copied into Python lists."""
        out = []
        for i in range(_lib.polyc_polyline_count(self._ctx)):
            pl = _Polyline()
            self._check(_lib.polyc_get_polyline(self._ctx, i, ctypes.byref(pl)), "get polyline")
            xy = pl.xy_m[:2 * pl.point_count]
            out.append(Polyline(list(zip(xy[0::2], xy[1::2])), bool(pl.closed)))
        return out

    def stats(self):
        s = _Stats()
        self._check(_lib.polyc_get_stats(self._ctx, ctypes.byref(s)), "stats")
        return {n: getattr(s, n) for n, _ in _Stats._fields_ if n != "reserved"}


def build_map(scans, memory_bytes=None, max_vertices=0, progress=None, **config):
    """Maps a sequence of scans (Scan or plain 6-sequences) as the polyc tool
    does: limits from the scans, one block, build. Returns a Result."""
    cfg = _config(config)
    held = [_scan(s) for s in scans]
    arr = (_Scan * max(len(held), 1))(*[s for s, _ in held])
    lim = _Limits()
    status = _lib.polyc_limits_for_scans(ctypes.byref(cfg), arr, len(held), ctypes.byref(lim))
    if status != OK:
        raise PolycError(status, "limits for scans",
                         "the data span more than max_extent_m" if status == ERR_EXTENT else "")
    if max_vertices:
        lim.max_vertices = max_vertices
    ctx = Context((lim.max_scans, lim.max_beams, lim.max_grid_cells, lim.max_vertices,
                   lim.max_points), memory_bytes, **config)
    for i, (s, _) in enumerate(held):
        ctx._check(_lib.polyc_add_scan(ctx._ctx, ctypes.byref(s)), "add scan %d" % i)
    ctx.build(progress)
    return Result(ctx.polylines(), ctx.stats())


def build_map_from_grid(cells, width, height, resolution, origin=(0.0, 0.0, 0.0),
                        memory_bytes=None, progress=None, **config):
    """Maps an occupancy grid as ROS keeps it (nav_msgs/OccupancyGrid): cells
    (column i, row j) at cells[j * width + i], -1 unknown, 0..100 occupancy
    (occupied from occupied_thresh * 100, free up to free_thresh * 100);
    origin = (x, y, yaw) of cell (0, 0)'s outer corner, resolution in metres.
    cells: bytes, bytearray, array('b'), a numpy int8 array (any buffer of
    int8) or a list of ints. Returns a Result, polylines in the map frame."""
    cfg = _config(config)
    g, _buf = _grid(cells, width, height, resolution, origin)
    lim = _Limits()
    status = _lib.polyc_limits_for_grid(ctypes.byref(cfg), ctypes.byref(g), ctypes.byref(lim))
    if status != OK:
        detail = {ERR_EXTENT: "the grid spans more than max_extent_m",
                  ERR_CONFIG: "a bad grid: resolution must be > 0, width and height >= 1, "
                              "cell values -1..100, origin finite",
                  ERR_NULL: "no cells"}.get(status, "")
        raise PolycError(status, "limits for grid", detail)
    ctx = Context((lim.max_scans, lim.max_beams, lim.max_grid_cells, lim.max_vertices,
                   lim.max_points), memory_bytes, **config)
    ctx._check(_lib.polyc_add_grid(ctx._ctx, ctypes.byref(g)), "add grid")
    ctx.build(progress)
    return Result(ctx.polylines(), ctx.stats())


if __name__ == "__main__":
    print("libpolyc %d.%d.%d from %s" % (version() + (_library_path(),)))
    print("defaults:", default_config())
