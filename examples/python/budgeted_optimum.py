"""u0 of a twin written in Python, searched within a budget (docs/python.md): a twin with contact
(its key points held back past a gap: piecewise affine deviations, a Q with kinks) that does not
know its optimum, searched by twincal.BudgetedOptimum on its deviations (least squares) and on Q
alone (trust region), against a reference search of thousands of calls.

    python3 examples/python/budgeted_optimum.py [SEED ...]   (twin seeds; 0 unless given)
"""

import sys

import numpy as np

import twincal


class GapTwin:
    """r(x, u) = a + B (u - c_x) at m key points, each held back by `strength` of how far it
    goes past a gap g (drawn per key point, on a drawn side); Q = ‖r‖ / √m."""

    def __init__(self, d, key_points=40, seed=0, assemblies=30, strength=0.8):
        rng = np.random.default_rng(seed)
        self.B = rng.normal(size=(key_points, d)) / np.sqrt(d)
        self.a = rng.normal(scale=0.2, size=(assemblies, key_points))
        self.c = rng.uniform(-0.3, 0.3, size=(assemblies, d))
        self.gap = rng.uniform(0.05, 0.3, size=key_points) * rng.choice([-1, 1], size=key_points)
        self.strength = strength
        self.key_point_count = key_points
        self.lower_bounds = -np.ones(d)
        self.upper_bounds = np.ones(d)
        self.assemblies = list(range(assemblies))

    def deviations_batch(self, x, controls):
        free = self.a[x][:, None] + self.B @ (controls - self.c[x][:, None])
        gap = self.gap[:, None]
        past = np.where(gap > 0, np.maximum(free - gap, 0.0), np.minimum(free - gap, 0.0))
        return free - self.strength * past

    def quality_batch(self, x, controls):
        r = self.deviations_batch(x, controls)
        return np.linalg.norm(r, axis=0) / np.sqrt(r.shape[0])


class QualityOnly:
    """The same twin as a black box that answers only Q."""

    def __init__(self, twin):
        self.twin = twin
        self.lower_bounds = twin.lower_bounds
        self.upper_bounds = twin.upper_bounds

    def quality_batch(self, x, controls):
        return self.twin.quality_batch(x, controls)


def reference_optima(twin):
    """z* per assembly: the better of NLopt's search (DIRECT-L 2000, then BOBYQA 1000: what a
    controller does for a twin without optimum) and least squares with 20 (d + 1)² calls."""
    d = len(twin.lower_bounds)
    full = twincal.IndividualizedController(QualityOnly(twin))
    long = twincal.BudgetedOptimum(twin, budget=20 * (d + 1) ** 2, seed=99)
    out = []
    for x in twin.assemblies:
        u = full.propose(x)
        out.append(min(float(twin.quality_batch(x, u[:, None])[0]), long.optimal_quality(x)))
    return np.array(out)


seeds = [int(s) for s in sys.argv[1:]] or [0]
print("d | seed | search | budget | within 1 % of z* | worst | evaluations | requests")
for d in (3, 12):
    for seed in seeds:
        twin = GapTwin(d, seed=seed)
        reference = reference_optima(twin)
        for method, searched_twin in (("least_squares", twin), ("trust_region", QualityOnly(twin))):
            for factor in (1, 2):
                search = twincal.BudgetedOptimum(searched_twin, method=method,
                                                 budget=factor * (d + 1) ** 2)
                gaps = np.array([search.optimal_quality(x) for x in twin.assemblies]) / reference - 1
                n = len(gaps)
                print(f"{d} | {seed} | {method} | {factor} (d + 1)² = {search.budget} | "
                      f"{np.sum(gaps <= 0.01)}/{n} | {100 * gaps.max():.2g} % | "
                      f"{search.evaluations / n:.1f} | {search.requests / n:.1f}")
                assert search.evaluations <= n * search.budget and search.searches == n
