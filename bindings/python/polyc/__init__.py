"""polyc - Python binding of libpolyc (ctypes, standard library only).

    import math, polyc
    scan = polyc.Scan(pose=(0.0, 0.0, 0.0), start_angle_rad=-math.pi / 2,
                      angle_step_rad=math.pi / 180, min_range_m=0.02,
                      max_range_m=30.0, ranges_m=ranges)   # any sequence or buffer
    result = polyc.build_map([scan], cell_m=0.05)     # config fields as keywords
    for line in result.polylines:
        print(line.closed, line.points.tolist())      # [(x, y), ...] in metres
        xy = numpy.asarray(line.points)               # N x 2 float64, no copy
    print(result.stats["memory_used_bytes"])

    scans = polyc.read_log("office.log")              # as the polyc tool reads it
    grid = polyc.read_map("map.yaml")                 # map_server YAML + PGM or PNG
    result = polyc.build_map_from_grid(grid.cells, grid.width, grid.height,
                                       grid.resolution, origin=grid.origin)

    online = polyc.OnlineMap(40.0, 361, config={"cell_m": 0.05})  # area side, beams
    seen = 0
    for s in scans:                                   # as they arrive
        scan_id = online.add_scan(*s)                 # Context.add_scan's arguments
        report = online.update()                      # within the default work budget
        changes = online.changes_since(seen)          # [(id, 'added', version), ...]
        seen = report.version
    online.finish()                                   # converge; online.polylines, .polyline_ids

The shared library is the package's own libpolyc.so (built by `pip install`
from the repository's C sources, with the polyc tool's log and map readers),
or the file $POLYC_LIB names; nothing else is searched. At import the ctypes
structs are checked against polyc_struct_size(): a binding that does not
match the library raises PolycError instead of corrupting memory.

Memory: each Context owns its block (ctypes.create_string_buffer of
polyc_memory_size() bytes, or memory_bytes if given), each OnlineMap its
block of polyc_online_memory_size() bytes; results are copied out.
Errors: a failing library call raises PolycError with the status, its
polyc_status_str() and polyc_last_error() (OnlineMap.changes_since's
POLYC_ERR_RANGE: ResyncError, a PolycError); bad arguments raise TypeError or
ValueError before the library sees them (no scans at all for build_map:
ValueError "no scans found"); read_log and read_map raise ValueError with
the tool's message for a bad file and the OSError open() raises for a file
not opened; an exception raised in a progress callback (KeyboardInterrupt
too) stops the optimiser and is raised again by the call that ran it.
Threads: each Context and OnlineMap holds a lock around every call into its
block; a call from another thread waits for the running one, a call from
inside the object's own progress callback raises PolycError POLYC_ERR_BUSY.
"""
import contextlib
import ctypes
import math
import numbers
import os
import signal
import struct
import sys
import threading
from array import array
from typing import NamedTuple, Sequence, Tuple

__all__ = ["PolycError", "ResyncError", "Scan", "Points", "Polyline", "Result", "Context",
           "OnlineMap", "OnlineReport", "OnlineArea", "Change", "Map", "GridImage",
           "build_map", "build_map_from_grid", "grid_image", "read_log", "read_map", "online_area",
           "default_config",
           "version", "STATUS", "FLAG_EXACT_POINTS", "FLAG_NO_GRAZING", "FLAG_GRID_TRACE",
           "FLAG_NO_ARCS", "ONLINE_WORK_DEFAULT", "CHANGE_KINDS", "Circle", "ArcPolyline"]

# polyc_status, append-only like the C enum
STATUS = {0: "POLYC_OK", 1: "POLYC_ERR_NULL", 2: "POLYC_ERR_CONFIG", 3: "POLYC_ERR_NOMEM",
          4: "POLYC_ERR_SCAN", 5: "POLYC_ERR_STATE", 6: "POLYC_ERR_EXTENT", 7: "POLYC_ERR_LIMIT",
          8: "POLYC_ERR_RANGE", 9: "POLYC_ERR_STOPPED", 10: "POLYC_ERR_BUSY"}
OK, ERR_NULL, ERR_CONFIG, ERR_NOMEM, ERR_SCAN, ERR_STATE = 0, 1, 2, 3, 4, 5
ERR_EXTENT, ERR_LIMIT, ERR_RANGE, ERR_STOPPED, ERR_BUSY = 6, 7, 8, 9, 10
FLAG_EXACT_POINTS = 0x1
FLAG_NO_GRAZING = 0x2
FLAG_GRID_TRACE = 0x4
FLAG_NO_ARCS = 0x8
ONLINE_WORK_DEFAULT = 8000                 # POLYC_ONLINE_WORK_DEFAULT: work units of one update
CHANGE_KINDS = {1: "added", 2: "modified", 3: "removed"}   # POLYC_CHANGE_*

_f32, _f64, _u32, _u64 = ctypes.c_float, ctypes.c_double, ctypes.c_uint32, ctypes.c_uint64
_RANGE = {_u32: (0, 2 ** 32 - 1), _u64: (0, 2 ** 64 - 1)}


class PolycError(Exception):
    """A libpolyc call failed: .status (int), .name ('POLYC_ERR_NOMEM'),
    .what (the operation), .detail (polyc_last_error, may be empty).
    .result: for POLYC_ERR_STOPPED from build_map or build_map_from_grid
    (the progress callback stopped the optimiser), the best map so far as
    a Result, as the C API keeps it; None otherwise."""

    def __init__(self, status, what, detail=""):
        self.status, self.what, self.detail = status, what, detail
        self.result = None
        self.name = STATUS.get(status, "status %d" % status)
        text = _lib.polyc_status_str(status).decode() if _lib else self.name
        super().__init__("%s: %s%s (%s)" % (what, text, ": " + detail if detail else "", self.name))


class ResyncError(PolycError):
    """OnlineMap.changes_since(version) for a version older than the
    removals the library still remembers (POLYC_ERR_RANGE): read the whole
    map again (polylines, polyline_ids, version) and ask for the changes
    since that version from then on."""


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


class _Circle(ctypes.Structure):
    _fields_ = [("center_x_m", _f32), ("center_y_m", _f32), ("radius_m", _f32),
                ("polyline_dev_m", _f32), ("same_as", _u32)]


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


class _OnlineLimits(ctypes.Structure):
    _fields_ = [("area_m", _f64), ("max_grid_cells", _u32), ("max_vertices", _u32),
                ("max_points", _u32), ("max_scan_beams", _u32), ("keep_scans", _u32),
                ("keep_beams", _u32), ("reserved", _u32)]


class _OnlineReport(ctypes.Structure):
    _fields_ = [("version", _u64), ("work", _u64), ("scans", _u32), ("pending_scans", _u32),
                ("backlog_tiles", _u32), ("changed", _u32), ("polylines", _u32),
                ("vertices", _u32), ("bic", _f64)]


class _Change(ctypes.Structure):
    _fields_ = [("id", _u32), ("kind", _u32), ("version", _u64)]


_STRUCTS = {"polyc_config": _Config, "polyc_limits": _Limits, "polyc_scan": _Scan,
            "polyc_box": _Box, "polyc_polyline": _Polyline, "polyc_stats": _Stats,
            "polyc_iteration": _Iteration, "polyc_occupancy_grid": _OccupancyGrid,
            "polyc_online_limits": _OnlineLimits, "polyc_online_report": _OnlineReport,
            "polyc_change": _Change, "polyc_circle": _Circle}
_PROGRESS = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.POINTER(_Iteration))


class _Map(ctypes.Structure):      # polyc_io_map of polyc_io.c
    _fields_ = [("grid", _OccupancyGrid), ("image_path", ctypes.c_char_p),
                ("occupied_thresh", _f64), ("free_thresh", _f64), ("mode", ctypes.c_int),
                ("negate", ctypes.c_int)]


class _GridImage(ctypes.Structure):  # gridimage of tools/gridimage.h
    _fields_ = [("pixels", ctypes.POINTER(ctypes.c_uint8)), ("width", _u32), ("height", _u32),
                ("cell_m", _f32), ("origin_x_m", _f64), ("origin_y_m", _f64),
                ("counts", _u64 * 256)]


# ---- loading ----

def _library_path():
    """$POLYC_LIB, else the libpolyc.so next to this file (nothing else: a
    library from a folder others may write to would run their code)."""
    env = os.environ.get("POLYC_LIB")
    if env:
        return env
    here = os.path.dirname(os.path.abspath(__file__))
    for name in ("libpolyc.so", "libpolyc.dylib", "libpolyc.dll"):
        path = os.path.join(here, name)
        if os.path.exists(path):
            return path
    raise OSError("libpolyc not found: %s has no libpolyc.so and POLYC_LIB is not set "
                  "(install the package: pip install ./bindings/python)" % here)


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
        "polyc_scan_extent": (None, [P(_Config), P(_Scan), P(_Box)]),
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
        "polyc_find_curves": (st, [ctx]),
        "polyc_copy_arcs": (st, [ctx, _u32, P(_f32), P(_f32), _u32, P(_u32), P(_u32)]),
        "polyc_get_circle": (st, [ctx, _u32, P(_Circle)]),
        "polyc_score": (st, [ctx, P(_f64), P(_f64)]),
        "polyc_last_error": (ctypes.c_char_p, [ctx]),
        # online mapping (polyc.h, "Online mapping")
        "polyc_online_limits_for_area": (st, [P(_Config), _f64, _u32, P(_OnlineLimits)]),
        "polyc_online_memory_size": (sz, [P(_Config), P(_OnlineLimits)]),
        "polyc_online_init": (st, [ctypes.c_void_p, sz, P(_Config), P(_OnlineLimits), P(ctx)]),
        "polyc_online_add_scan": (st, [ctx, P(_Scan), ctypes.c_int, P(_u32)]),
        "polyc_online_update": (st, [ctx, _u64, P(_OnlineReport)]),
        "polyc_online_finish": (st, [ctx, _PROGRESS, ctypes.c_void_p, P(_OnlineReport)]),
        "polyc_online_correct": (st, [ctx, _u32, _f64, _f64, _f64]),
        "polyc_online_changes": (st, [ctx, _u64, P(_Change), _u32, P(_u32)]),
        "polyc_polyline_id": (st, [ctx, _u32, P(_u32)]),
        "polyc_online_version": (_u64, [ctx]),
    }
    # the polyc tool's readers (bindings/python/polyc_io.c): in the package's
    # library, not in a plain libpolyc.so named by POLYC_LIB
    io = {
        "polyc_io_version": (ctypes.c_int, []),
        "polyc_io_struct_size": (sz, [ctypes.c_char_p]),
        "polyc_io_read_log": (ctypes.c_int, [ctypes.c_char_p, _f64, P(ctypes.c_void_p),
                                             ctypes.c_char_p, sz]),
        "polyc_io_log_count": (_u32, [ctypes.c_void_p]),
        "polyc_io_log_scans": (P(_Scan), [ctypes.c_void_p]),
        "polyc_io_log_free": (None, [ctypes.c_void_p]),
        "polyc_io_read_map": (ctypes.c_int, [ctypes.c_char_p, P(P(_Map)), ctypes.c_char_p, sz]),
        "polyc_io_map_free": (None, [P(_Map)]),
        "polyc_io_grid_image": (ctypes.c_int, [ctx, P(P(_GridImage)), P(st)]),
        "polyc_io_grid_image_free": (None, [P(_GridImage)]),
    }
    for name, (res, args) in signatures.items():
        fn = getattr(lib, name)
        fn.restype, fn.argtypes = res, args
    lib.has_io = hasattr(lib, "polyc_io_version")
    for name, (res, args) in io.items() if lib.has_io else ():
        fn = getattr(lib, name)
        fn.restype, fn.argtypes = res, args
    return lib


_lib = None                                # PolycError works before the load
_lib = _load()
for _name, _cls in _STRUCTS.items():
    _size = _lib.polyc_struct_size(_name.encode())
    if _size != ctypes.sizeof(_cls):
        raise PolycError(ERR_CONFIG, "loading " + _library_path(),
                         "struct %s is %d bytes in the library but %d in polyc: the binding "
                         "does not match this libpolyc" % (_name, _size, ctypes.sizeof(_cls)))
for _name, _cls in (("polyc_io_map", _Map), ("gridimage", _GridImage)) if _lib.has_io else ():
    if _lib.polyc_io_struct_size(_name.encode()) != ctypes.sizeof(_cls):
        raise PolycError(ERR_CONFIG, "loading " + _library_path(),
                         "struct %s differs between the library and polyc" % _name)
if _lib.has_io and _lib.polyc_io_version() != 2:
    raise PolycError(ERR_CONFIG, "loading " + _library_path(),
                     "its readers (polyc_io) are version %d, this binding wants 2"
                     % _lib.polyc_io_version())


# ---- numbers ----

_F32 = struct.Struct("f")


def _f32_of(v):
    return _F32.unpack(_F32.pack(v))[0]


def _shortest(v):
    """The float32 v (a float holding a float32 value) as the shortest
    decimal that rounds back to it: 1.999999761581421 -> 2.0 only if 2.0 is
    that float32, 0.1f -> 0.1. Digits 1..9 (9 always round-trips); a longer
    rounding is never farther away, so a bisection finds the shortest."""
    if v != v or v in (math.inf, -math.inf) or v == 0.0:
        return v
    lo, hi = 1, 9
    while lo < hi:
        mid = (lo + hi) // 2
        if _f32_of(float("%.*g" % (mid, v))) == v:
            hi = mid
        else:
            lo = mid + 1
    return float("%.*g" % (lo, v))


def _int_field(name, value, ctype):
    """value as an integer of the C type, or TypeError / ValueError (never a
    silent wrap: -1 is not 4294967295)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError("%s must be an integer, not %s" % (name, type(value).__name__))
    lo, hi = _RANGE[ctype]
    value = int(value)
    if not lo <= value <= hi:
        raise ValueError("%s must be in [%d, %d], not %d" % (name, lo, hi, value))
    return value


def _real_field(name, value):
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError("%s must be a number, not %s" % (name, type(value).__name__))
    return float(value)


def _set_fields(target, values, what):
    fields = [n for n, _ in target._fields_ if n != "reserved"]
    types = dict(target._fields_)
    for name, value in values.items():
        if name not in fields:
            raise TypeError("unknown %s field %r; the fields are: %s"
                            % (what, name, ", ".join(fields)))
        ctype = types[name]
        if ctype in _RANGE:
            setattr(target, name, _int_field(name, value, ctype))
        else:
            setattr(target, name, _real_field(name, value))


# ---- Python side ----

class Scan(NamedTuple):
    """One scan: beam i points at theta + start_angle_rad + i * angle_step_rad
    (a negative step is a clockwise scan); a range outside [min_range_m,
    max_range_m) is a beam with no return. ranges_m: a sequence of numbers or
    any buffer of float32 or float64 (array('f'), a numpy array, ...)."""
    pose: Tuple[float, float, float]       # x_m, y_m, theta_rad
    start_angle_rad: float
    angle_step_rad: float
    min_range_m: float
    max_range_m: float
    ranges_m: Sequence[float]


class Points:
    """A polyline's points, N x 2 float64 in metres: a sequence of (x, y)
    tuples, and numpy-ready without numpy: numpy.asarray(points) is an N x 2
    float64 array over the same memory (no copy), as is the buffer
    points.view (a memoryview of shape (N, 2), format 'd'). Each value is the
    library's float32 as its shortest decimal (2.0, not 1.999999761581421).
    Read-only."""
    __slots__ = ("_xy", "view")

    def __init__(self, xy):
        self._xy = xy                      # array('d'), x0 y0 x1 y1 ...
        n = len(xy) // 2
        mv = memoryview(xy)
        self.view = mv.cast("B").cast("d", (n, 2)).toreadonly() if n else mv.toreadonly()

    def __len__(self):
        return len(self._xy) // 2

    def __getitem__(self, i):
        if isinstance(i, slice):
            return [self[k] for k in range(*i.indices(len(self)))]
        n = len(self)
        if i < 0:
            i += n
        if not 0 <= i < n:
            raise IndexError("point index out of range")
        return (self._xy[2 * i], self._xy[2 * i + 1])

    def __iter__(self):
        xy = self._xy
        return iter(list(zip(xy[0::2], xy[1::2])))

    def tolist(self):
        """[(x, y), ...]"""
        xy = self._xy
        return list(zip(xy[0::2], xy[1::2]))

    def __eq__(self, other):
        if isinstance(other, Points):
            return self._xy == other._xy
        try:
            return self.tolist() == [tuple(p) for p in other]
        except TypeError:
            return NotImplemented

    def __repr__(self):
        return "Points(%r)" % (self.tolist(),)

    @property
    def __array_interface__(self):
        n = len(self)
        addr = self._xy.buffer_info()[0]
        return {"version": 3, "shape": (n, 2), "data": (addr, True),
                "typestr": "<f8" if sys.byteorder == "little" else ">f8"}

    def __buffer__(self, flags):           # memoryview(points), Python 3.12+
        return self.view


class Polyline(NamedTuple):
    points: Points                         # metres; a closed one does not repeat its start
    closed: bool


class Circle(NamedTuple):
    """A polyline of the map that the BIC prefers as a circle
    (polyc_find_curves): `index` into polylines, the centre (x, y) and
    radius in metres, and how far that polyline strays from the circle."""
    index: int
    center: tuple
    radius: float
    polyline_dev: float


class ArcPolyline(NamedTuple):
    """A polyline with its arcs (polyc_copy_arcs): the vertices that bound a
    straight segment or an arc, and per segment its bulge (tan of a quarter
    of the arc's angle, > 0 counter-clockwise, 0 straight; as DXF's
    LWPOLYLINE), one fewer than the points for an open polyline."""
    points: Points
    bulges: tuple
    closed: bool


class Result(NamedTuple):
    polylines: list                        # of Polyline
    stats: dict                            # the fields of polyc_stats


class OnlineReport(NamedTuple):
    """What OnlineMap.update or finish did and where the map stands
    (polyc_online_report)."""
    version: int                           # the map's version after the call (0: no update yet)
    work: int                              # work units the call spent
    scans: int                             # scans added so far
    pending_scans: int                     # scans added since the last update
    backlog_tiles: int                     # changed regions (tiles) not yet re-optimised
    changed: int                           # polylines the call added, modified or removed
    polylines: int
    vertices: int
    bic: float                             # BIC of the map against the data so far


class Change(NamedTuple):
    """One entry of OnlineMap.changes_since: a polyline's latest change."""
    id: int                                # the polyline's id (OnlineMap.polyline_ids)
    kind: str                              # 'added', 'modified' or 'removed'
    version: int                           # the version that made the change


class Map(NamedTuple):
    """An occupancy grid read from a map_server map (read_map): the arguments
    of build_map_from_grid, and what the YAML said."""
    cells: bytes                           # int8 values, row 0 at the bottom (OccupancyGrid order)
    width: int
    height: int
    resolution: float                      # metres per cell
    origin: Tuple[float, float, float]     # x, y, yaw of cell (0, 0)'s outer corner
    image_path: str
    occupied_thresh: float                 # the YAML's (its pixels are converted with them)
    free_thresh: float


class GridImage(NamedTuple):
    """A hit/miss grid as map_saver's trinary image, what `polyc grid` writes
    (grid_image, Context.grid_image)."""
    pixels: bytes                          # width * height, row 0 the top: 0 occupied, 254 free, 205 unknown
    width: int
    height: int
    cell_m: float
    origin: Tuple[float, float, float]     # x, y of cell (0, 0)'s lower-left corner, yaw 0


def version():
    """(major, minor, patch) of the loaded library."""
    v = _lib.polyc_version()
    return (v // 10000, v // 100 % 100, v % 100)


__version__ = "%d.%d.%d" % version()      # the library's: the package is built with it


def default_config():
    """The library's defaults (the paper's parameters) as a dict."""
    c = _Config()
    _lib.polyc_config_default(ctypes.byref(c))
    return {n: getattr(c, n) for n, _ in _Config._fields_ if n != "reserved"}


def _config(overrides):
    c = _Config()
    _lib.polyc_config_default(ctypes.byref(c))
    _set_fields(c, overrides, "polyc_config")
    why = ctypes.c_char_p()
    status = _lib.polyc_config_check(ctypes.byref(c), ctypes.byref(why))
    if status != OK:
        raise PolycError(status, "config", (why.value or b"").decode())
    return c


def _limits(limits):
    lim = _Limits()
    if isinstance(limits, dict):
        _set_fields(lim, limits, "polyc_limits")
    else:
        names = [n for n, _ in _Limits._fields_]
        limits = tuple(limits)
        if not 4 <= len(limits) <= 5:
            raise TypeError("limits: (max_scans, max_beams, max_grid_cells, max_vertices"
                            "[, max_points]) or a dict of them")
        _set_fields(lim, dict(zip(names, limits)), "polyc_limits")
    return lim


def _floats(values, what):
    """A ctypes float array of values: any buffer of native float32 / float64
    (one copy, no Python float per value for float32; any strides) or a
    sequence of numbers."""
    try:
        view = memoryview(values)
    except TypeError:
        view = None
    if view is not None:
        native = "<" if sys.byteorder == "little" else ">"
        order, fmt = (view.format[0], view.format[1:]) if view.format[:1] in "@=<>!" \
            else ("@", view.format)
        if fmt not in ("f", "d") or order not in ("@", "=", native) or view.ndim > 1:
            raise TypeError("%s: a 1-D buffer of float32 or float64 (format 'f' or 'd'), not "
                            "format %r with %d dimensions" % (what, view.format, view.ndim))
        data = view.tobytes()              # C order whatever the strides
        if fmt == "f":
            return (_f32 * len(view)).from_buffer_copy(data)
        wide = array("d")
        wide.frombytes(data)
        return (_f32 * len(view)).from_buffer_copy(array("f", wide).tobytes())
    try:
        return (_f32 * len(values))(*values)
    except TypeError:
        raise TypeError("%s: a sequence of numbers or a buffer of floats" % what) from None


def _scan(scan):
    """A _Scan and the float array it points to (keep both alive)."""
    pose, start, step, lo, hi, ranges = scan
    x, y, theta = (_real_field("pose", v) for v in pose)
    buf = _floats(ranges, "ranges_m")
    _int_field("beam count", len(buf), _u32)
    s = _Scan(x, y, theta, _real_field("start_angle_rad", start),
              _real_field("angle_step_rad", step), _real_field("min_range_m", lo),
              _real_field("max_range_m", hi), len(buf), 0,
              ctypes.cast(buf, ctypes.POINTER(_f32)))
    return s, buf


def _grid(cells, width, height, resolution, origin):
    """An _OccupancyGrid and the int8 array it points to (keep both alive).
    cells: any buffer of bytes (bytes, bytearray, array('b'), a numpy int8
    array; byte 255 is -1) or a sequence of ints, width * height of them,
    row-major from the origin's row."""
    width = _int_field("width", width, _u32)
    height = _int_field("height", height, _u32)
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
    x, y, yaw = (_real_field("origin", v) for v in origin)
    g = _OccupancyGrid(width, height, _real_field("resolution", resolution), 0, x, y, yaw,
                       ctypes.cast(buf, ctypes.POINTER(ctypes.c_int8)))
    return g, buf


class _Interrupts:
    """While the library runs on the main thread, SIGINT (Ctrl-C) only sets
    a flag: Python would raise KeyboardInterrupt on entry to the next ctypes
    callback, where nothing can catch it and ctypes prints and drops it.
    The callback turns the flag into a stop; when the call returns, the
    signal goes to the handler that was there before (KeyboardInterrupt for
    Python's own)."""

    def __init__(self):
        self.pending, self.previous = False, None

    def __enter__(self):
        if threading.current_thread() is threading.main_thread():
            try:
                previous = signal.getsignal(signal.SIGINT)
                if callable(previous):
                    signal.signal(signal.SIGINT, self._handler)
                    self.previous = previous
            except (ValueError, OSError):
                pass
        return self

    def _handler(self, signum, frame):
        self.pending = True

    def __exit__(self, *exc):
        if self.previous is not None:
            signal.signal(signal.SIGINT, self.previous)
        return False

    def deliver(self):
        if self.pending:
            self.pending = False
            self.previous(signal.SIGINT, None)


class _Progress:
    """The C callback around fn(dict of polyc_iteration): a true result
    stops. An exception in fn is kept, stops the optimiser and is raised
    again by _Block._run; so is a Ctrl-C (_Interrupts), for which the
    callback runs even without fn."""

    def __init__(self, fn, ctx, interrupts):
        if fn is not None and not callable(fn):
            raise TypeError("progress must be callable or None, not %s" % type(fn).__name__)
        self.fn, self.ctx, self.interrupts, self.error = fn, ctx, interrupts, None
        self.c = _PROGRESS(self._call)

    def _call(self, _user, it):
        try:
            if self.interrupts.pending:
                return 1
            if self.fn is None:
                return 0
            i = it.contents
            report = {n: getattr(i, n) for n, _ in _Iteration._fields_ if n != "reserved"}
            self.ctx._busy = True
            try:
                stop = self.fn(report)
            finally:
                self.ctx._busy = False
            return 1 if stop or self.interrupts.pending else 0
        except BaseException as e:          # KeyboardInterrupt too: raised again later
            self.error = e
            return 1


class _Block:
    """What a context in a block of its own does, batch or online: one
    thread at a time (a lock around every call into the block; another
    thread waits), refuse calls from its own progress callback, raise the
    library's errors, run the optimiser with a progress callback, copy the
    map out."""
    _busy = False
    _ctx = None

    @contextlib.contextmanager
    def _use(self, what):
        """The block to this thread for the calls of `what`: another thread
        waits until it is free. A call from inside the object's own
        progress callback (the thread that holds the lock, reentrant) is
        POLYC_ERR_BUSY at once, as the library would say."""
        with self._lock:
            if self._busy:
                raise PolycError(ERR_BUSY, what, "a context's methods may not be called from "
                                 "inside its own progress callback")
            yield

    def _check(self, status, what):
        if status != OK:
            detail = _lib.polyc_last_error(self._ctx).decode() if self._ctx else ""
            raise PolycError(status, what, detail)

    def _run(self, fn, progress, what):
        """fn(ctx, callback, None) with progress; the callback's exception
        first, then the status."""
        interrupts = _Interrupts()
        cb = _Progress(progress, self, interrupts)
        with self._use(what):
            with interrupts:
                status = fn(self._ctx, cb.c, None)
            interrupts.deliver()
            if cb.error is not None:
                error, cb.error = cb.error, None
                raise error
            self._check(status, what)

    def _copy_polylines(self):
        out = []
        for i in range(_lib.polyc_polyline_count(self._ctx)):
            pl = _Polyline()
            self._check(_lib.polyc_get_polyline(self._ctx, i, ctypes.byref(pl)), "get polyline")
            raw = array("f")
            raw.frombytes(ctypes.string_at(pl.xy_m, 8 * pl.point_count))
            out.append(Polyline(Points(array("d", map(_shortest, raw))), bool(pl.closed)))
        return out

    def _arc_polylines(self):
        self._check(_lib.polyc_find_curves(self._ctx), "find curves")
        out = []
        for i in range(_lib.polyc_polyline_count(self._ctx)):
            n, closed = _u32(), _u32()
            self._check(_lib.polyc_copy_arcs(self._ctx, i, None, None, 0, ctypes.byref(n), None),
                        "copy arcs")
            xy, bul = (_f32 * (2 * n.value + 2))(), (_f32 * (n.value + 1))()
            self._check(_lib.polyc_copy_arcs(self._ctx, i, xy, bul, n.value, ctypes.byref(n),
                                             ctypes.byref(closed)), "copy arcs")
            pts = Points(array("d", map(_shortest, xy[:2 * n.value])))
            nb = n.value if closed.value else max(n.value - 1, 0)
            out.append(ArcPolyline(pts, tuple(_shortest(b) for b in bul[:nb]), bool(closed.value)))
        return out

    def _find_circles(self):
        self._check(_lib.polyc_find_curves(self._ctx), "find circles")
        out = []
        for i in range(_lib.polyc_polyline_count(self._ctx)):
            c = _Circle()
            self._check(_lib.polyc_get_circle(self._ctx, i, ctypes.byref(c)), "get circle")
            if c.radius_m > 0 and c.same_as == i:   # (a ring in pieces: once, at the first)
                out.append(Circle(i, (_shortest(c.center_x_m), _shortest(c.center_y_m)),
                                  _shortest(c.radius_m), _shortest(c.polyline_dev_m)))
        return out

    def _get_stats(self):
        s = _Stats()
        self._check(_lib.polyc_get_stats(self._ctx, ctypes.byref(s)), "stats")
        return {n: getattr(s, n) for n, _ in _Stats._fields_ if n != "reserved"}


class Context(_Block):
    """A libpolyc context in a block this object owns.

    limits: dict or (max_scans, max_beams, max_grid_cells, max_vertices[, max_points]);
    memory_bytes: block size (default: polyc_memory_size); other keywords
    override polyc_config fields (cell_m=0.05, max_iterations=0, seed=3, ...).
    One thread at a time: a call from another thread waits until the
    running one returns. Its methods may not be called from inside its own
    progress callback (PolycError POLYC_ERR_BUSY)."""

    def __init__(self, limits, memory_bytes=None, **config):
        self._lock = threading.RLock()
        self._busy = False
        self._ctx = ctypes.c_void_p()
        self._cfg = _config(config)
        self._lim = _limits(limits)
        need = _lib.polyc_memory_size(ctypes.byref(self._cfg), ctypes.byref(self._lim))
        if need == 0:
            raise PolycError(ERR_CONFIG, "memory size", "the limits are too large for size_t")
        size = need if memory_bytes is None else _int_field("memory_bytes", memory_bytes, _u64)
        if size < need:
            raise PolycError(ERR_NOMEM, "init", "%d bytes given, polyc_memory_size says %d "
                             "are needed" % (size, need))
        self.memory_size = need
        self._block = ctypes.create_string_buffer(size)
        self._check(_lib.polyc_init(self._block, size, ctypes.byref(self._cfg),
                                    ctypes.byref(self._lim), ctypes.byref(self._ctx)), "init")

    def add_scan(self, pose, start_angle_rad, angle_step_rad, min_range_m, max_range_m,
                 ranges_m):
        """Copies one scan in (see Scan for the fields)."""
        s, _buf = _scan((pose, start_angle_rad, angle_step_rad, min_range_m, max_range_m,
                         ranges_m))
        with self._use("add scan"):
            self._check(_lib.polyc_add_scan(self._ctx, ctypes.byref(s)), "add scan")

    def add_grid(self, cells, width, height, resolution, origin=(0.0, 0.0, 0.0)):
        """Takes an occupancy grid (see build_map_from_grid for the arguments);
        a context holds one grid or scans, not both."""
        g, _buf = _grid(cells, width, height, resolution, origin)
        with self._use("add grid"):
            self._check(_lib.polyc_add_grid(self._ctx, ctypes.byref(g)), "add grid")

    def build(self, progress=None):
        """Grid, contour, trace and (if max_iterations > 0) the optimiser.
        progress(iteration_dict) returning True stops (PolycError POLYC_ERR_STOPPED;
        the best map so far is kept); an exception it raises stops too and
        is raised here."""
        self._run(_lib.polyc_build, progress, "build")

    def build_grid(self):
        """The hit/miss grid of the scans (or, for a grid added, the grid
        kept as it is), again from the scans if it was built; drops the
        contour and polylines. Runs no later stage."""
        with self._use("build grid"):
            self._check(_lib.polyc_build_grid(self._ctx), "build grid")

    def extract_contour(self):
        """The contour cells of the grid (building the grid first if it is
        not built), again if they were extracted; drops the polylines."""
        with self._use("extract contour"):
            self._check(_lib.polyc_extract_contour(self._ctx), "extract contour")

    def trace(self):
        """The initial polylines, traced from the contour (from the beam
        order for a context of one scan), running the earlier stages if
        they have not run; the map starts over from them (polylines() gives
        them, score() their BIC). A map that needs more vertices or data
        points than the limits hold: PolycError POLYC_ERR_NOMEM."""
        with self._use("trace"):
            self._check(_lib.polyc_trace(self._ctx), "trace")

    def optimize(self, progress=None):
        """The optimiser; progress as for build."""
        self._run(_lib.polyc_optimize, progress, "optimize")

    def score(self):
        """(bic, error_sq_m2) of the current polylines."""
        bic, err = _f64(), _f64()
        with self._use("score"):
            self._check(_lib.polyc_score(self._ctx, ctypes.byref(bic), ctypes.byref(err)),
                        "score")
        return bic.value, err.value

    def polylines(self):
        """The current map, copied out: a list of Polyline."""
        with self._use("polylines"):
            return self._copy_polylines()

    def circles(self):
        """The polylines of the current map that are circles (round things:
        polyc_find_curves), a list of Circle; none with flags FLAG_NO_ARCS."""
        with self._use("circles"):
            return self._find_circles()

    def arc_polylines(self):
        """The current map with its arcs (polyc_find_curves, polyc_copy_arcs):
        a list of ArcPolyline in the order of polylines(); every bulge 0 with
        flags FLAG_NO_ARCS."""
        with self._use("arc polylines"):
            return self._arc_polylines()

    def grid_image(self):
        """The hit/miss grid (run build_grid first) as the image `polyc grid`
        writes: a GridImage."""
        _need_io("grid_image")
        img = ctypes.POINTER(_GridImage)()
        status = ctypes.c_int(OK)
        with self._use("grid image"):
            made = _lib.polyc_io_grid_image(self._ctx, ctypes.byref(img), ctypes.byref(status))
            try:
                if made == -1:
                    self._check(status.value, "grid image")
                if made == -2:
                    g = img.contents
                    raise PolycError(ERR_EXTENT, "grid image", "the grid is %d x %d cells: "
                                     "empty, or more than a map may have" % (g.width, g.height))
                if made != 0:
                    raise MemoryError("grid image")
                g = img.contents
                return GridImage(ctypes.string_at(g.pixels, g.width * g.height), g.width,
                                 g.height, _shortest(g.cell_m), (g.origin_x_m, g.origin_y_m, 0.0))
            finally:
                _lib.polyc_io_grid_image_free(img)

    def stats(self):
        """The fields of polyc_stats (a dict): scans, beams and hits in,
        grid size, contour cells, the polylines and vertices traced and
        now, iterations, bic, error_sq_m2, the block's bytes used."""
        with self._use("stats"):
            return self._get_stats()


class OnlineMap(_Block):
    """A map kept up to date as scans arrive (polyc.h, "Online mapping"), in
    a block this object owns (ctypes buffer of polyc_online_memory_size()).

    area_m: side of the square the map may span, centred on the first
    scan's pose; max_scan_beams: beams in one scan; config: a dict of
    polyc_config fields (cell_m, alpha, seed, ...); keep_scans, keep_beams:
    how many scans (and their beams in all) add_scan(..., keep=True) may
    keep for correct(). The other limits (max_grid_cells, max_vertices,
    max_points) come from polyc_online_limits_for_area; keywords override
    them. One thread at a time: a call from another thread waits until the
    running one returns. Its methods may not be called from inside finish's
    progress callback (PolycError POLYC_ERR_BUSY)."""

    def __init__(self, area_m, max_scan_beams, config=None, keep_scans=0, keep_beams=0,
                 **limits):
        self._lock = threading.RLock()
        self._ctx = ctypes.c_void_p()
        self._cfg = _config(dict(config or {}))
        area_m = _real_field("area_m", area_m)
        max_scan_beams = _int_field("max_scan_beams", max_scan_beams, _u32)
        lim = _OnlineLimits()
        status = _lib.polyc_online_limits_for_area(ctypes.byref(self._cfg), area_m,
                                                   max_scan_beams, ctypes.byref(lim))
        if status != OK:
            why = {ERR_EXTENT: "a square over twice config.max_extent_m",
                   ERR_CONFIG: "area_m must be over 1 and at most 1e5, max_scan_beams over 0"}
            raise PolycError(status, "online limits for area", "%s (area_m %r, max_scan_beams %d)"
                             % (why.get(status, "refused"), area_m, max_scan_beams))
        _set_fields(lim, dict(limits, keep_scans=keep_scans, keep_beams=keep_beams),
                    "polyc_online_limits")
        self._lim = lim
        need = _lib.polyc_online_memory_size(ctypes.byref(self._cfg), ctypes.byref(lim))
        if need == 0:
            raise PolycError(ERR_CONFIG, "online memory size", "the limits are invalid or too "
                             "large for size_t: %s" % self.limits)
        self.memory_size = need
        self._block = ctypes.create_string_buffer(need)
        self._check(_lib.polyc_online_init(self._block, need, ctypes.byref(self._cfg),
                                           ctypes.byref(lim), ctypes.byref(self._ctx)),
                    "online init")

    @property
    def limits(self):
        """The polyc_online_limits the block was sized for, as a dict."""
        return {n: getattr(self._lim, n) for n, _ in _OnlineLimits._fields_ if n != "reserved"}

    def add_scan(self, pose, start_angle_rad, angle_step_rad, min_range_m, max_range_m,
                 ranges_m, keep=False):
        """Adds one scan (the arguments of Context.add_scan, see Scan; a Scan
        s goes in as add_scan(*s)); keep=True keeps it for correct().
        Returns its scan id (0 for the first). The map changes at the next
        update."""
        s, _buf = _scan((pose, start_angle_rad, angle_step_rad, min_range_m, max_range_m,
                         ranges_m))
        scan_id = _u32()
        with self._use("add scan"):
            self._check(_lib.polyc_online_add_scan(self._ctx, ctypes.byref(s),
                                                   1 if keep else 0, ctypes.byref(scan_id)),
                        "add scan")
        return scan_id.value

    @staticmethod
    def _report(r):
        return OnlineReport(*(getattr(r, n) for n in OnlineReport._fields))

    def update(self, work=ONLINE_WORK_DEFAULT):
        """Re-optimises what the scans since the last update changed, within
        about `work` units (0 is PolycError POLYC_ERR_CONFIG); the rest stays
        in the backlog. Waiting corrections count against the budget (a unit
        per two beams they cast); an update they spent it in does nothing
        else. Before any scan: PolycError POLYC_ERR_STATE. Returns an
        OnlineReport."""
        work = _int_field("work", work, _u64)
        r = _OnlineReport()
        with self._use("update"):
            self._check(_lib.polyc_online_update(self._ctx, work, ctypes.byref(r)), "update")
        return self._report(r)

    def finish(self, progress=None):
        """Converges the map as a batch build would (the backlog, then the
        full search); scans may be added after it. progress as for
        Context.build: returning True stops (PolycError POLYC_ERR_STOPPED,
        the best map so far kept), an exception it raises (KeyboardInterrupt
        too) stops and is raised here. Returns an OnlineReport."""
        r = _OnlineReport()
        self._run(lambda ctx, cb, user: _lib.polyc_online_finish(ctx, cb, user,
                                                                  ctypes.byref(r)),
                  progress, "finish")
        return self._report(r)

    def correct(self, scan_id, pose):
        """Gives kept scan scan_id the pose (x_m, y_m, theta_rad), after a
        loop closure. The pose waits: the next update(), finish() or
        add_scan() applies every waiting correction, and the updates
        re-optimise what changed. A scan not kept (or unknown): PolycError
        POLYC_ERR_RANGE."""
        scan_id = _int_field("scan_id", scan_id, _u32)
        x, y, theta = (_real_field("pose", v) for v in pose)
        with self._use("correct"):
            self._check(_lib.polyc_online_correct(self._ctx, scan_id, x, y, theta), "correct")

    def changes_since(self, version):
        """The polylines added, modified or removed by the versions after
        `version`, one Change (id, kind, version) per polyline, its latest,
        ids ascending. ResyncError (a PolycError, POLYC_ERR_RANGE) when
        removals that old are forgotten: read the whole map again."""
        since = _int_field("version", version, _u64)
        count = _u32()
        cap, out = 0, None
        with self._use("changes since"):
            while True:
                status = _lib.polyc_online_changes(self._ctx, since, out, cap,
                                                   ctypes.byref(count))
                if status == ERR_RANGE:
                    raise ResyncError(status, "changes since %d" % since,
                                      _lib.polyc_last_error(self._ctx).decode())
                self._check(status, "changes since %d" % since)
                if count.value <= cap:
                    break
                cap = count.value
                out = (_Change * cap)()
        return [Change(c.id, CHANGE_KINDS.get(c.kind, "kind %d" % c.kind), c.version)
                for c in (out[:count.value] if count.value else ())]

    @property
    def version(self):
        """The map's version: 0 before the first update, one more for every
        update or finish that changed the map."""
        with self._use("version"):
            return _lib.polyc_online_version(self._ctx)

    @property
    def polylines(self):
        """The map as the last update or finish left it, copied out: a list
        of Polyline, as in a batch Result."""
        with self._use("polylines"):
            return self._copy_polylines()

    @property
    def circles(self):
        """The polylines of the map as it stands that are circles
        (polyc_find_curves), a list of Circle, as Context.circles gives."""
        with self._use("circles"):
            return self._find_circles()

    @property
    def arc_polylines(self):
        """The map as it stands with its arcs, a list of ArcPolyline, as
        Context.arc_polylines gives."""
        with self._use("arc polylines"):
            return self._arc_polylines()

    @property
    def polyline_ids(self):
        """The ids of the polylines, in the order of polylines: an id stays
        the same while its polyline lives; ids start at 1, never reused."""
        ids = []
        one = _u32()
        with self._use("polyline ids"):
            for i in range(_lib.polyc_polyline_count(self._ctx)):
                self._check(_lib.polyc_polyline_id(self._ctx, i, ctypes.byref(one)),
                            "polyline id")
                ids.append(one.value)
        return ids

    @property
    def stats(self):
        """The fields of polyc_stats for the current map (a dict)."""
        with self._use("stats"):
            return self._get_stats()


class OnlineArea(NamedTuple):
    """What an OnlineMap needs for a set of scans (online_area)."""
    area_m: float              # side of the square round the first pose
    max_scan_beams: int        # beams of the largest scan (at least 1)


def online_area(scans, config=None):
    """The area and the beams an OnlineMap needs for these scans (a log
    read with read_log, say), as `polyc --online` sizes its map: the side
    of the square centred on the first scan's pose that holds every
    scan's pose and endpoints, with the 1 m the library keeps clear at its
    edge and 32 cells of air, and the beams of the largest scan. config:
    the dict of polyc_config fields the map will use (cell_m and
    max_range_m change the extent). Returns an OnlineArea(area_m,
    max_scan_beams): OnlineMap(*online_area(scans, cfg), config=cfg).
    No scans is a ValueError."""
    cfg = _config(dict(config or {}))
    box, first, beams = _Box(), None, 1
    for s in scans:
        rec, _buf = _scan(s)
        if first is None:
            first = (rec.pose_x_m, rec.pose_y_m)
            box.min_x_m = box.max_x_m = first[0]
            box.min_y_m = box.max_y_m = first[1]
        _lib.polyc_scan_extent(ctypes.byref(cfg), ctypes.byref(rec), ctypes.byref(box))
        beams = max(beams, rec.beam_count)
    if first is None:
        raise ValueError("no scans found: online_area was given none")
    x0, y0 = first
    reach = max(x0 - box.min_x_m, box.max_x_m - x0, y0 - box.min_y_m, box.max_y_m - y0)
    return OnlineArea(2.0 * (reach + 1.0 + 32.0 * _f32_of(cfg.cell_m)), beams)


def _scans_and_limits(cfg, scans, what):
    """The scans as held ctypes records (with the buffers they point into)
    and the limits polyc_limits_for_scans gives for them; no scans is a
    ValueError, as the tool refuses a log without scans."""
    held = [_scan(s) for s in scans]
    if not held:
        raise ValueError("no scans found: %s was given none (the polyc tool refuses such a "
                         "log too)" % what)
    _int_field("number of scans", len(held), _u32)
    arr = (_Scan * max(len(held), 1))(*[s for s, _ in held])
    lim = _Limits()
    status = _lib.polyc_limits_for_scans(ctypes.byref(cfg), arr, len(held), ctypes.byref(lim))
    if status != OK:
        raise PolycError(status, "limits for scans",
                         "the data span more than max_extent_m" if status == ERR_EXTENT else "")
    return held, lim


def _attach_best(error, ctx):
    """A stop by the progress callback (a deadline) keeps the best map so
    far in the context, as the C API says: it goes out with the error."""
    if error.status == ERR_STOPPED:
        error.result = Result(ctx.polylines(), ctx.stats())


def build_map(scans, memory_bytes=None, max_vertices=0, progress=None, **config):
    """Maps a sequence of scans (Scan or plain 6-sequences) as the polyc tool
    does: limits from the scans (polyc_limits_for_scans), one block, build;
    if the map needs more vertices or data points than those limits hold
    (POLYC_ERR_NOMEM after the grid), once more with the worst-case bound
    (max_vertices and max_points 0), as the tool does. progress is called
    again from the first iteration then. Returns a Result. A true value
    from progress stops the optimiser: PolycError POLYC_ERR_STOPPED whose
    .result is the best map so far (a Result)."""
    cfg = _config(config)
    if progress is not None and not callable(progress):
        raise TypeError("progress must be callable or None, not %s" % type(progress).__name__)
    max_vertices = _int_field("max_vertices", max_vertices, _u32)
    held, lim = _scans_and_limits(cfg, scans, "build_map")
    if max_vertices:
        lim.max_vertices = max_vertices
    for attempt in (0, 1):
        retry = attempt == 0 and (lim.max_vertices != 0 or lim.max_points != 0)
        ctx = Context((lim.max_scans, lim.max_beams, lim.max_grid_cells, lim.max_vertices,
                       lim.max_points), memory_bytes, **config)
        for i, (s, _) in enumerate(held):
            ctx._check(_lib.polyc_add_scan(ctx._ctx, ctypes.byref(s)), "add scan %d" % i)
        ctx.build_grid()
        try:
            ctx.build(progress)
        except PolycError as e:
            if e.status == ERR_NOMEM and retry:
                lim.max_points = 0
                lim.max_vertices = max_vertices
                continue
            _attach_best(e, ctx)
            raise
        return Result(ctx.polylines(), ctx.stats())


def grid_image(scans, **config):
    """The scans' hit/miss grid as map_saver's image, as `polyc grid` makes
    it (limits from the scans, build_grid): a GridImage."""
    cfg = _config(config)
    held, lim = _scans_and_limits(cfg, scans, "grid_image")
    ctx = Context((lim.max_scans, lim.max_beams, lim.max_grid_cells, lim.max_vertices,
                   lim.max_points), **config)
    for i, (s, _) in enumerate(held):
        ctx._check(_lib.polyc_add_scan(ctx._ctx, ctypes.byref(s)), "add scan %d" % i)
    ctx.build_grid()
    return ctx.grid_image()


def build_map_from_grid(cells, width, height, resolution, origin=(0.0, 0.0, 0.0),
                        memory_bytes=None, progress=None, **config):
    """Maps an occupancy grid as ROS keeps it (nav_msgs/OccupancyGrid): cells
    (column i, row j) at cells[j * width + i], -1 unknown, 0..100 occupancy
    (occupied from occupied_thresh * 100, free up to free_thresh * 100);
    origin = (x, y, yaw) of cell (0, 0)'s outer corner, resolution in metres.
    cells: bytes, bytearray, array('b'), a numpy int8 array (any buffer of
    int8) or a list of ints. Returns a Result, polylines in the map frame.
    progress as for build_map (a stop: PolycError POLYC_ERR_STOPPED with
    .result, the best map so far)."""
    cfg = _config(config)
    if progress is not None and not callable(progress):
        raise TypeError("progress must be callable or None, not %s" % type(progress).__name__)
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
    try:
        ctx.build(progress)
    except PolycError as e:
        _attach_best(e, ctx)
        raise
    return Result(ctx.polylines(), ctx.stats())


# ---- files, read by the polyc tool's own readers ----

def _need_io(what):
    if not _lib.has_io:
        raise OSError("%s needs the package's libpolyc.so (with the polyc tool's readers); %s "
                      "is the plain library" % (what, _library_path()))


def _path(path):
    """path (str, bytes or path-like) as the readers take it; a NUL in it is
    a ValueError, as for open()."""
    raw = os.fsencode(path)
    if b"\0" in raw:
        raise ValueError("embedded null byte")
    return raw


def _read_failed(status, path, error):
    """The error of a reader: the file not opened is the OSError open()
    raises (its errno, the path as given); anything else the tool's message
    as a ValueError."""
    if status > 0:
        raise OSError(status, os.strerror(status), os.fspath(path))
    raise ValueError(error.value.decode(errors="replace"))


def read_log(path, max_range_m=None):
    """The scans of a laser log (CARMEN FLASER / ROBOTLASER1 or polyc's plain
    format), read by the polyc tool's reader with its rules (docs/formats.md;
    max_range_m as its --max-range). A list of Scan, ranges_m as array('f').
    A bad log raises ValueError with the tool's message (FILE:LINE: what);
    a file not opened the OSError open() raises (FileNotFoundError,
    PermissionError, IsADirectoryError); a path with a NUL ValueError."""
    _need_io("read_log")
    raw = _path(path)
    limit = 0.0 if max_range_m is None else _real_field("max_range_m", max_range_m)
    handle = ctypes.c_void_p()
    error = ctypes.create_string_buffer(1024)
    status = _lib.polyc_io_read_log(raw, limit, ctypes.byref(handle), error, len(error))
    if status != 0:
        _read_failed(status, path, error)
    try:
        scans = []
        raw = _lib.polyc_io_log_scans(handle)
        for i in range(_lib.polyc_io_log_count(handle)):
            s = raw[i]
            ranges = array("f")
            if s.beam_count:
                ranges.frombytes(ctypes.string_at(s.range_m, 4 * s.beam_count))
            scans.append(Scan((s.pose_x_m, s.pose_y_m, s.pose_theta_rad), s.start_angle_rad,
                              s.angle_step_rad, s.min_range_m, s.max_range_m, ranges))
        return scans
    finally:
        _lib.polyc_io_log_free(handle)


def read_map(path):
    """A ROS map_server map: the YAML at path and its image (PGM or PNG,
    next to it), converted to OccupancyGrid values as `polyc map.yaml` does (nav2's
    rules: mode, negate, the YAML's thresholds). A Map; a bad map raises
    ValueError with the tool's message (FILE:LINE or FILE: byte N), an image
    that is not there too; a YAML not opened the OSError open() raises; a
    path with a NUL ValueError."""
    _need_io("read_map")
    raw = _path(path)
    handle = ctypes.POINTER(_Map)()
    error = ctypes.create_string_buffer(1024)
    status = _lib.polyc_io_read_map(raw, ctypes.byref(handle), error, len(error))
    if status != 0:
        _read_failed(status, path, error)
    try:
        m = handle.contents
        g = m.grid
        cells = ctypes.string_at(g.cells, g.width * g.height)
        return Map(cells, g.width, g.height, _shortest(g.resolution_m),
                   (g.origin_x_m, g.origin_y_m, g.origin_yaw_rad),
                   os.fsdecode(m.image_path), m.occupied_thresh, m.free_thresh)
    finally:
        _lib.polyc_io_map_free(handle)

