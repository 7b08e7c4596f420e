"""Helpers for tests in any area that run a helm: one ``.moos`` mission file for ``ivp-helm`` or ``pHelmIvP``.

The tests of the behaviors, the translators' live tests and the comparisons with the real pHelmIvP all write
their mission through :func:`write_helm_mission`, so the MOOS globals and the pHelmIvP block are written once.
"""

from __future__ import annotations

from pathlib import Path

ORIGIN = (43.8253, -70.3304)  # s1_alpha's LatOrigin/LongOrigin (the course's and MOOS-IvP's examples)

_MISSION = """\
ServerHost = 127.0.0.1
ServerPort = {port}
Community  = {community}
MOOSTimeWarp = {warp:g}
LatOrigin  = {lat}
LongOrigin = {lon}

ProcessConfig = pHelmIvP
{{
  AppTick    = {app_tick:g}
  CommsTick  = 4
  bhv_dir_not_found_ok = true
  behaviors  = {bhv}
  domain     = course:0:359:360
  domain     = speed:0:{max_speed}:41
{extra}}}
{blocks}"""


def write_helm_mission(directory: Path, port: int, bhv: Path, *, warp: float = 1.0, community: str = "alpha",
                       max_speed: str = "2", extra: str = "", app_tick: float = 4, blocks: str = "",
                       origin: tuple[float, float] = ORIGIN, name: str = "mission.moos") -> Path:
    """Write ``directory/name``: the MOOS globals and a pHelmIvP block running ``bhv``.

    ``extra`` lines go into the pHelmIvP block, ``blocks`` (other ProcessConfigs) after it.
    """
    path = directory / name
    path.write_text(_MISSION.format(port=port, community=community, warp=warp, lat=origin[0], lon=origin[1],
                                    app_tick=app_tick, bhv=bhv, max_speed=max_speed, extra=extra, blocks=blocks))
    return path
