#!/usr/bin/env python3
"""Compares the criterion benches of two trees over many code and stack placements.

One build run once is one draw of two placements that can each move an in-cache row by
10% or more on their own, so the ratio of one run of one build to one run of another mixes the
change under test with those draws:
- the code layout: moving a hot loop by a few bytes (a change in an unrelated function, a
  new symbol name) moves it against the decoded-uop cache, the loop buffer and the branch
  predictors, which are indexed by address;
- the stack offset: Linux places each process's stack at a random 16-byte offset within a
  page. Run with address-space randomisation off and the environment padded by 64-byte
  steps, one in-cache row of one binary took from 1x to 2.2x its best time depending on
  the offset alone; the likely cause is "4K aliasing", a load that shares its address
  bits 0-11 with a store still in flight (a spill slot against a constant or a column)
  taken for a dependency on it and replayed.
This script links each tree's bench binary N times with lld's
`--shuffle-sections=.text*=SEED` (the same object code in N function orders) and runs
every binary once, alternating sides (before, after, after, before, ...), so each run
draws a new code layout and, with address-space randomisation on, a new stack offset. Per
row it reports the median and the mean over runs of criterion's median, the ratio
after/before of each, and each side's spread over its runs.

Usage:
    python3 scripts/layout_ab.py BEFORE_DIR AFTER_DIR BENCH [FILTER] [--runs N] [--first-seed S]
                                 [--add EARLIER.json ...] [--json OUT] [--criterion "ARGS"]

BEFORE_DIR and AFTER_DIR are checkouts of the two trees (`git worktree add ../before REV`).
BENCH is a criterion bench target (`speed`, `classes`, `broadphase`); FILTER is criterion's
regular expression (default: every row). The seeds are S, S+1, ... (default 1), so a later
call with `--first-seed` draws new layouts, and `--add` joins the runs that earlier calls saved
with `--json` (of the same two trees) to this call's runs before the table; `--criterion` passes
options to each run (shorter warm-up and measurement times for many rows). Needs the x86_64
Linux default linker, rust-lld. Run nothing else meanwhile.

With 5 or more runs a side, the median over runs also keeps a row's figure when one or two
processes of a side run in a slow state of their own (on a VM, a whole process can run the
densest kernels 1.2-3.7x slower than the same binary in the next process).
"""
import argparse
import json
import os
import pathlib
import re
import shlex
import shutil
import statistics
import subprocess
import sys
import tempfile


def link_command(tree, bench):
    """Builds the bench target of `tree`, keeping its objects, and returns rustc's link command."""
    (tree / "benches" / f"{bench}.rs").touch()  # cargo reruns rustc only for a changed target
    # The benches need the `peers` feature where the tree has it (from issue 46 on).
    peers = ["--features", "peers"] if "\npeers = [" in (tree / "Cargo.toml").read_text() else []
    out = subprocess.run(
        ["cargo", "rustc", "--profile", "bench", *peers, "--bench", bench, "--",
         "-C", "save-temps", "--print", "link-args"],
        cwd=tree, check=True, stdout=subprocess.PIPE, text=True).stdout  # cargo's stderr shows
    lines = [line for line in out.splitlines() if ' "-o" ' in line]
    if len(lines) != 1:
        sys.exit(f"{tree}: no link command in `cargo rustc --print link-args` output")
    if "-fuse-ld=lld" not in lines[0]:
        sys.exit(f"{tree}: the link command does not use lld; --shuffle-sections needs it")
    return lines[0]


def relink(command, exe, seed):
    """Reruns `command` writing `exe`, with lld shuffling the .text sections by `seed`."""
    old = re.search(r'"-o" "[^"]*"', command).group(0)
    command = command.replace(old, f'"-o" {shlex.quote(str(exe))}')
    command += f' "-Wl,--shuffle-sections=.text*={seed}"'
    subprocess.run(["bash", "-c", command], check=True)


def run(exe, filt, criterion=()):
    """Runs one bench binary once; returns {row: criterion's median in ns}."""
    with tempfile.TemporaryDirectory() as home:
        subprocess.run([str(exe), "--bench", "--noplot", *criterion, filt], check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                       env=dict(os.environ, CRITERION_HOME=home))
        rows = {}
        for meta_path in pathlib.Path(home).glob("**/new/benchmark.json"):
            meta = json.loads(meta_path.read_text())
            est = json.loads((meta_path.parent / "estimates.json").read_text())
            rows[meta["full_id"]] = est["median"]["point_estimate"]
        return rows


def show(ns):
    for unit, scale in (("ms", 1e6), ("µs", 1e3)):
        if ns >= scale:
            return f"{ns / scale:.2f} {unit}"
    return f"{ns:.1f} ns"


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("before", type=pathlib.Path)
    p.add_argument("after", type=pathlib.Path)
    p.add_argument("bench")
    p.add_argument("filter", nargs="?", default="")
    p.add_argument("--runs", type=int, default=16)
    p.add_argument("--first-seed", type=int, default=1)
    p.add_argument("--add", type=pathlib.Path, nargs="*", default=[])
    p.add_argument("--json", type=pathlib.Path)
    p.add_argument("--criterion", default="",
                   help="options for criterion, e.g. \"--warm-up-time 1 --measurement-time 2\"")
    a = p.parse_args()

    work = pathlib.Path(tempfile.mkdtemp(prefix="layout_ab_"))
    sides = {"before": a.before.resolve(), "after": a.after.resolve()}
    seeds = range(a.first_seed, a.first_seed + a.runs)
    for side, tree in sides.items():
        command = link_command(tree, a.bench)
        for seed in seeds:
            relink(command, work / f"{side}{seed}", seed)
    runs = {"before": [], "after": []}
    for seed in seeds:
        for side in ("before", "after") if seed % 2 else ("after", "before"):
            runs[side].append(run(work / f"{side}{seed}", a.filter, shlex.split(a.criterion)))
            print(f"{side} run {seed} done", file=sys.stderr, flush=True)
    shutil.rmtree(work)
    if a.json:
        a.json.write_text(json.dumps(runs, indent=1))
    for earlier in a.add:
        for side, rows in json.loads(earlier.read_text()).items():
            runs[side] += rows
    n = len(runs["before"])

    rows = [k for k in runs["before"][0] if all(k in r for r in runs["before"] + runs["after"])]
    print(f"{n} runs of each tree, each its own code layout and stack offset; per row the "
          "median and the mean over runs of criterion's median\n")
    print("| row | before | after | after/before (medians) | (means) | before spread | after spread |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    ratios = []
    for row in sorted(rows):
        b = [r[row] for r in runs["before"]]
        f = [r[row] for r in runs["after"]]
        mb, mf = statistics.median(b), statistics.median(f)
        ratios.append(mf / mb)
        print(f"| {row} | {show(mb)} | {show(mf)} | {mf / mb:.3f} | "
              f"{statistics.mean(f) / statistics.mean(b):.3f} | "
              f"{min(b) / mb:.2f}-{max(b) / mb:.2f} | {min(f) / mf:.2f}-{max(f) / mf:.2f} |")
    if ratios:
        print(f"\n{len(ratios)} rows: median {statistics.median(ratios):.3f}, "
              f"min {min(ratios):.3f}, max {max(ratios):.3f}")


if __name__ == "__main__":
    main()
