"""An idle goby-broker with links sleeps (issue 24): its threads wake for the TDMA slots and ZeroMQ's heartbeats,
never for a polling loop. The count is the kernel's: the voluntary context switches of every thread of a real broker
process (each one wake-up from a wait), at warp 10 with the course's satellite and acoustic links and no peer."""

from __future__ import annotations

import os
import time
from pathlib import Path

from gateway.goby.intervehicle.testing import LoopbackLink, link_brokers
from tests.markers import needs_loopback_multicast

WARP = 10
SATELLITE = [(1, 5, 64), (2, 5, 64)]
ACOUSTIC = [(258, 10, 128), (259, 10, 128), (258, 10, 128), (260, 10, 128)]
#: At warp 10 the slots start 2 (satellite) + 1 (acoustic, on the same boundaries) times a second and ZeroMQ's I/O
#: threads wake for the heartbeats (about 10/s in all). A link loop at Goby's 10 Hz warped is 100 a second per link.
MAX_WAKEUPS_PER_S = 30


def wakeups(pid: int) -> int:
    """Voluntary context switches of every thread of ``pid`` so far."""
    total = 0
    for tid in os.listdir(f"/proc/{pid}/task"):
        try:
            with open(f"/proc/{pid}/task/{tid}/status") as status:
                total += next(int(line.split()[1]) for line in status if line.startswith("voluntary_ctxt_switches"))
        except (OSError, StopIteration):
            pass  # a thread that just ended
    return total


@needs_loopback_multicast
def test_an_idle_broker_with_two_links_wakes_only_for_its_slots(tmp_path: Path) -> None:
    links = {"usv": [LoopbackLink(SATELLITE).block(2), LoopbackLink(ACOUSTIC).block(258)]}
    with link_brokers(tmp_path, links, "idle", warp=WARP) as brokers:
        pid = int(brokers["usv"].endpoints["pid"])
        time.sleep(2.5)  # past the links' second announcement
        start, t0 = wakeups(pid), time.monotonic()
        time.sleep(5.0)
        rate = (wakeups(pid) - start) / (time.monotonic() - t0)
        log = brokers["usv"].stderr_text()
    assert "intervehicle link 2 up" in log and "intervehicle link 258 up" in log, log
    assert rate < MAX_WAKEUPS_PER_S, f"{rate:.1f} wake-ups a second"
