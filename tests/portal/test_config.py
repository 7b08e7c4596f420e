"""Configuration loading: text-format files, overrides, GOBY_INTERPROCESS, --example_config, errors."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from google.protobuf import text_format

from gateway.goby.portal import AppConfigError
from gateway.goby.portal.config import example_config, load_config
from gateway.goby.portal.protobuf.gobyd_config_pb2 import GobyDaemonConfig
from gateway.goby.protobuf.interprocess_config_pb2 import InterProcessPortalConfig
from gateway.moos_gateway.protobuf.moos_gateway_config_pb2 import GobyMOOSGatewayConfig
from tests.protobuf.sample_messages_pb2 import SampleAppConfig


def _write(tmp_path: Path, text: str) -> str:
    path = tmp_path / "app.pb.cfg"
    path.write_text(text)
    return str(path)


def test_file_then_command_line_overrides(tmp_path: Path) -> None:
    path = _write(tmp_path, 'app { name: "from_file" debug_cfg: false } interprocess { platform: "file" } count: 3')
    loaded = load_config(SampleAppConfig, [path, "--interprocess", 'platform: "cli"', "--count", "7",
                                         "--group", "a", "--group", "b;2", "-vv"], environ={})
    cfg = loaded.cfg
    assert cfg.app.name == "from_file"
    assert cfg.app.HasField("debug_cfg") and not cfg.app.debug_cfg
    assert cfg.interprocess.platform == "cli"
    assert cfg.count == 7
    assert list(cfg.group) == ["a", "b;2"]
    assert loaded.verbosity == 2


def test_goby_interprocess_env_only_when_no_block(tmp_path: Path) -> None:
    env = {"GOBY_INTERPROCESS": 'platform: "from_env" transport: TCP'}
    cfg = load_config(SampleAppConfig, [], prog="x", environ=env).cfg
    assert cfg.interprocess.platform == "from_env"
    assert cfg.interprocess.transport == InterProcessPortalConfig.TCP
    assert cfg.app.name == "x"
    path = _write(tmp_path, 'interprocess { platform: "file" }')
    assert load_config(SampleAppConfig, [path], environ=env).cfg.interprocess.platform == "file"


def test_glog_tty_verbosity_and_app_name_flag() -> None:
    loaded = load_config(SampleAppConfig, ["--app", "glog_config { tty_verbosity: DEBUG1 }", "-a", "named", "-n"],
                         environ={})
    assert loaded.verbosity == 2
    assert loaded.cfg.app.name == "named"


@pytest.mark.parametrize(
    "args, message",
    [
        (["--count", "many"], "--count"),
        (["--interprocess", "platfrm: 1"], "--interprocess"),
        (["/nonexistent/file.cfg"], "cannot read configuration file /nonexistent/file.cfg"),
    ],
)
def test_bad_config_is_a_named_error(args: list[str], message: str) -> None:
    with pytest.raises(AppConfigError, match=message):
        load_config(SampleAppConfig, args, environ={})


def test_bad_file_names_file_and_line(tmp_path: Path) -> None:
    path = _write(tmp_path, "app {\n  nmae: 1\n}\n")
    with pytest.raises(AppConfigError, match=r"app.pb.cfg: 2:"):
        load_config(SampleAppConfig, [path], environ={})


@pytest.mark.parametrize("text, line", [
    ("app {\n  name: \"x\"\n\ninterprocess { platform: \"p\" }\n\n", 1),  # the parser blames line 4
    ("app { name: \"{ #\" }\ninterprocess {  # a { in a comment\n  platform: \"p\"\n", 2),
])
def test_unclosed_brace_is_reported_where_it_opens(tmp_path: Path, text: str, line: int) -> None:
    path = _write(tmp_path, text)
    with pytest.raises(AppConfigError, match=rf"app.pb.cfg: line {line}: '{{' is never closed"):
        load_config(SampleAppConfig, [path], environ={})


@pytest.mark.parametrize("config_type", [SampleAppConfig, GobyDaemonConfig, GobyMOOSGatewayConfig])
def test_example_config_is_complete_and_parses_back(config_type: type) -> None:
    text = example_config(config_type)
    parsed = text_format.Parse(text, config_type())
    for field in config_type.DESCRIPTOR.fields:
        assert field.name in text
    assert "# (optional)" in text or "(optional)" in text
    assert parsed.app.HasField("name") is False and parsed.app.HasField("binary") is False
    assert not parsed.app.HasField("geodesy")  # a block with required fields stays commented
    if config_type is SampleAppConfig:
        assert list(parsed.group) == [] and "# group: " in text
    if config_type is GobyDaemonConfig:
        assert parsed.interprocess.platform == "default_goby_platform"
        assert "required_client" in text
        assert "# ip_address" in text  # second member of a oneof stays commented


def test_goby_broker_example_config_and_debug_cfg_cli() -> None:
    out = subprocess.run([sys.executable, "-m", "gateway.apps.goby_broker", "--example_config"],
                         capture_output=True, text=True, timeout=60)
    assert out.returncode == 0
    text_format.Parse(out.stdout, GobyDaemonConfig())
    out = subprocess.run([sys.executable, "-m", "gateway.apps.goby_broker", "--interprocess", 'platform: "p1"',
                          "--app", "debug_cfg: true"], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0
    assert text_format.Parse(out.stdout, GobyDaemonConfig()).interprocess.platform == "p1"
    out = subprocess.run([sys.executable, "-m", "gateway.apps.goby_broker", "--router_threads", "x"],
                         capture_output=True, text=True, timeout=60)
    assert out.returncode == 2
    assert "configuration error" in out.stderr and "--router_threads" in out.stderr


def test_goby_broker_reads_goby_interprocess() -> None:
    import os

    env = {**os.environ, "GOBY_INTERPROCESS": 'platform: "from_env" socket_name: "/tmp/x"'}
    out = subprocess.run([sys.executable, "-m", "gateway.apps.goby_broker", "--app", "debug_cfg: true"],
                         capture_output=True, text=True, timeout=60, env=env)
    assert out.returncode == 0, out.stderr
    cfg = text_format.Parse(out.stdout, GobyDaemonConfig())
    assert (cfg.interprocess.platform, cfg.interprocess.socket_name) == ("from_env", "/tmp/x")
