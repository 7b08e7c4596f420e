"""Issue #19 item 4 / issue #23 item 6 for Goby interprocess: across a goby-broker crash (SIGKILL) and restart,
every numbered publication is delivered, refused (``publish`` returned False: the connection is down, or the
subscription seen before the crash has not come back yet) or reported undelivered (``on_undelivered``: not yet
confirmed through the broker when the connection dropped). Nothing unexplained, duplicated or reordered, also
when the subscriber comes back well after the publisher (it does not poll for 1.5 s after the restart), and the
reports are few (not everything of the last half second)."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

from gateway.goby.portal.testing import PortalClient, broker_process

N = 3000
PERIOD_S = 0.002
READER_LATE_S = 1.5


@pytest.mark.parametrize("tcp", [False, True], ids=["ipc", "tcp"])
def test_broker_crash_accounting_is_exact(tmp_path: Path, tcp: bool) -> None:
    delivered: list[int] = []
    refused: list[int] = []
    reported: list[int] = []
    with broker_process(tmp_path, tcp=tcp) as broker:
        cfg = broker.interprocess_config()
        with PortalClient(cfg, "reader") as reader, PortalClient(cfg, "writer") as writer:
            reader.subscribe("seq", str, lambda text: delivered.append(int(text)))
            assert reader.wait_subscribed() and writer.wait_ready()
            # The writer's socket has seen the reader's subscription once -1 arrives.
            while not writer.publish("seq", "-1") or -1 not in delivered:
                writer.poll(0.01)
                reader.poll(0.01)
            writer.portal.on_undelivered = lambda lost: reported.extend(int(p.rstrip(b"\0")) for g, p in lost if g == "seq")
            reader_back_at = 0.0
            for i in range(N):
                if i == N // 3:
                    broker.kill()
                if i == N // 2:
                    broker.start()
                    reader_back_at = time.monotonic() + READER_LATE_S  # its subscription is sent by its own thread
                if not writer.publish("seq", str(i)):
                    refused.append(i)
                next_at = time.monotonic() + PERIOD_S
                while time.monotonic() < next_at:
                    writer.poll(0.0)
                    if time.monotonic() >= reader_back_at:
                        reader.poll(0.0005)
            assert time.monotonic() > reader_back_at
            reader.poll_until(lambda: False, 1.0)
            assert writer.portal.refused == len(refused) and writer.portal.in_doubt == len(reported)

    delivered = [i for i in delivered if i >= 0]
    sent = set(range(N))
    explained = set(delivered) | set(refused) | set(reported)
    print(f"sent {N}, delivered {len(delivered)}, refused {len(refused)}, reported {len(reported)} "
          f"(of which arrived after all: {len(set(reported) & set(delivered))})")
    assert delivered == sorted(set(delivered)), "duplicated or reordered"
    assert refused and not set(refused) & set(delivered)
    assert sent - explained == set(), f"unexplained: {sorted(sent - explained)[:20]}"
    assert max(delivered) > N // 2 + READER_LATE_S / PERIOD_S / 2, "the stream reached the reader again"
    assert len(reported) < 100, "reports name what no probe confirmed, not a time window"
