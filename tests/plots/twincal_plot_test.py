#!/usr/bin/env python3
"""`twincal plot --results` on a strength sweep: a controller keeps its colour whichever
controllers the study ran (apps/plots/twincal_plot.py, CONTROLLER_COLOURS). Two tiny sweeps, one
with w = 1 and one without; in both, the active controller's lines are drawn in C3 and the
baseline's in C0, and the sweep without w = 1 has no line in w = 1's C2 nor in C1 (default's,
which the active controller took before).

    twincal_plot_test.py TWINCAL
"""
import os
import re
import subprocess
import sys
import tempfile

# matplotlib's default cycle, C0 … C3
BLUE, ORANGE, GREEN, RED = "#1f77b4", "#ff7f0e", "#2ca02c", "#d62728"


def line_colours(svg_path):
    """The stroke colours of the SVG's plotted lines (matplotlib writes them as `stroke: #rrggbb`)."""
    with open(svg_path, encoding="utf-8") as f:
        return set(re.findall(r"stroke: (#[0-9a-f]{6})", f.read()))


def sweep(twincal, scratch, name, controllers):
    out = os.path.join(scratch, name)
    subprocess.run([twincal, "scaling", "--nonlinearity", "contact", "--dimensions", "2",
                    "--strengths", "0,1", "--controllers", controllers, "--runs", "2",
                    "--assemblies", "6", "--out", out],
                   check=True, capture_output=True, text=True)
    subprocess.run([twincal, "plot", "--results", out], check=True, capture_output=True,
                   text=True)
    return line_colours(os.path.join(out, "figures", "nonlinearity_contact_d2.svg"))


def main():
    twincal = sys.argv[1]
    with tempfile.TemporaryDirectory() as scratch:
        three = sweep(twincal, scratch, "three", "baseline,w=1,active")
        two = sweep(twincal, scratch, "two", "baseline,active")
    assert {BLUE, GREEN, RED} <= three, three
    assert {BLUE, RED} <= two, two
    assert GREEN not in two and ORANGE not in two, two
    print("the baseline in C0 and the active controller in C3, with and without w = 1")
    return 0


if __name__ == "__main__":
    sys.exit(main())
