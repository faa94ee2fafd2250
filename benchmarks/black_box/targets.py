#!/usr/bin/env python3
"""Every target of the black-box twins' study, measured and judged (docs/reproduction.md,
"Black-box twins: where the targets stand").

Runs `twincal run` for each cell of the study's target table on the given seed pairs, reads
each results directory's summary.json and prints one Markdown row per cell with the figures the
target is judged on and whether it is met:

  family     the analytic twin with contact, stiffening and kinks at strength 1, d = 3, 6, 12,
             19, its models from the key points' deviations and from Q² alone (the black box
             that answers only Q): active ≤ ½ baseline and ≤ w = 1 (run up to d = 6), none lost
             or diverged, twin evaluations per assembly ≤ 4 (d + 1)².
  fem        the FEM twins with flange contact: body-contact ABC and all ≤ ½ baseline, door-contact
             all ≤ baseline + 0.001, none lost.
  plant      the plant is not the twin (contact FEM behind the linear one; an analytic plant with
             a nonlinearity its quadratic twin lacks, d = 3 and 12): active's mean excess over the
             baseline, run by run, ≤ the baseline's run-to-run standard deviation.
  quadratic  the targets the active controller was first built to (quadratic twins, d up to 32):
             body/ABC ≤ 0.30, body/all ≤ ½ baseline, door/all ≤ baseline + 0.001, analytic
             ≤ ½ baseline, none diverged, evaluations ≤ 4 (d + 1)².
  external   the gap and clamp twins of examples/external_twin (Python programs, written as a
             user writes a black box), d = 3 and 12, answering only Q and with their deviations:
             active ≤ ½ baseline and ≤ w = 1 (d = 3), none lost, evaluations ≤ 4 (d + 1)²;
             the pairs' twin seeds are the programs' seeds. Not in the default --parts (about
             a minute per cell at d = 12).

usage: benchmarks/black_box/targets.py [--out DIR] [--pairs 2023/2023 7/11 ...]
                                       [--parts family,fem,plant,quadratic,external]
                                       [--dimensions 3,12]
                                       [--twincal PATH]
Results directories are kept under --out (default /tmp/twincal_black_box_targets); a rerun
reuses every finished directory (twincal run resumes), so the table can be printed again in
seconds; --fresh runs every cell anew. --dimensions 3,12 keeps only the cells
of those locator counts. Exits 1 when a target is missed, so it can gate a change, and 2 when
a run fails (twincal's message names why; a results directory of another build is refused, so
use --fresh or another --out after a rebuild). ctest's
apps.black_box_targets runs the quadratic, family and fem parts at d = 3 and 12 on seed pair
2023/2023 (about 10 s), where every target is met.
"""
import argparse
import json
import math
import pathlib
import shutil
import statistics
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
QUALITY_ONLY = {"active": {"surrogate": {"from_deviations": False}}}
NONLINEARITIES = ("contact", "stiffening", "kink")
FAMILY_DIMENSIONS = (3, 6, 12, 19)
W1_MAX_DIMENSION = 6  # 2^(2+d) candidates per assembly beyond that
QUADRATIC_DIMENSIONS = (3, 6, 12, 19, 32)


class CellFailed(RuntimeError):
    pass


class Cells:
    """Runs the cells: one `twincal run` of 10 runs per cell, its results directory under `out`
    (resumed, or removed first when `fresh`), only for the locator counts `wanted` (None: all)."""

    def __init__(self, twincal, out, fresh, wanted):
        self.twincal, self.out, self.fresh, self.wanted = twincal, out, fresh, wanted

    def wants(self, d):
        return self.wanted is None or d in self.wanted

    def run(self, name, args, config=None):
        """The cell's episodes grouped by controller (each list in run order), and its group."""
        directory = self.out / name
        if self.fresh and directory.exists():
            shutil.rmtree(directory)
        command = [str(self.twincal), "run", "--out", str(directory), "--quiet", "--runs",
                   "10"] + args
        if config is not None:
            directory.mkdir(parents=True, exist_ok=True)
            path = directory.parent / (directory.name + ".config.json")
            path.write_text(json.dumps(config))
            command += ["--config", str(path)]
        if subprocess.run(command, stdout=subprocess.DEVNULL).returncode != 0:
            raise CellFailed(f"cell {name}: `{' '.join(command)}` failed (its message is above)")
        summary = json.loads((directory / "summary.json").read_text())
        by_controller = {}
        for episode in summary["episodes"]:
            by_controller.setdefault(episode["controller"], []).append(episode)
        for episodes in by_controller.values():
            episodes.sort(key=lambda e: e["run"])
        return by_controller, summary["groups"][0]


def median(episodes):
    """The median relative residual of the runs that did not diverge, as `twincal summary`
    prints it (NaN when every run diverged)."""
    kept = [e["relative_residual"] for e in episodes if e["diverged_at"] is None]
    return statistics.median(kept) if kept else math.nan


def lost(episodes):
    return sum(1 for e in episodes if e["lost"])


def diverged(episodes):
    return sum(1 for e in episodes if e["diverged_at"] is not None)


def evaluations(episodes):
    return statistics.fmean(e["q_evaluations_per_assembly"] for e in episodes)


def budget(d):
    """Twin evaluations per assembly the study allows at d locators."""
    return 4 * (d + 1) ** 2


def black_box_judgement(runs, d):
    """The black-box target of one cell: active ≤ ½ baseline and ≤ w = 1 (where it ran and not
    every run diverged), none lost or diverged, evaluations within budget(d). Returns the
    figures printed for it and whether it is met."""
    base, active = median(runs["baseline"]), median(runs["active"])
    w1 = median(runs["w=1"]) if "w=1" in runs else math.nan
    figures = {"base": base, "active": active, "w1": w1, "lost": lost(runs["active"]),
               "diverged": diverged(runs["active"]), "evals": evaluations(runs["active"])}
    met = (active <= 0.5 * base and (math.isnan(w1) or active <= w1) and figures["lost"] == 0
           and figures["diverged"] == 0 and figures["evals"] <= budget(d))
    return figures, met


class Table:
    def __init__(self, title, header):
        self.misses = 0
        print(f"\n{title}\n\n| {' | '.join(header)} | met |")
        print("|" + "---|" * (len(header) + 1), flush=True)

    def row(self, cells, met):
        self.misses += 0 if met else 1
        print(f"| {' | '.join(cells)} | {'yes' if met else '**no**'} |", flush=True)


def family(cells, pairs):
    table = Table("Analytic family, strength 1 (active: median, × baseline, lost, diverged; "
                  "evaluations per assembly against 4 (d + 1)²)",
                  ["twin", "d", "models", "pair", "departure", "baseline", "w = 1", "active",
                   "× baseline", "lost", "diverged", "Q-evals"])
    for kind in NONLINEARITIES:
        for d in filter(cells.wants, FAMILY_DIMENSIONS):
            for source, config in (("deviations", None), ("Q only", QUALITY_ONLY)):
                for seed, twin_seed in pairs:
                    controllers = "baseline,active" + (",w=1" if d <= W1_MAX_DIMENSION else "")
                    tag = "dev" if config is None else "q"
                    runs, group = cells.run(
                        f"family-{kind}-d{d}-{tag}-{seed}-{twin_seed}",
                        ["--case", "analytic", "--locators", "all", "--dimension", str(d),
                         "--nonlinearity", kind, "--strength", "1", "--seed", str(seed),
                         "--twin-seed", str(twin_seed), "--controllers", controllers], config)
                    f, met = black_box_judgement(runs, d)
                    table.row([kind, str(d), source, f"{seed}/{twin_seed}",
                               f"{group['twin']['quadratic_departure']:.2f}", f"{f['base']:.3f}",
                               "–" if math.isnan(f["w1"]) else f"{f['w1']:.3f}",
                               f"{f['active']:.3f}", f"{f['active'] / f['base']:.2f}",
                               str(f["lost"]), str(f["diverged"]),
                               f"{f['evals']:.0f} / {budget(d)}"], met)
    return table.misses


def fem(cells, pairs):
    table = Table("FEM twins with flange contact (10 runs)",
                  ["case", "pair", "baseline", "default", "active", "target", "lost",
                   "Q-evals"])
    for case, locators, d in (("body-contact", "ABC", 3), ("body-contact", "all", 12),
                              ("door-contact", "all", 19)):
        if not cells.wants(d):
            continue
        for seed, twin_seed in pairs:
            runs, _ = cells.run(f"fem-{case}-{locators}-{seed}-{twin_seed}",
                                ["--case", case, "--locators", locators, "--seed", str(seed),
                                 "--twin-seed", str(twin_seed),
                                 "--controllers", "baseline,default,active"])
            base, active = median(runs["baseline"]), median(runs["active"])
            bound = base + 0.001 if case == "door-contact" else 0.5 * base
            lost_runs, evals = lost(runs["active"]), evaluations(runs["active"])
            met = active <= bound and lost_runs == 0 and evals <= budget(d)
            table.row([f"{case}/{locators}", f"{seed}/{twin_seed}", f"{base:.4f}",
                       f"{median(runs['default']):.4f}", f"{active:.4f}", f"≤ {bound:.4f}",
                       str(lost_runs), f"{evals:.0f}"], met)
    return table.misses


def plant(cells, pairs):
    table = Table("Plant ≠ twin (medians over every run, diverged or not; the mean of active − "
                  "baseline run by run against the baseline's standard deviation over the runs)",
                  ["plant behind twin", "pair", "baseline", "active", "mean excess",
                   "baseline sd", "gain", "active lost", "active diverged"])
    plants = [(f"body-contact/{loc} behind body/{loc}", f"plant-body-{loc}", d,
               ["--case", "body", "--plant", "body-contact", "--locators", loc])
              for loc, d in (("ABC", 3), ("all", 12))]
    plants.append(("door-contact/all behind door/all", "plant-door-all", 19,
                   ["--case", "door", "--plant", "door-contact", "--locators", "all"]))
    for kind in NONLINEARITIES:
        for d in (3, 12):
            plants.append((f"analytic {kind}, d = {d}, behind the quadratic twin",
                           f"plant-{kind}-d{d}", d,
                           ["--case", "analytic", "--locators", "all", "--dimension", str(d),
                            "--plant-nonlinearity", kind, "--plant-strength", "1"]))
    for label, name, d, args in plants:
        if not cells.wants(d):
            continue
        for seed, twin_seed in pairs:
            runs, _ = cells.run(f"{name}-{seed}-{twin_seed}",
                                args + ["--seed", str(seed), "--twin-seed", str(twin_seed),
                                        "--controllers", "baseline,active"])
            # Every run counts here, diverged or not: the excess is judged run by run.
            base = [e["relative_residual"] for e in runs["baseline"]]
            active = [e["relative_residual"] for e in runs["active"]]
            excess = statistics.fmean(a - b for a, b in zip(active, base))
            spread = statistics.stdev(base)
            gain = 1.0 - statistics.median(active) / statistics.median(base)
            table.row([label, f"{seed}/{twin_seed}", f"{statistics.median(base):.4f}",
                       f"{statistics.median(active):.4f}", f"{excess:+.4f}", f"{spread:.4f}",
                       f"{100 * gain:+.0f} %", str(lost(runs["active"])),
                       str(diverged(runs["active"]))],
                      excess <= spread)
    return table.misses


def quadratic(cells, pairs):
    table = Table("Quadratic twins (the active controller's first targets)",
                  ["group", "pair", "baseline", "active", "target", "diverged", "Q-evals"])
    groups = [("body/ABC", 3, ["--case", "body", "--locators", "ABC"], lambda b: 0.30),
              ("body/all", 12, ["--case", "body", "--locators", "all"], lambda b: 0.5 * b),
              ("door/all", 19, ["--case", "door", "--locators", "all"], lambda b: b + 0.001)]
    groups += [(f"analytic d = {d}", d, ["--case", "analytic", "--locators", "all",
                                         "--dimension", str(d)], lambda b: 0.5 * b)
               for d in QUADRATIC_DIMENSIONS]
    for label, d, args, bound_of in groups:
        if not cells.wants(d):
            continue
        for seed, twin_seed in pairs:
            name = "quadratic-" + label.replace("/", "-").replace(" = ", "").replace(" ", "-")
            runs, _ = cells.run(f"{name}-{seed}-{twin_seed}",
                                args + ["--seed", str(seed), "--twin-seed", str(twin_seed),
                                        "--controllers", "baseline,active"])
            base, active = median(runs["baseline"]), median(runs["active"])
            bound = bound_of(base)
            diverged_runs, evals = diverged(runs["active"]), evaluations(runs["active"])
            met = active <= bound and diverged_runs == 0 and evals <= budget(d)
            table.row([label, f"{seed}/{twin_seed}", f"{base:.4f}", f"{active:.4f}",
                       f"≤ {bound:.4f}", str(diverged_runs), f"{evals:.1f}"], met)
    return table.misses


def external(cells, pairs):
    """Black boxes written as a user writes them (examples/external_twin): the gap and clamp
    twins, which nothing in the controller was chosen on, each at the twin seeds given here."""
    table = Table("External black-box twins (examples/external_twin; parts 10 × 10, the pair's "
                  "seed for the runs, its twin seed for the program)",
                  ["twin", "d", "models", "pair", "baseline", "w = 1", "active", "× baseline",
                   "lost", "Q-evals"])
    programs = (("gap", "gap_twin.py", 60), ("clamp", "clamp_twin.py", 50))
    for label, program, key_points in programs:
        for d in filter(cells.wants, (3, 12)):
            for source in ("Q only", "deviations"):
                for seed, twin_seed in pairs:
                    twin = {"command": ["python3", str(ROOT / "examples" / "external_twin" /
                                                       program), str(d), str(twin_seed)],
                            "locators": [f"L{i + 1}" for i in range(d)],
                            "lower_bounds": [-1] * d, "upper_bounds": [1] * d,
                            "upper_parts": 10, "lower_parts": 10, "workers": 2}
                    if source == "deviations":
                        twin["key_points"] = key_points
                    controllers = ["baseline", "active"] + (["w=1"] if d <= 3 else [])
                    config = {"case": "external", "external_twin": twin, "locators": "all",
                              "controllers": controllers, "seed": seed, "twin_seed": twin_seed}
                    tag = "dev" if source == "deviations" else "q"
                    runs, _ = cells.run(f"external-{label}-d{d}-{tag}-{seed}-{twin_seed}", [],
                                        config)
                    f, met = black_box_judgement(runs, d)
                    table.row([label, str(d), source, f"{seed}/{twin_seed}", f"{f['base']:.3f}",
                               "–" if math.isnan(f["w1"]) else f"{f['w1']:.3f}",
                               f"{f['active']:.3f}", f"{f['active'] / f['base']:.2f}",
                               str(f["lost"]), f"{f['evals']:.0f} / {budget(d)}"], met)
    return table.misses


PARTS = {"family": family, "fem": fem, "plant": plant, "quadratic": quadratic,
         "external": external}


def seed_pair(text):
    try:
        seed, twin_seed = (int(v) for v in text.split("/"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"seed pair '{text}': must be SEED/TWIN_SEED, e.g. 7/11")
    return seed, twin_seed


def dimension_list(text):
    try:
        dimensions = [int(v) for v in text.split(",")]
    except ValueError:
        dimensions = []
    if not dimensions or min(dimensions) < 1:
        raise argparse.ArgumentTypeError(
            f"dimensions '{text}': must be locator counts >= 1 joined by commas, e.g. 3,12")
    return dimensions


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=pathlib.Path,
                        default=pathlib.Path("/tmp/twincal_black_box_targets"))
    parser.add_argument("--pairs", type=seed_pair, nargs="+", default=[(2023, 2023), (7, 11)])
    parser.add_argument("--parts", default="family,fem,plant,quadratic")
    parser.add_argument("--dimensions", type=dimension_list, default=None,
                        help="only the cells of these locator counts, e.g. 3,12 (default all)")
    parser.add_argument("--fresh", action="store_true",
                        help="run every cell anew instead of reusing --out's finished results")
    parser.add_argument("--twincal", type=pathlib.Path,
                        default=ROOT / "build" / "apps" / "twincal" / "twincal")
    args = parser.parse_args()
    parts = args.parts.split(",")
    unknown = [p for p in parts if p not in PARTS]
    if unknown:
        parser.error(f"--parts: '{unknown[0]}' is not one of {', '.join(PARTS)}")
    if not args.twincal.is_file():
        parser.error(f"--twincal: {args.twincal} is not a file (build the project first)")
    args.out.mkdir(parents=True, exist_ok=True)
    cells = Cells(args.twincal, args.out, args.fresh, args.dimensions)
    try:
        misses = sum(PARTS[p](cells, args.pairs) for p in parts)
    except CellFailed as failure:
        print(f"targets.py: {failure}", file=sys.stderr)
        return 2
    print(f"\n{misses} target(s) missed", flush=True)
    return 1 if misses else 0


if __name__ == "__main__":
    sys.exit(main())
