#!/usr/bin/env python3
"""Table of pathlab / Embree ratios from the files bench/run.sh writes: MESH.embree.K.txt
(embree_bench's output) and MESH.pathlab.K.json (`pathlab-bench rays --json`) for runs K = 1..N
taken in turns; each rate is the median over the runs. Usage: rays_table.py WORK N MESH..."""
import json, re, statistics, sys

work, reps, meshes = sys.argv[1], int(sys.argv[2]), sys.argv[3:]


def median_json(runs):
    """The runs' JSON with every number replaced by its median over the runs."""
    first = runs[0]
    if isinstance(first, dict):
        return {k: median_json([r[k] for r in runs]) for k in first}
    if isinstance(first, list):
        return [median_json(list(items)) for items in zip(*runs)]
    if isinstance(first, (int, float)) and not isinstance(first, bool):
        return statistics.median(runs)
    return first


def embree(m):
    """(build seconds, {threads: (primary, bounce)}), medians over the runs."""
    builds, rates = [], {}
    for k in range(1, reps + 1):
        text = open(f"{work}/{m}.embree.{k}.txt").read()
        builds.append(float(re.search(r"build_s ([0-9.]+)", text).group(1)))
        for t, p, b in re.findall(
                r"threads (\d+) primary_Mrays_per_s ([0-9.]+) bounce_Mrays_per_s ([0-9.]+)", text):
            rates.setdefault(int(t), []).append((float(p), float(b)))
    return statistics.median(builds), {
        t: (statistics.median(p for p, _ in v), statistics.median(b for _, b in v))
        for t, v in rates.items()}


def embree_bytes(m):
    """Embree's bytes per triangle with its vertex and index buffers (embree_memory's output),
    or None where it was not measured."""
    try:
        text = open(f"{work}/{m}.embree_memory.txt").read()
    except OSError:
        return None
    found = re.search(r"with_buffers_bytes_per_triangle ([0-9.]+)", text)
    return float(found.group(1)) if found else None


ours_of = {m: median_json([json.load(open(f"{work}/{m}.pathlab.{k}.json"))
                           for k in range(1, reps + 1)]) for m in meshes}
def bytes_cell(ours, theirs):
    """pathlab's bytes per triangle, Embree's and their ratio (pathlab's alone without it)."""
    if theirs is None:
        return f"{ours:5.0f}/{'-':<5} {'':>6}"
    return f"{ours:5.0f}/{theirs:<5.0f} {ours / theirs:6.2f}"


rows = []
print(f"{'mesh':<12} {'tris':>8} | {'build s':>16} {'ratio':>6} | "
      f"{'primary 1T Mrays/s':>19} {'ratio':>6} | {'packets of 8':>19} {'ratio':>6} | "
      f"{'bounce 1T Mrays/s':>18} {'ratio':>6} | "
      f"{'bounce NT':>13} {'ratio':>6} | {'B/tri':>11} {'ratio':>6} | {'agree %':>8}")
for m in meshes:
    build, per_thread = embree(m)
    e1, en = per_thread[1], per_thread[max(per_thread)]
    ours = ours_of[m]
    sets = {s["rays"]: s for s in ours["sets"]}
    p1 = sets["primary"]["mrays_per_s_1_thread"]
    p8 = sets["primary"]["mrays_per_s_1_thread_packets"]
    b1 = sets["bounce"]["mrays_per_s_1_thread"]
    bn = sets["bounce"]["mrays_per_s_all_threads"]
    agree = min(s["agreement"] for s in ours["sets"]) * 100
    print(f"{m:<12} {ours['triangles']:>8} | {ours['bvh_build_seconds']:7.3f}/{build:<8.3f} "
          f"{ours['bvh_build_seconds'] / build:6.2f} | {p1:8.2f}/{e1[0]:<10.2f} {p1 / e1[0]:6.2f} | "
          f"{p8:8.2f}/{e1[0]:<10.2f} {p8 / e1[0]:6.2f} | "
          f"{b1:7.2f}/{e1[1]:<10.2f} {b1 / e1[1]:6.2f} | {bn:5.2f}/{en[1]:<7.2f} {bn / en[1]:6.2f} | "
          f"{bytes_cell(ours['bytes_per_triangle'], embree_bytes(m))} | {agree:8.4f}")
print("(each cell: pathlab/Embree, medians of", reps, "runs taken in turns; ratio = pathlab / Embree,"
      " so > 1 is faster throughput, < 1 is faster build or less memory)")
print("(packets of 8: pathlab with eight consecutive rays walking its BVH together, against"
      " Embree's one ray at a time, rtcIntersect1, which is what embree_bench calls)")
print("(B/tri: pathlab's geometry bytes per triangle, everything its surface interactions read"
      " included; Embree's acceleration structure with its vertex and index buffers)")

# The obvhs crate's compressed wide BVH on the same rays, where pathlab was built with it.
rows = [(m, ours_of[m]) for m in meshes]
rows = [(m, d) for m, d in rows if "obvhs" in d.get("binary_bvh_baseline", {})]
if rows:
    print()
    print(f"{'mesh':<12} | {'obvhs build s':>13} | {'obvhs primary 1T':>17} {'pathlab/obvhs':>14} | "
          f"{'obvhs bounce 1T':>16} {'pathlab/obvhs':>14}")
    for m, d in rows:
        o = d["binary_bvh_baseline"]["obvhs"]
        sets = {s["rays"]: s for s in d["sets"]}
        p1 = sets["primary"]["mrays_per_s_1_thread"]
        b1 = sets["bounce"]["mrays_per_s_1_thread"]
        print(f"{m:<12} | {o['build_seconds']:13.3f} | {o['primary']['mrays_per_s']:17.2f} "
              f"{p1 / o['primary']['mrays_per_s']:14.2f} | {o['bounce']['mrays_per_s']:16.2f} "
              f"{b1 / o['bounce']['mrays_per_s']:14.2f}")
