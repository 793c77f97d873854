"""Shared fixtures of the tests (helpers shared by several modules are in helpers.py)."""

from __future__ import annotations

import numpy as np
import pytest


@pytest.fixture
def rng():
    return np.random.default_rng(20261121)
