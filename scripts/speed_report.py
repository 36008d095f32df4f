#!/usr/bin/env python3
"""Tabulates one `cargo bench --features peers --bench speed` run (criterion's JSON under target/criterion):
ns per box (criterion's median) for every path at 256, 1K, 64K and 4M boxes, and the
targets of the speed issue, each marked met or missed.

Usage: python3 scripts/speed_report.py [target/criterion] [GHz]
GHz converts ns to cycles for the L1-sized batch (default: the clock in /proc/cpuinfo).
"""
import json
import pathlib
import re
import sys

root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "target/criterion")
if len(sys.argv) > 2:
    ghz = float(sys.argv[2])
else:
    mhz = re.findall(r"cpu MHz\s*:\s*([0-9.]+)", pathlib.Path("/proc/cpuinfo").read_text())
    ghz = float(mhz[0]) / 1000 if mhz else 1.0

rows = {}
for bench in root.glob("**/new/benchmark.json"):
    meta = json.loads(bench.read_text())
    group = meta["group_id"]
    if not group.startswith("speed/"):
        continue
    size = group.split("/", 1)[1]
    name = meta["function_id"] + ("/" + meta["value_str"] if meta.get("value_str") else "")
    est = json.loads((bench.parent / "estimates.json").read_text())
    rows[(size, name)] = est["median"]["point_estimate"] / meta["throughput"]["Elements"]

sizes = [s for s in ["256", "1K", "64K", "4M"] if any(k[0] == s for k in rows)]
names = sorted({k[1] for k in rows}, key=lambda n: (not n.startswith("peer"), not n.startswith("roofline"), n))
get = lambda s, n: rows.get((s, n))

print("| path | " + " | ".join(f"{s}" for s in sizes) + " |")
print("|---|" + "---:|" * len(sizes))
for n in names:
    print(f"| {n} | " + " | ".join(f"{get(s, n):.2f}" if get(s, n) else "" for s in sizes) + " |")

print()
print(f"L1-sized batch (256 boxes), cycles per box at {ghz:.2f} GHz:")
for n in ["aosoa/abs-matrix/nearest", "aosoa/abs-matrix/outward", "aosoa/sign-select/nearest",
          "aosoa/sign-select/outward", "aosoa-rigid/abs-matrix/nearest", "aosoa-rigid/abs-matrix/outward"]:
    if get("256", n):
        print(f"- {n}: {get('256', n) * ghz:.1f} cycles")

print()
print("| target | measured | |")
print("|---|---|---|")


def target(label, pairs, limit, higher_is_better=False):
    """pairs: list of (size, numerator, denominator); the ratio must be <= limit."""
    cells, ok = [], True
    for s, a, b in pairs:
        x, y = get(s, a), get(s, b)
        if x is None or y is None:
            continue
        r = y / x if higher_is_better else x / y
        ok &= r >= limit if higher_is_better else r <= limit
        cells.append(f"{s}: {r:.2f}×")
    if cells:
        print(f"| {label} | {', '.join(cells)} | {'met' if ok else 'missed'} |")


# The targets of the subnormal issue (19): in cache, ratios within the run.
cache = ["256", "1K"]
layouts = ["single", "single-rigid", "aos", "aos-rigid", "soa", "soa-rigid", "aosoa", "aosoa-rigid",
           "aos2-rigid", "aos2-affine"]
for l in layouts:
    for m in ["abs-matrix", "sign-select"]:
        target(f"{l} {m}: Outward ≤ 1.2× Nearest", [(c, f"{l}/{m}/outward", f"{l}/{m}/nearest") for c in cache], 1.2)
for l in ["single", "aos", "soa", "aosoa", "aos2"]:
    target(f"{l}-translation: Outward ≤ 1.2× Nearest",
           [(c, f"{l}-translation/outward", f"{l}-translation/nearest") for c in cache], 1.2)
for m in ["abs-matrix", "sign-select"]:
    target(f"one box affine {m}: Nearest ≤ 1.15× the glam loop", [(c, f"single/{m}/nearest", "peer/glam-abs-matrix") for c in cache], 1.15)
    target(f"one box affine {m}: Outward ≤ 1.3× the glam loop", [(c, f"single/{m}/outward", "peer/glam-abs-matrix") for c in cache], 1.3)
    target(f"one box rigid {m}: Nearest ≤ 1.15× the glam rigid loop", [(c, f"single-rigid/{m}/nearest", "peer/glam-rigid-abs-matrix") for c in cache], 1.15)
    target(f"one box rigid {m}: Outward ≤ 1.3× the glam rigid loop", [(c, f"single-rigid/{m}/outward", "peer/glam-rigid-abs-matrix") for c in cache], 1.3)
    target(f"AoS affine {m}: Nearest ≥ 1.3× faster than the glam loop", [(c, f"aos/{m}/nearest", "peer/glam-abs-matrix") for c in cache], 1.3, True)
    target(f"AoS affine {m}: Outward no slower than the glam loop", [(c, f"aos/{m}/outward", "peer/glam-abs-matrix") for c in cache], 1.0, True)
    target(f"AoS rigid {m}: Nearest ≥ 1.3× faster than the glam rigid loop", [(c, f"aos-rigid/{m}/nearest", "peer/glam-rigid-abs-matrix") for c in cache], 1.3, True)
    target(f"AoS rigid {m}: Outward no slower than the glam rigid loop", [(c, f"aos-rigid/{m}/outward", "peer/glam-rigid-abs-matrix") for c in cache], 1.0, True)
target("AoSoA translation Outward ≤ 1.5× the glam translation loop", [(c, "aosoa-translation/outward", "peer/glam-translation") for c in cache], 1.5)

# The targets of the front-door issue (45): at 1K boxes in cache, and the AoS rows at 4M
# against the AoS copy roofline.
print()
print("| front-door target (issue 45) | measured | |")
print("|---|---|---|")
target("AoS affine abs-matrix: Nearest ≤ 0.77× the glam loop", [("1K", "aos/abs-matrix/nearest", "peer/glam-abs-matrix")], 0.77)
for m in ["abs-matrix", "sign-select"]:
    target(f"AoS affine {m}: Outward ≤ 1.0× the glam loop", [("1K", f"aos/{m}/outward", "peer/glam-abs-matrix")], 1.0)
target("AoS rigid abs-matrix: Nearest ≤ 0.7× the glam rigid loop", [("1K", "aos-rigid/abs-matrix/nearest", "peer/glam-rigid-abs-matrix")], 0.7)
target("AoS translation: Outward ≤ 1.3× the glam translation loop", [("1K", "aos-translation/outward", "peer/glam-translation")], 1.3)
target("one box affine abs-matrix: Nearest ≤ 1.3× the glam loop", [("1K", "single/abs-matrix/nearest", "peer/glam-abs-matrix")], 1.3)
target("one box affine abs-matrix: Outward ≤ 1.5× the glam loop", [("1K", "single/abs-matrix/outward", "peer/glam-abs-matrix")], 1.5)
for m in ["abs-matrix", "sign-select"]:
    for r in ["nearest", "outward"]:
        target(f"AoS affine {m} {r} at 4M: ≤ 1.15× the AoS roofline", [("4M", f"aos/{m}/{r}", "roofline/aos")], 1.15)
