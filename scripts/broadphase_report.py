#!/usr/bin/env python3
"""Tabulates one `cargo bench --features peers --bench broadphase` run (criterion's JSON under
target/criterion): per active fraction, ns per active object of the update and of the
memory roofline of the same accesses, and their ratio, for the `stay` case (no fat box
rewritten) and the `moved` case (every active fat box rewritten); the naive path; and the
`pipeline` groups: per scene, the mean ms per frame of each stage of each pipeline, and
each frame as a ratio to pipeline A's; and the `frame-share` group: C's and R's whole frame
per moving body at each share of 100K awake bodies moving, and C's as a ratio to R's.
Usage: python3 scripts/broadphase_report.py [target/criterion]
"""
import json
import pathlib
import sys

root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "target/criterion")
rows = {}  # (fraction, name) -> (ns per active object, total ms)
stages = {}  # (scene, pipeline, stage) -> mean ms per frame
shares = {}  # (pipeline, share) -> (ns per moving body, ms per frame)
for bench in root.glob("**/new/benchmark.json"):
    meta = json.loads(bench.read_text())
    group = meta["group_id"]
    if group.startswith("pipeline/"):
        pipeline, stage = meta["function_id"].split("/")
        mean = json.loads((bench.parent / "estimates.json").read_text())["mean"]["point_estimate"]
        stages[(group.split("/", 1)[1], pipeline, stage)] = mean / 1e6
        continue
    if group.startswith("frame-share/"):
        pipeline, share = meta["function_id"].split("/")
        median = json.loads((bench.parent / "estimates.json").read_text())["median"]["point_estimate"]
        shares[(pipeline, share)] = (median / meta["throughput"]["Elements"], median / 1e6)
        continue
    if not group.startswith("broadphase/"):
        continue
    fraction = group.split("/", 1)[1]
    elements = meta["throughput"]["Elements"]
    median = json.loads((bench.parent / "estimates.json").read_text())["median"]["point_estimate"]
    rows[(fraction, meta["function_id"])] = (median / elements, median / 1e6)

print("| active | case | AoS update ns/active | roofline ns/active | update / roofline | AoS ms per frame | AoSoA update ns/active |")
print("|---|---|---:|---:|---:|---:|---:|")
for fraction in ["1%", "10%", "100%"]:
    for case in ["stay", "moved"]:
        u = rows.get((fraction, f"update/{case}"))
        r = rows.get((fraction, f"roofline/{case}"))
        b = rows.get((fraction, f"update-aosoa/{case}"))
        if u and r:
            aosoa = f"{b[0]:.1f}" if b else "-"
            print(f"| {fraction} | {case} | {u[0]:.1f} | {r[0]:.1f} | {u[0] / r[0]:.2f}x | {u[1]:.2f} | {aosoa} |")
naive = rows.get(("100%", "naive/transform"))
if naive:
    print(f"\nnaive (every tight box rewritten, 1M objects): {naive[0]:.1f} ns per object, {naive[1]:.2f} ms per frame")

STAGES = ["boxes", "leaves", "optimise", "refit", "pairs", "frame"]
if stages:
    print("\n| scene | pipeline | " + " | ".join(STAGES) + " | frame / A's |")
    print("|---|---|" + "---:|" * (len(STAGES) + 1))
    for scene in sorted({k[0] for k in stages}, key=lambda s: (len(s), s)):
        for pipeline in sorted({k[1] for k in stages if k[0] == scene}):
            cells = [stages.get((scene, pipeline, s)) for s in STAGES]
            a = stages.get((scene, "A", "frame"))
            ratio = f"{cells[-1] / a:.2f}x" if a and cells[-1] else "-"
            print(f"| {scene} | {pipeline} | " + " | ".join(f"{c:.2f}" if c is not None else "-" for c in cells) + f" | {ratio} |")

if shares:
    print("\n| share moving | C ns per moving body | C ms per frame | R ns per moving body | R ms per frame | C / R |")
    print("|---:|---:|---:|---:|---:|---:|")
    for share in sorted({k[1] for k in shares}, key=lambda s: float(s.rstrip("%"))):
        c, r = shares.get(("C", share)), shares.get(("R", share))
        cell = lambda x: f"{x[0]:.0f} | {x[1]:.2f}" if x else "- | -"
        ratio = f"{c[1] / r[1]:.2f}x" if c and r else "-"
        print(f"| {share} | {cell(c)} | {cell(r)} | {ratio} |")
