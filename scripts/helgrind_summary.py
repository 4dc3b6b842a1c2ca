#!/usr/bin/env python3
"""Sorts the helgrind reports of `make helgrind` (valgrind XML files given as arguments).

Helgrind sees every load, store and pthread call of the whole manager, ROS and boost
included, so unlike ThreadSanitizer it needs no instrumented ROS. What it cannot see is
ordering made by lock-free atomics: a shared_ptr's count reaching zero on one thread
after another thread used the object, boost::once_flag, std::atomic counters. Reports
are sorted into
  ours        a racing load or store made by our code (nodelets or core): a finding;
  handover    ours only as the object destroyed after an atomic count reached zero;
  rosconsole  the unguarded statics that ROS_* / NODELET_* macros keep per call site
              (shared by every instance of a nodelet in one manager), by rosconsole's
              design;
  tbb         our code reading what OpenCV's parallel_for_ wrote on a TBB worker,
              ordered by TBB's lock-free task wait;
  library     both accesses made inside roscpp, boost, nodelet, tf2 or TBB (our code
              at most their caller): not ours to fix.
Exit status 1 when an `ours` report remains."""
import collections
import os
import re
import sys
import xml.etree.ElementTree as ET

OURS = ("mono_plane_detection::",)
OUR_LIB = "libmono_plane_detection"
LOG_MACRO = re.compile(r"\b(ROS|NODELET)_(DEBUG|INFO|WARN|ERROR|FATAL)\w*\(")
# Ordering helgrind cannot see: lock-free reference counts and atomics.
HANDOVER = ("sp_counted_base", "sp_counted_impl", "_Sp_counted_base", "_M_release",
            "shared_count", "std::atomic", "__atomic_base", "once_flag", "call_once")


SOURCE = {}  # (function, file:line) of a frame -> (directory, file, line)


def frames(stack):
    out = []
    for f in stack.findall("frame"):
        fn = f.findtext("fn") or "?"
        where = f.findtext("file")
        line = f.findtext("line")
        obj = f.findtext("obj") or "?"
        out.append((fn, "%s:%s" % (where, line) if where else obj, obj))
        if where:
            SOURCE[(fn, out[-1][1])] = (f.findtext("dir") or "", where, int(line))
    return out


def source_line(fn, where):
    """The source text of a frame, when its file is at hand (our own files are)."""
    if (fn, where) not in SOURCE:
        return ""
    directory, name, line = SOURCE[(fn, where)]
    try:
        with open(os.path.join(directory, name), errors="replace") as f:
            return f.readlines()[line - 1]
    except (OSError, IndexError):
        return ""


def in_log_macro(stack):
    """The access is made by a ROS_* / NODELET_* logging macro expanded in our code."""
    for fn, where, obj in stack:
        if any(p in obj for p in PASS_THROUGH):
            continue
        return bool(LOG_MACRO.search(source_line(fn, where)))
    return False


# Where the racing load or store was made: the first frame outside libc, libstdc++ and
# valgrind's own wrappers (a memcpy is made on behalf of its caller).
PASS_THROUGH = ("libc.so", "libstdc++", "vgpreload_", "ld-linux")


def accessing_object(stack):
    for _, _, obj in stack:
        if not any(p in obj for p in PASS_THROUGH):
            return obj
    return "?"


def is_ours(stack):
    return OUR_LIB in accessing_object(stack)


def first_ours(stack):
    for fn, where, _ in stack:
        if any(o in fn for o in OURS):
            return "%s (%s)" % (fn.split("(")[0], where)
    return "-"


def classify(stacks, where):
    if not any(is_ours(s) for s in stacks):
        return "library"
    # rosconsole's macros keep unguarded statics per call site by design (the
    # location's `initialized_` flag, the throttle's last time): shared by all
    # instances of a nodelet in one manager.
    if all(in_log_macro(s) or (s and "ros::console::" in s[0][0]) for s in stacks):
        return "rosconsole"
    # OpenCV's parallel_for_ hands its results back through TBB's lock-free task wait.
    if any("libtbb" in obj for s in stacks for _, _, obj in s):
        return "tbb"
    if any(any(h in fn for h in HANDOVER) for s in stacks for fn, _, _ in s[:12]):
        return "handover"
    return "ours"


def main(paths):
    kinds = collections.Counter()
    groups = collections.defaultdict(collections.Counter)
    examples = {}
    for path in paths:
        try:
            root = ET.parse(path).getroot()
        except ET.ParseError as e:  # a manager killed at the end leaves the file unclosed
            text = open(path, errors="replace").read()
            cut = text.rfind("</error>")
            root = ET.fromstring(text[:cut + len("</error>")] + "</valgrindoutput>") if cut > 0 else None
            if root is None:
                print("helgrind: %s unreadable (%s)" % (path, e))
                continue
        for error in root.iter("error"):
            kind = error.findtext("kind")
            what = error.findtext("xwhat/text") or error.findtext("what") or ""
            stacks = [frames(s) for s in error.findall("stack")]
            if kind == "Race":  # the two racing accesses; a third stack is the allocation
                stacks = stacks[:2]
            where = " ".join(a.text or "" for a in error.findall("auxwhat"))
            category = classify(stacks, where)
            kinds[(kind, category)] += 1
            if category == "ours":
                key = (kind, " | ".join(first_ours(s) for s in stacks if is_ours(s)))
                groups[category][key] += 1
                examples.setdefault(key, (what + "\n    " + where, stacks))
    total = sum(kinds.values())
    print("helgrind: %d report(s) in %d file(s)" % (total, len(paths)))
    for (kind, category), n in sorted(kinds.items()):
        print("  %5d %-9s %s" % (n, kind, category))
    ours = groups["ours"]
    print("helgrind: %d report(s) with our code on a racing stack" % sum(ours.values()))
    for (kind, key), n in ours.most_common():
        what, stacks = examples[(kind, key)]
        print("\n  %d x %s: %s" % (n, kind, what))
        for i, s in enumerate(stacks):
            print("    stack %d:" % i)
            for fn, where, _ in s[:14]:
                print("      %s  %s" % (fn[:110], where))
    return 1 if ours else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
