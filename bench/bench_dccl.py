"""DCCL benchmark: encode and decode time per message for the course's NavigationReport and USVCommand and a
ten-field nested message.

``python -m bench.bench_dccl``. The reference is the C++ ``dccl::Codec`` (DCCL 4.2, dynamic messages) measured on
this machine: about 13 µs to encode and 21 µs to decode a NavigationReport, 7 and 10 µs for a USVCommand.
Each figure is the best of 15 runs of 5,000 messages, in CPU time of this process (``time.process_time``), so
that other load on the shared machine does not count.
"""

from __future__ import annotations

import time
import timeit
from collections.abc import Callable

from google.protobuf.message import Message

from gateway.goby.dccl import Codec
from tests.protobuf.dccl_test_pb2 import BenchNested
from translators.trail.protobuf.nav_dccl_pb2 import NavigationReport
from translators.usv.protobuf.command_dccl_pb2 import USVCommand

CPP_US = {"NavigationReport": (13.0, 21.0), "USVCommand": (7.0, 10.0)}
RUNS = 15


def messages() -> list[Message]:
    now = time.time()
    nested = BenchNested(vehicle=3, time=now, depth=12.3, active=True)
    nested.pose.x, nested.pose.y, nested.pose.heading = 123.4, -56.7, 270
    nested.status.mode = BenchNested.Status.SURVEY
    nested.status.battery = 87
    nested.status.note = "ok"
    return [
        NavigationReport(vehicle=1, time=now, x=123.4, y=-56.7, z=-3, speed_over_ground=1.5, heading=90,
                         type=NavigationReport.USV),
        USVCommand(time=now, desired_state=USVCommand.POLYGON, polygon_sides=6, polygon_radius=300),
        nested,
    ]


def best_us(stmt: Callable[[], object], number: int) -> float:
    """CPU microseconds per call (process time: time spent waiting for the shared CPU does not count)."""
    return min(timeit.repeat(stmt, timer=time.process_time, number=number, repeat=RUNS)) / number * 1e6


def main() -> int:
    codec = Codec()
    rows = []
    for msg in messages():
        codec.load(type(msg))
        data = codec.encode(msg)
        assert codec.decode(data) is not None

        def encode(m: Message = msg) -> bytes:  # defaults bind this iteration's message, as a lambda's would
            return codec.encode(m)

        def decode(d: bytes = data) -> Message:
            return codec.decode(d)

        encode_us = best_us(encode, 5000)
        decode_us = best_us(decode, 5000)
        name = msg.DESCRIPTOR.name
        cpp = CPP_US.get(name)
        reference = f"{cpp[0]:.0f} / {cpp[1]:.0f}" if cpp else "-"
        verdict = ("yes" if encode_us <= cpp[0] and decode_us <= cpp[1] else "NO") if cpp else "-"
        rows.append((name, str(len(data)), f"{encode_us:.2f}", f"{1e6 / encode_us:,.0f}", f"{decode_us:.2f}",
                     f"{1e6 / decode_us:,.0f}", reference, verdict))
    header = ("message", "bytes", "encode µs/op", "encode msg/s", "decode µs/op", "decode msg/s",
              "C++ µs enc/dec", "as fast as C++")
    widths = [max(len(r[i]) for r in [header, *rows]) for i in range(len(header))]
    for row in [header, tuple("-" * w for w in widths), *rows]:
        print("  ".join(cell.rjust(w) if i else cell.ljust(w) for i, (cell, w) in enumerate(zip(row, widths,
                                                                                               strict=True))))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
