"""The paper's w-controller per assembly from Python: twincal.PaperController against the
paper's own stack (a filterpy UKF + scipy.stats.qmc.Sobol candidates, the loop written in
Python as the paper's code does it), on the same twin: one written in Python
(QuadraticRmsTwin, which twincal calls back in batches) and the built-in FEM car body
(twincal.Twin, locators A or ABC, which twincal calls without Python and the stack calls through
its Python methods).

    PYTHONPATH=build/python:/path/to/filterpy-checkout /usr/bin/python3 \\
        benchmarks/python/paper_controller_step.py [--assemblies 100] [--repeats 5]

Neither filterpy nor SciPy is a twincal dependency. The reference follows eqs. (11)-(14): per
assembly u0 = twin.optimum(x), the UKF's predict, 2^(2+d) scrambled Sobol points mapped to
N(u0 + δû, P) and kept inside |u - (u0 + δû)|_∞ <= 0.1, each scored by
L_w = (1 - w) Σ Wm_i Q(x, u - s_i) + w sqrt(tr P⁺(u)) / d with P⁺ from the same sigma-point values
(the twin called once per sigma point and candidate, as filterpy's hx is), then the update with
the measured z. Both run the same drifting plant; the script reports milliseconds per assembly
(medians of the repeats) and twin calls (Python twin) or Q-evaluations (FEM twin) per assembly.
"""

import statistics
import time

import numpy as np
from filterpy.kalman import MerweScaledSigmaPoints, UnscentedKalmanFilter
from scipy.stats import norm, qmc

import twincal
from twincal.reference_twins import QuadraticRmsTwin

from benchmark_cli import start_benchmark

COLUMNS = ["twin", "d", "candidates", "paper's stack (ms / assembly)", "twin evaluations",
           "twincal (ms / assembly)", "twin evaluations", "speed-up"]


class Counting:
    """Counts the calls into a twin (the stack's twin evaluations: one control per call)."""

    def __init__(self, twin):
        self.twin, self.calls = twin, 0
        self.lower_bounds, self.upper_bounds = twin.lower_bounds, twin.upper_bounds

    def quality_batch(self, assembly, controls):
        self.calls += controls.shape[1]
        return self.twin.quality_batch(assembly, controls)

    def optimum(self, assembly):
        return self.twin.optimum(assembly)


class PaperStackController:
    """The reference: filterpy + SciPy, the loop in Python."""

    def __init__(self, twin, d, w, seed):
        self.twin, self.d, self.w = twin, d, w
        rng = np.random.default_rng(seed)

        def hx(state, u, x):
            return np.array([twin.quality_batch(x, (u - state)[:, None])[0]])

        self.ukf = UnscentedKalmanFilter(dim_x=d, dim_z=1, dt=1.0, hx=hx, fx=lambda s, dt: s,
                                         points=MerweScaledSigmaPoints(d, 1.0, 2.0, 0.0))
        self.ukf.x = rng.normal(scale=np.sqrt(1e-3), size=d)
        self.ukf.P = 1e-3 * np.eye(d)
        self.ukf.Q = 1e-3 * np.eye(d)
        self.ukf.R = np.array([[1e-4]])
        self.sobol = qmc.Sobol(d, scramble=True, seed=seed)

    def propose(self, x):
        d, ukf = self.d, self.ukf
        u0 = self.twin.optimum(x)
        ukf.predict()
        centre = u0 + ukf.x
        uniform = self.sobol.random(2 ** (2 + d))
        candidates = centre + norm.ppf(np.clip(uniform, 1e-12, 1 - 1e-12)) @ np.linalg.cholesky(ukf.P).T
        candidates = candidates[np.all(np.abs(candidates - centre) <= 0.1, axis=1)]
        if len(candidates) == 0:
            candidates = centre[None, :]
        sigmas = ukf.points_fn.sigma_points(ukf.x, ukf.P)
        Wm, Wc = ukf.Wm, ukf.Wc
        best, best_loss = centre, np.inf
        for u in candidates:
            values = np.array([self.twin.quality_batch(x, (u - s)[:, None])[0] for s in sigmas])
            z_hat = Wm @ values
            S = Wc @ (values - z_hat) ** 2 + ukf.R[0, 0]
            Pxz = ((sigmas - ukf.x).T * Wc) @ (values - z_hat)
            K = Pxz / S
            P_post = ukf.P - np.outer(K, K) * S
            loss = (1 - self.w) * z_hat + self.w * np.sqrt(max(np.trace(P_post), 0.0)) / d
            if loss < best_loss:
                best, best_loss = u, loss
        return best

    def observe(self, x, u, z):
        self.ukf.update(np.array([z]), u=u, x=x)


def episode(controller, twin, assemblies, evaluations):
    """Seconds per assembly spent in the controller (propose and observe, its twin calls
    included; the plant's measurement is not) over `assemblies` assemblies against the drifting
    plant, and twin evaluations per assembly (`evaluations(controller)` after each step)."""
    d = len(twin.lower_bounds)
    order = np.random.default_rng(7).integers(len(twin_assemblies(twin)), size=assemblies)
    offset, step = np.zeros(d), np.full(d, 0.02 / np.sqrt(d))
    count, seconds = 0, 0.0
    for i in order:
        x = twin_assemblies(twin)[int(i)]
        start = time.perf_counter()
        u = controller.propose(x)
        seconds += time.perf_counter() - start
        z = float(twin.quality_batch(x, (u - offset)[:, None])[0])
        start = time.perf_counter()
        controller.observe(x, u, z)
        seconds += time.perf_counter() - start
        count += evaluations(controller)
        offset = offset + step
    return seconds / assemblies, count / assemblies


def twin_assemblies(twin):
    return getattr(twin, "assemblies", list(range(10)))


def measure(twin, d, args):
    """(stack ms, stack evaluations, twincal ms, twincal evaluations) per assembly."""
    stack, ours = [], []
    for _ in range(args.repeats):
        counted = Counting(twin)
        calls_before = [0]

        def stack_calls(_, counted=counted, before=calls_before):
            new, before[0] = counted.calls - before[0], counted.calls
            return new

        stack.append(episode(PaperStackController(counted, d, 1.0, 2023), twin, args.assemblies,
                             stack_calls))
        # propose's evaluations (candidates x sigma points) and the update's 2d + 1
        ours.append(episode(twincal.PaperController(twin, w=1.0, seed=2023), twin,
                            args.assemblies,
                            lambda c: c.last_proposal["quality_evaluations"] + 2 * d + 1))
    return (1e3 * statistics.median(s[0] for s in stack), stack[0][1],
            1e3 * statistics.median(s[0] for s in ours), ours[0][1])


def main():
    args = start_benchmark(__doc__, "assemblies", 100, "1,3", COLUMNS, left_aligned=2)
    for d in args.dimensions:
        twins = {"Python (QuadraticRmsTwin)": QuadraticRmsTwin(d, seed=2023)}
        if d in (1, 3):
            twins["FEM car body (twincal.Twin)"] = twincal.Twin(
                "body", locators="A" if d == 1 else "ABC")
        for name, twin in twins.items():
            t_stack, n_stack, t_ours, n_ours = measure(twin, d, args)
            print(f"| {name} | {d} | {2 ** (2 + d)} | {t_stack:.2f} | {n_stack:.0f} | "
                  f"{t_ours:.3f} | {n_ours:.0f} | {t_stack / t_ours:.0f}× |")


if __name__ == "__main__":
    main()
