#!/usr/bin/env python3
"""Tabulates one `cargo bench --features peers --bench trees` run (criterion's JSON under target/criterion):
per scene and query, µs per query (criterion's median over an iteration of 200 poses) for
bvkit's compact, quantized and paired trees and for parry3d, and parry3d's time over
bvkit's fastest layout (named).
Usage: python3 scripts/trees_report.py [target/criterion]
"""
import json
import pathlib
import sys

POSES = 200  # poses per iteration, as benches/trees.rs runs them
root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "target/criterion")
rows = {}  # (scene, query, who) -> µs per query
for bench in root.glob("**/new/benchmark.json"):
    meta = json.loads(bench.read_text())
    if not meta["group_id"].startswith("trees/"):
        continue
    scene = meta["group_id"].split("/", 1)[1]
    query, who = meta["function_id"].split("/")
    median = json.loads((bench.parent / "estimates.json").read_text())["median"]["point_estimate"]
    rows[(scene, query, who)] = median / 1e3 / POSES

QUERIES = {
    "intersects": "`intersects` vs `query::intersection_test`",
    "pairs": "`overlapping_triangles` vs `Bvh::leaf_pairs` + triangle tests",
}
LAYOUTS = {"bvkit": "compact", "bvkit-quantized": "quantized", "bvkit-paired": "paired"}
print("| scene | query | bvkit compact | bvkit quantized | bvkit paired | parry3d | parry3d / fastest bvkit |")
print("|---|---|---:|---:|---:|---:|---:|")
for scene in sorted({k[0] for k in rows}):
    for query, label in QUERIES.items():
        ours = {name: rows.get((scene, query, who)) for who, name in LAYOUTS.items()}
        p = rows.get((scene, query, "parry3d"))
        timed = {name: t for name, t in ours.items() if t is not None}
        if not timed or p is None:
            continue
        best = min(timed, key=timed.get)
        cells = " | ".join(f"{t:,.1f} µs" if t is not None else "-" for t in ours.values())
        print(f"| {scene} | {label} | {cells} | {p:,.1f} µs | {p / timed[best]:.1f}× ({best}) |")
