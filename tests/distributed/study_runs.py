#!/usr/bin/env python3
"""A study run whole, in shards, over MPI ranks and killed and resumed must write the same
results directory, apart from its wall-time columns (compare_results.py).

usage: study_runs.py TWINCAL WORKDIR shards
       study_runs.py TWINCAL WORKDIR mpi MPIEXEC
       study_runs.py TWINCAL WORKDIR mpi-kill MPIEXEC
       study_runs.py TWINCAL WORKDIR mpi-twin-pool MPIEXEC

shards:   three `--shard i/3` runs merged equal the whole study; two of them merged and the
          study run on the merge (it runs only the third's episodes) equal it in any order.
mpi:      `mpiexec -n 1` and `-n 3` of `twincal run` and of `twincal paper` equal the
          single-process runs.
mpi-kill: a job of 3 ranks killed after a seeded number of stored episodes (mpiexec ended with
          SIGTERM), then one of 3 ranks whose worker rank is killed (SIGKILL) mid-run, each
          resumed with 2 ranks, equal the single-process run in any order, having run only what
          was missing.
mpi-twin-pool:
          a study on an external twin (examples/external_twin/minimal_twin.py) with
          `--mpi-twin-pool` over 2 and 3 ranks equals the single-process run, also with u0
          searched on the key points' deviations (least_squares); a twin whose
          batches crash (tests/data/batch_crashing_twin.py) ends the study with the twin-failure
          error, naming the rank.
"""
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

from mpi_study import external_twin, launcher, mpi_environment

HERE = Path(__file__).resolve().parent
RUN = ["run", "--case", "analytic", "--runs", "3", "--assemblies", "20",
       "--controllers", "baseline,default,w=1,active", "--quiet"]
PAPER = ["paper", "--case", "body", "--runs", "2", "--assemblies", "30", "--quiet"]
# ~0.9 s of CPU per episode (w = 1 at d = 12), so that a kill lands mid-study on any machine:
# it comes after at most 6 of the 16 episodes are stored, with seconds of work left.
SLOW = ["run", "--case", "analytic", "--dimension", "12", "--locators", "all", "--runs", "16",
        "--controllers", "w=1", "--quiet"]
SLOW_EPISODES = 16


ROOT = HERE.parents[1]


def external_config(work, program, name, **settings):
    """A small study on the external twin `program` (a Python script), written to work/name;
    `settings` go into its external_twin."""
    config = {
        "case": "external",
        "external_twin": {**external_twin([sys.executable, str(program)], 3, 3), **settings},
        "locators": "all",
        "controllers": ["baseline", "default", "w=1", "active"],
        "runs": 2,
        "assemblies": 9,
    }
    path = work / name
    path.write_text(json.dumps(config))
    return path


def run(command, **kwargs):
    result = subprocess.run(command, capture_output=True, text=True, **kwargs)
    if result.returncode != 0:
        sys.exit(f"{' '.join(map(str, command))} exited {result.returncode}:\n"
                 f"{result.stdout}\n{result.stderr}")
    return result.stdout


def compare(expected, actual, any_order=False):
    run([sys.executable, HERE / "compare_results.py", expected, actual] +
        (["--any-order"] if any_order else []))


def stored(directory):
    path = Path(directory) / "episodes.jsonl"
    return path.read_text().count("\n") if path.exists() else 0


def shards(twincal, work):
    run([twincal] + RUN + ["--out", work / "whole"])
    for i in range(3):
        run([twincal] + RUN + ["--out", work / f"shard{i}", "--shard", f"{i}/3"])
    run([twincal, "merge", "--out", work / "merged",
         "--shards", ",".join(str(work / f"shard{i}") for i in range(3))])
    compare(work / "whole", work / "merged")
    out = run([twincal, "merge", "--out", work / "partial",
               "--shards", f"{work / 'shard0'},{work / 'shard2'}"])
    assert "4 missing" in out, out
    out = run([twincal] + RUN + ["--out", work / "partial"])
    assert "4 run now, 8 already in" in out, out
    compare(work / "whole", work / "partial", any_order=True)


def mpi(twincal, work, mpiexec):
    env = mpi_environment()
    for name, args in (("run", RUN), ("paper", PAPER)):
        run([twincal] + args + ["--out", work / f"{name}-single"])
        for ranks in (1, 3):
            out = run(launcher(mpiexec, ranks) + [twincal] + args +
                      ["--out", work / f"{name}-mpi{ranks}"], env=env)
            assert f"on {ranks} MPI rank(s)" in out, out
            compare(work / f"{name}-single", work / f"{name}-mpi{ranks}")


def kill_and_resume(twincal, work, mpiexec, out, kill):
    env = mpi_environment()
    job = subprocess.Popen(launcher(mpiexec, 3) + [twincal] + SLOW + ["--out", out], env=env,
                           stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                           start_new_session=True)
    at = random.Random(2023).randint(2, 6)
    deadline = time.monotonic() + 120
    while stored(out) < at and job.poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)
    if job.poll() is not None:
        sys.exit(f"the job ended before it was killed: {job.stderr.read()}")
    kill(job)
    job.wait(timeout=60)
    try:
        os.killpg(job.pid, signal.SIGKILL)  # anything the launcher left behind
    except ProcessLookupError:
        pass
    kept = stored(out)
    planned = SLOW_EPISODES
    assert kept < planned, f"{out}: all {kept} episodes were stored before the kill"
    result = run(launcher(mpiexec, 2) + [twincal] + SLOW + ["--out", out], env=env)
    assert f"{planned - kept} run now, {kept} already in" in result, result
    compare(work / "slow-single", out, any_order=True)


def session_processes(session, program):
    """The processes of session `session` whose command line mentions `program` (from /proc:
    a fresh machine may have no pgrep)."""
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            # The session id is the sixth field of stat, after the parenthesized command name.
            fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
            command = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode()
        except OSError:
            continue  # the process ended meanwhile
        if int(fields[3]) == session and program in command:
            found.append(int(entry.name))
    return found


def mpi_kill(twincal, work, mpiexec):
    run([twincal] + SLOW + ["--out", work / "slow-single"])

    def end_launcher(job):
        job.send_signal(signal.SIGTERM)

    def kill_a_worker_rank(job):
        # The ranks are the processes in the launcher's session running twincal; rank 0 opened
        # the results, so kill one that did not: any but the lowest pid is not rank 0 for
        # certain, so kill the newest.
        ranks = sorted(pid for pid in session_processes(job.pid, twincal) if pid != job.pid)
        if len(ranks) < 2:
            sys.exit(f"found ranks {ranks} in the job's session")
        os.kill(ranks[-1], signal.SIGKILL)

    kill_and_resume(twincal, work, mpiexec, work / "killed", end_launcher)
    kill_and_resume(twincal, work, mpiexec, work / "rank-died", kill_a_worker_rank)


def mpi_twin_pool(twincal, work, mpiexec):
    env = mpi_environment()
    config = external_config(work, ROOT / "examples" / "external_twin" / "minimal_twin.py",
                             "minimal.json")
    study = [twincal, "run", "--config", config, "--quiet"]
    run(study + ["--out", work / "single"])
    for ranks in (2, 3):
        out = run(launcher(mpiexec, ranks) + study +
                  ["--out", work / f"pool{ranks}", "--mpi-twin-pool"], env=env)
        assert f"its twins' workers on {ranks - 1} other rank(s)" in out, out
        compare(work / "single", work / f"pool{ranks}")
    # u0 searched on the key points' deviations, which the ranks relay too.
    deviations = external_config(work, ROOT / "examples" / "external_twin" / "minimal_twin.py",
                                 "deviations.json", key_points=4, optimum_method="least_squares")
    study = [twincal, "run", "--config", deviations, "--controllers", "baseline,w=1", "--quiet"]
    run(study + ["--out", work / "deviations-single"])
    run(launcher(mpiexec, 3) + study + ["--out", work / "deviations-pool3", "--mpi-twin-pool"],
        env=env)
    compare(work / "deviations-single", work / "deviations-pool3")
    crashing = external_config(work, ROOT / "tests" / "data" / "batch_crashing_twin.py",
                               "crashing.json")
    result = subprocess.run(launcher(mpiexec, 3) + [twincal, "run", "--config", crashing,
                                                    "--controllers", "w=1", "--quiet",
                                                    "--out", work / "crashing",
                                                    "--mpi-twin-pool"],
                            capture_output=True, text=True, env=env)
    assert result.returncode != 0, result.stdout
    for expected in ("episodes not stored because their twin failed", "external twin crashed",
                     "rank 1: "):
        assert expected in result.stderr, result.stderr


def main():
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    twincal, work, mode = sys.argv[1], Path(sys.argv[2]), sys.argv[3]
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    if mode == "shards":
        shards(twincal, work)
    elif mode == "mpi":
        mpi(twincal, work, sys.argv[4])
    elif mode == "mpi-kill":
        mpi_kill(twincal, work, sys.argv[4])
    elif mode == "mpi-twin-pool":
        mpi_twin_pool(twincal, work, sys.argv[4])
    else:
        sys.exit(__doc__)
    print(f"{mode}: ok")


if __name__ == "__main__":
    main()
