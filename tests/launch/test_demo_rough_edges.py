"""The demos' rough edges of issue 29: the documented `make demo` commands parse as the Makefile runs them,
the demos' --help works without the optional [demo] extra (and a run without it says which extra in one line),
and the trail demo's progress line shows each vehicle's real state (RECOVER), not the interface's COMMAND."""

from __future__ import annotations

import importlib
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from launch.record import MissionRecord

ROOT = Path(__file__).resolve().parents[2]
DOC = ROOT / "docs" / "launch.md"
MAKE_DEMO = re.compile(r"make demo(?:[ \t]+(?:[A-Z_]+=(?:\"[^\"]*\"|[^\s`,;)]+)))*")


def default_mission() -> str:
    """The Makefile's ``MISSION ?= ...``: what plain ``make demo`` runs."""
    found = re.search(r"^MISSION \?= (\w+)$", (ROOT / "Makefile").read_text(), re.MULTILINE)
    assert found, "the Makefile has no MISSION default"
    return found.group(1)


def documented_commands() -> list[tuple[str, str, list[str]]]:
    """Every ``make demo VAR=...`` of docs/launch.md as (text, mission module, DEMO_ARGS split as make passes them)."""
    out = []
    for match in MAKE_DEMO.finditer(DOC.read_text()):
        variables = dict(word.split("=", 1) for word in shlex.split(match.group(0))[2:])
        out.append((match.group(0), variables.get("MISSION", default_mission()),
                    shlex.split(variables.get("DEMO_ARGS", ""))))
    return out


def test_every_documented_make_demo_command_parses_for_the_mission_it_runs() -> None:
    commands = documented_commands()
    assert len(commands) >= 8 and {mission for _, mission, _ in commands} == {"trail", "usv"}
    for text, mission, args in commands:
        parser = importlib.import_module(f"launch.{mission}.demo").build_parser()
        try:
            parser.parse_args(args)
        except SystemExit:
            pytest.fail(f"docs/launch.md: `{text}` runs launch.{mission}.demo, which refuses {args}")


def test_the_documented_duration_and_warp_are_the_defaults_of_the_mission_named() -> None:
    text = " ".join(DOC.read_text().split())
    claims = re.findall(r"`(make demo[^`]*)` runs (\d+) simulated seconds at warp (\d+)", text)
    assert claims, "docs/launch.md no longer says what the USV demo runs by default"
    for command, seconds, warp in claims:
        variables = dict(word.split("=", 1) for word in shlex.split(command)[2:])
        mission = variables.get("MISSION", default_mission())
        args = importlib.import_module(f"launch.{mission}.demo").build_parser().parse_args([])
        assert (args.duration, args.warp) == (float(seconds), int(warp)), f"`{command}` runs launch.{mission}.demo"


@pytest.fixture
def without_matplotlib(tmp_path: Path) -> dict[str, str]:
    """An environment in which ``import matplotlib`` fails as it does when the [demo] extra is not installed."""
    blocker = tmp_path / "blocker"
    blocker.mkdir()
    (blocker / "matplotlib.py").write_text("raise ModuleNotFoundError(\"No module named 'matplotlib'\", "
                                           "name='matplotlib')\n")
    return {"PYTHONPATH": f"{blocker}:{ROOT}", "PATH": "/usr/bin:/bin", "HOME": str(tmp_path)}


@pytest.mark.parametrize("demo", ["launch.usv.demo", "launch.trail.demo"])
def test_demo_help_works_without_the_demo_extra(without_matplotlib: dict[str, str], demo: str) -> None:
    done = subprocess.run([sys.executable, "-m", demo, "--help"], cwd=ROOT, env=without_matplotlib,
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith(f"usage: python -m {demo}") and "--schedule" in done.stdout
    assert done.stderr == ""


@pytest.mark.parametrize("demo", ["launch.usv.demo", "launch.trail.demo"])
def test_demo_without_the_demo_extra_says_so_in_one_line_before_starting(without_matplotlib: dict[str, str],
                                                                           tmp_path: Path, demo: str) -> None:
    out = tmp_path / "out"
    done = subprocess.run([sys.executable, "-m", demo, "--out", str(out), "--duration", "5"], cwd=ROOT,
                          env=without_matplotlib, capture_output=True, text=True, timeout=60)
    assert done.returncode == 1
    assert "Traceback" not in done.stderr
    (line,) = done.stderr.splitlines()
    assert "matplotlib" in line and "[demo]" in line and "pip install -e '.[demo]'" in line, line
    assert not out.exists()  # refused before any process or run directory


def record(interface: list[str], deploy_var: str, deploy: list[str]) -> MissionRecord:
    out = MissionRecord()
    for t, state in enumerate(interface):
        out.add_event(t, "interface", "interface_state", state)
    for t, state in enumerate(deploy):
        out.add_event(10 + t, "moos", deploy_var, state)
    out.add_nav(11, "NAV_X", 12.0)
    out.add_nav(11, "NAV_Y", -3.0)
    return out


def test_progress_line_shows_recover_not_the_interface_state() -> None:
    from launch.trail.summary import progress_line

    records = {
        "topside": MissionRecord(),
        "usv": record(["INTERFACE_STANDBY", "INTERFACE_COMMAND"], "DEPLOY_STATE", ["POLYGON", "WAYPOINTS"]),
        "auv0": record(["INTERFACE_STANDBY", "INTERFACE_COMMAND"], "AUV_DEPLOY_STATE", ["TRAIL", "RECOVER"]),
        "auv1": record(["INTERFACE_STANDBY"], "AUV_DEPLOY_STATE", []),  # not yet under helm command
    }
    line = progress_line(records, 900.0, 1200.0)
    assert line.startswith("t=   900/1200 s | ")
    assert "usv WAYPOINTS (12,-3)" in line and "auv0 RECOVER (12,-3)" in line and "auv1 STANDBY (12,-3)" in line
    assert "COMM" not in line and "topside" not in line
