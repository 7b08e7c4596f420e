"""Test applications run as real processes by tests/portal: ``python -m tests.portal.apps.sample_app``.

Roles (``role:`` in SampleAppConfig):
* ``tx``: publish ``count`` Samples (a = 1..count) on every ``group`` after the hold is released, then quit.
* ``rx``: subscribe Sample on every ``group``; print ``RX <group> <a>`` per message; quit after ``count`` per group.
* ``threads``: like rx, but subscribing from a launched SimpleThread; the main thread relays each message on
  interthread ``relay`` to a second thread that prints it.
"""

from __future__ import annotations

import sys

from gateway.goby.portal import MultiThreadApplication, SimpleThread, SingleThreadApplication, run_application
from tests.protobuf.sample_messages_pb2 import Sample, SampleAppConfig


class TxApp(SingleThreadApplication):
    def __init__(self, cfg: SampleAppConfig) -> None:
        super().__init__(cfg, loop_frequency_hz=1.0 / cfg.publish_period)
        self.sent = 0

    def loop(self) -> None:
        if self.interprocess().hold_state():
            return
        if self.sent >= self.cfg().count:
            print("TX DONE", flush=True)
            self.quit()
            return
        self.sent += 1
        for group in self.cfg().group:
            self.interprocess().publish(group, Sample(a=self.sent, temperature=self.sent * 0.5))


class RxApp(SingleThreadApplication):
    def __init__(self, cfg: SampleAppConfig) -> None:
        super().__init__(cfg, loop_frequency_hz=10)
        self.counts = {g: 0 for g in cfg.group}
        for group in cfg.group:
            self.interprocess().subscribe(group, Sample, lambda msg, g=group: self.on_sample(g, msg))

    def on_sample(self, group: str, msg: Sample) -> None:
        self.counts[group] += 1
        print(f"RX {group} {msg.a}", flush=True)
        if all(c >= self.cfg().count for c in self.counts.values()):
            print("RX DONE", flush=True)
            self.quit()


class Printer(SimpleThread):
    def __init__(self, cfg: SampleAppConfig) -> None:
        super().__init__(cfg)
        self.interthread().subscribe("relay", Sample, self.on_relay)

    def on_relay(self, msg: Sample) -> None:
        print(f"RX relay {msg.a}", flush=True)


class Receiver(SimpleThread):
    def __init__(self, cfg: SampleAppConfig) -> None:
        super().__init__(cfg, loop_frequency_hz=10)
        self.seen = 0
        for group in cfg.group:
            self.interprocess().subscribe(group, Sample, lambda msg, g=group: self.on_sample(g, msg))

    def on_sample(self, group: str, msg: Sample) -> None:
        print(f"RX {group} {msg.a}", flush=True)
        self.interthread().publish("relay", msg)


class ThreadsApp(MultiThreadApplication):
    def __init__(self, cfg: SampleAppConfig) -> None:
        super().__init__(cfg, loop_frequency_hz=10)
        self.launch_thread(Printer)
        self.launch_thread(Receiver)


ROLES = {"tx": TxApp, "rx": RxApp, "threads": ThreadsApp}


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    role = next((a.split("=", 1)[1] for a in args if a.startswith("--role=")), "rx")
    args = [a for a in args if not a.startswith("--role=")]
    return run_application(ROLES[role], SampleAppConfig, args, prog=f"sample_{role}")


if __name__ == "__main__":
    sys.exit(main())
