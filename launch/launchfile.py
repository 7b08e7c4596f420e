"""Parser for goby_launch launch files: one command per line with optional ``[directive, ...]`` prefixes.

The format follows goby3's ``scripts/goby_launch``: ``#`` starts a comment anywhere on a line, blank
lines are dropped, and a leading ``[...]`` holds directives separated by any of ``;``, ``,`` or space:
``kill=SIGTERM|SIGINT|SIGKILL|goby_terminate``, ``env=NAME=value`` (repeatable) and ``name=...``.  Without
``kill=`` the launcher chooses, as goby_launch: goby_terminate when the file has exactly one broker line, else SIGTERM.
The command itself is left untouched: it is run by bash, which does its own expansion and process
substitution. Parsing is pure: no process is started and no environment is read here.
"""

from __future__ import annotations

import os
import re
import signal
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

from launch.errors import LaunchFileError
from launch.textfile import read_text

KILL_SIGNALS = {
    "SIGTERM": signal.SIGTERM,
    "SIGINT": signal.SIGINT,
    "SIGKILL": signal.SIGKILL,
    # goby_terminate asks a Goby app over interprocess to quit (launch/process_group.py runs goby-terminate);
    # SIGTERM is what follows when it does not answer or does not quit.
    "goby_terminate": signal.SIGTERM,
}

_DIRECTIVES = re.compile(r"^\s*\[([^\]]*)\]")
_DIRECTIVE_SPLIT = re.compile(r"[;, ]+")
_ENV_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
_VAR = re.compile(r"\$\{([A-Za-z_][A-Za-z0-9_]*)(?::-([^}]*))?\}|\$([A-Za-z_][A-Za-z0-9_]*)")


@dataclass(frozen=True)
class LaunchEntry:
    """One launch line: the command for bash, its directives, and where it came from."""

    command: str
    env: tuple[tuple[str, str], ...] = ()
    kill: str = "SIGTERM"
    name: str | None = None
    kill_given: bool = False  # kill= was written: the launcher's default (goby_terminate or SIGTERM) does not apply
    line_number: int = 0
    source: str = "<string>"

    @property
    def binary(self) -> str:
        """The program's base name (the first word of the command), as goby_launch names screens."""
        first = self.command.split()[0] if self.command.split() else ""
        return os.path.basename(first)

    @property
    def kill_signal(self) -> signal.Signals:
        """The first signal sent at shutdown."""
        return KILL_SIGNALS[self.kill]

    def environment(self, base: Mapping[str, str]) -> dict[str, str]:
        """``base`` plus this line's ``env=`` directives, each expanded against what came before it."""
        env = dict(base)
        for key, value in self.env:
            env[key] = expand_vars(value, env)
        return env


@dataclass
class LaunchFile:
    """A parsed launch file: its entries in launch order."""

    entries: list[LaunchEntry] = field(default_factory=list)
    path: Path | None = None


def expand_vars(text: str, env: Mapping[str, str]) -> str:
    """Expand ``$NAME``, ``${NAME}`` and ``${NAME:-default}`` as bash would (unset names become "")."""

    def substitute(match: re.Match[str]) -> str:
        name = match.group(1) or match.group(3)
        value = env.get(name, "")
        if match.group(1) and match.group(2) is not None and not value:
            return expand_vars(match.group(2), env)
        return value

    return _VAR.sub(substitute, text)


def _parse_directives(text: str, where: str) -> tuple[list[tuple[str, str]], str | None, str | None]:
    env: list[tuple[str, str]] = []
    kill: str | None = None
    name: str | None = None
    for directive in _DIRECTIVE_SPLIT.split(text.strip()):
        if not directive:
            continue
        key, sep, value = directive.partition("=")
        if not sep:
            raise LaunchFileError(f"{where}: directive {directive!r} is not key=value")
        if key == "kill":
            if value not in KILL_SIGNALS:
                raise LaunchFileError(
                    f"{where}: invalid kill={value}: use goby_terminate, SIGTERM, SIGINT or SIGKILL"
                )
            kill = value
        elif key == "env":
            env_key, env_sep, env_value = value.partition("=")
            if not env_sep or not _ENV_NAME.match(env_key):
                raise LaunchFileError(f"{where}: env directive {value!r} is not NAME=value")
            env.append((env_key, env_value))
        elif key == "name":
            if not value or "/" in value:
                raise LaunchFileError(f"{where}: name={value!r} must be a non-empty word without '/'")
            name = value
        else:
            raise LaunchFileError(f"{where}: unknown directive key {key!r} (known: kill, env, name)")
    return env, kill, name


def parse_lines(lines: Iterable[str], source: str = "<string>") -> LaunchFile:
    """Parse launch-file lines; raise LaunchFileError naming the line for anything not understood."""
    result = LaunchFile()
    for number, raw in enumerate(lines, start=1):
        line = raw.split("#", 1)[0].rstrip("\r\n")
        if not line.strip():
            continue
        where = f"{source}:{number}"
        env: list[tuple[str, str]] = []
        kill: str | None = None
        name: str | None = None
        match = _DIRECTIVES.match(line)
        if match:
            env, kill, name = _parse_directives(match.group(1), where)
            line = line[match.end() :]
        elif line.lstrip().startswith("["):
            raise LaunchFileError(f"{where}: directive block '[' is not closed by ']'")
        command = line.strip()
        if not command:
            raise LaunchFileError(f"{where}: directives without a command")
        result.entries.append(
            LaunchEntry(
                command=command,
                env=tuple(env),
                kill=kill or "SIGTERM",
                name=name,
                kill_given=kill is not None,
                line_number=number,
                source=source,
            )
        )
    return result


def parse_file(path: str | Path) -> LaunchFile:
    """Read and parse a launch file; a missing or unreadable file is a LaunchFileError."""
    path = Path(path)
    text = read_text(path, LaunchFileError, "cannot read launch file {path}: {reason}")
    parsed = parse_lines(text.splitlines(), source=str(path))
    parsed.path = path
    if not parsed.entries:
        raise LaunchFileError(f"{path}: no commands to launch")
    return parsed
