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
from collections.abc import Mapping
from pathlib import Path
from typing import Any, TypeVar

from launch.errors import MissionConfigError

T = TypeVar("T")

INVALID_BANNER = "=============== INVALID CONFIGURATION ================="
# Templates both missions render (app/interprocess blocks, broker, frontseat interface, gateway).
SHARED_TEMPLATES = Path(__file__).resolve().parent / "templates"


def render(template: str | Path, values: Mapping[str, object]) -> str:
    """Substitute ``$name`` placeholders in a template file; every placeholder must have a value."""
    path = Path(template)
    try:
        text = path.read_text()
    except OSError as exc:
        raise MissionConfigError(f"cannot read template {path}: {exc.strerror or exc}") from exc
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
