"""What the Python benchmarks (filter_step.py, paper_controller_step.py) share: their command
line and the header of the Markdown table they print."""

import argparse


def start_benchmark(doc, work, work_default, dimensions, columns, left_aligned):
    """Parses the command line and prints the table's header; returns the arguments.

    The arguments: `--<work>` (an int: what one repeat runs, e.g. steps), `--repeats` (the times
    are their medians) and `--dimensions` (comma-separated; returned as a list of ints). The
    description is the first line of `doc`, the script's docstring. The table has `columns`, the
    first `left_aligned` of them aligned left and the others right."""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument(f"--{work}", type=int, default=work_default)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--dimensions", default=dimensions)
    args = parser.parse_args()
    args.dimensions = [int(v) for v in args.dimensions.split(",")]
    print("| " + " | ".join(columns) + " |")
    print("|" + "|".join(["---"] * left_aligned + ["---:"] * (len(columns) - left_aligned)) + "|")
    return args
