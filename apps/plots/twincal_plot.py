#!/usr/bin/env python3
"""Figures of a twincal results directory, like Sjöberg et al. (2023), Figs. 4-11 and Table 1.

For every experiment group (case x locator set, or sweep point): box plots over the runs of each
controller's episode-mean relative residual (z - z*)/z* (upper panel) and episode-mean
estimation error |du^ - du*| (lower panel). Boxes cover the runs that did not diverge; the runs
that did are counted in a red circle above the controller whose redness grows with the count.
Lost runs (mean |du^ - du*| over the second half above the baseline's mean |du*|: worse than no
estimate, diverged or not) are counted in the controller's label, "w=1 (3 lost)".
Table 1 analog: mean wall time and Q-evaluations per assembly of the default controller and the
w-controllers, for 1 and 3 locators, per case (Markdown and CSV), plus every group x controller.
Scaling figure (groups of `twincal scaling`, tagged study = scaling): per case, the median
relative residual, the diverged fraction (solid) with the lost fraction (dashed) and the
Q-evaluations per assembly against the number d of controlled locators, one line per controller.
Nonlinearity figure (groups of `twincal scaling --nonlinearity K`, tagged study = nonlinearity):
per nonlinearity and d, the same three panels against the strength of the nonlinearity, each
tick labelled with how far that twin's Q^2 departs from a quadratic.

History figure (a `twincal serve` session, exported by `twincal history`): per locator the
estimate du^_t with its +-2 sigma band over the requests, and the measured quality z_t against
the twin's best z*(x_t) below.

    twincal_plot.py --results DIR --out DIR      (normally run by `twincal plot`)
    twincal_plot.py --history FILE.csv --out DIR
"""

import argparse
import csv
import itertools
import json
import math
import os
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)
from matplotlib.patches import Circle  # noqa: E402,F401


def number(value):
    return math.nan if value is None else float(value)


def load(results):
    with open(os.path.join(results, "summary.json"), encoding="utf-8") as f:
        summary = json.load(f)
    if summary.get("format") != "twincal.results":
        sys.exit(f"twincal_plot: {results}/summary.json is not a twincal results summary")
    return summary["groups"], summary["episodes"]


def lost_count(episodes):
    """Runs recorded as lost, or None when a record predates the rule (no "lost" field)."""
    if any("lost" not in e for e in episodes):
        return None
    return sum(1 for e in episodes if e["lost"])


def file_stem(name):
    return re.sub(r"[^A-Za-z0-9=.+-]+", "_", name).strip("_")


def group_title(group, runs):
    config = group["config"]
    twin = group["twin"]
    names = ", ".join(twin["locator_names"])
    label = config["locators"]
    locators = f"locator {label}" if len(twin["locator_names"]) == 1 else f"locators {label}"
    title = f"{group['name']}: {config['case']}, {locators} ({names})"
    return f"{title} — {runs} runs × {config['assemblies']} assemblies"


def plot_group(group, episodes, out):
    controllers = [c for c in group["config"]["controllers"]
                   if any(e["controller"] == c for e in episodes)]
    if not controllers:
        return None
    residuals, errors, diverged, labels, runs = [], [], [], [], 0
    for controller in controllers:
        mine = [e for e in episodes if e["controller"] == controller]
        runs = max(runs, len(mine))
        kept = [e for e in mine if e["diverged_at"] is None]
        residuals.append([number(e["relative_residual"]) for e in kept])
        errors.append([number(e["estimation_error"]) for e in kept])
        diverged.append((len(mine) - len(kept), len(mine)))
        lost = lost_count(mine)
        labels.append(f"{controller} ({lost} lost)" if lost else controller)

    figure, (upper, lower) = plt.subplots(2, 1, sharex=True, figsize=(max(6.0, 0.6 * len(controllers) + 2), 6.5))
    positions = list(range(1, len(controllers) + 1))
    for axis, data, label in ((upper, residuals, "mean (z − z*)/z*"),
                              (lower, errors, "mean ‖δû − δu*‖")):
        present = [(p, d) for p, d in zip(positions, data) if d]
        if present:
            axis.boxplot([d for _, d in present], positions=[p for p, _ in present], widths=0.6,
                         medianprops={"color": "tab:blue"}, flierprops={"markersize": 3})
        axis.set_ylabel(label)
        axis.grid(axis="y", alpha=0.3)
    # Divergences: a red circle above the controller, redder for more, with the count inside.
    for position, (count, total) in zip(positions, diverged):
        if count == 0:
            continue
        shade = plt.cm.Reds(0.35 + 0.65 * count / max(total, 1))
        upper.annotate(str(count), xy=(position, 1.0), xycoords=("data", "axes fraction"),
                       xytext=(0, 9), textcoords="offset points", ha="center", va="center",
                       fontsize=7, color="white" if count / max(total, 1) > 0.5 else "black",
                       bbox={"boxstyle": "circle,pad=0.3", "facecolor": shade, "edgecolor": "darkred"})
    lower.set_xticks(positions)
    lower.set_xticklabels(labels, rotation=45, ha="right")
    upper.set_title(group_title(group, runs), fontsize=9, pad=20)
    figure.tight_layout()
    stem = file_stem(group["name"])
    for extension in ("png", "svg"):
        figure.savefig(os.path.join(out, f"{stem}.{extension}"), dpi=150)
    plt.close(figure)
    return stem


def mean(values):
    values = [v for v in values if not math.isnan(v)]
    return sum(values) / len(values) if values else math.nan


def table1(groups, episodes, out):
    """Mean time (s) and Q-evaluations per assembly, by case, controller family and locators."""
    by_group = {g["name"]: g for g in groups}
    detail = []
    families = {}
    for group in groups:
        mine = [e for e in episodes if e["group"] == group["name"]]
        dimension = group["twin"]["dimension"]
        for controller in group["config"]["controllers"]:
            rows = [e for e in mine if e["controller"] == controller]
            if not rows:
                continue
            seconds = mean([number(e["seconds_per_assembly"]) for e in rows])
            evaluations = mean([number(e["q_evaluations_per_assembly"]) for e in rows])
            detail.append([group["name"], controller, dimension, len(rows), seconds, evaluations])
            family = ("w-controllers" if controller.startswith("w=") else
                      "per-component" if controller.startswith("per-component:") else
                      "default controller" if controller == "default" else controller)
            key = (group["config"]["case"], family, dimension)
            families.setdefault(key, []).append((seconds, evaluations))
    with open(os.path.join(out, "table1_detail.csv"), "w", newline="", encoding="utf-8") as f:
        writer = csv.writer(f)
        writer.writerow(["group", "controller", "locators", "runs", "seconds_per_assembly",
                         "q_evaluations_per_assembly"])
        writer.writerows(detail)

    cases = sorted({case for case, _, _ in families})
    dimensions = sorted({d for _, _, d in families})
    order = ["default controller", "w-controllers", "per-component", "active", "baseline",
             "nominal"]
    names = [n for n in order if any(f == n for _, f, _ in families)]
    columns = [(case, d) for case in cases for d in dimensions]
    with open(os.path.join(out, "table1.csv"), "w", newline="", encoding="utf-8") as f:
        writer = csv.writer(f)
        writer.writerow(["controllers", "case", "locators", "seconds_per_assembly",
                         "q_evaluations_per_assembly"])
        for name in names:
            for case, d in columns:
                values = families.get((case, name, d))
                if values:
                    writer.writerow([name, case, d, mean([v[0] for v in values]),
                                     mean([v[1] for v in values])])
    lines = ["Mean wall time (µs) / Q-evaluations per assembly, to propose u_t and update δû_t "
             "and P_t (the paper's Table 1 gives seconds, with the RD&T FEM software as the twin).", "",
             "| controllers | " + " | ".join(f"{c}, {d} locator{'s' if d != 1 else ''}"
                                            for c, d in columns) + " |",
             "|---|" + "---|" * len(columns)]
    for name in names:
        cells = []
        for case, d in columns:
            values = families.get((case, name, d))
            cells.append("–" if not values else
                         f"{1e6 * mean([v[0] for v in values]):.1f} µs / "
                         f"{mean([v[1] for v in values]):.0f}")
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    with open(os.path.join(out, "table1.md"), "w", encoding="utf-8") as f:
        f.write("\n".join(lines) + "\n")
    return "\n".join(lines)


def median(values):
    values = sorted(v for v in values if not math.isnan(v))
    if not values:
        return math.nan
    middle = len(values) // 2
    return values[middle] if len(values) % 2 else 0.5 * (values[middle - 1] + values[middle])


def controller_lines(mine, episodes, x_of):
    """Per controller of the groups `mine` (in order), its points (x, median residual, diverged
    fraction, Q-evaluations per assembly, lost fraction), x = x_of(group)."""
    controllers = []
    for group in mine:
        controllers += [c for c in group["config"]["controllers"] if c not in controllers]
    lines = {}
    for controller in controllers:
        points = []
        for group in mine:
            rows = [e for e in episodes
                    if e["group"] == group["name"] and e["controller"] == controller]
            if not rows:
                continue
            kept = [e for e in rows if e["diverged_at"] is None]
            lost = lost_count(rows)
            points.append((x_of(group),
                           median([number(e["relative_residual"]) for e in kept]),
                           (len(rows) - len(kept)) / len(rows),
                           mean([number(e["q_evaluations_per_assembly"]) for e in rows]),
                           math.nan if lost is None else lost / len(rows)))
        if points:
            lines[controller] = points
    return lines


# The CLI's controllers keep one colour in every figure, whichever of them a study ran (a
# figure without w = 1 would otherwise shift every later controller's colour); other labels
# (w = 0.5, nominal, …) take the colours left, in the order they appear.
CONTROLLER_COLOURS = {"baseline": "C0", "default": "C1", "w=1": "C2", "active": "C3",
                      "per-component:w=1": "C4"}


def controller_colours(controllers):
    """A matplotlib colour per controller label of `controllers`."""
    spare = itertools.cycle([f"C{i}" for i in range(10)
                             if f"C{i}" not in CONTROLLER_COLOURS.values()])
    return {c: CONTROLLER_COLOURS.get(c) or next(spare) for c in controllers}


def three_panels(lines, evaluations_title):
    """Residual, diverged (solid) and lost (dashed) fractions, Q-evaluations: one line per
    controller; returns the figure and its axes."""
    figure, axes = plt.subplots(1, 3, figsize=(14, 4.2))
    colours = controller_colours(lines)
    for controller, points in lines.items():
        for axis, column in zip(axes, (1, 2, 3)):
            axis.plot([p[0] for p in points], [p[column] for p in points],
                      marker="o", label=controller, color=colours[controller])
            if column == 2:  # the lost fraction beside the diverged one, same colour
                axes[1].plot([p[0] for p in points], [p[4] for p in points], marker="x",
                             linestyle="--", color=colours[controller])
    titles = ("median of the runs' mean (z − z*)/z*",
              "fraction of the runs: diverged (—), lost (- -)",
              evaluations_title)
    for axis, title in zip(axes, titles):
        axis.set_title(title, fontsize=9)
        axis.grid(alpha=0.3)
    axes[0].set_yscale("log")
    axes[2].set_yscale("log")
    axes[1].set_ylim(-0.05, 1.05)
    axes[0].legend(fontsize=8)
    return figure, axes


def save(figure, out, stem):
    figure.tight_layout()
    for extension in ("png", "svg"):
        figure.savefig(os.path.join(out, f"{stem}.{extension}"), dpi=150)
    plt.close(figure)
    return stem


def plot_nonlinearity(groups, episodes, out):
    """One figure per nonlinearity and d: three panels against its strength, a line per controller."""
    study = [g for g in groups if g.get("tags", {}).get("study") == "nonlinearity"]
    made = []
    for kind, d in sorted({(g["tags"]["nonlinearity"], g["tags"]["dimension"]) for g in study}):
        mine = sorted((g for g in study
                       if g["tags"]["nonlinearity"] == kind and g["tags"]["dimension"] == d),
                      key=lambda g: g["tags"]["strength"])
        lines = controller_lines(mine, episodes, lambda g: g["tags"]["strength"])
        figure, axes = three_panels(lines, "Q-evaluations per assembly")
        labels = []
        for g in mine:
            departure = g.get("twin", {}).get("quadratic_departure")
            labels.append(f"{g['tags']['strength']:g}" +
                          ("" if departure is None else f"\n({departure:.2f})"))
        for axis in axes:
            axis.set_xlabel("strength (Q² departure from a quadratic)")
            axis.set_xticks([g["tags"]["strength"] for g in mine])
            axis.set_xticklabels(labels, fontsize=8)
        figure.suptitle(f"analytic twin with {kind}, d = {d}", fontsize=10)
        made.append(save(figure, out, f"nonlinearity_{file_stem(kind)}_d{d}"))
    return made


def plot_scaling(groups, episodes, out):
    """One figure per case of the scaling groups: three panels against d, a line per controller."""
    scaling = [g for g in groups if g.get("tags", {}).get("study") == "scaling"]
    made = []
    for case in sorted({g["config"]["case"] for g in scaling}):
        mine = sorted((g for g in scaling if g["config"]["case"] == case),
                      key=lambda g: g["twin"]["dimension"])
        lines = controller_lines(mine, episodes, lambda g: g["twin"]["dimension"])
        cap = mine[0]["config"].get("candidate_cap")
        figure, axes = three_panels(
            lines, "Q-evaluations per assembly" +
            (f" (w-controllers: ≤ {cap} candidates)" if cap else ""))
        dimensions = [g["twin"]["dimension"] for g in mine]
        for axis in axes:
            axis.set_xlabel("controlled locators d")
            axis.set_xscale("log")
            axis.set_xticks(dimensions)
            axis.set_xticklabels([str(d) for d in dimensions])
        figure.suptitle(f"scaling with dimension: {case}", fontsize=10)
        made.append(save(figure, out, f"scaling_{file_stem(case)}"))
    return made


def plot_history(path, out):
    """δû ± 2σ per locator and z_t against z*, from `twincal history`'s CSV; returns the stem."""
    with open(path, encoding="utf-8", newline="") as f:
        rows = [row for row in csv.DictReader(f) if row["quality"] != ""]
    if not rows:
        sys.exit(f"twincal_plot: {path} has no observed request")
    locators = [key[len("estimate_"):] for key in rows[0] if key.startswith("estimate_")]
    t = [int(row["request_id"]) for row in rows]
    fig, axes = plt.subplots(len(locators) + 1, 1, sharex=True,
                             figsize=(8, 1.6 * (len(locators) + 1) + 1), squeeze=False)
    for axis, name in zip(axes[:-1, 0], locators):
        estimate = [float(row[f"estimate_{name}"]) for row in rows]
        sd = [number(row[f"sd_{name}"] or None) for row in rows]
        axis.plot(t, estimate, color="C0", linewidth=1)
        if not all(math.isnan(v) for v in sd):
            axis.fill_between(t, [e - 2 * v for e, v in zip(estimate, sd)],
                              [e + 2 * v for e, v in zip(estimate, sd)], color="C0", alpha=0.2,
                              linewidth=0)
        axis.set_ylabel(f"δû {name}")
        axis.grid(alpha=0.3)
    quality = axes[-1, 0]
    quality.plot(t, [float(row["quality"]) for row in rows], color="C3", linewidth=1,
                 label="measured z")
    quality.plot(t, [number(row["optimal_quality"] or None) for row in rows], color="0.4",
                 linewidth=1, linestyle="--", label="twin's best z*")
    quality.set_ylabel("quality (mm)")
    quality.set_xlabel("request")
    quality.legend(loc="upper right", fontsize="small")
    quality.grid(alpha=0.3)
    axes[0, 0].set_title(f"{os.path.basename(path)}: estimate ± 2σ per locator, quality")
    fig.tight_layout()
    stem = os.path.splitext(os.path.basename(path))[0]
    for extension in ("png", "svg"):
        fig.savefig(os.path.join(out, f"{stem}.{extension}"), dpi=120)
    plt.close(fig)
    return stem


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    source = parser.add_mutually_exclusive_group(required=True)
    source.add_argument("--results", help="a twincal results directory")
    source.add_argument("--history", help="a serve session's history (`twincal history`)")
    parser.add_argument("--out", help="where the figures go (default RESULTS/figures, or the "
                        "history's directory)")
    args = parser.parse_args()
    if args.history:
        out = args.out or os.path.dirname(os.path.abspath(args.history))
        os.makedirs(out, exist_ok=True)
        stem = plot_history(args.history, out)
        print(f"{stem}.png and {stem}.svg in {out}")
        return
    out = args.out or os.path.join(args.results, "figures")
    os.makedirs(out, exist_ok=True)
    groups, episodes = load(args.results)
    made = []
    for group in groups:
        stem = plot_group(group, [e for e in episodes if e["group"] == group["name"]], out)
        if stem:
            made.append(stem)
    made += plot_scaling(groups, episodes, out)
    made += plot_nonlinearity(groups, episodes, out)
    print(table1(groups, episodes, out))
    print(f"\n{len(made)} figures (PNG + SVG), table1.md, table1.csv and table1_detail.csv "
          f"in {out}")


if __name__ == "__main__":
    main()
