"""The paper's filter from Python (docs/python.md): a UKF tracks a constant locator offset
through a scalar RMS-like quality, evaluating every sigma point in one call of hx."""

import numpy as np

import twincal

H = np.diag([0.5, 0.3, 0.2])


def hx(points, u, a):
    """z = sqrt(q0 + e^T H e), e = u - x - a, for every sigma point x (a column) at once."""
    e = u[:, None] - points - a[:, None]
    return np.sqrt(0.04 + np.einsum("im,ij,jm->m", e, H, e))


points = twincal.MerweScaledSigmaPoints(3, alpha=1.0, beta=2.0, kappa=0.0)
ukf = twincal.UnscentedKalmanFilter(3, hx, points, P=1e-3 * np.eye(3), Q=1e-6 * np.eye(3),
                                    R=1e-6)
rng = np.random.default_rng(2023)
truth = np.array([0.03, -0.02, 0.01])
for t in range(100):
    u, a = rng.normal(scale=0.1, size=3), rng.normal(scale=0.1, size=3)
    e = u - truth - a
    z = np.sqrt(0.04 + e @ H @ e) + rng.normal(scale=1e-3)
    ukf.predict()
    ukf.update(z, u=u, a=a)  # hx(points, u=u, a=a): one call, all 7 points

error = np.linalg.norm(ukf.x - truth)
print(f"estimate {ukf.x}, error {error:.2e}, sd {np.sqrt(np.diag(ukf.P))}")
if error > 5e-3:
    raise SystemExit(f"the UKF did not find the offset: error {error:.3g} > 5e-3")
