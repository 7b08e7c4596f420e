"""MOOS clocks: pymoos's process-wide ``time()``/``set_moos_timewarp()`` stay, and clients given their own
:class:`MoosClock` neither read nor write the process-wide one (nor each other's).

Only the tests here that exercise pymoos's process-wide API touch ``DEFAULT_CLOCK``; they use the
``pymoos_clock`` fixture, which puts it back.  Nothing else in the suite changes it, so no test needs a reset."""

from __future__ import annotations

import sys
import time
import types
from collections.abc import Iterator

import pytest

import gateway.moos as moos
from gateway.moos import MoosClock, choose_client, comms
from gateway.moos.clock import DEFAULT_CLOCK
from gateway.moos.testing import collect_mail, connected_comms, running_moosdb
from util.process import wait_until


@pytest.fixture
def pymoos_clock() -> Iterator[MoosClock]:
    """pymoos's process-wide clock, for a test that changes it on purpose; put back as it was afterwards."""
    warp, skew = DEFAULT_CLOCK.warp, DEFAULT_CLOCK.skew
    try:
        yield DEFAULT_CLOCK
    finally:
        DEFAULT_CLOCK.set_warp(warp)
        DEFAULT_CLOCK.skew = skew


def test_module_functions_keep_pymoos_process_wide_semantics(pymoos_clock):
    """``set_moos_timewarp`` warps ``time()`` and clients without a clock, as pymoos does."""
    moos.set_moos_timewarp(7)
    assert moos.get_moos_timewarp() == 7.0 and pymoos_clock.warp == 7.0
    assert moos.local_time() / time.time() == pytest.approx(7.0, rel=1e-3)
    assert moos.local_time(apply_timewartping=False) == pytest.approx(time.time(), abs=1.0)
    assert comms().clock is pymoos_clock
    assert choose_client("ours").comms.clock is pymoos_clock
    with pytest.raises(ValueError, match="outside"):
        moos.set_moos_timewarp(0)


def test_factory_passes_an_explicit_clock_to_our_client():
    before = (DEFAULT_CLOCK.warp, DEFAULT_CLOCK.skew)
    own = MoosClock(3)
    chosen = choose_client("ours", clock=own)
    assert chosen.kind == "ours" and chosen.comms.clock is own and comms(clock=own).clock is own
    assert chosen.moos_time() / time.time() == pytest.approx(3.0, rel=1e-3)
    assert (DEFAULT_CLOCK.warp, DEFAULT_CLOCK.skew) == before


def test_factory_applies_an_explicit_clock_to_the_real_pymoos(monkeypatch):
    """The real pymoos has only libMOOS's process-wide clock: the explicit clock's warp goes there, and the
    matching time function is ``pymoos.time``."""
    warps: list[float] = []
    fake = types.ModuleType("pymoos")

    class FakeComms:
        pass

    fake.comms = FakeComms
    fake.set_moos_timewarp = warps.append
    fake.time = lambda: 42.0
    monkeypatch.setitem(sys.modules, "pymoos", fake)
    chosen = choose_client("pymoos", clock=MoosClock(5))
    assert isinstance(chosen.comms, FakeComms) and chosen.kind == "pymoos" and warps == [5.0]
    assert chosen.moos_time() == 42.0
    choose_client("auto")  # without a clock the process-wide warp is left alone
    assert warps == [5.0]


@pytest.fixture
def quiet_clients(our_db, pymoos_clock) -> Iterator[tuple[comms, comms, comms]]:
    """Three quiet clients (quiet ones apply the DB's skew even on this host) on our in-process DB (warp 1):
    one on a warp-10 clock, one on a warp-1 clock, one on the process-wide default clock."""
    clients = [comms(clock=MoosClock(10)), comms(clock=MoosClock(1)), comms()]
    try:
        for i, client in enumerate(clients):
            client.set_quiet(True)
            client.run("127.0.0.1", our_db.port, f"clock-{i}")
        for client in clients:
            assert client.wait_until_connected(10_000)
        yield clients[0], clients[1], clients[2]
    finally:
        for client in clients:
            client.close(True)


def test_clients_with_their_own_clocks_do_not_interfere(our_db, quiet_clients):
    fast, plain, default = quiet_clients
    assert fast.clock is not plain.clock and default.clock is DEFAULT_CLOCK
    # each client learned its own skew: the warp-10 one about -9 x unix time, so both tell the DB's time
    wait_until(lambda: fast.clock.skew < -8 * time.time(), 10, "fast.clock.skew < -8 * time.time()")
    assert abs(plain.clock.skew) < 1.0
    for client in (fast, plain, default):
        assert client.clock.time() == pytest.approx(our_db.clock.time(), abs=1.0)
    assert fast.clock.warp == 10.0 and plain.clock.warp == 1.0
    # the process-wide clock kept its warp; only the default client's skew (tiny, on this host) went there
    assert DEFAULT_CLOCK.warp == 1.0 and abs(DEFAULT_CLOCK.skew) < 1.0
    assert moos.time() == pytest.approx(time.time(), abs=1.0)
    # what they publish is stamped by their own clocks, all in the DB's time
    with connected_comms(our_db.port, "watcher", register=["FROM_FAST", "FROM_PLAIN"]) as watcher:
        fast.notify("FROM_FAST", 1.0)
        plain.notify("FROM_PLAIN", 2.0)
        mail = collect_mail(watcher, ["FROM_FAST", "FROM_PLAIN"])
    assert sorted(m.key() for m in mail) == ["FROM_FAST", "FROM_PLAIN"]
    for msg in mail:
        assert msg.time() == pytest.approx(our_db.clock.time(), abs=2.0)


def test_clients_on_dbs_with_different_warps_keep_separate_skews():
    """Two DBs (warp 1 and warp 20), one quiet client each on its own clock: each tracks its own DB."""
    before = (DEFAULT_CLOCK.warp, DEFAULT_CLOCK.skew)
    with running_moosdb(warp=1) as slow_db, running_moosdb(warp=20) as fast_db:
        slow, fast = comms(clock=MoosClock()), comms(clock=MoosClock())
        try:
            for client, db in ((slow, slow_db), (fast, fast_db)):
                client.set_quiet(True)
                client.run("127.0.0.1", db.port, "skewed")
                assert client.wait_until_connected(10_000)
            wait_until(lambda: fast.clock.skew > 18 * time.time(), 10, "fast.clock.skew > 18 * time.time()")
            assert slow.clock.time() == pytest.approx(slow_db.clock.time(), abs=1.0)
            assert fast.clock.time() == pytest.approx(fast_db.clock.time(), abs=20.0)
            assert abs(slow.clock.skew) < 1.0
        finally:
            slow.close(True)
            fast.close(True)
    assert (DEFAULT_CLOCK.warp, DEFAULT_CLOCK.skew) == before
