"""Hypothesis profiles.

``make test`` (and CI) use ``ci``: derandomised, so a run is reproducible and a red CI is a real
regression of a known example set.  ``make fuzz`` uses ``fuzz``: fresh random examples and more of
them, to look for new counter-examples; anything it finds becomes an explicit regression test.
"""

from __future__ import annotations

import pytest
from hypothesis import settings

settings.register_profile("ci", derandomize=True, print_blob=True)
settings.register_profile("fuzz", max_examples=200, print_blob=True)


def pytest_addoption(parser: pytest.Parser) -> None:
    """``--tour``: also run the README's whole tour on a fresh checkout (``make tour``)."""
    parser.addoption(
        "--tour", action="store_true", default=False, help="run the README tour (make tour)"
    )
