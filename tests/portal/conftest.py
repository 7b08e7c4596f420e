"""Fixtures for the portal tests: a broker subprocess on a per-test IPC path."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from gateway.goby.portal.testing import BrokerProcess, broker_process


@pytest.fixture
def broker(tmp_path: Path, request: pytest.FixtureRequest) -> Iterator[BrokerProcess]:
    """A running goby-broker for this test (platform named after the test)."""
    platform = "t" + str(abs(hash(request.node.nodeid)) % 10**8)
    with broker_process(tmp_path, platform=platform) as running:
        yield running
