"""Re-running a benchmark inside a private network namespace, for the C++ programs it runs beside ours.

The real MOOSDB, pHelmIvP and gobyd listen on every address, so a benchmark that starts them re-executes itself
under ``unshare -n`` (``-r`` when not root) and runs both sides in there: loopback up, with multicast and a route for
it (Goby's UDP multicast driver joins its group without naming an interface, which needs a multicast route a fresh
namespace lacks; ours names 127.0.0.1 and needs none). The route's source is 127.0.0.1: a socket bound to
0.0.0.0, as the real gobyd's link, would otherwise send from 0.0.0.0, which our links drop as no peer. The re-run gets ``--in-netns`` so it does not do it again.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from collections.abc import Callable, Mapping
from pathlib import Path

from bench.progress import progress
from gateway.moos.testing import private_netns

NETNS_FLAG = "--in-netns"
REPO = Path(__file__).resolve().parents[1]
SCRIPT = 'ip link set lo up multicast on && ip route add 224.0.0.0/4 dev lo src 127.0.0.1 && exec "$@"'


def reexec_in_netns(module: str, argv: list[str], skipped: str, why_needed: str,
                    env: Mapping[str, str] | None = None, say: Callable[[str], None] = progress) -> int | None:
    """Run ``python -m module *argv --in-netns`` inside a new private network namespace and return its exit status;
    None when no namespace can be made (then ``"(<skipped> skipped: <reason>)"`` is said and the caller runs ours
    alone). ``why_needed`` ends the line said before the re-run; ``env`` replaces the environment (this checkout is
    appended to its PYTHONPATH either way, so ``-m module`` is found from any directory)."""
    unshare = shutil.which("unshare")
    if unshare is None:
        say(f"({skipped} skipped: {why_needed} and `unshare` is missing)")
        return None
    user = [] if os.geteuid() == 0 else ["-r"]
    head = [unshare, *user, "-n", "bash", "-c", SCRIPT, module.rsplit(".", 1)[-1]]
    base = dict(os.environ if env is None else env)
    base["PYTHONPATH"] = os.pathsep.join(p for p in (base.get("PYTHONPATH"), str(REPO)) if p)
    probe = subprocess.run([*head, "true"], env=base, capture_output=True, text=True)
    if probe.returncode != 0:
        say(f"({skipped} skipped: no private network namespace: {probe.stderr.strip()[-200:]})")
        return None
    say(f"(running inside a private network namespace: {why_needed})")
    return subprocess.call([*head, sys.executable, "-m", module, *argv, NETNS_FLAG], env=base, cwd=REPO)


def cpp_side_here(why_missing: str | None, in_netns: bool, module: str, argv: list[str], skipped: str,
                  why_needed: str) -> tuple[bool, int | None]:
    """Where a benchmark's C++ side runs: ``(True, None)`` here (this is a private network namespace already),
    ``(False, status)`` once the whole benchmark has run again inside one (return that status), ``(False, None)``
    not at all (``why_missing``, or no namespace could be made: said, and the caller runs ours alone)."""
    if why_missing is not None:
        progress(f"({skipped} skipped: {why_missing})")
        return False, None
    if in_netns or private_netns():
        return True, None
    return False, reexec_in_netns(module, argv, skipped, why_needed)
