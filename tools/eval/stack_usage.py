#!/usr/bin/env python3
"""stack_usage.py - worst-case stack depth of a program from GCC's call graphs.

usage: stack_usage.py [--root main] [--top 10] [--cross arm-none-eabi-]
                      [--elf FILE.elf] FILE.ci...

Input: the .ci files of -fstack-usage -fcallgraph-info=su (frame sizes as in
the .su files) with their objects FILE.o next to them. Output: the largest
frames, and the deepest call chain from --root with its total.

- An indirect call may reach any function whose address is taken in the
  objects (a relocation that is not a call); the worst of them is counted.
- Functions outside the graph (newlib, libgcc) get their frame from the
  disassembly of the linked --elf (push, vpush, sub sp in the prologue) and
  their callees from its bl/b.w instructions; without --elf they count 0.
- A recursive cycle is cut at the back edge and reported: count its depth
  by hand.
"""
import argparse
import re
import subprocess
import sys

CALL_RELOCS = {"R_ARM_THM_CALL", "R_ARM_THM_JUMP24", "R_ARM_THM_JUMP19",
               "R_ARM_CALL", "R_ARM_JUMP24", "R_ARM_PC24"}
INDIRECT = "__indirect_call"


def read_graphs(paths):
    """frames {title: bytes}, edges {title: [title]}, names {title: name}, file of each .ci."""
    frames, edges, names, units = {}, {}, {}, {}
    node = re.compile(r'node: \{ title: "([^"]+)" label: "([^"]*)"')
    edge = re.compile(r'edge: \{ sourcename: "([^"]+)" targetname: "([^"]+)"')
    for path in paths:
        with open(path) as f:
            for line in f:
                m = node.match(line)
                if m:
                    title, label = m.groups()
                    parts = label.split("\\n")
                    names[title] = parts[0]
                    size = re.match(r"(\d+) bytes", parts[-1])
                    if size:
                        frames[title] = int(size.group(1))
                    continue
                m = edge.match(line)
                if m:
                    edges.setdefault(m.group(1), []).append(m.group(2))
                elif line.startswith("graph:"):
                    units[path] = re.search(r'title: "([^"]+)"', line).group(1)
    return frames, edges, names, units


def address_taken(cross, units, frames):
    """Titles of the functions whose address is taken in the objects."""
    taken = set()
    for ci, unit in units.items():
        obj = ci[:-3] + ".o"
        out = subprocess.run([cross + "objdump", "-r", obj], capture_output=True,
                             text=True, check=True).stdout
        for line in out.splitlines():
            f = line.split()
            if len(f) != 3 or f[1] in CALL_RELOCS or not f[1].startswith("R_"):
                continue
            sym = f[2].split("+")[0]
            sym = sym[len(".text."):] if sym.startswith(".text.") else sym
            for title in (unit + ":" + sym, sym):
                if title in frames:
                    taken.add(title)
                    break
    return taken


def read_elf(cross, elf):
    """Frames and callees of every function of a linked image, from its disassembly."""
    out = subprocess.run([cross + "objdump", "-d", "--no-show-raw-insn", elf],
                         capture_output=True, text=True, check=True).stdout
    frames, calls, cur, prologue = {}, {}, None, 0
    head = re.compile(r"^[0-9a-f]+ <([^>]+)>:$")
    for line in out.splitlines():
        m = head.match(line)
        if m:
            cur, prologue = m.group(1), 24
            frames[cur], calls[cur] = 0, set()
            continue
        f = line.split("\t")
        if cur is None or len(f) < 2:
            continue
        op, arg = f[1].strip(), f[2] if len(f) > 2 else ""
        if prologue > 0:
            prologue -= 1
            if op.startswith("push") or (op.startswith("stmdb") and arg.startswith("sp!")):
                frames[cur] += 4 * len(re.findall(r"\b(r\d+|lr|ip|fp|sl|sb)\b", arg.split("{")[-1]))
            elif op.startswith("vpush"):
                regs = re.findall(r"[ds](\d+)", arg)
                span = re.search(r"([ds])(\d+)-[ds](\d+)", arg)
                n = int(span.group(3)) - int(span.group(2)) + 1 if span else len(regs)
                frames[cur] += n * (8 if "d" in arg else 4)
            elif re.match(r"subw?(\.w)?$", op) and arg.startswith("sp, "):
                imm = re.search(r"#(\d+)", arg)
                frames[cur] += int(imm.group(1)) if imm else 0
        target = re.search(r"<([^>+]+)>$", line)
        if target and op.startswith("b") and target.group(1) != cur:  # calls, tail calls
            calls[cur].add(target.group(1))
    # other names of the same code (__aeabi_dadd is __adddf3)
    by_addr = {}
    for line in subprocess.run([cross + "nm", elf], capture_output=True, text=True,
                               check=True).stdout.splitlines():
        f = line.split()
        if len(f) == 3 and f[1] in "TtWw":
            by_addr.setdefault(f[0], []).append(f[2])
    for aliases in by_addr.values():
        known = [n for n in aliases if n in frames]
        for n in aliases:
            if known and n not in frames:
                frames[n], calls[n] = frames[known[0]], calls[known[0]]
    return frames, calls


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--root", default="main")
    ap.add_argument("--top", type=int, default=10)
    ap.add_argument("--cross", default="arm-none-eabi-")
    ap.add_argument("--elf")
    ap.add_argument("ci", nargs="+")
    a = ap.parse_args()

    frames, edges, names, units = read_graphs(a.ci)
    taken = address_taken(a.cross, units, frames)
    elf_frames, elf_calls = read_elf(a.cross, a.elf) if a.elf else ({}, {})
    recursive, outside = set(), set()
    memo = {}

    def plain(t):
        name = names.get(t, t)
        return name[len("__builtin_"):] if name.startswith("__builtin_") else name

    def callees(t):
        if t in frames:
            out = []
            for c in edges.get(t, []):
                out.extend(sorted(taken - {t}) if c == INDIRECT else [c])
            return out
        return sorted(elf_calls.get(plain(t), ()))

    def frame(t):
        if t in frames:
            return frames[t]
        name = plain(t)
        if name not in elf_frames:
            outside.add(name)
        return elf_frames.get(name, 0)

    def deepest(t, stack):
        """(bytes, chain) of the deepest path from t; cycles cut at the back edge."""
        if t in memo:
            return memo[t]
        stack.add(t)
        best = (0, [])
        for c in callees(t):
            if c in stack:
                recursive.add(names.get(c, c))
                continue
            best = max(best, deepest(c, stack), key=lambda x: x[0])
        stack.discard(t)
        memo[t] = (frame(t) + best[0], [t] + best[1])
        return memo[t]

    roots = [t for t in frames if names[t] == a.root]
    if not roots:
        sys.exit("stack_usage: no function %s in the graphs" % a.root)
    print("largest frames (-fstack-usage, bytes):")
    for t in sorted(frames, key=lambda t: -frames[t])[:a.top]:
        print("  %6d  %s" % (frames[t], t))
    total, chain = deepest(roots[0], set())
    print("deepest chain from %s: %d bytes" % (a.root, total))
    for t in chain:
        where = "" if t in frames else "   (from the ELF)" if plain(t) in elf_frames else "   (unknown: 0)"
        print("  %6d  %s%s" % (frame(t), plain(t), where))
    if taken:
        print("indirect calls resolved to: " + ", ".join(sorted(names[t] for t in taken)))
    if recursive:
        print("recursion cut (count its depth separately): " + ", ".join(sorted(recursive)))
    if outside:
        print("no frame known (counted 0): " + ", ".join(sorted(outside)))


if __name__ == "__main__":
    main()
