"""The C++ ``dccl`` tool (DCCL 4.x) and our codec give the same bytes and the same messages, both ways, for random
messages of every test type (in and out of bounds), and the same ``--analyze`` report. Runs when ``dccl`` is on
PATH; skipped otherwise."""

from __future__ import annotations

import random
import shutil
import subprocess
import time
from pathlib import Path

import pytest
from google.protobuf import text_format

from gateway.goby.dccl import Codec
from tests.dccl.conftest import COURSE_TYPES
from tests.dccl.random_messages import fill
from tests.protobuf import dccl_test_pb2 as pb

pytestmark = [pytest.mark.interop, pytest.mark.skipif(shutil.which("dccl") is None,
                                                      reason="the C++ dccl tool is not on PATH")]
REPO = Path(__file__).resolve().parents[2]
TYPES = [pb.Everything, pb.Layout, pb.Subscription, pb.BenchNested, *COURSE_TYPES]
PROTOS = ["tests/protobuf/dccl_test.proto", "translators/trail/protobuf/nav_dccl.proto",
          "translators/usv/protobuf/command_dccl.proto", "translators/trail/protobuf/health_status.proto"]


def dccl_tool(*args: str, stdin: str) -> list[str]:
    command = ["dccl", *args, "-I", str(REPO / "gateway/goby/protobuf/include"), "-I", str(REPO),
               *(a for p in PROTOS for a in ("-f", p))]
    result = subprocess.run(command, input=stdin, capture_output=True, text=True, cwd=REPO, timeout=120)
    assert result.returncode == 0, result.stderr
    return [line.strip() for line in result.stdout.splitlines() if line.strip()]


def test_random_messages_give_the_same_bytes_and_decode_the_same_both_ways():
    rnd = random.Random(20231114)
    clock = time.time()
    codec = Codec()
    for message_type in TYPES:
        codec.load(message_type)
    messages = [fill(rnd, rnd.choice(TYPES)(), clock) for _ in range(400)]
    messages = [m for m in messages if m.IsInitialized()]
    lines = [f"|{m.DESCRIPTOR.full_name}| {text_format.MessageToString(m, as_one_line=True)}" for m in messages]
    ours = [codec.encode(m).hex() for m in messages]
    theirs = dccl_tool("-e", "--format", "hex", "-m", "goby.test.dccl.Everything", stdin="\n".join(lines) + "\n")
    assert theirs == ours
    decoded = dccl_tool("-d", "--format", "hex", stdin="\n".join(ours) + "\n")
    by_name = {t.DESCRIPTOR.full_name: t for t in TYPES}
    for line, data in zip(decoded, ours, strict=True):
        name, _, text = line[1:].partition("| ")
        assert text_format.Parse(text, by_name[name]()) == codec.decode(bytes.fromhex(data)), line


@pytest.mark.parametrize("message_type", TYPES, ids=lambda t: t.DESCRIPTOR.name)
def test_analyze_report_matches_apart_from_the_hash(message_type):
    name = message_type.DESCRIPTOR.full_name
    theirs = subprocess.run(
        ["dccl", "-a", "-m", name, "-I", str(REPO / "gateway/goby/protobuf/include"), "-I", str(REPO),
         *(a for p in PROTOS for a in ("-f", p))], capture_output=True, text=True, cwd=REPO, timeout=120).stdout
    codec = Codec()
    codec.load(message_type)
    ours = codec.info(message_type)
    assert ours.splitlines()[1:] == theirs.splitlines()[1:]
    assert f" {message_type.DESCRIPTOR.full_name} " in theirs.splitlines()[0]
