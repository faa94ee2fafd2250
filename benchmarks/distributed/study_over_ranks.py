#!/usr/bin/env python3
"""Episodes per second of a study over MPI ranks, on an external twin that sleeps per call
(docs/benchmarks.md, "Studies over MPI ranks").

usage: study_over_ranks.py TWINCAL [--ranks 1,2,4,8,16] [--sleep 0.05] [--runs 64]
                           [--work DIR]

The study: `twincal run` of the default controller (3 twin calls per assembly at d = 3) over
--runs runs of 10 assemblies on sleeping_twin.py (one worker process per rank), u0 by the
budgeted search (optimum_budget 16). Every rank builds the twins itself, so the set-up (the u0
searches, on each rank at once) is reported apart; episodes per second count the rest. The
results directories of every rank count are checked to be the same as the first's
(tests/distributed/compare_results.py). Needs mpiexec (OpenMPI: --oversubscribe is added).
"""
import argparse
import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests" / "distributed"))
from mpi_study import external_twin, launcher, mpi_environment  # noqa: E402


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("twincal")
    parser.add_argument("--ranks", default="1,2,4,8,16")
    parser.add_argument("--sleep", type=float, default=0.05)
    parser.add_argument("--runs", type=int, default=64)
    parser.add_argument("--work", default="/tmp/twincal_study_over_ranks")
    args = parser.parse_args()
    work = Path(args.work)
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    config = {
        "name": "sleeping",
        "case": "external",
        "external_twin": external_twin(
            [sys.executable, str(Path(__file__).resolve().parent / "sleeping_twin.py"),
             "--sleep", str(args.sleep)], 2, 5),
        "locators": "all",
        "controllers": ["default"],
        "runs": args.runs,
        "assemblies": 10,
    }
    (work / "config.json").write_text(json.dumps(config))
    env = mpi_environment()
    print("| ranks | wall time | of it set-up | episodes per second | speed-up | ÷ ranks |")
    print("|---|---|---|---|---|---|")
    first = None
    base_rate = None
    for ranks in [int(r) for r in args.ranks.split(",")]:
        out = work / f"ranks{ranks}"
        result = subprocess.run(
            launcher("mpiexec", ranks) +
            [args.twincal, "run", "--config", str(work / "config.json"), "--out", str(out),
             "--quiet"], capture_output=True, text=True, env=env)
        if result.returncode != 0:
            sys.exit(f"{ranks} ranks: exit {result.returncode}\n{result.stdout}\n{result.stderr}")
        match = re.search(r"(\d+) run now.*; ([\d.]+) s on \d+ MPI rank\(s\) \(([\d.]+) s of it",
                          result.stdout)
        episodes, seconds, setup = int(match[1]), float(match[2]), float(match[3])
        rate = episodes / (seconds - setup)
        base_rate = base_rate or rate / ranks
        print(f"| {ranks} | {seconds:.1f} s | {setup:.1f} s | {rate:.2f} | "
              f"{rate / base_rate:.2f}× | {rate / base_rate / ranks:.2f} |", flush=True)
        if first is None:
            first = out
        else:
            subprocess.run([sys.executable, ROOT / "tests" / "distributed" / "compare_results.py",
                            first, out], check=True, capture_output=True)


if __name__ == "__main__":
    main()
