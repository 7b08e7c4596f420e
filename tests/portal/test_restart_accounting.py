"""Issue #19 item 4 for Goby interprocess: across a goby-broker crash (SIGKILL) and restart, every numbered
publication is delivered, refused (``publish`` returned False while the broker connection is down) or reported
undelivered (``on_undelivered``: sent in the last moments before the connection dropped). Nothing unexplained,
nothing duplicated or reordered."""

from __future__ import annotations

import time
from pathlib import Path

from gateway.goby.portal.testing import PortalClient, broker_process

N = 3000
PERIOD_S = 0.002


def test_broker_crash_accounting_is_exact(tmp_path: Path) -> None:
    delivered: list[int] = []
    refused: list[int] = []
    reported: list[int] = []
    with broker_process(tmp_path) as broker:
        cfg = broker.interprocess_config()
        with PortalClient(cfg, "reader") as reader, PortalClient(cfg, "writer") as writer:
            reader.subscribe("seq", str, lambda text: delivered.append(int(text)))
            assert reader.wait_subscribed() and writer.wait_ready()
            writer.portal.on_undelivered = lambda lost: reported.extend(int(p.rstrip(b"\0")) for g, p in lost if g == "seq")
            for i in range(N):
                if i == N // 3:
                    broker.kill()
                if i == N // 2:
                    broker.start()
                if not writer.publish("seq", str(i)):
                    refused.append(i)
                next_at = time.monotonic() + PERIOD_S
                while time.monotonic() < next_at:
                    writer.poll(0.0)
                    reader.poll(0.0005)
            reader.poll_until(lambda: False, 1.0)
            assert writer.portal.refused == len(refused) and writer.portal.in_doubt == len(reported)

    sent = set(range(N))
    explained = set(delivered) | set(refused) | set(reported)
    print(f"sent {N}, delivered {len(delivered)}, refused {len(refused)}, reported {len(reported)} "
          f"(of which arrived after all: {len(set(reported) & set(delivered))})")
    assert delivered == sorted(set(delivered)), "duplicated or reordered"
    assert refused and not set(refused) & set(delivered)
    assert sent - explained == set(), f"unexplained: {sorted(sent - explained)[:20]}"
