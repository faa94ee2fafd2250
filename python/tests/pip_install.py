"""`pip install` and `pip uninstall` of the package into a fresh venv, as docs/python.md tells a
user to do it (ctest python.pip_install).

    pip_install.py SOURCE_DIR BUILD_DIR

The venv sees the system's packages (NumPy, SciPy, setuptools, wheel: --system-site-packages),
pip runs offline (--no-index, --no-build-isolation), and setup.py builds the extension in
BUILD_DIR, the release build that ctest runs from (TWINCAL_CMAKE_BUILD_DIR), instead of
compiling the libraries a second time. The installed package is then imported from outside the
checkout with no PYTHONPATH, used, and uninstalled."""

import os
import subprocess
import sys
import tempfile
from pathlib import Path

source_dir, build_dir = (Path(arg).resolve() for arg in sys.argv[1:3])


def run(command, env, cwd, expect_failure=False):
    """Runs command; returns its output; exits with both outputs if it fails (or succeeds when
    expect_failure)."""
    result = subprocess.run(command, env=env, cwd=cwd, capture_output=True, text=True)
    if (result.returncode != 0) != expect_failure:
        sys.exit(f"{' '.join(map(str, command))} exited with {result.returncode} (expected "
                 f"{'failure' if expect_failure else 'success'})\n--- stdout\n{result.stdout}"
                 f"\n--- stderr\n{result.stderr}")
    return result.stdout + result.stderr


with tempfile.TemporaryDirectory(prefix="twincal-pip-") as scratch:
    scratch = Path(scratch)
    venv = scratch / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--system-site-packages", str(venv)],
                   check=True)
    python = venv / "bin" / "python"
    env = {key: value for key, value in os.environ.items() if key != "PYTHONPATH"}
    env["PIP_DISABLE_PIP_VERSION_CHECK"] = "1"
    install = [python, "-m", "pip", "install", "--no-index", "--no-build-isolation",
               str(source_dir / "python")]

    # A build directory given as a relative path is refused with the rule it broke.
    output = run(install, {**env, "TWINCAL_CMAKE_BUILD_DIR": "build"}, scratch,
                 expect_failure=True)
    assert "TWINCAL_CMAKE_BUILD_DIR: value is build; rule: must be an absolute path" in output, output

    run(install, {**env, "TWINCAL_CMAKE_BUILD_DIR": str(build_dir)}, scratch)
    check = """
import numpy as np, scipy.stats.qmc as qmc, twincal, sys
from pathlib import Path
from twincal.reference_twins import QuadraticRmsTwin
assert Path(twincal.__file__).is_relative_to(sys.prefix), (twincal.__file__, sys.prefix)
assert isinstance(twincal.Sobol(3, seed=7), qmc.QMCEngine)
twin = QuadraticRmsTwin(3)
controller = twincal.PaperController(twin, w=1.0, seed=2023)
u = controller.propose(0)
controller.observe(0, u, float(twin.quality_batch(0, u[:, None])[0]))
assert controller.offset_estimate.shape == (3,)
print("installed", twincal.__file__)
"""
    print(run([python, "-c", check], env, scratch).strip())
    listed = run([python, "-m", "pip", "show", "--files", "twincal"], env, scratch)
    assert "twincal/_twincal." in listed and "twincal/qmc.py" in listed, listed

    run([python, "-m", "pip", "uninstall", "--yes", "twincal"], env, scratch)
    output = run([python, "-c", "import twincal"], env, scratch, expect_failure=True)
    assert "No module named 'twincal'" in output, output
    site = run([python, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"], env,
               scratch).strip()
    left = sorted(p.name for p in Path(site).glob("twincal*"))
    assert not left, f"pip uninstall left {left} in {site}"
    print("uninstalled: nothing of twincal is left in", site)
