"""The paper's loop from Python (docs/python.md): a twin written in NumPy
(twincal.reference_twins, the protocol's reference implementation), a plant whose locator offset
drifts (eq. (15)), and the paper's w-controller against the baseline."""

import numpy as np

import twincal
from twincal.reference_twins import QuadraticRmsTwin


def run(controller, twin, assemblies, steps):
    """Mean relative residual (z - z*)/z* against a plant Q(x, u - offset), offset drifting."""
    offset, step, residuals = np.zeros(3), np.array([0.02, -0.015, 0.01]), []
    for x in assemblies[:steps]:
        u = controller.propose(x)
        z = float(twin.quality_batch(x, (u - offset)[:, None])[0])  # the plant
        controller.observe(x, u, z)
        residuals.append(z / twin.optimal_quality(x) - 1.0)
        offset += step
        if np.any(np.abs(offset) > 0.5):
            step = -step
    return np.mean(residuals)


twin = QuadraticRmsTwin(3)
assemblies = np.random.default_rng(7).integers(10, size=100).tolist()
baseline = run(twincal.IndividualizedController(twin), twin, assemblies, 100)
paper = twincal.PaperController(twin, w=1.0, seed=2023)
calibrated = run(paper, twin, assemblies, 100)
print(f"mean relative residual: baseline {baseline:.4f}, paper's w = 1 {calibrated:.4f}")
print(f"offset estimate {paper.offset_estimate}, last loss {paper.last_proposal['loss']:.4g}")
if not calibrated < 0.5 * baseline:
    raise SystemExit(f"the w-controller ({calibrated:.4g}) did not halve the baseline's residual "
                     f"({baseline:.4g})")
