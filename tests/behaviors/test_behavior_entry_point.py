"""A third party adds a ``BHV_`` type without touching this repository: a package declaring an entry point in
group ``ivp_helm.behaviors`` is pip-installed (``pulse_distribution/``, offline, into a directory of its own)
and the real ``ivp-helm`` process, given that directory on its path, runs a ``.bhv`` that uses the type."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

from behaviors.helm.registry import BEHAVIOR_POINT, behavior_class
from behaviors.helm.testing import helm_from_text
from gateway.moos import MoosClock
from gateway.moos.testing import running_moosdb

from .moos_harness import WARP, bhv_block, helm_process, observer, write_mission

DISTRIBUTION = Path(__file__).with_name("pulse_distribution")
PULSE_BHV = bhv_block("Pulse", name="pulse", speed=1.25) + bhv_block("ConstantHeading", name="steer", heading=45)
WATCH = ["PULSE_COUNT", "DESIRED_SPEED", "DESIRED_HEADING", "IVPHELM_STATE", "BHV_ERROR"]


def install_distribution(tmp_path: Path) -> Path:
    """``pip install`` the test distribution into ``tmp_path/site`` (built from a copy: the build writes files)."""
    source = tmp_path / "pulse_src"
    shutil.copytree(DISTRIBUTION, source, ignore=shutil.ignore_patterns("build", "*.egg-info", "__pycache__"))
    site = tmp_path / "site"
    subprocess.run([sys.executable, "-m", "pip", "install", "--quiet", "--no-deps", "--no-build-isolation",
                    "--no-index", "--target", str(site), str(source)], check=True, capture_output=True, timeout=120)
    return site


def test_an_installed_behaviour_runs_in_ivp_helm(tmp_path: Path) -> None:
    site = install_distribution(tmp_path)
    assert (next(site.glob("ivp_helm_pulse-*.dist-info")) / "entry_points.txt").read_text().count("BHV_Pulse") == 1
    bhv = tmp_path / "pulse.bhv"
    bhv.write_text(PULSE_BHV)
    clock = MoosClock(WARP)
    with running_moosdb("alpha", warp=WARP) as db, observer(db.port, clock, WATCH) as obs:
        mission = write_mission(tmp_path, db.port, bhv)
        with helm_process(mission, tmp_path, env={"PYTHONPATH": str(site)}) as proc:
            log = tmp_path / "helm.log"
            assert obs.wait(lambda: obs.last("IVPHELM_STATE") == "PARK"), log.read_text()
            for var, value in (("NAV_X", 0.0), ("NAV_Y", 0.0), ("NAV_HEADING", 0.0), ("NAV_SPEED", 0.0)):
                obs.post(var, value)
            obs.post("MOOS_MANUAL_OVERRIDE", "false")
            assert obs.wait(lambda: obs.last("IVPHELM_STATE") == "DRIVE"), log.read_text()
            # the third-party behaviour's own postings, and its objective function deciding the speed
            assert obs.wait(lambda: (obs.last("PULSE_COUNT") or 0) >= 3), obs.mail[-20:]
            assert obs.wait(lambda: obs.last("DESIRED_SPEED") == 1.25), obs.mail[-20:]
            assert obs.last("DESIRED_HEADING") == 45.0
            assert obs.values("BHV_ERROR") == []
            assert proc.poll() is None
    counts = obs.values("PULSE_COUNT")
    assert counts == sorted(counts) and counts[0] == 1.0


def test_without_the_distribution_the_type_is_unknown_and_the_helm_says_where(tmp_path: Path) -> None:
    """In this process the package is not installed: the same .bhv puts the helm in MALCONFIG, naming the file,
    the line and the type."""
    assert behavior_class("BHV_Pulse") is None and BEHAVIOR_POINT.entry_point("BHV_Pulse") is None
    helm = helm_from_text(PULSE_BHV, directory=tmp_path)
    assert helm.state == "MALCONFIG"
    assert helm.problems == [f"{tmp_path / 'test.bhv'}:1: unknown behaviour type (not built in, and no entry point "
                             "of that name in group ivp_helm.behaviors) (at 'BHV_Pulse')"]


def test_a_bad_behaviour_entry_point_is_refused_with_its_cause(tmp_path: Path, monkeypatch) -> None:
    """Entry points that do not name a Behavior of their own type: MALCONFIG, naming the entry point and why."""
    dist = tmp_path / "bad_behaviours-1.0.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: bad-behaviours\nVersion: 1.0\n")
    (dist / "entry_points.txt").write_text("[ivp_helm.behaviors]\nBHV_NotABehavior = json:JSONDecoder\n"
                                           "BHV_Renamed = pulse_behavior:PulseBehavior\n"
                                           "BHV_Missing = no_such_behaviour_module_xyz:Thing\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.syspath_prepend(str(DISTRIBUTION))  # pulse_behavior importable, its own entry point not installed
    causes = {
        "BHV_NotABehavior": "the entry point names <class 'json.decoder.JSONDecoder'>, not a Behavior subclass",
        "BHV_Renamed": "the entry point names PulseBehavior, whose TYPE is 'BHV_Pulse'",
        "BHV_Missing": "entry point BHV_Missing = no_such_behaviour_module_xyz:Thing: ModuleNotFoundError",
    }
    try:
        for type_name, cause in causes.items():
            helm = helm_from_text(f"Behavior = {type_name}\n{{\n  name = b\n}}\n", directory=tmp_path)
            assert helm.state == "MALCONFIG"
            assert f"test.bhv:1: Failed to open helm behaviour: {type_name}, reason: {cause}" in helm.problems[0]
    finally:
        sys.modules.pop("pulse_behavior", None)
