#!/usr/bin/env python3
"""Sorts the ThreadSanitizer reports of `make tsan` by kind, and by whether our code is
on both sides of a race. Debian's ROS is not instrumented, so hand-overs inside roscpp
(message deserialised on one thread, used in the callback on another; nodelet created on
the main thread, called on a worker) show up as races; the count to look at is the last
line: races between two of our own accesses outside onInit and message hand-overs."""
import collections
import glob
import re
import sys

reports = []
for path in glob.glob(sys.argv[1] + "/*"):
    text = open(path, errors="replace").read()
    reports += [r for r in text.split("==================") if "WARNING: ThreadSanitizer" in r]

kinds = collections.Counter()
ours = collections.Counter()
for r in reports:
    kind = re.search(r"WARNING: ThreadSanitizer: ([^(]+)", r).group(1).strip()
    kinds[kind] += 1
    parts = re.split(r"\n\s*Previous ", r)
    if len(parts) < 2:
        continue
    previous = parts[1].split("Location is")[0].split("Mutex ")[0]
    first_ours = [l.strip() for l in parts[0].split("\n") if " #" in l and "mono_plane_detection::" in l]
    prev_ours = [l.strip() for l in previous.split("\n") if " #" in l and "mono_plane_detection::" in l]
    handover = any(s in previous for s in ("ros::serialization", "onInit", "shared_count", "MetaObject"))
    if first_ours and prev_ours and not handover:
        ours[(first_ours[0][:120], prev_ours[0][:120])] += 1

print("tsan: %d report(s)" % len(reports))
for kind, n in kinds.most_common():
    print("  %4d %s" % (n, kind))
print("tsan: %d race report(s) between two of our own accesses (not init, not a message hand-over)"
      % sum(ours.values()))
for (a, b), n in ours.most_common(5):
    print("  %d x %s\n       vs %s" % (n, a, b))
