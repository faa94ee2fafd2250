"""Sobol and Halton engines that are ``scipy.stats.qmc`` engines.

``twincal.Sobol`` and ``twincal.Halton`` subclass ``scipy.stats.qmc.QMCEngine`` when SciPy is
installed, so they go wherever SciPy takes an engine (``qmc.MultivariateNormalQMC(mean, cov,
engine=twincal.Sobol(2, seed=7))``, ``qmc.discrepancy``, …) and take SciPy's arguments: ``d``
(0 gives empty samples), ``scramble``, ``seed`` (an int, a ``numpy.random.Generator`` or None),
``optimization`` (``"random-cd"`` or ``"lloyd"``: SciPy's post-processing, delegated to SciPy),
``random(n, workers=…)``, ``integers``, ``reset``, ``fast_forward`` and Sobol's ``random_base2``
and ``bits``. The points come from twincal's C++ samplers (``_twincal.Sobol``/``Halton``):
unscrambled they are SciPy's to the bit (Sobol) or to 1e-15 (Halton); scrambled they are drawn
from twincal's own seeded streams, so they differ from SciPy's for the same seed.

Seeds: an int is the C++ engine's scrambling seed itself (``Sobol(d, seed=5)`` gives the same
points as before these engines were SciPy's); a Generator or None (fresh entropy, as in SciPy)
gives it one draw, ``integers(2**63)``. Either way ``engine.scramble_seed`` records the seed in
use, so a scrambled sample can be drawn again.

Differences from SciPy, all deliberate: ``bits`` lies in [1, 52] (every point an exact double;
SciPy allows 64) and defaults to 32 (SciPy: 30); ``scramble="owen"`` adds nested uniform
scrambling; ``workers`` is accepted and checked but does not change anything (the C++ engines
draw 10⁶ points per ~10 ms on one thread). Without SciPy the engines keep this interface except
``optimization``, which then raises an error that says so.
"""

import numbers
import warnings

import numpy as np

from . import _twincal

try:
    from scipy.stats import qmc as _scipy_qmc

    _Engine = _scipy_qmc.QMCEngine
except ImportError:  # pragma: no cover - exercised where SciPy is missing
    _scipy_qmc = None
    _Engine = object

MAX_SEED = 2**63


def _check_dimension(d):
    if not isinstance(d, numbers.Integral) or isinstance(d, bool) or d < 0:
        raise _twincal.InvalidArgumentError(
            f"d: value is {d!r}; rule: d must be a non-negative integer value")
    return int(d)


def _check_workers(workers):
    if (not isinstance(workers, numbers.Integral) or isinstance(workers, bool)
            or (workers < 1 and workers != -1)):
        raise _twincal.InvalidArgumentError(
            f"workers: value is {workers!r}; rule: must be a positive integer or -1 (all CPU "
            "threads); it does not change the points")


def _scramble_seed(seed):
    """The C++ engine's seed for a SciPy-style seed (int, Generator or None)."""
    if seed is None:
        return int(np.random.default_rng().integers(MAX_SEED))
    if isinstance(seed, np.random.Generator):
        return int(seed.integers(MAX_SEED))
    if isinstance(seed, numbers.Integral) and not isinstance(seed, bool) and 0 <= seed < 2**64:
        return int(seed)
    raise _twincal.InvalidArgumentError(
        f"seed: value is {seed!r}; rule: must be None, an integer in [0, 2^64) or a "
        "numpy.random.Generator")


class _FallbackEngine:
    """QMCEngine's interface where SciPy is missing (no ``optimization``)."""

    def __init__(self, d, *, optimization=None, seed=None):
        if optimization is not None:
            raise _twincal.InvalidArgumentError(
                f"optimization: value is {optimization!r}; rule: needs SciPy "
                "(scipy.stats.qmc's optimizers), which is not installed")
        self.d = d
        self.rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
        self.num_generated = 0
        self.optimization_method = None

    def random(self, n=1, *, workers=1):
        sample = self._random(n, workers=workers)
        self.num_generated += n
        return sample

    def integers(self, l_bounds, u_bounds=None, n=1, *, endpoint=False, workers=1):
        if u_bounds is None:
            l_bounds, u_bounds = 0, l_bounds
        l_bounds, u_bounds = np.atleast_1d(l_bounds), np.atleast_1d(u_bounds)
        if endpoint:
            u_bounds = u_bounds + 1
        if (not np.issubdtype(l_bounds.dtype, np.integer)
                or not np.issubdtype(u_bounds.dtype, np.integer)):
            raise _twincal.InvalidArgumentError(
                "bounds: 'u_bounds' and 'l_bounds' must be integers or array-like of integers")
        sample = self.random(n, workers=workers)
        return np.floor(l_bounds + sample * (u_bounds - l_bounds)).astype(np.int64)

    def reset(self):
        self.num_generated = 0
        return self


_Base = _Engine if _scipy_qmc is not None else _FallbackEngine


class _NativeEngine(_Base):
    """A SciPy engine over one of twincal's C++ samplers (``self._native``)."""

    def __init__(self, d, seed, optimization):
        d = _check_dimension(d)
        self.scramble_seed = _scramble_seed(seed)
        # SciPy's base keeps its own generator (its optimizers draw from it); a Generator given
        # as the seed has just given the scrambling its draw.
        super().__init__(d=d, optimization=optimization, seed=seed)

    def _random(self, n=1, *, workers=1):
        _check_workers(workers)
        if not isinstance(n, numbers.Integral) or n < 0:
            raise _twincal.InvalidArgumentError(f"n: value is {n!r}; rule: must be >= 0")
        if self.d == 0:
            return np.empty((int(n), 0))
        return self._native.random(int(n))

    def reset(self):
        """Back to the first point, with the same scrambling (and SciPy's generator reset)."""
        super().reset()
        if self._native is not None:
            self._native.reset()
        return self

    def fast_forward(self, n):
        """Skips n points (without drawing them, unlike SciPy's base class)."""
        if not isinstance(n, numbers.Integral) or n < 0:
            raise _twincal.InvalidArgumentError(f"n: value is {n!r}; rule: must be >= 0")
        if self._native is not None:
            self._native.fast_forward(int(n))
        self.num_generated += int(n)
        return self


class Sobol(_NativeEngine):
    """The Sobol' sequence (Joe & Kuo's direction numbers, d <= 21201) as a SciPy engine.

    Sobol(d, *, scramble=True, bits=None, seed=None, optimization=None): scramble True is a
    random linear matrix scramble and digital shift (SciPy's method, twincal's stream), False
    none, "owen" nested uniform scrambling; bits in [1, 52] (default 32). The module's doc
    lists what differs from ``scipy.stats.qmc.Sobol``.
    """

    MAXDIM = 21201

    def __init__(self, d, *, scramble=True, bits=None, seed=None, optimization=None):
        d = _check_dimension(d)
        if d > self.MAXDIM:
            raise _twincal.InvalidArgumentError(
                f"d: value is {d}; rule: Maximum supported dimensionality is {self.MAXDIM}.")
        if bits is not None and (not isinstance(bits, numbers.Integral) or bits > 64):
            raise _twincal.InvalidArgumentError(
                f"bits: value is {bits!r}; rule: Maximum supported 'bits' is 64 in SciPy, "
                "52 in twincal (exact doubles)")
        super().__init__(d, seed, optimization)
        self.scramble = scramble
        # The C++ engine checks every option (scramble, bits) and names the one at fault.
        native = _twincal.Sobol(max(d, 1), scramble=scramble, seed=self.scramble_seed, bits=bits)
        self.bits = native.bits
        self._native = native if d > 0 else None

    def _random(self, n=1, *, workers=1):
        if n > 0 and self.num_generated + n > 2**self.bits:
            raise _twincal.InvalidArgumentError(
                f"n: {self.num_generated} points generated, then {n}; rule: at most 2^bits = "
                f"{2**self.bits} points — consider increasing `bits`")
        if self.num_generated == 0 and n > 0 and n & (n - 1):
            # SciPy's rule (a first draw of a power of two; random_base2 checks the rest) and its
            # words, which its tests match; the C++ engine's own warning is not repeated.
            warnings.warn(f"The balance properties of Sobol' points require n to be a power of "
                          f"2: the first draw is of {n} points", UserWarning, stacklevel=3)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)
            return super()._random(n, workers=workers)

    def random_base2(self, m):
        """The next 2^m points; the points drawn so far plus these must be a power of two."""
        if not isinstance(m, numbers.Integral) or m < 0 or m > self.bits:
            raise _twincal.InvalidArgumentError(
                f"m: value is {m!r}; rule: 0 <= m <= bits = {self.bits}")
        n = 2**int(m)
        total = self.num_generated + n
        if total & (total - 1):
            raise _twincal.InvalidArgumentError(
                f"m: The balance properties of Sobol' points require n to be a power of 2. "
                f"{self.num_generated} points have been previously generated, then: "
                f"n={self.num_generated}+2**{m}={total}; rule: the position must be a "
                "multiple of 2^m (use random() to draw anyway)")
        return self.random(n)

    def __repr__(self):
        return (f"twincal.Sobol(d={self.d}, scramble={self.scramble!r}, bits={self.bits}, "
                f"scramble_seed={self.scramble_seed})")


class Halton(_NativeEngine):
    """The Halton sequence as a SciPy engine: Halton(d, *, scramble=True, seed=None,
    optimization=None); scramble permutes the digits (SciPy's scheme, twincal's stream)."""

    def __init__(self, d, *, scramble=True, seed=None, optimization=None):
        super().__init__(d, seed, optimization)
        self.scramble = bool(scramble)
        native = _twincal.Halton(max(self.d, 1), scramble=self.scramble, seed=self.scramble_seed)
        self._native = native if self.d > 0 else None

    def __repr__(self):
        return (f"twincal.Halton(d={self.d}, scramble={self.scramble!r}, "
                f"scramble_seed={self.scramble_seed})")


__all__ = ["Halton", "Sobol"]
