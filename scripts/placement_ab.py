#!/usr/bin/env python3
"""Compares two trees with the function that holds a row's hot loop at each address mod 64.

A hot loop's speed can hang on its address alone. Rust places functions 16 bytes apart at
the least, so under a new code layout a function starts at one of four offsets within a
64-byte line, and so does every loop within it. If the same loop runs 10% slower at one of
the four, an A/B over a few random layouts (`layout_ab.py`) can draw that offset more often
on one side and report the loop's code as slower when it is not.

This script links each tree's bench binary with lld's `--shuffle-sections=.text*=SEED` for
seeds 1, 2, ... until it holds one binary for each start offset (0, 16, 32, 48 mod 64) of the
named function, then runs the eight binaries REPS times, alternating the trees. Per offset
it prints each tree's times, so the trees are compared with the loop at the same place.

Usage:
    python3 scripts/placement_ab.py BEFORE_DIR AFTER_DIR BENCH FILTER \\
        BEFORE_FUNCTION AFTER_FUNCTION [--reps N]

A FUNCTION is a regular expression on the demangled symbol, with `@SIZE` (bytes, decimal)
appended when one name has several instances (`'aos::every@5158'`); `perf report --sort sym`
names the function and `nm -C -S` gives its size. Run nothing else meanwhile.
"""
import argparse
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile

from layout_ab import link_command, relink, run, show

OFFSETS = (0, 16, 32, 48)


def start(exe, function):
    """The address of the one symbol of `exe` that `function` (REGEX[@SIZE]) names."""
    pattern, _, size = function.partition("@")
    found = []
    nm = subprocess.run(["nm", "-C", "-S", str(exe)], check=True, capture_output=True, text=True)
    for line in nm.stdout.splitlines():
        fields = line.split(" ", 3)
        if len(fields) != 4 or not re.fullmatch("[0-9a-f]+", fields[1]):
            continue
        if re.search(pattern, fields[3]) and (not size or int(fields[1], 16) == int(size)):
            found.append(int(fields[0], 16))
    if len(found) != 1:
        sys.exit(f"{exe}: {len(found)} symbols match {function!r}; name one (append @SIZE)")
    return found[0]


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("before", type=pathlib.Path)
    p.add_argument("after", type=pathlib.Path)
    p.add_argument("bench")
    p.add_argument("filter")
    p.add_argument("before_function")
    p.add_argument("after_function")
    p.add_argument("--reps", type=int, default=2)
    a = p.parse_args()

    work = pathlib.Path(tempfile.mkdtemp(prefix="placement_ab_"))
    sides = {"before": (a.before.resolve(), a.before_function),
             "after": (a.after.resolve(), a.after_function)}
    exes = {}
    for side, (tree, function) in sides.items():
        command = link_command(tree, a.bench)
        for seed in range(1, 65):
            exe = work / f"{side}{seed}"
            relink(command, exe, seed)
            offset = start(exe, function) % 64
            if (side, offset) in exes:
                exe.unlink()
                continue
            exes[side, offset] = exe
            print(f"{side}: seed {seed} starts the function at {offset} mod 64",
                  file=sys.stderr, flush=True)
            if all((side, o) in exes for o in OFFSETS):
                break
        else:
            sys.exit(f"{side}: 64 seeds did not place the function at every offset")

    times = {}
    for rep in range(a.reps):
        for offset in OFFSETS:
            for side in ("before", "after") if rep % 2 else ("after", "before"):
                for row, ns in run(exes[side, offset], a.filter).items():
                    times.setdefault((row, offset, side), []).append(ns)
    shutil.rmtree(work)
    print(f"{a.reps} runs per tree and offset; each cell lists criterion's medians\n")
    print("| row | function at (mod 64) | before | after |")
    print("|---|---:|---|---|")
    for row in sorted({row for row, _, _ in times}):
        for offset in OFFSETS:
            cells = [", ".join(show(ns) for ns in times.get((row, offset, side), []))
                     for side in ("before", "after")]
            print(f"| {row} | {offset} | {cells[0]} | {cells[1]} |")


if __name__ == "__main__":
    main()
