"""The real Goby3 3.1 ``goby_frontseat_interface`` (basic simulator driver) and ``goby_basic_frontseat_simulator``
in the USV mission in place of ours, with our goby-broker, moos-db, ivp-helm and moos-gateway: the config our
launcher writes is accepted by the real interface, which reaches INTERFACE_COMMAND and the vehicle moves.
Skipped with the reason unless the binaries are on PATH inside a private network namespace (tests/goby3_real.py).

Command lines as Goby3 ships them: ``goby_basic_frontseat_simulator PORT`` (basic_frontseat_simulator.cpp), and
``goby_frontseat_interface CFG`` with ``FRONTSEAT_DRIVER_LIBRARY=libgoby_frontseat_basic_simulator.so.30`` (what
the generated ``goby_frontseat_interface_basic_simulator`` wrapper sets; frontseat_interface/CMakeLists.txt).
"""

from __future__ import annotations

import math
import os
import shutil
import sys
from pathlib import Path

import pytest
from google.protobuf import text_format

from frontseat import groups
from frontseat.protobuf.frontseat_data_pb2 import NodeStatus
from frontseat.protobuf.frontseat_pb2 import INTERFACE_COMMAND, InterfaceState, InterfaceStatus
from gateway.goby.portal.protobuf.gobyd_config_pb2 import GobyDaemonConfig
from gateway.goby.portal.testing import PortalClient, app_process
from launch.usv.config import generate
from launch.usv.settings import UsvSettings
from tests.goby3_real import GOBY_SOVERSION, real_goby_skip_reason, short_ipc_dir
from util.process import ChildProcess, free_port

pytestmark = pytest.mark.interop
BIN = Path(sys.executable).parent


def test_real_interface_and_simulator_reach_command_with_our_moos_side(tmp_path: Path) -> None:
    reason = real_goby_skip_reason("goby_basic_frontseat_simulator", "goby_frontseat_interface")
    if reason:
        pytest.skip(reason)
    ipc_dir = short_ipc_dir()
    settings = UsvSettings(run_dir=tmp_path / "run", warp=5, moos_port=free_port(), sim_port=free_port(),
                           socket_name=str(ipc_dir / "goby_usv"))
    configs = {app: tmp_path / f"{app}.pb.cfg" for app in ("broker", "frontseat_interface", "moos_gateway")}
    for app, path in configs.items():
        path.write_text(generate(app, settings))
    mission = generate("moos", settings)  # writes the .moos file, returns its path
    interprocess = text_format.Parse(configs["broker"].read_text(), GobyDaemonConfig()).interprocess
    # Goby's generated wrapper sets LD_LIBRARY_PATH and the driver library; without it, name the library ourselves
    wrapper = shutil.which("goby_frontseat_interface_basic_simulator")
    interface = [wrapper] if wrapper else ["goby_frontseat_interface"]
    fs_env = dict(os.environ, FRONTSEAT_DRIVER_LIBRARY=f"libgoby_frontseat_basic_simulator.so.{GOBY_SOVERSION}")
    gw_env = dict(os.environ, GOBY_MOOS_GATEWAY_PLUGINS="translators.usv.command_translation")
    commands = [
        (["goby_basic_frontseat_simulator", str(settings.sim_port)], None),
        ([str(BIN / "goby-broker"), str(configs["broker"])], None),
        ([str(BIN / "moos-db"), mission], None),
        ([str(BIN / "ivp-helm"), mission], None),
        ([*interface, str(configs["frontseat_interface"])], fs_env),
        ([str(BIN / "moos-gateway"), str(configs["moos_gateway"])], gw_env),
    ]
    procs: list[ChildProcess] = []
    try:
        for index, (args, env) in enumerate(commands):
            procs.append(app_process(args, env=env, log_path=tmp_path / f"{index}-{Path(args[0]).name}.log"))
        with PortalClient(interprocess, "interop_observer") as observer:
            status = observer.collect(groups.status, InterfaceStatus)
            nav = observer.collect(groups.node_status, NodeStatus)
            assert observer.wait_subscribed(60)
            logs = lambda: "\n".join(f"{p.name}: {p.read_text()[-2000:]}" for p in sorted(tmp_path.glob("*.log")))  # noqa: E731
            reached = observer.poll_until(lambda: any(s.state == INTERFACE_COMMAND for s in status), 120)
            assert reached, f"states {[InterfaceState.Name(s.state) for s in status]}\n{logs()}"
            start = len(nav)
            assert observer.poll_until(lambda: len(nav) > start + 5, 60), logs()
            first = nav[start]

            def moved() -> float:
                return math.hypot(nav[-1].local_fix.x - first.local_fix.x, nav[-1].local_fix.y - first.local_fix.y)

            assert observer.poll_until(lambda: moved() > 10.0, 60), f"moved {moved():.1f} m\n{logs()}"
        for proc in procs:
            assert proc.running, f"{proc.args[0]} exited\n{logs()}"
    finally:
        for proc in reversed(procs):
            proc.stop()
        shutil.rmtree(ipc_dir, ignore_errors=True)
