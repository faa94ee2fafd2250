"""What the distributed tests (study_runs.py) and the benchmark of studies over MPI ranks
(benchmarks/distributed/study_over_ranks.py) share: the environment and the command that start
a job of ranks, and the external twin settings of their studies."""
import os
import subprocess


def mpi_environment():
    """The environment for mpiexec: this one, letting OpenMPI run as root."""
    env = dict(os.environ)
    if os.geteuid() == 0:  # CI containers run as root, which OpenMPI refuses by default
        env["OMPI_ALLOW_RUN_AS_ROOT"] = "1"
        env["OMPI_ALLOW_RUN_AS_ROOT_CONFIRM"] = "1"
    return env


def launcher(mpiexec, ranks):
    """The command prefix that runs a program on `ranks` ranks (oversubscribed under OpenMPI)."""
    version = subprocess.run([mpiexec, "--version"], capture_output=True, text=True).stdout
    extra = ["--oversubscribe"] if "Open MPI" in version or "OpenRTE" in version else []
    return [mpiexec, "-n", str(ranks)] + extra


def external_twin(command, upper_parts, lower_parts):
    """A config's external_twin: the program `command` (argv) with three locators A, B, C in
    [-1, 1], one worker and the budgeted u0 search (16 evaluations)."""
    return {
        "command": command,
        "locators": ["A", "B", "C"],
        "lower_bounds": [-1.0, -1.0, -1.0],
        "upper_bounds": [1.0, 1.0, 1.0],
        "upper_parts": upper_parts,
        "lower_parts": lower_parts,
        "workers": 1,
        "optimum_budget": 16,
    }
