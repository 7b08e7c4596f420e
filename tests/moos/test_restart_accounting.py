"""Issue #19 item 4 for the MOOS client: across a moos-db crash (SIGKILL) and restart, every numbered message a
publisher sends is delivered, or refused (``notify`` returned False, as pymoos), or reported undelivered (the
on-undelivered callback: in flight at the crash). sent = delivered + reported, nothing unexplained, nothing
duplicated or reordered."""

from __future__ import annotations

import threading
import time
from pathlib import Path

from gateway.moos import comms
from gateway.moos.testing import connected_comms, moosdb_process
from util.process import wait_until

N = 6000


def test_db_crash_accounting_is_exact(tmp_path: Path) -> None:
    with moosdb_process(tmp_path) as db, connected_comms(db.port, "reader", ["SEQ"]) as reader:
        delivered: list[int] = []
        reported: list[int] = []
        refused: list[int] = []
        reader_back = threading.Event()
        reader_back.set()
        reader.set_on_mail_callback(
            lambda: delivered.extend(int(m.double()) for m in reader.fetch() if m.key() == "SEQ"))

        pub = comms()
        # Queued mail goes after on-connect returns: here, once the reader is back, so what the DB confirms
        # after the restart has a subscriber (MOOS keeps no mail for a client that is not registered).
        pub.set_on_connect_callback(lambda: reader_back.wait(30))
        pub.set_on_undelivered_callback(lambda msgs: reported.extend(int(m.double()) for m in msgs
                                                                     if m.key() == "SEQ"))
        pub.run("127.0.0.1", db.port, "writer")
        try:
            assert pub.wait_until_connected(10_000)
            for i in range(N):
                if i == N // 3:
                    reader_back.clear()
                    db.kill()  # the crash: whatever is in flight now must be reported, not assumed sent
                if i == N // 2:
                    db.start()
                    with connected_comms(db.port, "probe") as probe:  # -1 arrives once the reader re-registered
                        wait_until(lambda: probe.notify("SEQ", -1.0) and -1 in delivered, 20, "the reader back", interval=0.2)
                    reader_back.set()
                if not pub.notify("SEQ", float(i)):
                    refused.append(i)
                if i % 20 == 0:
                    time.sleep(0.01)
            wait_until(lambda: len(set(delivered) | set(reported) | set(refused)) >= N, 30, "every message accounted for")
        finally:
            pub.close()

    delivered = [i for i in delivered if i >= 0]
    sent = set(range(N))
    explained = set(delivered) | set(refused) | set(reported)
    assert delivered == sorted(set(delivered)), "duplicated or reordered"
    assert not set(refused) & set(delivered)
    assert sent - explained == set(), f"unexplained: {sorted(sent - explained)[:20]}"
    assert refused and pub.get_number_of_refused_messages() == len(refused)
    assert pub.get_number_of_undelivered_messages() == len(reported)
    print(f"sent {N}, delivered {len(delivered)}, refused {len(refused)}, reported in flight {len(reported)} "
          f"(of which arrived after all: {len(set(reported) & set(delivered))})")
