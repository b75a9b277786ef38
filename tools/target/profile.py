#!/usr/bin/env python3
"""profile.py - where an emulated Cortex-M4F run spends its instructions,
from the PC samples of the harness (startup.c built with -DTARGET_PROFILE:
a sample every 4,000 instructions).

usage: profile.py --elf FILE.elf [--nm arm-none-eabi-nm] [--top 15] [--callers]
                  [--call WHAT --out RUN.out] --name NAME PCS.bin

Prints the share of the samples of the top functions, and the share in
software double-precision routines (libgcc's __aeabi_d*, __*df3, __*df2,
conversions to and from double) and in double libm (sin, cos, sqrt, atan2 ...
and their __ieee754_ / __kernel_ helpers).
"""
import argparse
import bisect
import collections
import re
import struct
import subprocess
import sys

SOFT_DOUBLE = re.compile(r"^__(aeabi_(d|[fil]2d|d2|ui2d|ul2d)\w*|\w+df[23]|extendsfdf2|truncdfsf2|"
                         r"fix\w*df\w*|float\w*df|(eq|ne|lt|le|gt|ge|un|cmp)df2|"
                         r"aeabi_cdc\w+|aeabi_cdrc\w+|clzdi2|muldi3|udivmoddi4|aeabi_[lu]?ldivmod)$")
# (newlib's float kernels, __ieee754_rem_pio2f, __kernel_cosf, ..., end in f)
DOUBLE_LIBM = re.compile(r"^(__ieee754_\w*[^f\W]|__kernel_\w*[^f\W]|sin|cos|tan|atan2?|asin|acos|exp|log|log10|pow|sqrt|"
                         r"hypot|floor|ceil|fabs|fmod|round|lround|copysign|scalbn|frexp|ldexp|modf|"
                         r"rint|nearbyint|trunc)$")


def symbols(nm, elf):
    out = subprocess.run([nm, "-n", "--defined-only", elf], check=True,
                         capture_output=True, text=True).stdout
    addrs, names = [], []
    for line in out.splitlines():
        w = line.split()
        if len(w) == 3 and w[1] in "tTwW":
            addrs.append(int(w[0], 16) & ~1)
            names.append(w[2])
    return addrs, names


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--elf", required=True)
    ap.add_argument("--nm", default="arm-none-eabi-nm")
    ap.add_argument("--top", type=int, default=15)
    ap.add_argument("--name", default="")
    ap.add_argument("--callers", action="store_true",
                    help="also the callers of the double routines (by the sampled LR)")
    ap.add_argument("--call", metavar="WHAT",
                    help="only the samples of the calls marked WHAT (the run's own "
                         "'instructions WHAT INDEX N' lines, from --out)")
    ap.add_argument("--out", help="the profiled run's output (for --call)")
    ap.add_argument("pcs")
    a = ap.parse_args()
    data = open(a.pcs, "rb").read()
    words = struct.unpack("<%dI" % (len(data) // 4), data)
    pcs, lrs = words[0::2], words[1::2]
    if a.call:
        # samples are 4,000 instructions apart from main's start: keep those
        # that fall in the marked calls' spans
        spans, t = [], 0
        for line in open(a.out):
            w = line.split()
            if len(w) == 4 and w[0] == "instructions":
                n = int(w[3])
                if w[1] == a.call:
                    spans.append((t, t + n))
                t += n
        keep = [k for k in range(len(pcs)) if any(lo <= k * 4000 < hi for lo, hi in spans)]
        pcs = [pcs[k] for k in keep]
        lrs = [lrs[k] for k in keep]
    if not pcs:
        sys.exit("profile.py: no samples in " + a.pcs)
    addrs, names = symbols(a.nm, a.elf)

    def name(addr):
        i = bisect.bisect_right(addrs, addr & ~1) - 1
        return names[i] if i >= 0 else "?"
    hist = collections.Counter()
    callers = collections.Counter()  # soft double and double libm, by the caller (LR)
    for pc, lr in zip(pcs, lrs):
        f = name(pc)
        hist[f] += 1
        if SOFT_DOUBLE.match(f) or DOUBLE_LIBM.match(f):
            callers[name(lr)] += 1
    n = len(pcs)
    soft = sum(c for f, c in hist.items() if SOFT_DOUBLE.match(f))
    libm = sum(c for f, c in hist.items() if DOUBLE_LIBM.match(f))
    print("profile %s: %d samples (about %d M instructions)" % (a.name, n, n * 4000 // 1000000))
    print("profile %s: software double arithmetic %.1f %%, double libm %.1f %%"
          % (a.name, 100.0 * soft / n, 100.0 * libm / n))
    for f, c in hist.most_common(a.top):
        kind = " (soft double)" if SOFT_DOUBLE.match(f) else " (double libm)" if DOUBLE_LIBM.match(f) else ""
        print("profile %s: %6.2f %%  %s%s" % (a.name, 100.0 * c / n, f, kind))
    for f, c in callers.most_common(a.top if a.callers else 0):
        print("profile %s: %6.2f %%  double work called from %s" % (a.name, 100.0 * c / n, f))
    return 0


if __name__ == "__main__":
    sys.exit(main())
