"""Issue #23 item 5: point counts in a .bhv (``radial:: pts=``, waypoint lists, domains) are bounded and a
binary .bhv file is a configuration error naming the file: the helm goes to MALCONFIG, it neither grows by
gigabytes nor dies with a traceback."""

from __future__ import annotations

from pathlib import Path

import pytest

from behaviors.helm.ivp import MAX_DOMAIN_POINTS
from behaviors.helm.point_strings import MAX_POINTS
from behaviors.helm.testing import helm_from_text
from gateway.moos import MoosClock
from gateway.moos.testing import running_moosdb

from .moos_harness import WARP, helm_process, observer, write_mission

HUGE_RADIAL = "radial:: x=0,y=-75,radius=40,pts=100000000"


def _rss_mib(pid: int) -> float:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    raise AssertionError("no VmRSS")


def test_ivp_helm_with_a_huge_radial_polygon_is_malconfig_and_stays_small(tmp_path: Path) -> None:
    """The attack as reported: ``pts=100000000`` grew ivp-helm by 6.7 GiB."""
    bhv = tmp_path / "huge.bhv"
    bhv.write_text(f"Behavior = BHV_Loiter\n{{\n  name = loiter\n  polygon = {HUGE_RADIAL}\n}}\n")
    clock = MoosClock(WARP)
    with running_moosdb("alpha", warp=WARP) as db, observer(db.port, clock, ["IVPHELM_STATE",
                                                                            "IVPHELM_CONFIG_WARNING"]) as obs:
        with helm_process(write_mission(tmp_path, db.port, bhv), tmp_path) as helm:
            assert obs.wait(lambda: obs.values("IVPHELM_STATE")[-2:] == ["MALCONFIG"] * 2, timeout=60)
            warning = str(obs.last("IVPHELM_CONFIG_WARNING"))
            assert warning.startswith(f"{bhv}:4: ") and f"3 <= pts <= {MAX_POINTS}" in warning
            assert _rss_mib(helm.pid) < 300
            assert helm.running


@pytest.mark.parametrize("param, value, reason", [
    ("polygon", HUGE_RADIAL, f"3 <= pts <= {MAX_POINTS}"),
    ("polygon", "radial: 0, -75, 40, 1e400", "pts=inf"),
    ("polygon", "format=radial, x=0, y=0, radius=1e400, pts=8", "radius=inf"),
])
def test_bad_loiter_polygons_are_malconfig(param: str, value: str, reason: str) -> None:
    helm = helm_from_text(f"Behavior = BHV_Loiter\n{{\n  name = l\n  {param} = {value}\n}}\n")
    assert helm.state == "MALCONFIG"
    assert reason in helm.problems[0] and ":4: " in helm.problems[0]


def test_a_waypoint_list_over_the_bound_is_malconfig() -> None:
    points = ":".join(f"{i},0" for i in range(MAX_POINTS + 1))
    helm = helm_from_text(f"Behavior = BHV_Waypoint\n{{\n  name = w\n  points = {points}\n}}\n")
    assert helm.state == "MALCONFIG" and f"at most {MAX_POINTS}" in helm.problems[0]
    at_bound = ":".join(f"{i},0" for i in range(MAX_POINTS))
    assert helm_from_text(f"Behavior = BHV_Waypoint\n{{\n  name = w\n  points = {at_bound}\n}}\n").state != "MALCONFIG"


@pytest.mark.parametrize("domain, reason", [
    ("course:0:359:1e9", f"at most {MAX_DOMAIN_POINTS}"),
    ("speed:0:4:delta=1e-300", f"at most {MAX_DOMAIN_POINTS}"),
    ("speed:0:4:1e400", "npts must be a whole number"),
    ("speed:0:1e400:5", "must be finite"),
])
def test_a_domain_over_the_bound_is_malconfig(domain: str, reason: str) -> None:
    helm = helm_from_text("", domains=(domain,))
    assert helm.state == "MALCONFIG"
    assert any(reason in p and domain in p for p in helm.problems), helm.problems


@pytest.mark.parametrize("content, where", [
    (b"Behavior = BHV_Loiter\n{\n\x9f\x92\x96\xff\n}\n", ":3: not a UTF-8 text behaviour file"),
    (b"Behavior = BHV_Loiter\n\x00\x01\x02\n", ":2: not a text behaviour file"),
])
def test_a_binary_bhv_file_is_malconfig_naming_the_file(tmp_path: Path, content: bytes, where: str) -> None:
    from behaviors.helm.config import HelmConfig
    from behaviors.helm.helm import Helm

    path = tmp_path / "binary.bhv"
    path.write_bytes(content)
    helm = Helm(HelmConfig.from_pairs([("behaviors", str(path)), ("domain", "course:0:359:360")], "m.moos"))
    assert helm.state == "MALCONFIG"
    assert helm.problems[0].startswith(f"{path}{where}")


def test_ivp_helm_with_a_binary_bhv_file_is_malconfig_not_a_traceback(tmp_path: Path) -> None:
    bhv = tmp_path / "binary.bhv"
    bhv.write_bytes(bytes(range(256)) * 4)
    clock = MoosClock(WARP)
    with running_moosdb("alpha", warp=WARP) as db, observer(db.port, clock, ["IVPHELM_STATE",
                                                                            "IVPHELM_CONFIG_WARNING"]) as obs:
        with helm_process(write_mission(tmp_path, db.port, bhv), tmp_path) as helm:
            assert obs.wait(lambda: obs.values("IVPHELM_STATE")[-2:] == ["MALCONFIG"] * 2, timeout=60)
            assert str(obs.last("IVPHELM_CONFIG_WARNING")).startswith(f"{bhv}:2: not a UTF-8 text behaviour file")
            assert "Traceback" not in helm.output()
