#!/usr/bin/env python3
"""docs_figures.py - every figure that README.md and docs/ quote, tied to the
command that prints it, and compared with what that command prints today.

    tools/docs_figures.py [--make MAKE] [--build DIR]           (make docs-figures)
    tools/docs_figures.py --data DIR [--bench-out FILE] ...     (make docs-figures-data)
    tools/docs_figures.py --list [--data DIR]                   the table, nothing run

Each entry of FIGURES names a document, the text around the figures as the
document quotes them (`{}` where a figure stands; any run of white space in
the text matches any run, line breaks included), the source that prints them
(SOURCES: a command, or a table of `make bench`'s output) and how to read
each figure from it (a regular expression with one group a figure, or a
function). A figure is the same when the measured value, scaled as the entry
says and rounded to the quoted number of decimals, is the quoted number
(thousands separators ignored). Timings are compared within a band (BAND
times or 1 / BAND the quoted value), and only from `make bench` (--data):
the default build's times in `make docs-figures` are printed, not compared.
The quoted text must occur exactly once in its document: a figure whose text
was rewritten fails until its entry follows it. A Table entry stands for a
table the document quotes as its source prints it (`make bench`'s, the
sweep's summary): every cell of every quoted row is compared, but the times.

To update a figure: run the command the failure names, put its value in the
document; if the text around it changed, change the entry's text too.

Without --data the sources are the repository's own: the bundled example
(examples/office.log), the grid `polyc grid` makes of it, the embedded
examples (host, `make cross`, `make target`), `make footprint`, and the
simulator's scenes (`build/sweep`, the same maps as `make sweep`'s). With --data DIR: the real logs, the
simulated logs and the TurtleBot3 map of DIR, through `make bench` (or the
saved output of one, --bench-out) and `build/polyc`.
"""
import argparse
import os
import re
import shlex
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# ---- sources: what prints the figures -------------------------------------
# {polyc}: the default build's tool; {tmp}: a scratch folder in the build
# folder; {make}: make; {data}: the data folder (--data only).
SOURCES = {
    'office-grid': '{polyc} grid --cell 0.05 -o {tmp}/office examples/office.log'
                   ' && {polyc} --stats -o {tmp}/office-map.svg {tmp}/office.yaml',
    'office-online': 'rm -rf {tmp}/frames && {polyc} --online --stats --frames {tmp}/frames'
                     ' -o {tmp}/office-online.svg examples/office.log',
    'footprint': '{make} --no-print-directory footprint',
    'embedded': '{make} --no-print-directory {build}/embedded_scan {build}/embedded_online'
                ' >/dev/null && {build}/embedded_scan && {build}/embedded_online',
    'cross': '{make} --no-print-directory cross',
    'target': '{make} --no-print-directory target',
    'sweep': '{make} --no-print-directory {build}/sweep >/dev/null && {build}/sweep',
    'profile': '{make} --no-print-directory target-profile',
    'cli-test': 'cat tests/cli_bad_input.sh',
    'room': 'cat examples/embedded_room.h examples/embedded_scan.c examples/embedded_online.c Makefile',
    # --data only
    'bench': None,  # `make bench DATA=...`, or --bench-out
    'turtlebot': '{polyc} --stats -o {tmp}/turtlebot.svg {data}/maps/turtlebot3_world.yaml',
    'intel': '{polyc} --stats -o {tmp}/intel.svg {data}/carmen/intel.log',
    'noreturn': 'for f in {data}/carmen/*.log; do echo "log $(basename $f .log)";'
                ' {polyc} convert --stats -o /dev/null $f 2>&1 | grep "^no-return"; done',
    'intel-initial': '{polyc} --no-optimize --stats -o {tmp}/intel0.svg {data}/carmen/intel.log',
}
DATA_SOURCES = {'bench', 'turtlebot', 'intel', 'intel-initial', 'noreturn'}
COMMANDS = {  # how a reader runs a source by hand
    'bench': 'make bench DATA={data}',
}
BENCH_TIMEOUT = 3600


class Fig:
    """doc, text with {} per figure, source, reader(s) of the figures.
    read: a regex whose groups are the figures in order, or a function of the
    source's output returning the list of figures; scale: a number or a
    function applied to each measured figure; time: timings (compared within
    BAND with --data, not compared otherwise)."""

    def __init__(self, doc, text, src, read, scale=1.0, time=False):
        self.doc, self.text, self.src, self.read = doc, text, src, read
        self.scale, self.time = scale, time


class Table:
    """a table the document quotes as its source prints it (a code block):
    every row the document has must be in the source's table, every cell
    the same but the columns skip_cols (times), counted from 0 (the name)"""

    def __init__(self, doc, name, src, skip_cols=()):
        self.doc, self.name, self.src, self.skip = doc, name, src, set(skip_cols)
        self.text = '%s table' % name
        self.time = False

    def rows(self, text):
        if self.name == 'sweep':
            return sweep_summary(text)
        return bench_tables(text).get(self.name, {})


def g(rx, *groups):
    """the groups of the first match of rx (multiline)"""
    def f(out):
        m = re.search(rx, out, re.M)
        if not m:
            raise LookupError('no match for /%s/' % rx)
        return [m.group(i) for i in (groups or range(1, m.re.groups + 1))]
    f.desc = rx
    return f


def nth(rx, n):
    """the groups of the n-th match (0-based) of rx"""
    def f(out):
        ms = list(re.finditer(rx, out, re.M))
        if len(ms) <= n:
            raise LookupError('fewer than %d matches of /%s/' % (n + 1, rx))
        return list(ms[n].groups())
    f.desc = '/%s/ match %d' % (rx, n + 1)
    return f


# ---- make bench's tables ----------------------------------------------------
HEADS = {}  # each bench table's column names, as its header line has them


ROW_LINES = {}  # the last text bench_tables read: {table: {row key: its line, 0-based}}


def bench_tables(out):
    """{table: {row key: [tokens]}}: each table from its header line; '|' dropped"""
    ROW_LINES.clear()
    heads = {
        'main': r'^scene\s+scans\s+beams\s+\|\s+parse',
        'topo': r'^scene\s+len\s+dcov',
        'single': r'^log\s+scans\s+mean f',
        'occ': r'^scene\s+grid\s+cells\s+occ',
        'online': r'^scene\s+scans\s+area\s+blockMiB',
        'final': r'^scene\s+map\s+\|\s+lines',
        'memory': r'^scene\s+area\s+onlineMiB',
        'memmap': (r'^scene\s+map\s+\|\s+lines', 1),
        'correct': r'^scene\s+kept\s+blockMiB',
        'corrmap': (r'^scene\s+map\s+\|\s+lines', 2),
    }
    lines = out.splitlines()
    tables = {}
    for name, rx in heads.items():
        rows = {}
        ROW_LINES[name] = {}
        rx, nth_head = rx if isinstance(rx, tuple) else (rx, 0)
        starts = [i for i, ln in enumerate(lines) if re.match(rx, ln)]
        for i in starts[nth_head:nth_head + 1]:
            head = [x for x in lines[i].split() if x != '|']
            if name == 'occ':
                head = head[:5] + head[6:]
            HEADS[name] = head
            for j, row in enumerate(lines[i + 1:], i + 1):
                if not row.strip() or re.match(r'^(scene|log|peak RSS)\s', row):
                    break
                t = [x for x in row.split() if x != '|']
                if not re.match(r'(sim|carmen)/', t[0]):
                    continue
                key = t[0]
                if name == 'occ':
                    key += ' ' + t[5]  # method
                    t = t[:5] + t[6:]
                if name in ('final', 'memmap', 'corrmap'):
                    key += ' ' + t[1]
                rows[key] = t
                ROW_LINES[name][key] = j
        tables[name] = rows
    return tables


def cell(table, key, col):
    """a bench table's cell: col counts the row's tokens from 0 (the name)"""
    def f(out):
        rows = bench_tables(out).get(table, {})
        if key not in rows:
            raise LookupError('no row %s in the bench\'s %s table' % (key, table))
        return [rows[key][c] for c in (col if isinstance(col, tuple) else (col,))]
    f.desc = 'bench %s table, row %s, column %s' % (table, key, col)
    return f


def over_rows(table, col, fn, prefix='carmen/', method=None):
    """fn over one column of every row whose name starts with prefix (and,
    in the occupancy table, whose method is method)"""
    def f(out):
        rows = bench_tables(out).get(table, {})
        vals = [float(r[col]) for k, r in rows.items()
                if k.startswith(prefix) and (method is None or k.endswith(' ' + method))]
        if not vals:
            raise LookupError('no %s rows in the bench\'s %s table' % (prefix, table))
        return fn(vals)
    f.desc = 'bench %s table, column %d of the %s rows' % (table, col, prefix)
    return f


def per100m(out):
    """the most runs over 20 cm without data per 100 m of map, over the logs"""
    rows = bench_tables(out)['topo']
    return [max(100.0 * float(r[5]) / float(r[1]) for k, r in rows.items()
                if k.startswith('carmen/'))]


per100m.desc = 'bench topology table: max of uns20 / len x 100 over the logs'


def sweep_summary(out):
    """the sweep's summary rows: {'KIND med' or 'KIND worst': tokens}"""
    rows, kind = {}, None
    for ln in out.splitlines():
        m = re.match(r'^([a-z]+)\s+med\s', ln)
        if m:
            kind = m.group(1)
            rows[kind + ' med'] = ln.split()
        elif kind and re.match(r'^\s+worst\s', ln):
            rows[kind + ' worst'] = [kind] + ln.split()
    return rows


def sweep_rows(out):
    """the sweep's scene rows (kind, seed, ... missed), one a scene"""
    rows = [ln.split() for ln in out.splitlines() if re.match(r'^[a-z]+\s+\d+\s+\d+\s+\d+\s', ln)]
    if not rows:
        raise LookupError('no scene rows in the sweep')
    return rows


EMB = (r'^block (\d+) bytes, memory_size (\d+) bytes\nmemory_used (\d+) bytes\n(?:.*\n)*?'
       r'polylines (\d+) vertices (\d+)')
INSTR_MS = lambda i, v: float(v) * (MHZ168 if i == 1 else 1)  # noqa: E731 (instructions | ms)


def calls(out, name):
    """the online example's instructions of each call NAME, in scan order"""
    v = [int(x) for x in re.findall(r'embedded_online: %s\s+\d+\s+(\d+)' % name, out)]
    if not v:
        raise LookupError('no "%s" lines from embedded_online' % name)
    return v


def prof(example, *funcs):
    """make target-profile: samples, software double %, then each function's %"""
    def f(out):
        v = g(r'profile %s: (\d+) samples' % example)(out)
        v += g(r'profile %s: software double arithmetic ([0-9.]+) %%' % example)(out)
        for fn in funcs:
            v += g(r'profile %s:\s+([0-9.]+) %%\s+%s$' % (example, re.escape(fn)))(out)
        return v
    f.desc = 'make target-profile, %s' % example
    return f


def noreturn(logs):
    """the no-return threshold (max_range_m) polyc convert --stats finds, the
    same on every log named"""
    def f(out):
        vals = set()
        for name in logs:
            m = re.search(r'^log %s\nno-return\s+FLASER max range ([0-9.]+) m' % re.escape(name), out, re.M)
            if not m:
                raise LookupError('no threshold for %s' % name)
            vals.add(m.group(1))
        if len(vals) != 1:
            raise LookupError('the logs %s differ: %s' % (', '.join(logs), ', '.join(sorted(vals))))
        return list(vals)
    f.desc = 'polyc convert --stats, no-return line'
    return f


KB = 1e-3   # the docs' KB and MB are 1000 and 1,000,000 bytes
MHZ168 = 1e3 / 168e6   # instructions at 168 MHz, one cycle each, in ms

# ---- the figures ----------------------------------------------------------
R = 'README.md'
P = 'docs/performance.md'
A = 'docs/api.md'
FMT = 'docs/formats.md'
FINAL = r'^final\s+(\d+) polylines, (\d+) vertices'
FIGURES = [
    # README: the saved map of the office example
    Fig(R, 'gives {} polylines of {} vertices from this grid', 'office-grid', g(FINAL)),
    Fig(R, 'from this grid in about {} ms', 'office-grid', g(r'^time ms .*total ([0-9.]+)'), time=True),
    Fig(R, 'a map of which at least {} of the length', 'cli-test', g(r'a >= ([0-9.]+) && b >= ')),
    # README: the simulator's scenes (`make sweep`)
    Fig(R, 'Over {} simulated\nscenes', 'sweep', lambda o: [len(sweep_rows(o))]),
    Fig(R, '{} crossings, {} m of double cover and {} stretches over 20 cm without data',
        'sweep', lambda o: [max(float(r[c]) for r in sweep_rows(o)) for c in (20, 19, 21)]),
    Fig(R, '(`band15`) at most {} % of a map', 'sweep', lambda o: [max(float(r[22]) for r in sweep_rows(o))]),
    Fig(R, 'vertices are at most {} times the ideal', 'sweep',
        lambda o: [max(float(r[7]) for r in sweep_rows(o))]),
    Fig(R, 'completeness is {} or more on the {} scenes without drift', 'sweep',
        lambda o: (lambda rs: [min(float(r[17]) for r in rs), len(rs)])(
            [r for r in sweep_rows(o) if r[0] not in ('drift', 'farhall')])),
    Fig(R, '{} of the {} meet every target', 'sweep',
        lambda o: [sum(r[25] == 'ok' for r in sweep_rows(o)), len(sweep_rows(o))]),
    # docs/formats.md: the --online --stats sample (office.log)
    Fig(FMT, 'online         {} scans, --work {}, a square of {} m, block {} bytes', 'office-online',
        g(r'^online\s+(\d+) scans, --work (\d+), a square of ([0-9.]+) m, block (\d+) bytes')),
    Fig(FMT, 'backlog        at most {} tiles\n    frames         {} in frames', 'office-online',
        lambda o: g(r'^backlog\s+at most (\d+) tiles')(o) + g(r'^frames\s+(\d+) in')(o)),
    Fig(FMT, 'add ms         median {}, p99 {}, max {}\n    add+update ms  median {}, p99 {}, max {}',
        'office-online', lambda o: g(r'^add ms\s+median ([0-9.]+), p99 ([0-9.]+), max ([0-9.]+)')(o)
        + g(r'^add\+update ms\s+median ([0-9.]+), p99 ([0-9.]+), max ([0-9.]+)')(o), time=True),
    # README: the embedded examples' settings, from their sources
    Fig(R, 'are used, at {} m cells, a {} m range cap, {}-bit counters and {}\n  vertices',
        'room', lambda o: g(r'define CELL_M ([0-9.]+)f')(o) + g(r'define RANGE_CAP_M ([0-9.]+)f')(o)
        + g(r'-DPOLYC_COUNTER_BITS=(\d+)')(o) + nth(r'define MAX_VERTICES (\d+)', 0)(o)),
    Fig(R, 'for an {} m square at {} m cells, {} cells with\n  endpoints and {} vertices', 'room',
        lambda o: g(r'define AREA_M ([0-9.]+)')(o) + g(r'define CELL_M ([0-9.]+)f')(o)
        + g(r'define MAX_POINTS (\d+)u')(o) + nth(r'define MAX_VERTICES (\d+)', 1)(o)),
    Fig(R, '(core precision within {} % or {} mm of the ideal fit', 'sweep',
        g(r'P core <= max\(([0-9.]+) x fit, fit \+ ([0-9.]+) mm\)'),
        scale=lambda i, v: (float(v) - 1) * 100 if i == 0 else float(v)),
    # README: microcontroller
    Fig(R, 'flash: {} KB for libpolyc', 'cross', g(r'^\s*(\d+)\s+\d+\s+\d+\s+\d+\s+\w+\s+\(TOTALS\)'),
        scale=KB),
    Fig(R, 'with newlib-nano, {} bytes of firmware', 'cross',
        lambda o: [sum(map(int, g(r'^\s*(\d+)\s+(\d+)\s+\d+\s+\d+\s+\w+\s+\S*embedded_scan.elf')(o)))]),
    Fig(R, 'example and {} for the online one', 'cross',
        lambda o: [sum(map(int, g(r'^\s*(\d+)\s+(\d+)\s+\d+\s+\d+\s+\w+\s+\S*embedded_online.elf')(o)))]),
    Fig(R, 'a block of {} KB of\n  which {} KB are used', 'embedded',
        nth(r'^block \d+ bytes, memory_size (\d+) bytes\nmemory_used (\d+)', 0), scale=KB),
    Fig(R, 'plus {} bytes of stack over the deepest', 'cross', nth(r'deepest chain from main: (\d+)', 0)),
    Fig(R, '{} M\n  instructions on the emulated chip', 'target',
        g(r'embedded_scan: library\s+total\s+(\d+)'), scale=1e-6),
    Fig(R, 'chip, {} ms at 168 MHz', 'target', g(r'embedded_scan: library\s+total\s+(\d+)'),
        scale=MHZ168),
    Fig(R, 'a block of {} KB ({} bytes) of\n  which {} KB are used', 'embedded',
        lambda o: (lambda b, u: [b, b, u])(*nth(r'^block \d+ bytes, memory_size (\d+) bytes\n'
                                                r'memory_used (\d+)', 1)(o)),
        scale=lambda i, v: float(v) * (1 if i == 1 else KB)),
    Fig(R, 'and {} bytes of\n  stack', 'cross', nth(r'deepest chain from main: (\d+)', 1)),
    Fig(R, 'update take at most {} M instructions ({} ms at 168 MHz)', 'target',
        lambda o: g(r'largest add \+ update \(scan \d+\) (\d+)')(o) * 2,
        scale=lambda i, v: float(v) * (1e-6 if i == 0 else MHZ168)),
    Fig(R, 'the finish {} M', 'target', g(r'embedded_online: finish\s+\d+\s+(\d+)'), scale=1e-6),
    Fig(R, 'about {} KB per square metre', 'footprint', nth(r'\s(\d+) bytes per square metre', 0),
        scale=KB),
    Fig(R, 'formula: {} KB + {} B/scan + {} B/beam + {} B/vertex + {} KB per 0.8 m tile', 'footprint',
        nth(r'memory_size = (\d+) \+ ([0-9.]+)/scan \+ ([0-9.]+)/beam \+ ([0-9.]+)/vertex \+ (\d+)/tile', 0),
        scale=lambda i, v: float(v) * (KB if i in (0, 4) else 1)),

    # docs/performance.md: memory, the Cortex-M4
    Fig(P, 'cm: {} B + {} B/scan + {} B/beam + {} B/vertex + {} B per 0.8 m tile', 'footprint',
        nth(r'memory_size = (\d+) \+ ([0-9.]+)/scan \+ ([0-9.]+)/beam \+ ([0-9.]+)/vertex \+ (\d+)/tile', 0)),
    Fig(P, '({} B per square metre of the bounding box), {} B\nper tile with 8-bit ones', 'footprint',
        lambda o: nth(r'\s(\d+) bytes per square metre', 0)(o) + nth(r'\+ (\d+)/tile', 1)(o)),
    Fig(P, 'libpolyc is {} B of flash', 'cross', g(r'^\s*(\d+)\s+\d+\s+\d+\s+\d+\s+\w+\s+\(TOTALS\)')),
    Fig(P, '| `examples/embedded_scan.c` | {} | {} | {} | {} B |', 'cross',
        lambda o: g(r'^\s*(\d+)\s+(\d+)\s+(\d+)\s+\d+\s+\w+\s+\S*embedded_scan.elf')(o)
        + nth(r'deepest chain from main: (\d+)', 0)(o)),
    Fig(P, '| `examples/embedded_online.c` | {} | {} | {} | {} B |', 'cross',
        lambda o: g(r'^\s*(\d+)\s+(\d+)\s+(\d+)\s+\d+\s+\w+\s+\S*embedded_online.elf')(o)
        + nth(r'deepest chain from main: (\d+)', 1)(o)),
    Fig(P, 'a block of {} B of\n  its {}, {} B used; {} polylines of {} vertices', 'embedded',
        lambda o: (lambda b, m, u, l, v: [m, b, u, l, v])(*nth(EMB, 0)(o))),
    Fig(P, 'endpoints, a block of {} B, {} B used; {} polylines of {} vertices', 'embedded',
        lambda o: nth(EMB, 1)(o)[1:]),
    Fig(P, 'cm of the room\'s true walls ({} cm and {} cm today)', 'target',
        lambda o: [g(r'embedded_scan: .*vertices within ([0-9.]+) m')(o)[0],
                   g(r'embedded_online: .*vertices within ([0-9.]+) m')(o)[0]], scale=100),
    Fig(P, '(the maps are {} and {} m\nlong)', 'target',
        lambda o: [g(r'embedded_scan: .* ([0-9.]+) m long')(o)[0],
                   g(r'embedded_online: .* ([0-9.]+) m long')(o)[0]]),
    Fig(P, '| one scan: config, sizing, `polyc_init` | {} | {} ms |', 'target',
        lambda o: g(r'embedded_scan: init\s+\d+\s+(\d+)')(o) * 2, scale=INSTR_MS),
    Fig(P, '| one scan: `polyc_add_scan` | {} | {} ms |', 'target',
        lambda o: g(r'embedded_scan: add\s+\d+\s+(\d+)')(o) * 2, scale=INSTR_MS),
    Fig(P, '| one scan: `polyc_build` | {} | {} ms |', 'target',
        lambda o: g(r'embedded_scan: build\s+\d+\s+(\d+)')(o) * 2, scale=INSTR_MS),
    Fig(P, '| one scan: the whole pipeline | {} | {} ms |', 'target',
        lambda o: g(r'embedded_scan: library\s+total\s+(\d+)')(o) * 2, scale=INSTR_MS),
    Fig(P, '| online: `polyc_online_add_scan`, scans 0-7 | {}-{} | {}-{} ms |', 'target',
        lambda o: (lambda a: [min(a), max(a)] * 2)(calls(o, 'add')),
        scale=lambda i, v: float(v) * (1 if i < 2 else MHZ168)),
    Fig(P, '| online: `polyc_online_update`, scans 0-7 | {}; {} at most (scan {}) | up to {} ms |', 'target',
        lambda o: (lambda u: [min(u), max(u), u.index(max(u)), max(u)])(calls(o, 'update')),
        scale=lambda i, v: float(v) * (MHZ168 if i == 3 else 1)),
    Fig(P, '| online: the largest add + update (scan {}) | {} | {} ms |', 'target',
        lambda o: (lambda s, n: [s, n, n])(*g(r'largest add \+ update \(scan (\d+)\) (\d+)')(o)),
        scale=lambda i, v: float(v) * (MHZ168 if i == 2 else 1)),
    Fig(P, '| online: `polyc_online_finish` | {} | {} ms |', 'target',
        lambda o: g(r'embedded_online: finish\s+\d+\s+(\d+)')(o) * 2, scale=INSTR_MS),
    Fig(P, '| online: the whole run | {} | {} ms |', 'target',
        lambda o: g(r'embedded_online: library\s+total\s+(\d+)')(o) * 2, scale=INSTR_MS),
    Fig(P, 'which the largest add and update\ntake {} % of at that', 'target',
        g(r'largest add \+ update \(scan \d+\) (\d+)'), scale=100 / 16.8e6),
    Fig(P, '| one scan | {} | {} % | `polyc__walk_step` {} %, `count_beam` {} %, `list_near_points` {} %, '
        '`beam_fill` {} % |',
        'profile', prof('embedded_scan', 'polyc__walk_step', 'count_beam', 'list_near_points', 'beam_fill')),
    Fig(P, '| online | {} | {} % | `list_near_points` {} %, `polyc__segment_region` {} %, '
        '`polyc__seg_pre_cost` {} %, `polyc__local_eval` {} % |',
        'profile', prof('embedded_online', 'list_near_points', 'polyc__segment_region',
                        'polyc__seg_pre_cost', 'polyc__local_eval')),
    # docs/performance.md: the sweep's summary, every column but ms
    Table(P, 'sweep', 'sweep', skip_cols=(4,)),

    # --data: the TurtleBot3 map, intel through the tool
    Fig(R, 'The TurtleBot3 world map ({} × {} cells at {}\ncm) gives {} polylines of {} vertices', 'turtlebot',
        lambda o: g(r'^map\s+(\d+) x (\d+) cells of ([0-9.]+) m')(o) + g(FINAL)(o),
        scale=lambda i, v: float(v) * (100 if i == 2 else 1)),
    Fig(A, 'covers the whole build: {} bytes for the turtlebot3 map\n  ({} x {} cells, {} occupied',
        'turtlebot', lambda o: g(r'^memory\s+block (\d+)')(o) + g(r'^map\s+(\d+) x (\d+)')(o)
        + g(r'^cells\s+occupied (\d+)')(o)),
    Fig(P, 'the TurtleBot3 map takes a block\nof {} bytes and gives {} polylines of {} vertices', 'turtlebot',
        lambda o: g(r'^memory\s+block (\d+)')(o) + g(FINAL)(o)),
    Fig(R, '| initial polylines: {} polylines, {} vertices |', 'intel-initial', g(r'^initial\s+(\d+) polylines, (\d+)')),
    Fig(R, '| optimised: {} polylines, {} vertices, no crossing |', 'intel', g(FINAL)),
    Fig(R, 'on `carmen/intel.log` ({} scans, {} beams; `make images`)', 'bench',
        cell('main', 'carmen/intel', (1, 2))),
    Fig(A, 'intel\'s 910 corrections take {} ms in the update that applies', 'bench',
        cell('correct', 'carmen/intel', 6), time=True),
    # --data: docs/formats.md, the FLASER no-return threshold found on each log
    Fig(FMT, '| intel | 81.83 | {} |', 'noreturn', noreturn(('intel',))),
    Fig(FMT, '| freiburg-079, csail, belgioioso | 81.91 | {} |', 'noreturn', noreturn(('freiburg-079', 'csail', 'belgioioso'))),
    Fig(FMT, '| freiburg-101, freiburg-campus | 81.83, 81.91 | {} |', 'noreturn', noreturn(('freiburg-101', 'freiburg-campus'))),
    Fig(FMT, '| seattle | 81.87–81.91 | {} |', 'noreturn', noreturn(('seattle',))),
    Fig(FMT, '| aces | 49.71–50.00 | {} |', 'noreturn', noreturn(('aces',))),
    Fig(FMT, '| acapulco | 50.00 and 51.14–51.25 | {} |', 'noreturn', noreturn(('acapulco',))),
    Fig(FMT, '| edmonton | 51.09–51.16 | {} |', 'noreturn', noreturn(('edmonton',))),
    Fig(FMT, '| fhw | 51.05–51.10 | {} |', 'noreturn', noreturn(('fhw',))),
    Fig(FMT, '| infinite-corridor | 51.01–51.16 | {} |', 'noreturn', noreturn(('infinite-corridor',))),
    Fig(FMT, '| orebro | 32.59–32.767 | {} |', 'noreturn', noreturn(('orebro',))),
    # --data: README, the online paragraph (make bench's online section)
    Fig(R, 'an add takes {} ms and an add with its update {} ms\n(medians)', 'bench',
        cell('online', 'carmen/intel', (4, 5)), time=True),
    Fig(R, 'the {} steps and the finish take {} s in all', 'bench',
        lambda o: cell('online', 'carmen/intel', (1, 8))(o), scale=lambda i, v: float(v) * (1 if i == 0 else 1e-3),
        time=True),
    Fig(R, 'for a map of {}\npolylines of {} vertices (the batch map: {} and {})', 'bench',
        lambda o: cell('final', 'carmen/intel online', (2, 3))(o) + cell('main', 'carmen/intel', (14, 15))(o)),
    Fig(R, 'The online map scores\n{} times the batch map\'s BIC on the batch\'s own data ({} against\n{};', 'bench',
        lambda o: cell('final', 'carmen/intel online', (6, 5))(o) + cell('final', 'carmen/intel batch', 4)(o)),
    Fig(R, 'corrected at once, the update that applies them takes {} ms', 'bench',
        cell('correct', 'carmen/intel', 6), time=True),
    Fig(R, 'under a load average of\n{} on the 2 cores', 'bench', g(r'load average at the start: ([0-9.]+)'),
        time=True),
    # --data: README, the simulated logs
    Fig(R, 'comes out\nas {} polylines of {} vertices', 'bench', cell('main', 'sim/corridor', (14, 15))),
    Fig(R, '| corridor ({} scans, {} beams) | {} / {} | {} mm | {} | {} s |', 'bench',
        cell('main', 'sim/corridor', (1, 2, 15, 16, 18, 22, 10)), scale=lambda i, v: float(v) * (1e-3 if i == 6 else 1)),
    Fig(R, '| angled (30°/60° walls) | {} / {} | {} mm | {} | {} s |', 'bench',
        cell('main', 'sim/angled', (15, 16, 18, 22, 10)), scale=lambda i, v: float(v) * (1e-3 if i == 4 else 1)),
    Fig(R, '| office (rooms through doors) | {} / {} | {} mm | {} | {} s |', 'bench',
        cell('main', 'sim/office', (15, 16, 18, 22, 10)), scale=lambda i, v: float(v) * (1e-3 if i == 4 else 1)),
    Fig(R, 'scores {}, {} and {}\nmm (column `fit`)', 'bench',
        lambda o: [cell('main', 'sim/' + k, 21)(o)[0] for k in ('corridor', 'angled', 'office')]),
    Fig(R, 'the library\'s\nmaps score {}–{} mm (core precision)', 'bench',
        over_rows('occ', 9, lambda v: [min(v), max(v)], prefix='sim/', method='libpolyc')),
    Fig(R, 'do, {}–{} mm with\n{} to {} times the ideal vertex count', 'bench',
        lambda o: over_rows('occ', 9, lambda v: [min(v), max(v)], 'sim/', 'contours')(o)
        + over_rows('occ', 8, lambda v: [min(v), max(v)], 'sim/', 'contours')(o)),
    # --data: README, the real logs
    Fig(R, '(same-side doubled walls, `band15`, at most {} % of a map\'s length', 'bench',
        over_rows('topo', 9, lambda v: [max(v)])),
    Fig(R, 'no segment crosses another ({} crossings)', 'bench', over_rows('topo', 4, lambda v: [max(v)])),
    Fig(R, 'along another ({} m of double cover)', 'bench', over_rows('topo', 2, lambda v: [max(v)])),
    Fig(R, 'at most {} runs over 20 cm without a\nscan endpoint per 100 m of map', 'bench', per100m),
    Fig(R, 'map: intel {} with {} vertices in {} s', 'bench',
        lambda o: cell('topo', 'carmen/intel', 10)(o) + cell('main', 'carmen/intel', (15, 10))(o),
        scale=lambda i, v: float(v) * (1e-3 if i == 2 else 1)),
    Fig(R, 'freiburg-079 ({} M beams)\n{}, aces {}, fhw {}', 'bench',
        lambda o: cell('main', 'carmen/freiburg-079', 2)(o) + [cell('topo', 'carmen/' + k, 10)(o)[0]
                                                              for k in ('freiburg-079', 'aces', 'fhw')],
        scale=lambda i, v: float(v) * (1e-6 if i == 0 else 1)),
    Fig(R, 'over {} scans of each of\nthe {} logs (`make bench`), f = {} and ray RMSE {}–{} mm', 'bench',
        lambda o: over_rows('single', 1, lambda v: [max(v), len(v)])(o)
        + over_rows('single', 2, lambda v: [min(v)])(o) + over_rows('single', 3, lambda v: [min(v), max(v)])(o)),
    Fig(R, 'in {}–{} ms a\nscan (the median per log), none over {} ms, none with a crossing', 'bench',
        lambda o: over_rows('single', 6, lambda v: [min(v), max(v)])(o) + [2 + over_rows('single', 8, sum)(o)]),
    # --data: docs/performance.md, the bench's tables (times not compared)
    Table(P, 'main', 'bench', skip_cols=tuple(range(3, 11)) + (13,)),  # times, the process's RSS
    Table(P, 'topo', 'bench', skip_cols=(15,)),
    Table(P, 'occ', 'bench', skip_cols=(4, 15)),
    Table(P, 'online', 'bench', skip_cols=range(4, 11)),
    Table(P, 'final', 'bench'),
    Fig(P, 'maze               files     {}x{}   {}       - | read', 'bench',
        g(r'^maze\s+files\s+(\d+)x(\d+)\s+(\d+)\s')),
    Fig(P, '(target < 1000); {} lines, {} vertices', 'bench', g(r'^maze\s.*\(target < 1000\); (\d+) lines, (\d+) vertices')),
    Fig(P, 'ms: total {} ms (target', 'bench', g(r'^maze\s.* ms: total ([0-9.]+) ms'), time=True),
    Fig(P, 'On every log f = {} (every', 'bench', over_rows('single', 2, lambda v: [min(v)])),
    Fig(P, 'with a ray RMSE of {}–{} mm', 'bench', over_rows('single', 3, lambda v: [min(v), max(v)])),
    Fig(P, 'takes {}–{} ms (the median per log), the slowest {} ms', 'bench',
        lambda o: over_rows('single', 6, lambda v: [min(v), max(v)])(o) + over_rows('single', 7, lambda v: [max(v)])(o),
        time=True),
    Fig(P, 'load average of about {} on the 2 cores', 'bench', g(r'load average at the start: ([0-9.]+)'),
        scale=1, time=True),
    Fig(P, 'an add takes {} ms and an add with its update {} ms (medians)', 'bench',
        cell('online', 'carmen/intel', (4, 5)), time=True),
    Fig(P, 'the 910 steps and the finish take {} s, {} times the batch build\'s', 'bench',
        cell('online', 'carmen/intel', (8, 9)), scale=lambda i, v: float(v) * (1e-3 if i == 0 else 1), time=True),
    Fig(P, 'for a map of {} polylines of {} vertices (batch: {} and {})\nscoring {} times', 'bench',
        lambda o: cell('final', 'carmen/intel online', (2, 3))(o) + cell('main', 'carmen/intel', (14, 15))(o)
        + cell('final', 'carmen/intel online', 6)(o)),
    Fig(P, 'sized for its area ({} MiB; batch {})', 'bench', cell('memory', 'carmen/intel', (2, 3))),
    Fig(P, 'intel replayed {} times over\nin the block of one pass ends ok with {} vertices', 'bench',
        lambda o: cell('memory', 'carmen/intel', 4)(o) + cell('memmap', 'carmen/intel 10', 4)(o)),
    Fig(P, 'the `polyc_online_correct` calls take {} ms,\nthe update that applies them {} ms', 'bench',
        cell('correct', 'carmen/intel', (4, 6)), time=True),
    Fig(P, 'and {} updates re-converge the map', 'bench', cell('correct', 'carmen/intel', 7)),
    Fig(P, 're-converge the map: {}\nvertices, {} times the batch map\'s BIC', 'bench',
        cell('corrmap', 'carmen/intel corrected', (3, 6))),
]


# ---- checking ---------------------------------------------------------------
NUM = r'([0-9][0-9,]*(?:\.[0-9]+)?)'


def doc_pattern(text):
    parts = text.split('{}')
    esc = [r'\s+'.join(re.escape(w) for w in p.split()) for p in parts]
    # keep the white space at a part's edges: 'of {} vertices' needs the blanks
    out = ''
    for i, (p, e) in enumerate(zip(parts, esc)):
        if p[:1].isspace() and e:
            e = r'\s+' + e
        if p[-1:].isspace() and e:
            e = e + r'\s+'
        elif p.strip() == '' and p:
            e = r'\s+'
        out += e + (NUM if i < len(parts) - 1 else '')
    return out


def as_number(s):
    s = str(s).replace(',', '')
    return float(s), (len(s.split('.')[1]) if '.' in s else 0)


def same(quoted, measured, dec):
    return '%.*f' % (dec, measured + 0.0) == '%.*f' % (dec, quoted)


class Runner:
    def __init__(self, args):
        self.args, self.cache, self.secs = args, {}, {}
        self.tmp = os.path.join(args.build, 'docs-figures')
        os.makedirs(os.path.join(ROOT, self.tmp), exist_ok=True)

    def command(self, src):
        a = self.args
        if src == 'bench':
            cmd = COMMANDS['bench'].format(data=a.data)
            return cmd + (' (its saved output %s)' % a.bench_out if a.bench_out else '')
        return SOURCES[src].format(polyc=os.path.join(a.build, 'polyc'), tmp=self.tmp,
                                   make=a.make, build=a.build, data=a.data)

    def output(self, src):
        if src in self.cache:
            return self.cache[src]
        t0 = time.time()
        if src == 'bench' and self.args.bench_out:
            with open(self.args.bench_out, encoding='utf-8', errors='replace') as f:
                out = f.read()
        else:
            cmd = self.command(src)
            if src == 'bench':
                cmd = '%s bench DATA=%s' % (self.args.make, shlex.quote(self.args.data))
            p = subprocess.run(cmd, shell=True, cwd=ROOT, stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, universal_newlines=True,
                               timeout=BENCH_TIMEOUT, errors='replace')
            out = p.stdout
            if p.returncode != 0:
                out = '\n(exit %d)' % p.returncode + out
                self.cache[src] = out
                raise RuntimeError('`%s` failed (exit %d):\n%s' % (cmd, p.returncode, out[-2000:]))
        self.secs[src] = time.time() - t0
        self.cache[src] = out
        return out


def table_cell_span(line, col, occ=False):
    """where the col-th cell of a table row (its tokens but '|') stands in line"""
    toks = [m for m in re.finditer(r'\S+', line) if m.group(0) != '|']
    if occ and col >= 5:
        col += 1  # (the occupancy table's method column is part of its key)
    return toks[col].span() if col < len(toks) else None


def check_table(t, text, runner, fixes=None):
    """(cells compared, failures) of a Table; with a list `fixes`, each
    differing cell also as (document, start, end, measured) in the text"""
    cmd = runner.command(t.src)
    quoted = t.rows(text)
    own_line = dict(ROW_LINES.get(t.name, {})) if t.name != 'sweep' else {}
    if not quoted:
        return 0, ['%s: no %s in the document (tools/docs_figures.py, its Table entry)' % (t.doc, t.text)]
    try:
        measured = t.rows(runner.output(t.src))
    except (LookupError, RuntimeError) as e:
        return 0, ['%s: %s: cannot measure: %s (`%s`)' % (t.doc, t.text, e, cmd)]
    n, bad = 0, []
    for key, row in quoted.items():
        line = own_line[key] + 1 if key in own_line else next(
            (i + 1 for i, ln in enumerate(text.splitlines())
             if ln.split()[:1] == key.split()[:1] and set(key.split()) <= set(ln.split())), 0)
        where = '%s:%d: %s, row %s' % (t.doc, line, t.text, key)
        got = measured.get(key)
        if got is None:
            bad.append('%s: not in the output of `%s`' % (where, cmd))
            continue
        for c, q in enumerate(row):
            if c in t.skip:
                continue
            n += 1
            m = got[c] if c < len(got) else '(none)'
            if q != m:
                if fixes is not None and line:
                    at = sum(len(ln) + 1 for ln in text.splitlines()[:line - 1])
                    span = table_cell_span(text.splitlines()[line - 1], c, t.name == 'occ')
                    if span:
                        fixes.append((t.doc, at + span[0], at + span[1], m))
                head = HEADS.get(t.name, [])
                col = '%d (%s)' % (c, head[c]) if c < len(head) else '%d' % c
                bad.append('%s, column %s: %s quoted, %s measured by `%s`' % (where, col, q, m, cmd))
    return n, bad


def quote_like(quoted, value):
    """value written as quoted is: its decimals, its thousands commas"""
    _, dec = as_number(quoted)
    out = '%.*f' % (dec, value)
    if ',' in quoted:
        whole, _, frac = out.partition('.')
        out = '{:,}'.format(int(whole)) + ('.' + frac if frac else '')
    return out


def check(figs, runner, band, compare_times, fixes=None):
    """(failures, figures checked, timings); with a list `fixes`, each differing
    figure outside the tables also as (document, start, end, measured as quoted)"""
    docs = {}
    fails, checked, times = [], 0, []
    for fig in figs:
        if fig.doc not in docs:
            with open(os.path.join(ROOT, fig.doc), encoding='utf-8') as f:
                docs[fig.doc] = f.read()
        text = docs[fig.doc]
        if isinstance(fig, Table):
            n, bad = check_table(fig, text, runner, fixes)
            checked += n
            fails.extend(bad)
            continue
        found = list(re.finditer(doc_pattern(fig.text), text))
        where = '%s: "%s"' % (fig.doc, ' '.join(fig.text.split()))
        if len(found) != 1:
            fails.append('%s: the text is %s in the document (update the entry in '
                         'tools/docs_figures.py with the text)' %
                         (where, 'not' if not found else '%d times' % len(found)))
            continue
        m = found[0]
        line = text.count('\n', 0, m.start()) + 1
        where = '%s:%d: "%s"' % (fig.doc, line, ' '.join(m.group(0).split()))
        cmd = runner.command(fig.src)
        try:
            vals = fig.read(runner.output(fig.src))
        except (LookupError, RuntimeError, ValueError) as e:
            fails.append('%s: cannot measure: %s (`%s`)' % (where, e, cmd))
            continue
        if len(vals) != len(m.groups()):
            fails.append('%s: %d figures quoted, %d measured by `%s`' %
                         (where, len(m.groups()), len(vals), cmd))
            continue
        for i, (q, v) in enumerate(zip(m.groups(), vals)):
            quoted, dec = as_number(q)
            sc = fig.scale
            try:
                meas = sc(i, v) if callable(sc) else float(str(v).replace(',', '')) * sc
            except ValueError:
                fails.append('%s: figure %d: %s quoted, "%s" measured by `%s`' % (where, i + 1, q, v, cmd))
                continue
            checked += 1
            if fig.time:
                ratio = meas / quoted if quoted else float('inf')
                times.append('%s: figure %d: %s quoted, %.*f measured' % (where, i + 1, q, dec, meas))
                if compare_times and not (1 / band <= ratio <= band):
                    fails.append('%s: timing %s quoted, %.*f measured (outside %.1f x either way) by `%s`'
                                 % (where, q, dec, meas, band, cmd))
                continue
            if not same(quoted, meas, dec):
                if fixes is not None:
                    fixes.append((fig.doc, m.start(i + 1), m.end(i + 1), quote_like(q, meas)))
                desc = getattr(fig.read, 'desc', None)
                fails.append('%s: figure %d: %s quoted, %.*f measured%s by `%s`'
                             % (where, i + 1, q, max(dec, 1) if meas != int(meas) else 0, meas,
                                ' (%s)' % desc if desc else '', cmd))
    return fails, checked, times


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('--make', default='make')
    ap.add_argument('--build', default='build')
    ap.add_argument('--data', help='the data folder: check the figures of the real logs')
    ap.add_argument('--bench-out', help='with --data: a saved `make bench DATA=...` output')
    ap.add_argument('--band', type=float, default=2.0,
                    help='with --data: timings within BAND x or 1/BAND x the quoted (default 2)')
    ap.add_argument('--list', action='store_true', help='print each figure\'s document, text and command')
    ap.add_argument('--fix', action='store_true',
                    help='write each differing figure outside the tables into its document as '
                         'measured (as the document writes it: decimals, commas); read the diff')
    args = ap.parse_args()
    data = bool(args.data)
    if data and not os.path.isdir(args.data):
        print('docs-figures: data folder %s not found: pass DATA=path (a folder with carmen/, '
              'sim/ and maps/: build-bench/bench --help)' % args.data)
        return 2
    figs = [f for f in FIGURES if (f.src in DATA_SOURCES) == data]
    runner = Runner(args)
    if args.list:
        for f in figs:
            print('%s\t"%s"\t`%s`' % (f.doc, ' '.join(f.text.split()), runner.command(f.src)))
        return 0
    t0 = time.time()
    fixes = [] if args.fix else None
    fails, checked, times = check(figs, runner, args.band, data, fixes)
    for doc in sorted({d for d, _, _, _ in fixes or []}):
        path = os.path.join(ROOT, doc)
        with open(path, encoding='utf-8') as f:
            text = f.read()
        for _, a, b, new in sorted((x for x in fixes if x[0] == doc), key=lambda x: -x[1]):
            pad = (b - a) - len(new)
            while pad < 0 and a > 0 and text[a - 1] == ' ' and a - 2 >= 0 and text[a - 2] == ' ':
                a, pad = a - 1, pad + 1  # (eat a blank of the column before, keep one)
            text = text[:a] + ' ' * max(pad, 0) + new + text[b:]
        with open(path, 'w', encoding='utf-8') as f:
            f.write(text)
        print('docs-figures: wrote %d figures into %s' % (sum(1 for x in fixes if x[0] == doc), doc))
    name = 'docs-figures-data' if data else 'docs-figures'
    for t in times:
        print('%s: timing%s: %s' % (name, '' if data else ' (not compared)', t))
    for f in fails:
        print('%s: FAIL %s' % (name, f))
    srcs = ', '.join('%s %.1f s' % kv for kv in runner.secs.items())
    print('%s: %d figures of %d entries in %d documents, %d differ; sources: %s; %.1f s' %
          (name, checked, len(figs), len({f.doc for f in figs}), len(fails), srcs, time.time() - t0))
    return 1 if fails else 0


if __name__ == '__main__':
    sys.exit(main())
