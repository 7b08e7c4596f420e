"""The quick-start example in docs/portal.md runs as written."""

from __future__ import annotations

import os
import re
import sys
from pathlib import Path

from gateway.goby.portal.testing import BrokerProcess, app_process

REPO = Path(__file__).resolve().parents[2]


def test_quick_start_example_runs(broker: BrokerProcess, tmp_path: Path) -> None:
    text = (REPO / "docs" / "portal.md").read_text()
    code = re.search(r"## Quick start\n\n```python\n(.*?)```", text, re.S)
    assert code is not None
    script = tmp_path / "talker.py"
    script.write_text(code.group(1))
    cmd = [sys.executable, str(script), "--interprocess", broker.interprocess_text(), "--count", "3", "-v"]
    env = {**os.environ, "PYTHONPATH": str(REPO)}  # the example's messages are the test suite's (tests/protobuf)
    with app_process(cmd, env=env, cwd=REPO, log_path=tmp_path / "talker.log") as talker:
        assert talker.wait(60) == 0, talker.stderr_text()
    assert talker.lines()[:3] == ["got a=1", "got a=2", "got a=3"]
