"""Helpers for the interop tests against a real Goby3 (3.1.x, built by hand: DCCL 4 with its apps, Goby3 with the
zeromq middleware, the frontseat interface and MOOS). They run only when the binaries are on PATH *and* the test
process is inside a private network namespace whose only interface is loopback (as the MOOS-IvP interop tests:
``unshare -rn sh -c 'ip link set lo up && exec .venv/bin/python -m pytest -m interop ...'`` or ``netns-run``),
because the real simulator listens on every address; otherwise they skip with the reason.
"""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

from google.protobuf import text_format

from gateway.goby.protobuf.interprocess_config_pb2 import InterProcessPortalConfig
from gateway.moos.testing import private_netns

GOBY_SOVERSION = "30"  # Goby3 3.x's GOBY_SOVERSION (CMakeLists.txt): libgoby_frontseat_basic_simulator.so.30


def real_goby_skip_reason(*binaries: str) -> str | None:
    """Why the real Goby3 ``binaries`` cannot be used here, or None when they can."""
    for binary in binaries:
        if shutil.which(binary) is None:
            return f"the real Goby3 {binary} is not on PATH (build Goby3 3.1 by hand; see tests/goby3_real.py)"
    if not private_netns():
        return "real Goby3 servers listen on all addresses: run inside a private network namespace (unshare -n, lo up)"
    return None


def short_ipc_dir() -> Path:
    """A directory short enough for AF_UNIX socket paths (Goby appends to ``socket_name``)."""
    return Path(tempfile.mkdtemp(prefix="gb", dir="/tmp"))


def interprocess_text(cfg: InterProcessPortalConfig) -> str:
    """The one-line text format Goby's ``--interprocess`` option and ``interprocess { }`` blocks take."""
    return text_format.MessageToString(cfg, as_one_line=True)
