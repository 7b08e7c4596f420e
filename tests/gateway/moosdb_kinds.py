"""Our moos-db or the real C++ MOOSDB as a child process, with the same start/restart/stop interface.

The real MOOSDB listens on every address, so it is used only inside a private network namespace
(``/opt/moos/bin/netns-run``) with it on PATH; otherwise ``real_moosdb_skip_reason`` says why not.
"""

from __future__ import annotations

import contextlib
import subprocess
import time
from collections.abc import Iterator
from pathlib import Path

from gateway.moos.testing import free_port, moosdb_process, port_open, real_moos_skip_reason


def real_moosdb_skip_reason() -> str | None:
    return real_moos_skip_reason("MOOSDB")


class RealMoosDB:
    """The C++ MOOSDB on a fixed free port; ``restart`` kills it (as a crash) and starts it on the same port."""

    def __init__(self, workdir: Path) -> None:
        self.workdir = workdir
        self.port = free_port()
        self.proc: subprocess.Popen[bytes] | None = None

    def start(self, timeout: float = 20.0) -> RealMoosDB:
        with open(self.workdir / "MOOSDB.out", "ab") as out:
            self.proc = subprocess.Popen(["MOOSDB", f"--moos_port={self.port}", "--moos_suicide_disable"],
                                         stdout=out, stderr=subprocess.STDOUT, cwd=self.workdir)
        deadline = time.monotonic() + timeout
        while not port_open(self.port):
            if self.proc.poll() is not None or time.monotonic() > deadline:
                self.stop()
                raise RuntimeError(f"MOOSDB did not start: {(self.workdir / 'MOOSDB.out').read_text()}")
            time.sleep(0.05)
        return self

    def stop(self) -> None:
        if self.proc is not None and self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(5)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(5)

    def restart(self) -> RealMoosDB:
        if self.proc is not None and self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait(5)
        return self.start()


@contextlib.contextmanager
def any_moosdb(kind: str, workdir: Path) -> Iterator[object]:
    """``kind`` "ours" (moos-db) or "real" (C++ MOOSDB); yields an object with ``port`` and ``restart()``."""
    if kind == "ours":
        with moosdb_process(workdir) as db:
            yield db
        return
    db = RealMoosDB(workdir).start()
    try:
        yield db
    finally:
        db.stop()
