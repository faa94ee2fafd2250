#!/usr/bin/env python3
"""Draws a sheet-metal twin layout (JSON from twincal_export_layout) as a PNG.

usage: plot_layout.py LAYOUT.json OUT.png

Both parts with their mesh, the overlap flange, locators (each with its clamp), spot welds, key
measurement points and, for a nominal final frame, the supports.
"""
import json
import sys

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Rectangle
except ImportError:
    sys.exit(
        "plot_layout.py: this interpreter has no matplotlib; run it with one that has "
        "(set TWINCAL_PYTHON, or use /usr/bin/python3 with python3-matplotlib)"
    )


def draw_part(ax, outline, h, color, label):
    x0, y0, w, hh = outline["x0"], outline["y0"], outline["width"], outline["height"]
    ax.add_patch(Rectangle((x0, y0), w, hh, facecolor=color, alpha=0.18, edgecolor=color,
                           linewidth=1.5, label=label))
    nx, ny = round(w / h), round(hh / h)
    for i in range(nx + 1):
        ax.plot([x0 + i * h] * 2, [y0, y0 + hh], color=color, linewidth=0.2, alpha=0.5)
    for j in range(ny + 1):
        ax.plot([x0, x0 + w], [y0 + j * h] * 2, color=color, linewidth=0.2, alpha=0.5)


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    with open(sys.argv[1]) as f:
        layout = json.load(f)
    h = layout["element_size"]
    fig, ax = plt.subplots(figsize=(9, 9 * (layout["upper"]["y0"] + layout["upper"]["height"])
                                    / max(layout["lower"]["width"], 1) * 0.85))
    draw_part(ax, layout["lower"], h, "tab:blue", "lower part")
    draw_part(ax, layout["upper"], h, "tab:orange", "upper part")
    loc = layout["locators"]
    ax.scatter([p["x"] for p in loc], [p["y"] for p in loc], marker="^", s=90, color="black",
               zorder=5, label="locator + clamp (adjustable, u)")
    ax.scatter([p["x"] for p in loc], [p["y"] for p in loc], marker="s", s=220,
               facecolors="none", edgecolors="black", linewidths=0.8, zorder=5)
    for p in loc:
        ax.annotate(p["name"], (p["x"], p["y"]), textcoords="offset points", xytext=(6, 6),
                    fontsize=8)
    welds = layout["welds"]
    ax.scatter([w["x"] for w in welds], [w["y"] for w in welds], marker="x", s=40,
               color="red", zorder=6, label="spot weld")
    keys = layout["key_points"]
    ax.scatter([p["x"] for p in keys], [p["y"] for p in keys], marker="o", s=30,
               color="tab:green", zorder=6, label="key point")
    if layout["final_support"] == "nominal_frame":
        sup = layout["supports"]
        ax.scatter([p["x"] for p in sup], [p["y"] for p in sup], marker="D", s=120,
                   facecolors="none", edgecolors="purple", linewidths=1.5, zorder=7,
                   label="final nominal support")
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_title(f"{layout['name']}: {len(loc)} locators, {len(welds)} welds "
                 f"({layout['weld_tie'].replace('_', ' ')}), {len(keys)} key points,\n"
                 f"final support: {layout['final_support'].replace('_', ' ')}, "
                 f"{h:g} mm ACM elements")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.08), ncol=3, fontsize=8)
    fig.tight_layout()
    fig.savefig(sys.argv[2], dpi=110)


if __name__ == "__main__":
    main()
