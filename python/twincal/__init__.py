"""twincal: online calibration and control of digital twins, from Python.

The filters, sigma-point schemes and samplers are twincal's C++ ones (the ``_twincal``
extension); the names follow filterpy and ``scipy.stats.qmc`` so existing code reads alike::

    import numpy as np
    import twincal

    def hx(points, u, a):             # every sigma point at once: points is n x m
        e = u[:, None] - points - a[:, None]
        return np.sqrt(0.04 + np.einsum("im,ij,jm->m", e, H, e))

    ukf = twincal.UnscentedKalmanFilter(3, hx, twincal.MerweScaledSigmaPoints(3, 1.0, 2.0, 0.0),
                                        P=1e-3 * np.eye(3), Q=1e-4 * np.eye(3), R=1e-4)
    ukf.predict()
    ukf.update(z, u=u, a=a)

Errors raise twincal.Error subclasses (InvalidArgumentError and DimensionMismatchError are
ValueErrors; NonFiniteError and NotPositiveDefiniteError are ArithmeticErrors) with the C++
message, which names the argument, its value and the rule; the filter is then unchanged.
"""

from ._twincal import (
    DimensionMismatchError,
    Error,
    FifthDegreeCubaturePoints,
    Halton,
    InvalidArgumentError,
    JulierSigmaPoints,
    MerweScaledSigmaPoints,
    NonFiniteError,
    NotPositiveDefiniteError,
    SigmaPointKalmanFilter,
    SimplexSigmaPoints,
    Sobol,
    SphericalRadialSigmaPoints,
    SquareRootKalmanFilter,
)


def UnscentedKalmanFilter(dim_x, hx, points, **options):
    """filterpy's name: a SigmaPointKalmanFilter with a UKF scheme (MerweScaledSigmaPoints,
    JulierSigmaPoints or SimplexSigmaPoints). Keyword options as SigmaPointKalmanFilter's; the
    default refresh='redraw' is filterpy's current UKF, refresh='reuse_propagated' its 1.4.5
    release."""
    return SigmaPointKalmanFilter(dim_x, hx, points, **options)


def CubatureKalmanFilter(dim_x, hx, **options):
    """filterpy's name: the cubature Kalman filter (third-degree spherical-radial points). As
    filterpy's CKF, the update reuses the propagated points unless refresh='redraw' is given."""
    options.setdefault("refresh", "reuse_propagated")
    return SigmaPointKalmanFilter(dim_x, hx, SphericalRadialSigmaPoints(dim_x), **options)


__all__ = [
    "CubatureKalmanFilter",
    "DimensionMismatchError",
    "Error",
    "FifthDegreeCubaturePoints",
    "Halton",
    "InvalidArgumentError",
    "JulierSigmaPoints",
    "MerweScaledSigmaPoints",
    "NonFiniteError",
    "NotPositiveDefiniteError",
    "SigmaPointKalmanFilter",
    "SimplexSigmaPoints",
    "Sobol",
    "SphericalRadialSigmaPoints",
    "SquareRootKalmanFilter",
    "UnscentedKalmanFilter",
]
