"""A twin written in Python: the protocol's reference implementation, to read and to copy.

twincal's controllers accept any object with

- ``quality_batch(assembly, controls)``: ``controls`` is a d × k array, one control per column;
  returns k qualities (one call per filter update or candidate set, so vectorise it);
- ``optimum(assembly)``: u0, the control that minimises the quality of that assembly (eq. (3));
- ``lower_bounds`` and ``upper_bounds``: d numbers each; optionally ``locator_names``;
- optionally ``deviations_batch(assembly, controls)`` with ``key_point_count`` (m): the m × k
  deviations r of the twin's key points, Q = ‖r‖ / √m. The active controller then fits its
  models from them (Gauss–Newton), as it does for FEM twins: fewer calls, and models that hold
  where Q² is not a quadratic (``KeyPointRmsTwin`` below).

An assembly is whatever the twin understands; twincal only hands it back.
"""

import numpy as np


class QuadraticRmsTwin:
    """Q(x, u) = sqrt(q0_x + (u - a_x)^T H (u - a_x)) over ``assemblies`` assemblies x = 0, 1, …:
    assembly x has the optimum a_x and the optimal quality sqrt(q0_x); H is a random symmetric
    positive definite curvature. Seeded: the same seed gives the same twin."""

    def __init__(self, d, seed=2023, assemblies=10):
        rng = np.random.default_rng(seed)
        m = rng.normal(size=(d, d))
        self.H = m @ m.T / d + np.eye(d)
        self.optima = rng.uniform(-0.3, 0.3, size=(assemblies, d))
        self.q0 = rng.uniform(0.5, 1.0, size=assemblies)
        self.lower_bounds = -np.ones(d)
        self.upper_bounds = np.ones(d)

    def quality_batch(self, assembly, controls):
        """The qualities of the columns of ``controls`` (d × k) for ``assembly``."""
        e = controls - self.optima[assembly][:, None]
        return np.sqrt(self.q0[assembly] + np.einsum("im,ij,jm->m", e, self.H, e))

    def optimum(self, assembly):
        """u0 of ``assembly``."""
        return self.optima[assembly]

    def optimal_quality(self, assembly):
        """z* of ``assembly``: the quality at u0."""
        return float(np.sqrt(self.q0[assembly]))


class KeyPointRmsTwin:
    """Q(x, u) = ‖r(x, u)‖ / √m with the key points' deviations r(x, u) = w_x + B (u − a_x): an
    affine (compliant) twin that answers its deviations (``deviations_batch``,
    ``key_point_count``) besides Q. w_x is orthogonal to the range of B, so u0 = a_x and
    z* = ‖w_x‖ / √m. Seeded: the same seed gives the same twin."""

    def __init__(self, d, key_points=20, seed=2023, assemblies=10):
        rng = np.random.default_rng(seed)
        self.B = rng.normal(size=(key_points, d)) / np.sqrt(d)
        q, _ = np.linalg.qr(self.B)
        w = rng.normal(scale=0.2, size=(assemblies, key_points))
        self.w = w - (w @ q) @ q.T  # no component the locators can take out
        self.optima = rng.uniform(-0.3, 0.3, size=(assemblies, d))
        self.key_point_count = key_points
        self.lower_bounds = -np.ones(d)
        self.upper_bounds = np.ones(d)

    def deviations_batch(self, assembly, controls):
        """The m × k deviations of the columns of ``controls`` (d × k) for ``assembly``."""
        return self._deviations(assembly, controls)

    def quality_batch(self, assembly, controls):
        """The qualities of the columns of ``controls`` (d × k): the deviations' RMS."""
        r = self._deviations(assembly, controls)
        return np.linalg.norm(r, axis=0) / np.sqrt(r.shape[0])

    def _deviations(self, assembly, controls):
        e = controls - self.optima[assembly][:, None]
        return self.w[assembly][:, None] + self.B @ e

    def optimum(self, assembly):
        """u0 of ``assembly``."""
        return self.optima[assembly]

    def optimal_quality(self, assembly):
        """z* of ``assembly``: the quality at u0."""
        return float(np.linalg.norm(self.w[assembly]) / np.sqrt(self.w.shape[1]))
