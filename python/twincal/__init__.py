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
message, which names the argument, its value and the rule; the filter is then unchanged. A twin
written in Python raises TwinError for a failure the controllers go on after (a proposal on the
default control, a dropped measurement).
"""

from ._twincal import (
    ActiveController,
    BudgetedOptimum,
    DefaultController,
    DimensionMismatchError,
    Error,
    FifthDegreeCubaturePoints,
    IndividualizedController,
    InvalidArgumentError,
    JulierSigmaPoints,
    MerweScaledSigmaPoints,
    NonFiniteError,
    NotPositiveDefiniteError,
    PaperController,
    PerComponentController,
    SigmaPointKalmanFilter,
    SimplexSigmaPoints,
    SphericalRadialSigmaPoints,
    SquareRootKalmanFilter,
    Twin,
    TwinError,
)
from .qmc import Halton, Sobol


def run_experiment(config, out=None, threads=0):
    """Runs one group of the paper's protocol, as ``twincal run`` does, and returns its summary.

    ``config`` is a dict with docs/cli.md's keys, e.g. ``{"case": "analytic",
    "analytic_dimension": 3, "locators": "all", "controllers": ["baseline", "active"],
    "runs": 10, "seed": 2023}`` (missing keys take their defaults; no "controllers": the paper's
    13 and "active"). Results go to the directory ``out`` (episodes already there are kept, as
    on the command line) or to a temporary one that is removed afterwards. ``threads``: worker
    threads, 0 for all cores; results do not depend on it.

    Returns ``{"config": the resolved config (seeds included), "rows": [one dict per
    controller: group, controller, runs, diverged, lost (runs worse than the baseline over the
    second half, docs/cli.md), median_relative_residual, median_estimation_error,
    seconds_per_assembly, q_evaluations_per_assembly]}``, and, when
    pandas is installed, ``"frame"``: the rows as a pandas DataFrame.
    """
    import json
    import tempfile

    from . import _twincal

    if not isinstance(config, dict):
        raise InvalidArgumentError(f"config: value is a {type(config).__name__}; rule: must be a dict")
    text = json.dumps(config)
    if out is None:
        with tempfile.TemporaryDirectory(prefix="twincal-") as directory:
            result = json.loads(_twincal._run_experiment(text, directory, threads))
    else:
        result = json.loads(_twincal._run_experiment(text, str(out), threads))
    try:
        import pandas
    except ImportError:
        return result
    result["frame"] = pandas.DataFrame(result["rows"])
    return result


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
    "ActiveController",
    "BudgetedOptimum",
    "CubatureKalmanFilter",
    "DefaultController",
    "DimensionMismatchError",
    "Error",
    "FifthDegreeCubaturePoints",
    "Halton",
    "IndividualizedController",
    "InvalidArgumentError",
    "JulierSigmaPoints",
    "MerweScaledSigmaPoints",
    "NonFiniteError",
    "NotPositiveDefiniteError",
    "PaperController",
    "PerComponentController",
    "SigmaPointKalmanFilter",
    "SimplexSigmaPoints",
    "Sobol",
    "SphericalRadialSigmaPoints",
    "SquareRootKalmanFilter",
    "Twin",
    "TwinError",
    "UnscentedKalmanFilter",
    "run_experiment",
]
