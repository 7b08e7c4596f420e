"""Health and terminate with the real Goby3 3.1 tools on our goby-broker: the real ``goby_coroner`` reports our
applications ``HEALTH__OK`` and a killed one as died; the real ``goby_terminate`` stops our application.  Skipped
with the reason unless the binaries are on PATH inside a private network namespace (tests/goby3_real.py)."""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

import pytest

from gateway.goby.portal.health import HEALTH_REPORT
from gateway.goby.portal.protobuf.coroner_pb2 import HEALTH__OK, VehicleHealth
from gateway.goby.portal.testing import BrokerProcess, PortalClient, app_process
from tests.goby3_real import interprocess_text, real_goby_skip_reason, short_ipc_dir

pytestmark = pytest.mark.interop
APP = [sys.executable, "-m", "tests.health.apps.health_app"]


def test_real_coroner_and_terminate_on_our_broker(tmp_path: Path) -> None:
    reason = real_goby_skip_reason("goby_coroner", "goby_terminate")
    if reason:
        pytest.skip(reason)
    ipc_dir = short_ipc_dir()
    broker = BrokerProcess(ipc_dir, platform="interop", log_path=tmp_path / "broker.log").start()
    ipc = interprocess_text(broker.interprocess_config())
    apps = [app_process([*APP, f"--role={role}", "--app", f'name: "{name}"'], tmp_path / f"{name}.log",
                        env=broker.env()) for role, name in (("single", "ours1"), ("threads", "ours2"))]
    coroner_cfg = tmp_path / "coroner.pb.cfg"
    coroner_cfg.write_text(f'interprocess {{ {ipc} }}\nexpected_name: "ours1"\nexpected_name: "ours2"\n'
                           "request_interval: 2\nresponse_timeout: 1\n")
    coroner = app_process(["goby_coroner", str(coroner_cfg)], tmp_path / "goby_coroner.log")
    try:
        for app in apps:
            app.wait_ready("READY")
        with PortalClient(broker.interprocess_config()) as client:
            reports = client.collect(HEALTH_REPORT, VehicleHealth)
            assert client.wait_subscribed()

            def states() -> dict[str, int]:
                return {p.name: p.main.state for p in reports[-1].process} if reports else {}

            assert client.poll_until(lambda: states() == {"ours1": HEALTH__OK, "ours2": HEALTH__OK}, 30), states()
            children = {c.name for p in reports[-1].process for c in p.main.child}
            assert children == {"__main__.Worker", "__main__.Hanger"}
            apps[0].kill()
            assert client.poll_until(lambda: states().get("ours1", HEALTH__OK) != HEALTH__OK, 30)
            assert reports[-1].process[0].main.error_message == "Process ours1 has died"
        terminate_cfg = tmp_path / "terminate.pb.cfg"
        terminate_cfg.write_text(f"interprocess {{ {ipc} }}\n")
        terminate = app_process(["goby_terminate", str(terminate_cfg), "--target_name", "ours2"],
                                tmp_path / "goby_terminate.log")
        assert apps[1].wait(60) == 0  # reaped here: goby_terminate sees a process end by kill(pid, 0), not a zombie
        assert terminate.wait(60) == 0, terminate.tail()
    finally:
        coroner.stop()
        for app in apps:
            app.stop()
        broker.close()
        shutil.rmtree(ipc_dir, ignore_errors=True)
