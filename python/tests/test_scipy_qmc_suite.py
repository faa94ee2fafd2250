"""SciPy's own tests of its Sobol and Halton engines, run against twincal's.

The test classes are SciPy's (scipy/stats/tests/test_qmc.py of the installed SciPy: TestSobol,
TestHalton and the QMCEngineTests they share), with twincal's engines in their place — as
`qmce` and wherever the tests name `qmc.Sobol` or `qmc.Halton` themselves. Skipped when SciPy or
its tests are not installed. What is expected to differ is listed in EXPECTED_DIFFERENCES, with
the reason; conftest.py marks those tests as strict expected failures, so a difference that
disappears fails too.
"""
import pytest

import twincal

test_qmc = pytest.importorskip("scipy.stats.tests.test_qmc",
                               reason="SciPy's tests (scipy/stats/tests) are not installed")

SCRAMBLED = ("scrambled points are drawn from twincal's own seeded streams, so they differ from "
             "SciPy's reference values for the same seed")

EXPECTED_DIFFERENCES = {
    "TestSobolFromScipy::test_sample[Scrambled]": SCRAMBLED,
    "TestHaltonFromScipy::test_sample[Scrambled]": SCRAMBLED,
    "TestHaltonFromScipy::test_workers": SCRAMBLED,
    "TestSobolFromScipy::test_64bits": "bits = 64 is refused: at most 52 (exact doubles)",
}


@pytest.fixture(autouse=True)
def twincal_engines(monkeypatch):
    monkeypatch.setattr(test_qmc.qmc, "Sobol", twincal.Sobol)
    monkeypatch.setattr(test_qmc.qmc, "Halton", twincal.Halton)


class TestSobolFromScipy(test_qmc.TestSobol):
    qmce = twincal.Sobol


class TestHaltonFromScipy(test_qmc.TestHalton):
    qmce = twincal.Halton
