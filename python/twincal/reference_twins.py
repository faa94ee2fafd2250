"""A twin written in Python: the protocol's reference implementation, to read and to copy.

twincal's controllers accept any object with

- ``quality_batch(assembly, controls)``: ``controls`` is a d × k array, one control per column;
  returns k qualities (one call per filter update or candidate set, so vectorise it);
- ``optimum(assembly)``: u0, the control that minimises the quality of that assembly (eq. (3));
- ``lower_bounds`` and ``upper_bounds``: d numbers each; optionally ``locator_names``.

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
