"""Fidelity to Goby3's protos as shipped (tests/data/goby3_field_set.json, written by tools/goby_field_set.py
from GobySoft/goby3 3.1.5): our protos that claim a Goby3 package declare nothing Goby3 lacks, and every config
our launchers generate for a Goby3 application uses only fields the real application knows."""

from __future__ import annotations

import importlib
import json
from collections.abc import Iterator
from pathlib import Path

from google.protobuf import descriptor as pb_descriptor
from google.protobuf import descriptor_pb2, text_format
from google.protobuf import message as pb_message

from tools.generate_protos import INCLUDE_ROOT, REPO_ROOT, proto_files

FIELD_SET = json.loads((Path(__file__).parent / "data" / "goby3_field_set.json").read_text())
MESSAGES: dict[str, dict] = FIELD_SET["messages"]
ENUMS: dict[str, dict[str, int]] = FIELD_SET["enums"]
EXTENSIONS = {(e["extendee"], e["number"]): e for e in FIELD_SET["extensions"]}
_TYPE = {v: k[len("TYPE_"):].lower() for k, v in descriptor_pb2.FieldDescriptorProto.Type.items()}


def _claims_goby(package: str) -> bool:
    return (package == "goby" or package.startswith("goby.")) and not package.startswith("goby.test.")


def _our_files() -> list[pb_descriptor.FileDescriptor]:
    files = []
    for path in proto_files():
        if path.is_relative_to(INCLUDE_ROOT) or path.is_relative_to(REPO_ROOT / "tests"):
            continue
        module = ".".join(path.relative_to(REPO_ROOT).with_suffix("").parts) + "_pb2"
        files.append(importlib.import_module(module).DESCRIPTOR)
    return files


def _messages(container) -> Iterator[pb_descriptor.Descriptor]:
    for msg in container.message_types_by_name.values() if hasattr(container, "message_types_by_name") \
            else container.nested_types:
        yield msg
        yield from _messages(msg)


def _label(field: pb_descriptor.FieldDescriptor) -> str:
    return "repeated" if field.is_repeated else "required" if field.is_required else "optional"


def _compare_field(field: pb_descriptor.FieldDescriptor, goby: dict, where: str) -> list[str]:
    ours = {"name": field.full_name if field.is_extension else field.name, "number": field.number,
            "type": _TYPE[field.type], "label": _label(field)}
    if field.message_type is not None or field.enum_type is not None:
        ours["type_name"] = (field.message_type or field.enum_type).full_name
    theirs = {k: goby.get(k) for k in ours}
    return [] if ours == theirs else [f"{where}: ours {ours}, Goby3 {theirs}"]


def test_field_set_is_goby_3_1_and_covers_the_config_roots() -> None:
    assert FIELD_SET["source"] == "GobySoft/goby3 3.1.5"
    for name in ("goby.middleware.protobuf.AppConfig", "goby.apps.zeromq.protobuf.FrontSeatInterfaceConfig",
                 "goby.apps.moos.protobuf.GobyMOOSGatewayConfig", "goby.apps.zeromq.protobuf.GobyDaemonConfig",
                 "goby.middleware.frontseat.protobuf.BasicSimulatorFrontSeatConfig"):
        assert name in MESSAGES, name
    # the fields issue #18 found in our copies and not in Goby3 3.1
    app = {f["number"] for f in MESSAGES["goby.middleware.protobuf.AppConfig"]["fields"]}
    assert app == {1, 2, 10, 20, 30, 40, 50, 100}
    status = {f["name"] for f in MESSAGES["goby.middleware.frontseat.protobuf.InterfaceStatus"]["fields"]}
    assert "frontseat_providing_data" not in status and "helm_state" in status


def test_our_goby_package_protos_declare_nothing_goby_lacks() -> None:
    problems: list[str] = []
    checked = 0
    for fd in _our_files():
        if not _claims_goby(fd.package):
            for ext in fd.extensions_by_name.values():  # a project extension of a Goby message: in its range,
                extendee = ext.containing_type.full_name  # clear of Goby's own extensions
                if extendee in MESSAGES:
                    ranges = MESSAGES[extendee]["extension_ranges"]
                    if not any(lo <= ext.number <= hi for lo, hi in ranges) or (extendee, ext.number) in EXTENSIONS:
                        problems.append(f"{fd.name}: {ext.full_name} = {ext.number} clashes with Goby3's {extendee}")
            continue
        for msg in _messages(fd):
            goby = MESSAGES.get(msg.full_name)
            if goby is None:
                problems.append(f"{fd.name}: message {msg.full_name} is not in Goby3")
                continue
            by_number = {f["number"]: f for f in goby["fields"]}
            for field in msg.fields:
                checked += 1
                if field.number not in by_number:
                    if (msg.full_name, field.name, field.number) not in OUR_FIELDS:
                        problems.append(f"{fd.name}: {field.full_name} = {field.number} is not in Goby3")
                else:
                    problems += _compare_field(field, by_number[field.number], f"{fd.name}: {field.full_name}")
            for enum in msg.enum_types:
                problems += _compare_enum(enum, fd.name)
        for enum in fd.enum_types_by_name.values():
            problems += _compare_enum(enum, fd.name)
        for ext in fd.extensions_by_name.values():
            goby = EXTENSIONS.get((ext.containing_type.full_name, ext.number))
            if goby is None:
                problems.append(f"{fd.name}: extension {ext.full_name} = {ext.number} is not in Goby3")
            else:
                problems += _compare_field(ext, goby, f"{fd.name}: {ext.full_name}")
    assert not problems, "\n".join(problems)
    assert checked > 100  # the walk really saw our Goby-package protos


#: Enum values we add to a Goby3 enum on purpose, each documented where it is used: proto2 enums cannot be extended,
#: and issue 26 asks for ``goby-log-tool --format MCAP`` (docs/logging.md: a config with it does not parse in the
#: real goby_log_tool).
OUR_ENUM_VALUES = {("goby.apps.middleware.protobuf.LogToolConfig.OutputFormat", "MCAP", 4)}
#: Fields we add to a Goby3 message on purpose (it has no extension range): goby-opencpn-interface binds loopback
#: unless told otherwise, where Goby binds every interface (docs/opencpn.md).
OUR_FIELDS = {("goby.middleware.protobuf.TCPServerConfig", "bind_address", 100)}


def _compare_enum(enum: pb_descriptor.EnumDescriptor, where: str) -> list[str]:
    goby = ENUMS.get(enum.full_name)
    if goby is None:
        return [f"{where}: enum {enum.full_name} is not in Goby3"]
    return [f"{where}: {enum.full_name}.{v.name} = {v.number} is not in Goby3" for v in enum.values
            if goby.get(v.name) != v.number and (enum.full_name, v.name, v.number) not in OUR_ENUM_VALUES]


def goby_field_problems(msg: pb_message.Message, where: str) -> list[str]:
    """Every set field of ``msg`` (recursively, extensions included) that Goby3's field set does not have."""
    problems: list[str] = []
    name = msg.DESCRIPTOR.full_name
    goby = MESSAGES.get(name)
    if goby is None:
        return [f"{where}: {name} is not a Goby3 message"]
    by_number = {f["number"]: f for f in goby["fields"]}
    for field, value in msg.ListFields():
        path = f"{where}.{field.full_name if field.is_extension else field.name}"
        known = EXTENSIONS.get((name, field.number)) if field.is_extension else by_number.get(field.number)
        if known is None:
            problems.append(f"{path} (= {field.number}) is not in Goby3's {name}")
            continue
        problems += _compare_field(field, known, path)
        if field.message_type is not None:
            for item in value if field.is_repeated else [value]:
                problems += goby_field_problems(item, path)
    return problems


def test_the_field_check_catches_an_extra_field() -> None:
    from frontseat.protobuf import basic_simulator_tuning_pb2 as tuning_pb
    from frontseat.protobuf.frontseat_interface_config_pb2 import FrontSeatInterfaceConfig

    cfg = FrontSeatInterfaceConfig()
    cfg.frontseat_cfg.Extensions[tuning_pb.basic_simulator_tuning].data_timeout = 5
    cfg.frontseat_cfg.require_helm = True
    problems = goby_field_problems(cfg, "cfg")
    assert len(problems) == 1 and "basic_simulator_tuning" in problems[0]


def _goby_app_types() -> dict[str, type[pb_message.Message]]:
    """The launcher apps whose real Goby3 counterpart reads the same file, and the config type both read."""
    import frontseat.basic_simulator_driver  # noqa: F401  (registers the driver's Config extension, as loading it does)
    from frontseat.protobuf.frontseat_interface_config_pb2 import FrontSeatInterfaceConfig
    from gateway.goby.portal.protobuf.gobyd_config_pb2 import GobyDaemonConfig
    from gateway.moos_gateway.protobuf.moos_gateway_config_pb2 import GobyMOOSGatewayConfig
    from launch.liaison.protobuf.liaison_config_pb2 import LiaisonConfig

    return {"gobyd": GobyDaemonConfig, "frontseat_interface": FrontSeatInterfaceConfig,
            "moos_gateway": GobyMOOSGatewayConfig, "liaison": LiaisonConfig}


def _usv_configs(tmp_path: Path) -> Iterator[tuple[str, pb_message.Message]]:
    from launch.usv.config import generate
    from launch.usv.settings import UsvSettings

    settings = UsvSettings(run_dir=tmp_path, warp=20, socket_name=str(tmp_path / "goby_usv"))
    for app, config_type in _goby_app_types().items():
        text = generate("broker" if app == "gobyd" else app, settings)
        yield f"usv mission {app}", text_format.Parse(text, config_type())


def _trail_configs(tmp_path: Path) -> Iterator[tuple[str, pb_message.Message]]:
    try:
        from launch.trail.config import generate
        from launch.trail.settings import TrailSettings, Vehicle
    except ModuleNotFoundError:  # the trail mission's launcher is not there yet
        return
    from launch.errors import MissionConfigError

    settings = TrailSettings(run_dir=tmp_path / "trail", socket_dir=tmp_path / "s")
    for vehicle in (Vehicle("topside", 1), Vehicle("usv", 1), Vehicle("auv", 1, 0)):
        for app, config_type in _goby_app_types().items():
            try:
                text = generate(vehicle.kind, app, settings, vehicle)
            except MissionConfigError:  # not an app of this platform
                continue
            yield f"trail {vehicle.kind} {app}", text_format.Parse(text, config_type())


def test_generated_goby_configs_use_only_goby3_fields(tmp_path: Path) -> None:
    configs = [*_usv_configs(tmp_path), *_trail_configs(tmp_path)]
    assert len(configs) >= 4
    problems = [p for where, cfg in configs for p in goby_field_problems(cfg, where)]
    assert not problems, "\n".join(problems)


def test_the_recording_tool_reads_descriptors_as_the_committed_file_has_them() -> None:
    # our AppConfig and basic simulator config are now exactly Goby's: recorded by the tool's own code, they must
    # come out as the committed data file has Goby3's (the tool itself needs a Goby3 clone, not available in CI)
    from frontseat.protobuf import basic_simulator_config_pb2
    from gateway.goby.protobuf import app_config_pb2
    from tools.goby_field_set import dump, field_set

    files = descriptor_pb2.FileDescriptorSet()
    for module, goby_path in ((app_config_pb2, "goby/middleware/protobuf/app_config.proto"),
                              (basic_simulator_config_pb2,
                               "goby/middleware/frontseat/simulator/basic/basic_simulator_frontseat_driver_config.proto")):
        fd = files.file.add()
        module.DESCRIPTOR.CopyToProto(fd)
        fd.name = goby_path
    recorded = field_set(files, "test")
    assert json.loads(dump(recorded)) == recorded
    for name in ("goby.middleware.protobuf.AppConfig", "goby.middleware.protobuf.AppConfig.SimulatorSettings.Time",
                 "goby.middleware.frontseat.protobuf.BasicSimulatorFrontSeatConfig.StartParams.VehicleConfig"):
        assert recorded["messages"][name] == MESSAGES[name], name
    ext = [e for e in recorded["extensions"] if e["name"].endswith("basic_simulator_config")]
    assert ext == [EXTENSIONS[("goby.middleware.frontseat.protobuf.Config", 1001)]]
