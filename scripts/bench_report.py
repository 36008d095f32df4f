#!/usr/bin/env python3
"""Tabulates one `cargo bench --features peers --bench batch` and `--bench classes` run (criterion's JSON
under target/criterion).

Prints, per batch size, ns per box (criterion's median) for every kernel, layout and
backend, the peers and the memory rooflines, and the ratios the batch issue asks for:
speed-up over the parry3d loop, Outward over Nearest, and time over the roofline of the
same layout. Usage: python3 scripts/bench_report.py [target/criterion]
"""
import json
import pathlib
import sys

root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "target/criterion")
rows = {}  # (size, name) -> ns per box
classes = {}  # (size, name) -> ns per box, from the classes group
for bench in root.glob("**/new/benchmark.json"):
    meta = json.loads(bench.read_text())
    group = meta["group_id"]
    if group.startswith("classes/"):
        size = group.split("/", 1)[1]
        estimates = json.loads((bench.parent / "estimates.json").read_text())
        elements = meta["throughput"]["Elements"]
        classes[(size, meta["function_id"])] = estimates["median"]["point_estimate"] / elements
        continue
    if not group.startswith("batch/"):
        continue
    size = group.split("/", 1)[1]
    name = meta["function_id"] + ("/" + meta["value_str"] if meta.get("value_str") else "")
    elements = meta["throughput"]["Elements"]
    estimates = json.loads((bench.parent / "estimates.json").read_text())
    rows[(size, name)] = estimates["median"]["point_estimate"] / elements

sizes = [s for s in ["1K", "64K", "4M"] if any(k[0] == s for k in rows)]
names = sorted({k[1] for k in rows}, key=lambda n: (not n.startswith("peer"), not n.startswith("roofline"), n))


def get(size, name):
    return rows.get((size, name))


print("| kernel | " + " | ".join(f"{s} ns/box" for s in sizes) + " |")
print("|---|" + "---:|" * len(sizes))
for n in names:
    cells = [f"{get(s, n):.3f}" if get(s, n) is not None else "" for s in sizes]
    print(f"| {n} | " + " | ".join(cells) + " |")

print()
print("| ratio | " + " | ".join(sizes) + " |")
print("|---|" + "---:|" * len(sizes))
backends = ["avx512", "avx2", "baseline", "wide", "scalar"]  # the order of Backend::detect()
best = next((b for b in backends if any(k[1] == f"aosoa/{b}/abs-matrix/nearest" for k in rows)), None)


def ratio(label, num, den):
    cells = []
    for s in sizes:
        a, b = get(s, num), get(s, den)
        cells.append(f"{a / b:.2f}" if a and b else "")
    print(f"| {label} | " + " | ".join(cells) + " |")


if best:
    k = f"aosoa/{best}"
    ratio(f"parry3d loop / {k} abs-matrix nearest (speed-up)", "peer/parry3d-transform_by", f"{k}/abs-matrix/nearest")
    ratio(f"glam abs-matrix loop / {k} abs-matrix nearest (speed-up)", "peer/glam-abs-matrix", f"{k}/abs-matrix/nearest")
    for m in ["abs-matrix", "sign-select"]:
        ratio(f"{k} {m}: outward / nearest", f"{k}/{m}/outward", f"{k}/{m}/nearest")
    for layout in ["aosoa", "soa", "aos"]:
        for m in ["abs-matrix/nearest", "abs-matrix/outward", "sign-select/nearest"]:
            ratio(f"{layout}/{best} {m} / roofline/{layout}", f"{layout}/{best}/{m}", f"roofline/{layout}")
    ratio(f"{k} abs-matrix nearest: wide / {best}", f"aosoa/wide/abs-matrix/nearest", f"{k}/abs-matrix/nearest")
    ratio(f"{k} abs-matrix nearest: baseline / {best}", f"aosoa/baseline/abs-matrix/nearest", f"{k}/abs-matrix/nearest")

if classes:
    # Bytes per box (AoSoA, read and written): boxes 24 + output 24 + the class's fields.
    fields = {"translation3": 3, "rigid3": 7, "similarity3": 8, "trs3": 10, "affine3": 12}
    csizes = [s for s in ["4K", "4M"] if any(k[0] == s for k in classes)]
    c = lambda size, name: classes.get((size, name))
    print()
    print("| class | bytes/box | " + " | ".join(
        f"AoSoA abs-matrix nearest {s} | roofline {s} | × roofline {s}" for s in csizes
    ) + " | AoS abs-matrix nearest 4K | sign-select outward AoSoA 4M |")
    print("|---|---:|" + "---:|---:|---:|" * len(csizes) + "---:|---:|")
    for cls, n in fields.items():
        cells = []
        for s in csizes:
            k, r = c(s, f"aosoa/{cls}/abs-matrix/nearest"), c(s, f"roofline/{cls}")
            cells += [f"{k:.3f}" if k else "", f"{r:.3f}" if r else "", f"{k / r:.2f}x" if k and r else ""]
        aos = c("4K", f"aos/{cls}/abs-matrix/nearest")
        out = c("4M", f"aosoa/{cls}/sign-select/outward")
        cells += [f"{aos:.3f}" if aos else "", f"{out:.3f}" if out else ""]
        print(f"| {cls} | {48 + 4 * n} | " + " | ".join(cells) + " |")
    print()
    print("| peer | 4K ns/box | 4M ns/box |\n|---|---:|---:|")
    for peer in ["peer/parry3d-transform_by", "peer/glam-abs-matrix-affine", "peer/glam-abs-matrix-rigid"]:
        print(f"| {peer} | " + " | ".join(f"{c(s, peer):.3f}" if c(s, peer) else "" for s in csizes) + " |")
    print()
    print("| target | measured | goal |\n|---|---:|---:|")
    def cr(size, num, den):
        a, b = c(size, num), c(size, den)
        return f"{a / b:.2f}x" if a and b else "n/a"
    print(f"| affine AoSoA / rigid AoSoA, 4M | {cr('4M', 'aosoa/affine3/abs-matrix/nearest', 'aosoa/rigid3/abs-matrix/nearest')} | >= 1.25x |")
    print(f"| rigid AoSoA / its roofline, 4M | {cr('4M', 'aosoa/rigid3/abs-matrix/nearest', 'roofline/rigid3')} | <= 1.15x |")
    print(f"| affine AoSoA / translation AoSoA, 4M | {cr('4M', 'aosoa/affine3/abs-matrix/nearest', 'aosoa/translation3/abs-matrix/nearest')} | >= 1.6x |")
    print(f"| parry3d loop / rigid AoS, 4K | {cr('4K', 'peer/parry3d-transform_by', 'aos/rigid3/abs-matrix/nearest')} | >= 8x |")
