"""Shared fixtures."""

from __future__ import annotations

from collections.abc import Iterator

import numba
import pytest


@pytest.fixture(scope="module")
def one_thread() -> Iterator[None]:
    """Few-particle runs on one Numba thread (results do not depend on it, see
    test_threads.py; parallel regions on a busy machine cost milliseconds per call for a few
    particles). A module takes it with ``pytestmark = pytest.mark.usefixtures("one_thread")``."""
    previous = numba.get_num_threads()
    numba.set_num_threads(1)
    yield
    numba.set_num_threads(previous)
