"""goby-log-tool --format HDF5 and MCAP as processes, read back with h5py and the mcap library; and the real
goby_playback replaying our log into our broker (skipped with the reason unless the real binaries are on PATH
inside a private network namespace, as tests/goby_log/test_interop.py)."""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path
from typing import Any

import h5py
import numpy as np
import pytest
from google.protobuf import descriptor_pb2, descriptor_pool, message_factory
from google.protobuf.descriptor import EnumDescriptor
from mcap.reader import make_reader
from mcap.stream_reader import StreamReader

from frontseat.protobuf.frontseat_data_pb2 import NodeStatus
from gateway.goby.dccl import Codec
from gateway.goby.log import LogWriter, bson
from gateway.goby.portal import Scheme
from gateway.goby.portal.testing import PortalClient, app_process, broker_process
from tests.goby3_real import real_goby_skip_reason
from tests.protobuf.sample_messages_pb2 import DCCLSample, Sample

PY = sys.executable
T0 = 1_795_859_707_386_269
SAMPLE = Sample.DESCRIPTOR.full_name
NODE_GROUP = "goby::middleware::frontseat/node_status"  # a "/" in a Goby group nests HDF5 groups
INT32_EMPTY = 2**31 - 1




def vehicle_type() -> EnumDescriptor:
    enum = NodeStatus.DESCRIPTOR.fields_by_name["type"].enum_type
    assert enum is not None
    return enum


VEHICLE_TYPE = vehicle_type()


def node(name: str, lat: float, with_local: bool) -> NodeStatus:
    msg = NodeStatus(time=lat, name=name)
    msg.type = VEHICLE_TYPE.values[1].number  # type: ignore[assignment]  # an enum value's number
    msg.global_fix.lat, msg.global_fix.lon = lat, -70.0
    msg.pose.heading = 90.0
    msg.speed.over_ground = 1.5
    if with_local:
        msg.local_fix.x, msg.local_fix.y = 10.0, -20.0
    return msg


def descriptor(name: str, fields: list[tuple[str, int]]) -> descriptor_pb2.DescriptorProto:
    msg = descriptor_pb2.DescriptorProto(name=name)
    for field_name, number in fields:
        msg.field.add(name=field_name, number=number, label=descriptor_pb2.FieldDescriptorProto.LABEL_REPEATED)
    return msg


def write_log(path: Path, node_group: str = NODE_GROUP) -> list[tuple[int, str, str, int, bytes]]:
    """A log of every scheme, nested, repeated and string fields, DCCL and an unknown type; returns its entries
    as (scheme, group, type, time, data)."""
    entries: list[tuple[int, str, str, int, bytes]] = []
    codec = Codec()
    codec.load(DCCLSample)
    for i in range(4):
        padding = b"p" * i if i != 2 else None  # a bytes field left unset once
        sample = Sample(a=i, depth=i * 0.5, padding=padding) if padding is not None else Sample(a=i, depth=i * 0.5)
        entries.append((Scheme.PROTOBUF, "nav", SAMPLE, T0 + 10 * i, sample.SerializeToString()))
        entries.append((Scheme.CSTR, "text", "CSTR", T0 + 10 * i + 1, f"line {i}\0".encode()))
    entries.append((Scheme.PROTOBUF, node_group, NodeStatus.DESCRIPTOR.full_name, T0 + 100,
                    node("usv", 42.5, True).SerializeToString()))
    entries.append((Scheme.PROTOBUF, node_group, NodeStatus.DESCRIPTOR.full_name, T0 + 101,
                    node("auv", 42.25, False).SerializeToString()))
    entries.append((Scheme.PROTOBUF, "desc", "google.protobuf.DescriptorProto", T0 + 200,
                    descriptor("Two", [("first", 1), ("second_field", 2)]).SerializeToString()))
    entries.append((Scheme.PROTOBUF, "desc", "google.protobuf.DescriptorProto", T0 + 201,
                    descriptor("None", []).SerializeToString()))
    entries.append((Scheme.JSON, "json", "nlohmann::json", T0 + 300, bson.encode({"depth": 12.5, "name": "auv"})))
    entries.append((Scheme.DCCL, "dccl", DCCLSample.DESCRIPTOR.full_name, T0 + 400, codec.encode(DCCLSample(a=42))))
    entries.append((Scheme.PROTOBUF, "mystery", "no.such.Type", T0 + 500, b"\x08\x01"))
    with open(path, "wb") as f:
        writer = LogWriter(f.write, lambda: T0)
        for scheme, group, type_name, t, data in entries:
            writer.write(data, scheme, type_name, group, t)
    return entries


def log_tool(tmp_path: Path, name: str, *args: str, env: dict[str, str] | None = None) -> tuple[int | None, str]:
    tool = app_process([PY, "-m", "gateway.apps.goby_log_tool", *args], tmp_path / f"{name}.log", env=env)
    code = tool.wait(120)
    return code, (tmp_path / f"{name}.log").read_text()


def strings(group: Any, name: str) -> list[bytes]:
    chars, sizes = group[name][()], group[name + "_size"][()]
    return [bytes(row[:size].astype(np.uint8)) for row, size in zip(chars, sizes, strict=True)]


# ---- HDF5 ----------------------------------------------------------------------------------------------------
def test_hdf5_has_gobys_layout_and_every_protobuf_entry(tmp_path: Path) -> None:
    log = tmp_path / "mission.goby"
    entries = write_log(log)
    code, err = log_tool(tmp_path, "h5", str(log), str(tmp_path / "mission.h5"), "--format", "HDF5")
    assert code == 0, err
    assert "Traceback" not in err and "no.such.Type" in err  # the unknown type is named, not a crash
    with h5py.File(tmp_path / "mission.h5", "r") as f:
        assert sorted(f) == ["dccl", "desc", "goby::middleware::frontseat", "nav"]  # no CSTR, JSON, unknown type
        nav = f["nav"][SAMPLE]
        samples = [Sample.FromString(d) for s, g, t, _, d in entries if g == "nav"]
        assert list(nav["_utime_"][()]) == [t for s, g, _, t, _ in entries if g == "nav"]
        assert nav["_utime_"].dtype == np.uint64 and list(nav["_scheme_"][()]) == [Scheme.PROTOBUF] * 4
        assert nav["_datenum_"][0] == pytest.approx(719529 + T0 / 1e6 / 86400)
        assert list(nav["a"][()]) == [m.a for m in samples] and nav["a"].dtype == np.int32
        assert list(nav["depth"][()]) == [m.depth for m in samples]
        assert np.isnan(nav["salinity"][()]).all()  # an unset optional double holds NaN
        assert list(nav["sent_micro"][()]) == [2**63 - 1] * 4  # an unset int64 holds its maximum
        assert strings(nav, "padding") == [m.padding for m in samples]  # int8 chars + _size
        assert nav["padding"].shape == (4, 3) and nav["padding"].dtype == np.int8
        assert nav["a"].attrs["default_value"][0] == 0

        ns = f["goby::middleware::frontseat/node_status"][NodeStatus.DESCRIPTOR.full_name]
        assert list(ns["global_fix/lat"][()]) == [42.5, 42.25]
        assert list(ns["local_fix/x"][()]) == [10.0, 0.0]  # required in an unset message: its default
        assert np.isnan(ns["local_fix/z"][()]).all()
        assert strings(ns, "name") == [b"usv", b"auv"]
        assert list(ns["type"].attrs["enum_names"]) == [v.name for v in VEHICLE_TYPE.values]
        assert list(ns["type"].attrs["enum_values"]) == [v.number for v in VEHICLE_TYPE.values]
        assert list(ns["source/position"][()]) == [INT32_EMPTY] * 2

        desc = f["desc"]["google.protobuf.DescriptorProto"]
        assert desc["field/number"].shape == (2, 2)  # a repeated message field adds a dimension
        assert desc["field/number"][()].tolist() == [[1, 2], [INT32_EMPTY, INT32_EMPTY]]
        assert desc["field/name"].shape == (2, 2, len("second_field"))
        assert desc["field/name_size"][()].tolist() == [[5, 12], [0, 0]]
        assert desc["field/label"][()].tolist()[0] == [descriptor_pb2.FieldDescriptorProto.LABEL_REPEATED] * 2
        assert strings(desc, "name") == [b"Two", b"None"]

        dccl = f["dccl"][DCCLSample.DESCRIPTOR.full_name]
        assert list(dccl["_scheme_"][()]) == [Scheme.DCCL] and list(dccl["a"][()]) == [42]

    # chunked and compressed (bounded memory): the same datasets
    code, err = log_tool(tmp_path, "h5c", str(log), str(tmp_path / "chunked.h5"), "--format", "HDF5",
                         "--hdf5_chunk_length", "2", "--hdf5_compression_level", "4")
    assert code == 0, err
    with h5py.File(tmp_path / "mission.h5", "r") as whole, h5py.File(tmp_path / "chunked.h5", "r") as chunked:
        names: list[str] = []
        whole.visititems(lambda name, obj: names.append(name) if isinstance(obj, h5py.Dataset) else None)
        assert len(names) > 100
        for name in names:
            assert chunked[name].shape == whole[name].shape, name
            assert np.array_equal(chunked[name][()], whole[name][()], equal_nan=whole[name].dtype.kind == "f"), name
        assert chunked[f"nav/{SAMPLE}/a"].chunks is not None and chunked[f"nav/{SAMPLE}/a"].compression == "gzip"


def test_without_the_log_extra_hdf5_and_mcap_exit_1_naming_it(tmp_path: Path) -> None:
    log = tmp_path / "m.goby"
    write_log(log)
    blocker = tmp_path / "blocker"
    for module in ("h5py", "mcap"):
        (blocker / module).mkdir(parents=True)
        (blocker / module / "__init__.py").write_text(f"raise ImportError('no {module} here')\n")
    env = {"PATH": "/usr/bin:/bin", "PYTHONPATH": f"{blocker}:{Path.cwd()}"}
    for fmt in ("HDF5", "MCAP"):
        code, err = log_tool(tmp_path, f"no_{fmt}", str(log), str(tmp_path / f"out.{fmt}"), "--format", fmt, env=env)
        assert code == 1, err
        assert "'log' extra" in err and "Traceback" not in err
        assert not (tmp_path / f"out.{fmt}").exists()


# ---- MCAP ----------------------------------------------------------------------------------------------------
def protobuf_class(schema_name: str, schema_data: bytes) -> Any:
    """The message class from an MCAP schema alone (a fresh pool: nothing of this process is used)."""
    pool = descriptor_pool.DescriptorPool()
    for file in descriptor_pb2.FileDescriptorSet.FromString(schema_data).file:
        pool.Add(file)
    return message_factory.GetMessageClass(pool.FindMessageTypeByName(schema_name))


def test_mcap_validates_and_every_message_decodes_with_its_schema(tmp_path: Path) -> None:
    log = tmp_path / "mission.goby"
    entries = write_log(log)
    code, err = log_tool(tmp_path, "mcap", str(log), "--format", "MCAP", "-o", str(tmp_path / "mission.mcap"))
    assert code == 0, err
    assert "no.such.Type" in err and "kept as bytes" in err and "Traceback" not in err

    with open(tmp_path / "mission.mcap", "rb") as f:  # every record, CRCs checked (chunks and data section)
        records = list(StreamReader(f, validate_crcs=True).records)
    assert records
    with open(tmp_path / "mission.mcap", "rb") as f:
        reader = make_reader(f, validate_crcs=True)
        summary = reader.get_summary()
        assert summary is not None and summary.statistics is not None
        assert summary.statistics.message_count == len(entries)
        got = list(reader.iter_messages())
        assert {m.name for m in reader.iter_metadata()} == {"goby_log"}
    assert [m.log_time for _, _, m in got] == [t * 1000 for _, _, _, t, _ in entries]
    classes: dict[int, Any] = {}
    for (scheme, group, type_name, _, data), (schema, channel, message) in zip(entries, got, strict=True):
        assert channel.topic == group
        assert channel.metadata["goby.type"] == type_name and channel.metadata["goby.scheme"] == Scheme(scheme).name
        assert message.publish_time == message.log_time
        if type_name == "no.such.Type":
            assert schema is None and channel.message_encoding == "application/octet-stream"
            assert message.data == data
        elif scheme == Scheme.CSTR:
            assert channel.message_encoding == "json" and schema is not None and schema.encoding == "jsonschema"
            assert json.loads(message.data) == {"value": data[:-1].decode()}
        elif scheme == Scheme.JSON:
            assert channel.message_encoding == "json" and schema is not None and schema.name == "nlohmann::json"
            assert json.loads(message.data) == bson.decode(data)
        else:
            assert channel.message_encoding == "protobuf" and schema is not None and schema.encoding == "protobuf"
            assert schema.name == type_name
            if schema.id not in classes:
                classes[schema.id] = protobuf_class(schema.name, schema.data)
            decoded = classes[schema.id].FromString(message.data)
            if scheme == Scheme.DCCL:  # decoded by DCCL, re-serialized as protobuf
                assert decoded.a == 42
            else:
                assert decoded.SerializeToString() == data
    assert {s.name for s in summary.schemas.values()} >= {SAMPLE, "goby.CSTR", NodeStatus.DESCRIPTOR.full_name}


def test_mcap_to_stdout_and_hdf5_not(tmp_path: Path) -> None:
    log = tmp_path / "m.goby"
    entries = write_log(log)
    tool = app_process([PY, "-m", "gateway.apps.goby_log_tool", str(log), "-", "--format", "MCAP"],
                       tmp_path / "stdout.log")
    assert tool.wait(120) == 0
    with open(tmp_path / "stdout.log.out", "rb") as f:
        assert sum(1 for _ in make_reader(f, validate_crcs=True).iter_messages()) == len(entries)
    code, err = log_tool(tmp_path, "h5stdout", str(log), "-", "--format", "HDF5")
    assert code == 1 and "cannot go to stdout" in err and "Traceback" not in err


# ---- the real goby_playback into our broker --------------------------------------------------------------------
@pytest.mark.interop
def test_real_goby_playback_replays_our_log_into_our_broker(tmp_path: Path) -> None:
    reason = real_goby_skip_reason("goby_playback")
    if reason:
        pytest.skip(reason)
    log = tmp_path / "ours.goby"
    entries = write_log(log, node_group="node_status")  # a "/" in a group cannot travel (Goby's identifier)
    ours = [(g, s, t, d) for s, g, t, _, d in entries]
    with broker_process(tmp_path, platform="pb") as broker, PortalClient(broker.interprocess_config(), "rx") as rx:
        got: list[tuple[str, int, str, bytes]] = []
        rx.portal.subscribe_regex(lambda data, scheme, tname, group: got.append((group, scheme, tname, data)))
        assert rx.wait_subscribed()
        playback = app_process([shutil.which("goby_playback") or "goby_playback", str(log), "--rate", "4",
                                "--playback_start_delay", "1", "--interprocess", broker.interprocess_text()],
                               tmp_path / "playback.log")
        try:
            groups = {g for g, *_ in ours}
            assert rx.poll_until(lambda: len([g for g in got if g[0] in groups]) == len(ours), 60), playback.tail()
            assert playback.wait(30) == 0, playback.tail()
        finally:
            playback.stop()
    assert [g for g in got if g[0] in groups] == ours  # same groups, schemes, types, bytes, order
