"""Intervehicle link benchmark: capacity used versus the theoretical maximum, and CPU per vehicle.

``python -m bench.bench_intervehicle``. Two real ``Link`` objects (the broker's link logic: DynamicBuffer, TDMA MAC,
frame building, acks) on an in-process ether, driven by a simulated warped clock at Goby's 10 Hz link loop; the USV
publishes to an AUV subscriber with full queues. Capacity = DCCL bytes sent / (USV slots x max_frame_bytes) on the
course's acomms slot plan (USV and AUV alternate, 10 s / 128 B). CPU is this process's CPU time (``process_time``)
for both links, per simulated hour, and as a share of one core at the course's warp 5.
"""

from __future__ import annotations

import time
from collections.abc import Callable

from gateway.goby.acomms.ether import Ether, EtherDriver
from gateway.goby.acomms.protobuf.amac_config_pb2 import MAC_FIXED_DECENTRALIZED
from gateway.goby.dccl import Codec
from gateway.goby.intervehicle.link import Link, LinkConfig, LinkOutputs
from gateway.goby.intervehicle.protobuf.intervehicle_pb2 import Subscription
from gateway.goby.intervehicle.protobuf.transporter_config_pb2 import TransporterConfig
from gateway.goby.intervehicle.serialization import metadata_for, serialize_publication
from translators.trail.protobuf.health_status_pb2 import HealthStatus
from translators.trail.protobuf.nav_dccl_pb2 import NavigationReport
from translators.usv.protobuf.command_dccl_pb2 import USVCommand

USV, AUV = 258, 259
SLOTS = [(USV, 10.0, 128), (AUV, 10.0, 128)]
LOOP_HZ = 10.0
CYCLES = 200
WARP = 5


def link(modem_id: int, ether: Ether, clock: Callable[[], float]) -> Link:
    cfg = LinkConfig(modem_id=modem_id, subnet_mask=0xFF00)
    cfg.driver.driver_name = "ether"
    cfg.mac.type = MAC_FIXED_DECENTRALIZED
    for src, sec, nbytes in SLOTS:
        cfg.mac.slot.add(src=src, slot_seconds=sec, max_frame_bytes=nbytes)
    out = Link(cfg, EtherDriver(ether), clock, LinkOutputs())
    out.start()
    return out


def samples() -> dict[str, list]:
    now = time.time()
    nav = NavigationReport(vehicle=2, time=now, x=1, y=2, z=0, speed_over_ground=1, heading=0,
                           type=NavigationReport.USV)
    cmd = USVCommand(time=now, desired_state=USVCommand.WAYPOINTS)
    health = HealthStatus(state=HealthStatus.GOOD, timestamp=int(now * 1e6))
    mix = [nav, cmd, health]
    return {"NavigationReport (13 B)": [nav], "mix of course messages": mix}


def run(workload: list) -> tuple[float, float, float, float]:
    """(capacity used, messages per warped hour, bytes per warped hour, CPU s per simulated hour)."""
    t = [1_700_000_000.0]
    clock = lambda: t[0]  # noqa: E731
    ether = Ether()
    usv, auv = link(USV, ether, clock), link(AUV, ether, clock)
    codec = Codec()
    cfg = TransporterConfig()
    cfg.intervehicle.buffer.max_queue = 1000
    cfg.intervehicle.buffer.newest_first = False
    cfg.intervehicle.buffer.ttl = 86400
    for i, msg in enumerate(workload):
        codec.load(type(msg))
        auv.codec.load(type(msg))  # the AUV's own subscriber would have brought the type (its metadata)
        sub = Subscription(api_version=1, action=Subscription.SUBSCRIBE, dccl_id=codec.id(type(msg)), group=i + 1)
        sub.header.src = AUV
        sub.intervehicle.CopyFrom(cfg.intervehicle)
        sub.metadata.CopyFrom(metadata_for(type(msg)))
        usv.accept_subscription(sub)
    encoded = [(codec.encode(m), m, i + 1) for i, m in enumerate(workload)]

    def refill() -> None:
        while usv.buffer.size() < 200:
            for data, msg, group in encoded:
                usv.buffer_message(serialize_publication(data, msg, f"g;{group}", group, int(t[0] * 1e6), cfg,
                                                         with_metadata=False))

    cycle = sum(s[1] for s in SLOTS)
    refill()
    for _ in range(int(2 * cycle * LOOP_HZ)):  # let the MAC find its first slot
        t[0] += 1 / LOOP_HZ
        usv.loop()
        auv.loop()
    start_bytes, start_frames = usv.counters.bytes_sent, usv.counters.frames_sent
    start_packets = auv.counters.packets_received
    cpu0 = time.process_time()
    steps = int(CYCLES * cycle * LOOP_HZ)
    for step in range(steps):
        t[0] += 1 / LOOP_HZ
        if step % 10 == 0:
            refill()
        usv.loop()
        auv.loop()
    cpu = time.process_time() - cpu0
    sent = usv.counters.bytes_sent - start_bytes
    frames = usv.counters.frames_sent - start_frames
    packets = auv.counters.packets_received - start_packets
    usv.stop()
    auv.stop()
    hours = CYCLES * cycle / 3600
    theoretical = CYCLES * sum(nbytes for src, _, nbytes in SLOTS if src == USV)
    assert frames == CYCLES, (frames, CYCLES)
    return sent / theoretical, packets / hours, sent / hours, cpu / hours


def main() -> int:
    print(f"acomms slot plan {SLOTS}, {CYCLES} cycles, queues full, link loop {LOOP_HZ:g} Hz (warped)")
    print(f"{'workload':<26} {'capacity used':>14} {'msgs/h':>9} {'bytes/h':>9} {'CPU s/sim h':>12} "
          f"{'core % @warp ' + str(WARP):>15}")
    for name, workload in samples().items():
        used, msgs, nbytes, cpu = run(workload)
        print(f"{name:<26} {used:>13.1%} {msgs:>9.0f} {nbytes:>9.0f} {cpu:>12.3f} {cpu * WARP / 3600:>15.3%}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
