"""Shared fixtures: the reference data of tests/data (filterpy and SciPy outputs)."""

import json
import os
import pathlib

import pytest

DATA_DIR = pathlib.Path(
    os.environ.get("TWINCAL_TEST_DATA_DIR", pathlib.Path(__file__).parents[2] / "tests" / "data"))


def load(name):
    with open(DATA_DIR / name, encoding="utf-8") as f:
        return json.load(f)


@pytest.fixture(scope="session")
def qmc_reference():
    return load("qmc.json")
