"""Config generation helpers shared by missions, in the manner of the Goby3 course's ``config/goby/config.py``.

A mission's ``config`` module prints one application's configuration to stdout for a launch line
(``app <(python -m launch.usv.config app)``); every value comes from one settings object, so the
processes cannot disagree about warp, origin or ports.
"""

from __future__ import annotations

import dataclasses
import os
import string
import sys
from collections.abc import Callable, Iterable, Mapping
from pathlib import Path
from typing import Any, ClassVar, TypeVar

from launch.errors import MissionConfigError
from launch.textfile import read_text

T = TypeVar("T")
S = TypeVar("S", bound="EnvSettings")

INVALID_BANNER = "=============== INVALID CONFIGURATION ================="
# Templates both missions render (app/interprocess blocks, broker, frontseat interface, gateway).
SHARED_TEMPLATES = Path(__file__).resolve().parent / "templates"


def render(template: str | Path, values: Mapping[str, object]) -> str:
    """Substitute ``$name`` placeholders in a template file; every placeholder must have a value."""
    path = Path(template)
    text = read_text(path, MissionConfigError, "cannot read template {path}: {reason}")
    try:
        return string.Template(text).substitute({k: str(v) for k, v in values.items()})
    except KeyError as exc:
        raise MissionConfigError(f"template {path.name} needs a value for ${exc.args[0]}") from exc
    except ValueError as exc:
        raise MissionConfigError(f"template {path.name}: {exc}") from exc


def fail(message: str) -> int:
    """Report an invalid configuration the way the course's ``config.fail`` does; returns exit status 1.

    The banner goes to stdout on purpose: it becomes the "config file" a process-substituted app reads,
    so that app fails loudly too instead of starting on an empty configuration.
    """
    print(INVALID_BANNER, flush=True)
    print(f"invalid configuration: {message}", file=sys.stderr, flush=True)
    return 1


def find_generator(generators: Mapping[str, T], app: str) -> T:
    """The generator of ``app``'s configuration; MissionConfigError naming the known apps if there is none."""
    try:
        return generators[app]
    except KeyError:
        raise MissionConfigError(f"App: {app} not defined (known: {', '.join(sorted(generators))})") from None


def make_dirs(run_dir: Path, *dirs: Path) -> None:
    """Create the run directory and ``dirs`` (sockets, logs) if missing; MissionConfigError naming the run
    directory if that fails."""
    try:
        for path in (run_dir, *dirs):
            path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise MissionConfigError(f"cannot create the run directory {run_dir}: {exc.strerror or exc}") from exc


def config_main(argv: list[str] | None, usage: str, nargs: int, generate: Callable[..., str]) -> int:
    """A mission config module's ``main``: ``generate(*argv)`` (``nargs`` arguments, else ``usage``) printed to
    stdout; a MissionConfigError is reported with ``fail``."""
    args = sys.argv[1:] if argv is None else argv
    if len(args) != nargs:
        return fail(f"usage: {usage}")
    try:
        text = generate(*args)
    except MissionConfigError as exc:
        return fail(str(exc))
    print(text, flush=True)
    return 0


def text_format_string(value: str) -> str:
    """A protobuf text-format string literal."""
    return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'


def settings_from_env(cls: type[T], names: Mapping[str, str], environ: Mapping[str, str] | None = None) -> T:
    """A settings dataclass from environment variables (``names``: field -> variable); unset ones keep defaults.

    Each value is converted to its field's type (int, float, Path or str); a bad one raises MissionConfigError
    naming the variable, so every launch line that reads the settings fails the same clear way.
    """
    environ = os.environ if environ is None else environ
    types = {f.name: f.type for f in dataclasses.fields(cls)}  # type: ignore[arg-type]
    kwargs: dict[str, Any] = {}
    for name, var in names.items():
        raw = environ.get(var)
        if raw is None or raw == "":
            continue
        kind = types[name]
        try:
            if kind in ("int", int):
                kwargs[name] = int(raw)
            elif kind in ("float", float):
                kwargs[name] = float(raw)
            elif kind in ("Path", Path):
                kwargs[name] = Path(raw)
            else:
                kwargs[name] = raw
        except ValueError as exc:
            raise MissionConfigError(f"{var}={raw!r} is not a valid {kind}") from exc
    return cls(**kwargs)


def env_variables(prefix: str, fields: Iterable[str], **renamed: str) -> dict[str, str]:
    """field -> environment variable: ``prefix`` and the field's name in capitals, unless ``renamed`` names it."""
    return {name: renamed.get(name, prefix + name.upper()) for name in fields}


class EnvSettings:
    """A mission's frozen settings dataclass that travels to the launch lines as environment variables.

    ``ENV`` (field -> variable) names the variables; the config generator run by each line rebuilds the same
    settings with ``from_env``.
    """

    ENV: ClassVar[Mapping[str, str]]
    __dataclass_fields__: ClassVar[dict[str, dataclasses.Field[Any]]]  # subclasses are dataclasses

    def to_env(self) -> dict[str, str]:
        """The variables that reproduce these settings in a launch line."""
        return {var: str(getattr(self, name)) for name, var in self.ENV.items()}

    @classmethod
    def from_env(cls: type[S], environ: Mapping[str, str] | None = None) -> S:
        """Settings from the variables; unset ones keep the defaults. Bad values raise MissionConfigError."""
        return settings_from_env(cls, cls.ENV, environ)

    def replace(self: S, **changes: object) -> S:
        return dataclasses.replace(self, **changes)


def check_warp_and_origin(warp: int, lat_origin: float, lon_origin: float) -> None:
    """MissionConfigError unless the warp is >= 1 and the origin a latitude,longitude."""
    if warp < 1:
        raise MissionConfigError(f"warp must be a whole number >= 1, not {warp}")
    if not -90 <= lat_origin <= 90 or not -180 <= lon_origin <= 180:
        raise MissionConfigError(f"origin {lat_origin},{lon_origin} is not a latitude,longitude")
