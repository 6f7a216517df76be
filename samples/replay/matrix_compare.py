#!/usr/bin/env python3
"""Compares two quality matrices written by matrix.sh (docs/replay.md, "Quality matrix").

    matrix_compare.py BEFORE_DIR AFTER_DIR [--only SUBSTRING] [--by-garment] [--by-take]
                      [--fail-if-different]

One row per run present in both (take_garment): pooled P99 stretch, frames with an opening off,
the mean share of vertices deeper than 2 mm in the body, the worst measured frame's body
penetration P99, particle-frames inside an ellipsoid (and how many frames were measured: the
off-frame count is out of those); then, per figure, in how many runs it is
lower / higher / equal, and the geometric mean of the ratios after / before (runs where both are
positive). --by-garment adds the same geometric means per garment (a run named
take_garment[_particles]) with the frames off summed before -> after: a change that helps one
garment and costs another shows there, where the pooled means hide it. --by-take adds one line
per take and garment with its resolutions pooled (frames off summed, mean stretch and worst
frame): where on which take a change acts, over several draws. Exit status: 0; 1 with
--fail-if-different when any figure of any run differs (a determinism check: the same tree twice
must give the same numbers); 2 on bad input.
"""
import json
import math
import os
import sys

# (name in the table, how to read it from stats.json's "garment", format)
FIGURES = [
    ("P99 stretch %", lambda g: 100.0 * g["p99_stretch"], "{:7.2f}"),
    ("off frames", lambda g: float(g["openings"]["off_frames"]), "{:4.0f}"),
    ("> 2 mm %", lambda g: 100.0 * g["deeper_than_2mm"], "{:6.2f}"),
    ("in body %", lambda g: 100.0 * g["inside_body"], "{:6.2f}"),  # stats files since 2026-12-01
    ("worst P99 mm", lambda g: g["body_penetration_mm"]["p99"], "{:6.1f}"),
    ("inside", lambda g: float(g["proxy_inside"]), "{:4.0f}"),
]
READ = {label: read for label, read, _ in FIGURES}


def load(directory):
    runs = {}
    for name in sorted(os.listdir(directory)):
        if not name.endswith(".json"):
            continue
        with open(os.path.join(directory, name)) as f:
            stats = json.load(f)
        garment = stats.get("garment")
        if not isinstance(garment, dict):
            continue  # --garment none, or not a drape-replay stats file
        runs[name[:-5]] = (garment, garment.get("frames_measured"))
    return runs


def number(read, garment):
    try:
        v = read(garment)
    except (KeyError, TypeError):
        return None
    return v if isinstance(v, (int, float)) and math.isfinite(v) else None


def geometric_mean(logs):
    """exp of the mean of logs of after / before ratios, as printed; "n/a" for none."""
    return f"{math.exp(sum(logs) / len(logs)):.3f}" if logs else "n/a"


def garment_of(run):
    """The garment of a run named take_garment or take_garment_particles (matrix.sh)."""
    return take_garment_of(run).split("_")[-1]


def take_garment_of(run):
    """take_garment of a run named take_garment or take_garment_particles (matrix.sh)."""
    parts = run.split("_")
    if len(parts) >= 2 and parts[-1].isdigit():
        parts = parts[:-1]
    return "_".join(parts)


def grouped(names, key):
    """The runs of `names` grouped by key(run), as {group: [runs]}."""
    groups = {}
    for n in names:
        groups.setdefault(key(n), []).append(n)
    return groups


def off_frames(runs, side):
    """Frames with an opening off, summed over `runs` of one side (before or after)."""
    return sum(number(READ["off frames"], side[n][0]) or 0 for n in runs)


def by_take(names, before, after):
    """One line per take x garment, its resolutions pooled: frames off summed, and the mean over
    its runs of the pooled P99 stretch and of the worst frame's penetration P99, before -> after."""
    groups = grouped(names, take_garment_of)
    width = max(len(g) for g in groups)
    print()
    print("per take and garment (resolutions pooled): runs, frames off summed, mean P99 stretch %, "
          "mean worst P99 mm, before -> after")

    def mean(label, runs, side):
        values = [number(READ[label], side[n][0]) for n in runs]
        values = [v for v in values if v is not None]
        return sum(values) / len(values) if values else float("nan")

    for group in sorted(groups):
        runs = groups[group]
        print(f"  {group:{width}s} {len(runs):3d} runs  off {off_frames(runs, before):4.0f} -> {off_frames(runs, after):4.0f}"
              f"  stretch {mean('P99 stretch %', runs, before):6.2f} -> {mean('P99 stretch %', runs, after):6.2f}"
              f"  worst {mean('worst P99 mm', runs, before):5.1f} -> {mean('worst P99 mm', runs, after):5.1f}")


def by_garment(names, before, after):
    groups = grouped(names, garment_of)
    print()
    print("per garment: runs, geometric mean of after / before per figure, frames off summed")
    for garment in sorted(groups):
        runs = groups[garment]
        cells = []
        for label, read, _ in FIGURES:
            if label == "off frames":
                continue
            logs = []
            for n in runs:
                b, a = number(read, before[n][0]), number(read, after[n][0])
                if a is not None and b is not None and a > 0 and b > 0:
                    logs.append(math.log(a / b))
            cells.append(f"{label} {geometric_mean(logs)}")
        print(f"  {garment:12s} {len(runs):3d} runs  " + "  ".join(cells)
              + f"  off frames {off_frames(runs, before):.0f} -> {off_frames(runs, after):.0f}")


def main(argv):
    args = [a for a in argv if not a.startswith("--")]
    only = None
    if "--only" in argv:
        i = argv.index("--only")
        if i + 1 >= len(argv):
            print("matrix_compare.py: --only needs a substring", file=sys.stderr)
            return 2
        only = argv[i + 1]
        args.remove(only)
    if len(args) != 2 or not all(os.path.isdir(a) for a in args):
        print(__doc__, file=sys.stderr)
        return 2
    before, after = load(args[0]), load(args[1])
    names = [n for n in before if n in after and (only is None or only in n)]
    if not names:
        print("matrix_compare.py: no run in both folders", file=sys.stderr)
        return 2
    missing = sorted(n for n in set(before) ^ set(after) if only is None or only in n)
    width = max(len(n) for n in names)
    print(f"{'run':{width}s}  " + "  ".join(f"{f[0]:>17s}" for f in FIGURES) + "   measured frames")
    lower = [0] * len(FIGURES)
    higher = [0] * len(FIGURES)
    equal = [0] * len(FIGURES)
    logs = [[] for _ in FIGURES]
    differs = False
    for n in names:
        (gb, fb), (ga, fa) = before[n], after[n]
        cells = []
        for k, (_, read, fmt) in enumerate(FIGURES):
            b, a = number(read, gb), number(read, ga)
            if b is None or a is None:
                cells.append(f"{'n/a':>17s}")
                differs |= (b is None) != (a is None)
                continue
            cells.append(f"{fmt.format(b)} -> {fmt.format(a)}".rjust(17))
            if a < b:
                lower[k] += 1
            elif a > b:
                higher[k] += 1
            else:
                equal[k] += 1
            differs |= a != b
            if a > 0 and b > 0:
                logs[k].append(math.log(a / b))
        differs |= fb != fa
        print(f"{n:{width}s}  " + "  ".join(cells) + f"   {fb}" + ("" if fb == fa else f" -> {fa}"))
    print()
    print(f"{len(names)} runs; per figure: lower / higher / equal after, geometric mean of after / before")
    for k, (label, _, _) in enumerate(FIGURES):
        print(f"  {label:14s} {lower[k]:3d} / {higher[k]:3d} / {equal[k]:3d}   {geometric_mean(logs[k])}")
    if "--by-garment" in argv:
        by_garment(names, before, after)
    if "--by-take" in argv:
        by_take(names, before, after)
    if missing:
        print(f"in one folder only: {', '.join(missing)}")
    if "--fail-if-different" in argv and (differs or missing):
        print("matrix_compare.py: the two matrices differ", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
