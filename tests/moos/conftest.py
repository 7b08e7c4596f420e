"""Fixtures for the MOOS tests: our DB in-process, and the real C++ MOOSDB when it may run here.

The real MOOSDB listens on every address, so it is only started inside a private network namespace (one
whose only interface is loopback), e.g. under ``/opt/moos/bin/netns-run``.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from gateway.moos.server import MoosDB
from gateway.moos.testing import moosdb_process, real_moos_skip_reason


@pytest.fixture
def our_db() -> Iterator[MoosDB]:
    with MoosDB(community="moos") as db:
        yield db


@pytest.fixture(params=["ours", "real"])
def db_port(request: pytest.FixtureRequest, tmp_path: Path) -> Iterator[int]:
    """The port of a running DB: ours (always) and the real MOOSDB (when it may run here)."""
    if request.param == "ours":
        with MoosDB(community="moos") as db:
            yield db.port
    else:
        reason = real_moos_skip_reason()
        if reason:
            pytest.skip(reason)
        with moosdb_process(tmp_path, program="MOOSDB") as db:
            yield db.port

