"""One UKF predict + update from Python: twincal (hx over all sigma points in one call) against
filterpy (hx once per point), on the paper's measurement z = sqrt(q0 + e^T H e), e = u - x.

    PYTHONPATH=build/python:/path/to/filterpy-checkout /usr/bin/python3 \\
        benchmarks/python/filter_step.py [--steps 2000] [--repeats 5]

filterpy is not a dependency: point PYTHONPATH at a checkout of it (its filterpy/ folder), as the
C++ comparison does for mherb/kalman (docs/benchmarks.md). Both filters run the same inputs; the
script checks that their estimates agree before it reports times (medians of the repeats, in
microseconds per step).
"""

import statistics
import time

import numpy as np

import twincal
from filterpy.kalman import MerweScaledSigmaPoints as FilterpyPoints
from filterpy.kalman import UnscentedKalmanFilter as FilterpyUkf

from benchmark_cli import start_benchmark

Q0 = 0.04
COLUMNS = ["d", "filterpy (µs/step)", "twincal, hx per point", "twincal, hx batched",
           "speed-up (batched)", "max |x_twincal − x_filterpy|"]


def problem(d, steps, seed=2023):
    rng = np.random.default_rng(seed)
    a = rng.normal(size=(d, d))
    H = a @ a.T / d + np.eye(d)
    controls = rng.normal(scale=0.1, size=(steps, d))
    truth = rng.normal(scale=0.05, size=d)
    z = np.array([np.sqrt(Q0 + (u - truth) @ H @ (u - truth)) for u in controls])
    return H, controls, z


def run_twincal(d, H, controls, z, batched):
    def hx_batched(points, u):
        e = u[:, None] - points
        return np.sqrt(Q0 + np.einsum("im,ij,jm->m", e, H, e))

    def hx_per_point(points, u):  # the same work as filterpy's: one Python call per point
        out = np.empty(points.shape[1])
        for j in range(points.shape[1]):
            e = u - points[:, j]
            out[j] = np.sqrt(Q0 + e @ H @ e)
        return out

    f = twincal.UnscentedKalmanFilter(
        d, hx_batched if batched else hx_per_point, twincal.MerweScaledSigmaPoints(d, 1.0, 2.0, 0.0),
        P=1e-3 * np.eye(d), Q=1e-4 * np.eye(d), R=1e-4, symmetrize=False)
    start = time.perf_counter()
    for u, measured in zip(controls, z):
        f.predict()
        f.update(measured, u=u)
    return time.perf_counter() - start, f.x


def run_filterpy(d, H, controls, z):
    def hx(x, u):
        e = u - x
        return np.array([np.sqrt(Q0 + e @ H @ e)])

    f = FilterpyUkf(dim_x=d, dim_z=1, dt=1.0, hx=hx, fx=lambda x, dt: x,
                    points=FilterpyPoints(d, alpha=1.0, beta=2.0, kappa=0.0))
    f.P = 1e-3 * np.eye(d)
    f.Q = 1e-4 * np.eye(d)
    f.R = np.array([[1e-4]])
    start = time.perf_counter()
    for u, measured in zip(controls, z):
        f.predict()
        f.update(np.array([measured]), u=u)
    return time.perf_counter() - start, f.x


def main():
    args = start_benchmark(__doc__, "steps", 2000, "1,3,6,12", COLUMNS, left_aligned=1)
    for d in args.dimensions:
        H, controls, z = problem(d, args.steps)
        times = {"filterpy": [], "per_point": [], "batched": []}
        for _ in range(args.repeats):
            t, x_fp = run_filterpy(d, H, controls, z)
            times["filterpy"].append(t)
            t, x_pp = run_twincal(d, H, controls, z, batched=False)
            times["per_point"].append(t)
            t, x_b = run_twincal(d, H, controls, z, batched=True)
            times["batched"].append(t)
        disagreement = max(np.max(np.abs(x_b - x_fp)), np.max(np.abs(x_pp - x_fp)))
        if disagreement > 1e-9:
            raise SystemExit(f"d={d}: twincal and filterpy disagree by {disagreement:.3g}")
        micro = {k: 1e6 * statistics.median(v) / args.steps for k, v in times.items()}
        print(f"| {d} | {micro['filterpy']:.1f} | {micro['per_point']:.1f} | "
              f"{micro['batched']:.1f} | {micro['filterpy'] / micro['batched']:.1f}× | "
              f"{disagreement:.1e} |")


if __name__ == "__main__":
    main()
