#!/usr/bin/env python3
"""Compares two twincal results directories apart from their wall-time columns.

usage: compare_results.py EXPECTED ACTUAL [--any-order]

The files must be the same byte for byte once the wall times are taken out: the `seconds`
column of assemblies.csv and `seconds_per_assembly` of episodes.jsonl and summary.json. With
--any-order the episodes may come in another order (a study resumed after a kill stores the
episodes it runs then after the ones it kept), each episode's rows and line still identical.
Exits 1 naming the first difference.
"""
import json
import sys
from pathlib import Path


def csv_rows(directory):
    lines = (Path(directory) / "assemblies.csv").read_text().splitlines()
    header = lines[0].split(",")
    if header[-1] != "seconds":
        sys.exit(f"{directory}/assemblies.csv: last column is {header[-1]!r}, not 'seconds'")
    return [lines[0]] + [line.rsplit(",", 1)[0] for line in lines[1:]]


def jsonl_lines(directory):
    out = []
    for line in (Path(directory) / "episodes.jsonl").read_text().splitlines():
        episode = json.loads(line)
        episode.pop("seconds_per_assembly")
        out.append(json.dumps(episode))
    return out


def summary(directory):
    value = json.loads((Path(directory) / "summary.json").read_text())
    for episode in value["episodes"]:
        episode.pop("seconds_per_assembly")
    return value


def episode_key(text):
    if text.startswith("{"):
        episode = json.loads(text)
        return (episode["group"], episode["controller"], episode["run"])
    group, controller, run = text.split(",")[:3]
    return (group, controller, int(run))


def first_difference(expected, actual, what):
    for i, (a, b) in enumerate(zip(expected, actual)):
        if a != b:
            return f"{what}: entry {i} differs:\n  expected {a}\n  actual   {b}"
    if len(expected) != len(actual):
        return f"{what}: {len(expected)} entries expected, {len(actual)} found"
    return None


def main():
    args = [a for a in sys.argv[1:] if a != "--any-order"]
    any_order = "--any-order" in sys.argv[1:]
    if len(args) != 2:
        sys.exit(__doc__)
    expected, actual = args
    checks = [
        ("assemblies.csv", csv_rows(expected), csv_rows(actual)),
        ("episodes.jsonl", jsonl_lines(expected), jsonl_lines(actual)),
    ]
    problems = []
    for what, a, b in checks:
        if any_order:
            # Rows keep their order within an episode; episodes may move as blocks.
            a = [a[0]] + sorted(a[1:], key=episode_key) if what.endswith("csv") else sorted(
                a, key=episode_key)
            b = [b[0]] + sorted(b[1:], key=episode_key) if what.endswith("csv") else sorted(
                b, key=episode_key)
        if problem := first_difference(a, b, what):
            problems.append(problem)
    s_expected, s_actual = summary(expected), summary(actual)
    if any_order:
        for value in (s_expected, s_actual):
            value["episodes"].sort(
                key=lambda e: (e["group"], e["controller"], e["run"]))
    if s_expected != s_actual:
        problems.append("summary.json: differs (groups or episodes)")
    if problems:
        sys.exit(f"{actual} differs from {expected}:\n" + "\n".join(problems))
    print(f"{actual} matches {expected} (wall times aside{', any order' if any_order else ''})")


if __name__ == "__main__":
    main()
