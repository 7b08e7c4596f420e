"""Issue #19 item 4 / issue #23 item 6 for the MOOS client: across a moos-db crash (SIGKILL) and restart, every
numbered message a publisher sends is delivered, or refused (``notify`` returned False, as pymoos: the link is
down, or the variable's subscribers have not registered again since the reconnection), or reported undelivered
(the on-undelivered callback: in flight at the crash). sent = delivered + refused + reported, nothing unexplained,
duplicated or reordered, also when the subscriber registers again well after the publisher reconnected (its
on-connect callback is slow)."""

from __future__ import annotations

import threading
import time
from pathlib import Path

import pytest

from gateway.moos import comms
from gateway.moos.testing import moosdb_process
from util.process import wait_until

N = 9000
READER_LATE_S = 1.5


@pytest.mark.parametrize(
    ("settle_s", "kill_at", "restart_at"),
    [(1.2, N // 3, N // 2), (0.0, 20, 600)],
    ids=["publishing-for-a-while", "drop-in-the-first-second-of-publishing"],
)
def test_db_crash_accounting_is_exact(tmp_path: Path, settle_s: float, kill_at: int, restart_at: int) -> None:
    """The second case drops the DB before the writer's once-a-second subscriber query has come round: its first
    publication of SEQ must have asked already, or the reader, slow to register again, misses mail silently."""
    delivered: list[int] = []
    reported: list[int] = []
    refused: list[int] = []
    connects = [0]

    with moosdb_process(tmp_path) as db:
        reader = comms()

        def reader_on_connect() -> None:
            connects[0] += 1
            if connects[0] > 1:
                time.sleep(READER_LATE_S)  # its registrations are written after on-connect returns
            reader.register("SEQ", 0)

        reader.set_on_connect_callback(reader_on_connect)
        reader.set_on_mail_callback(
            lambda: delivered.extend(int(m.double()) for m in reader.fetch() if m.key() == "SEQ"))
        pub = comms()
        pub.set_on_undelivered_callback(lambda msgs: reported.extend(int(m.double()) for m in msgs
                                                                     if m.key() == "SEQ"))
        reader.run("127.0.0.1", db.port, "reader")
        pub.run("127.0.0.1", db.port, "writer")
        done = threading.Event()
        try:
            assert reader.wait_until_connected(10_000) and pub.wait_until_connected(10_000)
            # -1 arrives once the reader is registered; the writer asked who subscribes when it first published SEQ
            wait_until(lambda: pub.notify("SEQ", -1.0) and -1 in delivered, 20, "the reader", interval=0.1)
            time.sleep(settle_s)
            for i in range(N):
                if i == kill_at:
                    db.kill()  # the crash: whatever is in flight now must be reported, not assumed sent
                if i == restart_at:
                    db.start()
                if not pub.notify("SEQ", float(i)):
                    refused.append(i)
                if i % 20 == 0:
                    time.sleep(0.02)
            done.set()
            wait_until(lambda: len(set(delivered) | set(reported) | set(refused)) >= N + 1, 30,
                       "every message accounted for")
        finally:
            pub.close()
            reader.close()

    delivered = [i for i in delivered if i >= 0]
    sent = set(range(N))
    explained = set(delivered) | set(refused) | set(reported)
    print(f"sent {N}, delivered {len(delivered)}, refused {len(refused)}, reported in flight {len(reported)} "
          f"(of which arrived after all: {len(set(reported) & set(delivered))})")
    assert connects[0] >= 2 and max(delivered) > restart_at, "the reader came back and received again"
    assert delivered == sorted(set(delivered)), "duplicated or reordered"
    assert not set(refused) & set(delivered)
    assert sent - explained == set(), f"unexplained: {sorted(sent - explained)[:20]}"
    assert refused and pub.get_number_of_refused_messages() == len(refused)
    assert pub.get_number_of_undelivered_messages() == len(reported)
