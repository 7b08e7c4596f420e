"""The frontseat-interface command line without a driver: --help and --example_config, as real processes."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from google.protobuf import text_format

BIN = Path(sys.executable).parent
EXTENSION = "[goby.middleware.frontseat.protobuf.basic_simulator_config]"


def run(args: list[str], tmp_path: Path, **env: str) -> subprocess.CompletedProcess[str]:
    environ = {k: v for k, v in os.environ.items() if k != "FRONTSEAT_DRIVER_LIBRARY"}
    environ.update(env)
    return subprocess.run(args, capture_output=True, text=True, timeout=60, cwd=tmp_path, env=environ)


@pytest.mark.parametrize("flag", ["--help", "-h"])
def test_help_needs_no_driver_and_loads_none(tmp_path: Path, flag: str) -> None:
    done = run([str(BIN / "frontseat-interface"), flag], tmp_path)
    assert done.returncode == 0, done.stderr
    assert "usage: frontseat-interface" in done.stdout
    assert "FRONTSEAT_DRIVER_LIBRARY" in done.stdout and "frontseat-interface-basic-simulator" in done.stdout
    assert "Loading frontseat driver library" not in done.stdout + done.stderr
    # with the variable set (even to a driver that does not exist) --help still loads nothing
    done = run([str(BIN / "frontseat-interface"), flag], tmp_path, FRONTSEAT_DRIVER_LIBRARY="no_such_driver")
    assert done.returncode == 0 and "Loading" not in done.stderr and "no_such_driver" not in done.stderr


def test_example_config_without_a_driver_shows_the_basic_simulator_block(tmp_path: Path) -> None:
    from frontseat.protobuf import basic_simulator_config_pb2 as sim_pb
    from frontseat.protobuf import basic_simulator_tuning_pb2 as tuning_pb
    from frontseat.protobuf import frontseat_interface_config_pb2 as app_pb

    for flag in ("--example_config", "-e"):
        done = run([str(BIN / "frontseat-interface"), flag], tmp_path)
        assert done.returncode == 0, done.stderr
        assert "Loading frontseat driver library" not in done.stderr
        assert done.stdout.startswith("# FRONTSEAT_DRIVER_LIBRARY is unset")
        assert EXTENSION in done.stdout
        cfg = text_format.Parse(done.stdout, app_pb.FrontSeatInterfaceConfig())
        assert cfg.frontseat_cfg.HasExtension(sim_pb.basic_simulator_config)
        # our driver's own settings are shown commented out: the example stays a config Goby3 accepts
        assert "# [goby_moos_py.frontseat.protobuf.basic_simulator_tuning] {" in done.stdout
        assert not cfg.frontseat_cfg.HasExtension(tuning_pb.basic_simulator_tuning)


def test_example_config_with_a_driver_uses_that_driver(tmp_path: Path) -> None:
    driver = tmp_path / "plain_driver.py"
    driver.write_text("def frontseat_driver_load(cfg):\n    raise RuntimeError('not for examples')\n")
    done = run([str(BIN / "frontseat-interface"), "--example_config"], tmp_path, FRONTSEAT_DRIVER_LIBRARY=str(driver))
    assert done.returncode == 0, done.stderr
    assert EXTENSION not in done.stdout and "is unset" not in done.stdout  # this driver declares no extension
    done = run([str(BIN / "frontseat-interface"), "-e"], tmp_path, FRONTSEAT_DRIVER_LIBRARY="no_such_driver")
    assert done.returncode == 1 and "no_such_driver" in done.stderr


def test_running_without_the_variable_still_fails_with_exit_1(tmp_path: Path) -> None:
    done = run([str(BIN / "frontseat-interface"), "x.cfg"], tmp_path)
    assert done.returncode == 1 and "FRONTSEAT_DRIVER_LIBRARY must be set" in done.stderr


def test_basic_simulator_console_script(tmp_path: Path) -> None:
    script = BIN / "frontseat-interface-basic-simulator"
    assert script.exists(), "run `pip install -e .` so the console script declared in pyproject.toml exists"
    done = run([str(script), "--example_config"], tmp_path)
    assert done.returncode == 0, done.stderr
    assert "Loading frontseat driver library: basic_simulator" in done.stderr
    assert EXTENSION in done.stdout and "is unset" not in done.stdout
    done = run([str(script), "--help"], tmp_path)
    assert done.returncode == 0 and "usage:" in done.stdout
