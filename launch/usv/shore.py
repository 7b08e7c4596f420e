"""``python -m launch.usv.shore CONFIG --schedule ...``: the shore operator, sending USV commands at set sim times.

Sim time starts when the vehicle is first under helm command (the frontseat interface reports
INTERFACE_COMMAND), so the plan does not depend on how long the processes took to start. Each command
is sent with ``usv-command`` (the same tool a person would use), whose configuration is this script's own
``interprocess`` block; its output goes to this script's log. The script stays up until stopped.

Schedule format: comma-separated ``T:waypoints`` or ``T:polygon:SIDES:RADIUS`` entries, T in sim seconds.
"""

from __future__ import annotations

import argparse
import logging
import os
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

from google.protobuf import text_format

from frontseat import groups as frontseat_groups
from frontseat.protobuf.frontseat_pb2 import INTERFACE_COMMAND, InterfaceStatus
from gateway.portal import SingleThreadApplication, run_application
from launch.errors import ConfigError
from launch.usv.settings import DEFAULT_SCHEDULE
from translators.usv.protobuf.usv_config_pb2 import CommandTool

log = logging.getLogger(__name__)
PROG = "usv-shore"


@dataclass(frozen=True)
class ScheduledCommand:
    """One planned command: when (sim seconds after COMMAND) and the usv-command arguments."""

    at: float
    args: tuple[str, ...]

    def describe(self) -> str:
        return " ".join(self.args)


def parse_schedule(text: str) -> list[ScheduledCommand]:
    """Parse ``0:polygon:6:200,500:waypoints``; ConfigError names the bad entry."""
    plan = []
    for item in (part.strip() for part in text.split(",")):
        if not item:
            continue
        fields = item.split(":")
        try:
            at = float(fields[0])
            kind = fields[1].lower()
            if kind == "waypoints" and len(fields) == 2:
                args: tuple[str, ...] = ("waypoints",)
            elif kind == "polygon" and len(fields) == 4:
                args = ("polygon", "--sides", str(int(fields[2])), "--radius", str(int(fields[3])))
            else:
                raise ValueError(item)
        except (ValueError, IndexError):
            raise ConfigError(
                f"bad schedule entry {item!r}: use T:waypoints or T:polygon:SIDES:RADIUS (T in sim seconds)"
            ) from None
        if at < 0:
            raise ConfigError(f"bad schedule entry {item!r}: time must be >= 0")
        plan.append(ScheduledCommand(at, args))
    return sorted(plan, key=lambda c: c.at)


class ShoreOperator(SingleThreadApplication):
    """Waits for INTERFACE_COMMAND, then runs ``usv-command`` for each entry when its sim time comes."""

    def __init__(self, cfg: CommandTool, plan: list[ScheduledCommand], tool_config: Path) -> None:
        super().__init__(cfg, loop_frequency_hz=2.0)
        self._plan = list(plan)
        self._tool_config = tool_config
        self._warp = max(1, cfg.app.simulation.time.warp_factor) if cfg.app.simulation.time.use_sim_time else 1
        self._t0: float | None = None
        self._running: subprocess.Popen[str] | None = None
        self._running_cmd: ScheduledCommand | None = None
        self.interprocess().subscribe(frontseat_groups.status, InterfaceStatus, self._on_status)
        print(f"shore: {len(plan)} commands planned: "
              + "; ".join(f"t={c.at:g} s {c.describe()}" for c in plan), flush=True)

    def _sim_elapsed(self) -> float:
        return 0.0 if self._t0 is None else (time.monotonic() - self._t0) * self._warp

    def _on_status(self, status: InterfaceStatus) -> None:
        """Start the plan's clock at the first INTERFACE_COMMAND. Runs on the main thread."""
        if self._t0 is None and status.state == INTERFACE_COMMAND:
            self._t0 = time.monotonic()
            print("shore: vehicle is under helm command; plan clock started", flush=True)

    def loop(self) -> None:
        """Reap a finished usv-command, start the next one when due. Runs on the main thread."""
        if self._running is not None:
            if self._running.poll() is None:
                return
            output = self._running.stdout.read() if self._running.stdout else ""
            verdict = "acknowledged" if self._running.returncode == 0 else f"FAILED ({self._running.returncode})"
            print(f"shore: t={self._sim_elapsed():.0f} s usv-command {self._running_cmd.describe()}: {verdict}\n"
                  + output.rstrip(), flush=True)
            if self._running.returncode != 0:
                log.error("usv-command %s failed with status %s", self._running_cmd.describe(),
                          self._running.returncode)
            self._running = None
        if self._t0 is None or not self._plan or self._plan[0].at > self._sim_elapsed():
            return
        command = self._plan.pop(0)
        tool = shutil.which("usv-command") or "usv-command"
        print(f"shore: t={self._sim_elapsed():.0f} s sending {command.describe()}", flush=True)
        self._running_cmd = command
        self._running = subprocess.Popen(
            [tool, *command.args, str(self._tool_config)],
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, stdin=subprocess.DEVNULL,
        )

    def finalize(self) -> None:
        if self._running is not None and self._running.poll() is None:
            self._running.terminate()
            try:
                self._running.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self._running.kill()
                self._running.wait()


def _tool_config_file(cfg: CommandTool) -> Path:
    """usv-command's config: our app/interprocess blocks under its own name, in the run directory."""
    tool = CommandTool()
    tool.CopyFrom(cfg)
    tool.app.name = "usv-command"
    directory = Path(os.environ.get("USV_RUN_DIR") or "/tmp")
    directory.mkdir(parents=True, exist_ok=True)
    path = directory / f"usv-command.{os.getpid()}.pb.cfg"
    path.write_text(text_format.MessageToString(tool))
    return path


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    parser = argparse.ArgumentParser(prog=PROG, description=__doc__.split("\n\n")[0])
    parser.add_argument("--schedule", default=os.environ.get("USV_SHORE_SCHEDULE") or DEFAULT_SCHEDULE,
                        help="T:waypoints / T:polygon:SIDES:RADIUS, comma-separated "
                        f"(default $USV_SHORE_SCHEDULE or {DEFAULT_SCHEDULE})")
    args, goby_argv = parser.parse_known_args(argv)
    try:
        plan = parse_schedule(args.schedule)
    except ConfigError as exc:
        print(f"{PROG}: {exc}", file=sys.stderr)
        return 2
    if not plan:
        print(f"{PROG}: empty schedule (--schedule or USV_SHORE_SCHEDULE)", file=sys.stderr)
        return 2
    tool_config: list[Path] = []

    def make_app(cfg: CommandTool) -> ShoreOperator:
        tool_config.append(_tool_config_file(cfg))
        return ShoreOperator(cfg, plan, tool_config[0])

    try:
        return run_application(make_app, CommandTool, goby_argv, prog=PROG)
    finally:
        for path in tool_config:
            path.unlink(missing_ok=True)


if __name__ == "__main__":
    sys.exit(main())
