"""Application configuration: protobuf text-format files, command-line overrides, ``GOBY_INTERPROCESS``, and the
commented ``--example_config`` text.

Precedence: command-line overrides > config file > ``GOBY_INTERPROCESS`` (used only when neither the file nor
the command line set the ``interprocess`` block), as Goby's configurator does.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Generic, TypeVar

from google.protobuf import descriptor as pb_descriptor
from google.protobuf import message as pb_message
from google.protobuf import text_encoding, text_format

from gateway.goby.portal.errors import AppConfigError
from gateway.goby.protobuf.app_config_pb2 import AppConfig
from gateway.goby.protobuf.interprocess_config_pb2 import InterProcessPortalConfig
from util.cli import HelpFormatter
from util.descriptors import descriptor_of, enum_type_of, initialization_errors, message_type_of
from util.logsetup import add_verbosity_argument

INTERPROCESS_ENV = "GOBY_INTERPROCESS"
_FD = pb_descriptor.FieldDescriptor

# app.glog_config.tty_verbosity -> our -v count
_TTY_VERBOSITY = {1: 0, 2: 0, 4: 1, 5: 2, 6: 3, 7: 3}


ConfigT = TypeVar("ConfigT", bound=pb_message.Message)


@dataclass
class LoadedConfig(Generic[ConfigT]):
    """The result of :func:`load_config`: ``cfg`` is of the type asked for."""

    cfg: ConfigT
    verbosity: int
    example_requested: bool
    debug_cfg: bool


def _has_field(cfg: Any, name: str) -> bool:
    descriptor = getattr(cfg, "DESCRIPTOR", None)
    return descriptor is not None and name in descriptor.fields_by_name


def interprocess_config_of(cfg: Any) -> InterProcessPortalConfig | None:
    """The ``interprocess`` block of an application config, if its type has one (Goby's config types declare it
    as ``InterProcessPortalConfig``); None for anything else."""
    if not _has_field(cfg, "interprocess"):
        return None
    block: InterProcessPortalConfig = cfg.interprocess
    return block


def app_config_of(cfg: Any) -> AppConfig | None:
    """The ``app`` block (``AppConfig``) of an application config, if its type has one; None for anything else."""
    if not _has_field(cfg, "app"):
        return None
    block: AppConfig = cfg.app
    return block


def app_name_of(cfg: Any, default: str = "") -> str:
    """``app.name`` of an application config, or ``default`` when it has no ``app`` block or no name set."""
    app = app_config_of(cfg)
    return app.name if app is not None and app.HasField("name") else default


def _merge_text(target: pb_message.Message, text: str, where: str) -> None:
    try:
        text_format.Merge(text, target)
    except text_format.ParseError as exc:
        unclosed = unclosed_braces(text)
        if unclosed:  # the parser trips over whatever follows; the real fault is the opening brace
            lines = ", ".join(str(n) for n in unclosed)
            raise AppConfigError(f"{where}: line {lines}: '{{' is never closed (parser: {exc})") from None
        raise AppConfigError(f"{where}: {exc}") from None


def unclosed_braces(text: str) -> list[int]:
    """Line numbers of ``{``/``<`` in protobuf text format that are never closed (strings and ``#`` skipped)."""
    stack: list[int] = []
    line, i, n = 1, 0, len(text)
    while i < n:
        ch = text[i]
        if ch == "\n":
            line += 1
        elif ch == "#":
            end = text.find("\n", i)
            i = n if end < 0 else end
            continue
        elif ch in "\"'":
            i += 1
            while i < n and text[i] not in (ch, "\n"):
                i += 2 if text[i] == "\\" else 1
            if i < n and text[i] == "\n":
                continue  # an unterminated string ends at the line's end; the newline is counted next
        elif ch in "{<":
            stack.append(line)
        elif ch in "}>" and stack:
            stack.pop()
        i += 1
    return stack


def _scalar_override(field: pb_descriptor.FieldDescriptor, value: str) -> str:
    """Text-format for ``--field value`` of a scalar field: strings are quoted unless already quoted."""
    if field.type in (_FD.TYPE_STRING, _FD.TYPE_BYTES) and not (value.startswith('"') or value.startswith("'")):
        value = '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    return f"{field.name}: {value}"


def project_extensions(config_type: type[pb_message.Message]) -> list[pb_descriptor.FieldDescriptor]:
    """Extensions of the config message declared outside Goby's packages: this project's own settings.

    A config file with them is refused by the real Goby app, so launchers give them on the command line instead,
    ``--<extension name> TEXT`` (as ``--<field>`` for Goby's fields), and the file keeps Goby's fields only.
    """
    descriptor = descriptor_of(config_type)
    found = descriptor.file.pool.FindAllExtensions(descriptor)
    return sorted((e for e in found if not e.full_name.startswith("goby.")), key=lambda e: e.number)


def build_parser(config_type: type[pb_message.Message], prog: str | None = None) -> argparse.ArgumentParser:
    """Goby-style command line: a config file, ``--<top-level field> VALUE`` overrides, ``-e``, ``-v``."""
    parser = argparse.ArgumentParser(
        formatter_class=HelpFormatter,
        prog=prog,
        description=f"Configuration: {descriptor_of(config_type).full_name} in protobuf text format.",
        epilog="Message fields take text format (e.g. --interprocess 'platform: \"usv\"'); repeat an option to add "
        "to a repeated field.",
    )
    parser.add_argument("config_file", nargs="?", help="configuration file (protobuf text format)")
    parser.add_argument("-c", "--cfg_path", help="configuration file (alternative to the positional argument)")
    parser.add_argument("-e", "--example_config", action="store_true", help="print a commented example and exit")
    parser.add_argument("-a", "--app_name", help="set app.name")
    parser.add_argument("-n", "--ncurses", action="store_true",
                        help="accepted for compatibility with Goby command lines; there is no ncurses GUI (ignored)")
    add_verbosity_argument(parser)
    for field in descriptor_of(config_type).fields:
        kind = "message (text format)" if field.type == _FD.TYPE_MESSAGE else _type_label(field)
        try:
            parser.add_argument(f"--{field.name}", action="append", metavar="VALUE", dest=f"field_{field.name}",
                                help=f"override {field.name}: {kind}")
        except argparse.ArgumentError:
            pass  # a field named like a common option (e.g. "verbose"): set it in the file or a message block
    for ext in project_extensions(config_type):
        try:
            parser.add_argument(f"--{ext.name}", action="append", metavar="TEXT", dest=f"ext_{ext.full_name}",
                                help=f"set the project extension [{ext.full_name}] (text format)")
        except argparse.ArgumentError:
            pass  # named like a field or option: give it in the config file as [{full_name}] { ... }
    return parser


def load_config(
    config_type: type[ConfigT], argv: list[str] | None = None, prog: str | None = None,
    environ: Mapping[str, str] | None = None,
) -> LoadedConfig[ConfigT]:
    """Parse ``argv`` into a ``config_type`` message; ``AppConfigError`` names the file/option that is wrong."""
    env: Mapping[str, str] = os.environ if environ is None else environ
    parser = build_parser(config_type, prog)
    args = parser.parse_args(argv)
    cfg = config_type()
    if args.example_config:
        return LoadedConfig(cfg, args.verbose, True, False)
    path = args.cfg_path or args.config_file
    if path:
        try:
            text = Path(path).read_text(encoding="utf-8")
        except OSError as exc:
            raise AppConfigError(f"cannot read configuration file {path}: {exc.strerror}") from None
        except UnicodeDecodeError as exc:  # a binary file: say so instead of a traceback
            line = exc.object[:exc.start].count(b"\n") + 1
            raise AppConfigError(f"configuration file {path}: line {line}: not protobuf text format "
                                 f"(byte 0x{exc.object[exc.start]:02x} at offset {exc.start} is not UTF-8)") from None
        _merge_text(cfg, text, f"configuration file {path}")
    for field in descriptor_of(config_type).fields:
        for value in getattr(args, f"field_{field.name}", None) or ():
            if field.type == _FD.TYPE_MESSAGE:
                target = getattr(cfg, field.name).add() if _is_repeated(field) else getattr(cfg, field.name)
                _merge_text(target, value, f"--{field.name}")
                if not _is_repeated(field):
                    getattr(cfg, field.name).SetInParent()
            else:
                _merge_text(cfg, _scalar_override(field, value), f"--{field.name}")
    for ext in project_extensions(config_type):
        for value in getattr(args, f"ext_{ext.full_name}", None) or ():
            if ext.type == _FD.TYPE_MESSAGE and not _is_repeated(ext):
                # The stubs index Extensions only by the typed handles generated code declares, not by an
                # extension found at run time.
                block: pb_message.Message = cfg.Extensions[ext]  # type: ignore[index]
                _merge_text(block, value, f"--{ext.name}")
                block.SetInParent()
            else:
                _merge_text(cfg, f"[{ext.full_name}]: {value}", f"--{ext.name}")
    interprocess = interprocess_config_of(cfg)
    if interprocess is not None and not cfg.HasField("interprocess") and env.get(INTERPROCESS_ENV):
        _merge_text(interprocess, env[INTERPROCESS_ENV], f"${INTERPROCESS_ENV}")
        interprocess.SetInParent()
    app = app_config_of(cfg)
    if app is not None:
        if args.app_name:
            app.name = args.app_name
        if not app.HasField("name"):
            app.name = prog or os.path.basename(sys.argv[0] or "app")
    if not cfg.IsInitialized():
        missing = ", ".join(initialization_errors(cfg))
        raise AppConfigError(f"configuration is missing required field(s): {missing}")
    check_values(cfg)
    verbosity = args.verbose
    debug_cfg = False
    if app is not None:
        if app.HasField("glog_config") and app.glog_config.HasField("tty_verbosity"):
            verbosity = max(verbosity, _TTY_VERBOSITY.get(app.glog_config.tty_verbosity, 0))
        debug_cfg = app.debug_cfg
    return LoadedConfig(cfg, verbosity, False, debug_cfg)


_INTEGER_TYPES = {_FD.TYPE_INT32, _FD.TYPE_INT64, _FD.TYPE_UINT32, _FD.TYPE_UINT64, _FD.TYPE_SINT32,
                  _FD.TYPE_SINT64, _FD.TYPE_FIXED32, _FD.TYPE_FIXED64, _FD.TYPE_SFIXED32, _FD.TYPE_SFIXED64}


def check_values(cfg: pb_message.Message, where: str = "") -> None:
    """Refuse values the types allow but nothing can use, naming the field: a port outside 0..65535 (a uint32
    that the socket layer would silently wrap: 99999 listens on 34463) and a ``warp_factor`` that is not > 0."""
    for field, value in cfg.ListFields():
        name = f"[{field.full_name}]" if field.is_extension else field.name
        path = f"{where}.{name}" if where else name
        values = value if _is_repeated(field) else [value]
        if field.type == _FD.TYPE_MESSAGE:
            for i, sub in enumerate(values):
                check_values(sub, f"{path}[{i}]" if _is_repeated(field) else path)
            continue
        if field.type not in _INTEGER_TYPES and field.type not in (_FD.TYPE_DOUBLE, _FD.TYPE_FLOAT):
            continue
        for number in values:
            if (field.name == "port" or field.name.endswith("_port")) and field.type in _INTEGER_TYPES:
                if not 0 <= number <= 65535:
                    raise AppConfigError(f"{path}: {number} is not a port number (0..65535)")
            if field.name == "warp_factor" and not (math.isfinite(number) and number > 0):
                raise AppConfigError(f"{path}: {number} must be a finite number > 0")


def _is_repeated(field: pb_descriptor.FieldDescriptor) -> bool:
    return bool(field.is_repeated)


def _is_required(field: pb_descriptor.FieldDescriptor) -> bool:
    return bool(field.is_required)


_TYPE_NAMES = {
    _FD.TYPE_DOUBLE: "double", _FD.TYPE_FLOAT: "float", _FD.TYPE_INT64: "int64", _FD.TYPE_UINT64: "uint64",
    _FD.TYPE_INT32: "int32", _FD.TYPE_FIXED64: "fixed64", _FD.TYPE_FIXED32: "fixed32", _FD.TYPE_BOOL: "bool",
    _FD.TYPE_STRING: "string", _FD.TYPE_BYTES: "bytes", _FD.TYPE_UINT32: "uint32", _FD.TYPE_SFIXED32: "sfixed32",
    _FD.TYPE_SFIXED64: "sfixed64", _FD.TYPE_SINT32: "sint32", _FD.TYPE_SINT64: "sint64",
}


def _type_label(field: pb_descriptor.FieldDescriptor) -> str:
    if field.type == _FD.TYPE_ENUM:
        return f"enum {enum_type_of(field).name}"
    if field.type == _FD.TYPE_MESSAGE:
        return message_type_of(field).full_name
    return _TYPE_NAMES.get(field.type, "?")


def _example_value(field: pb_descriptor.FieldDescriptor) -> str:
    if field.has_default_value or field.type in (_FD.TYPE_ENUM, _FD.TYPE_BOOL):
        value: Any = field.default_value
        if field.type == _FD.TYPE_ENUM:
            enum_type = enum_type_of(field)
            enum_value = enum_type.values_by_number.get(value) or enum_type.values[0]
            return enum_value.name
    else:
        value = {_FD.TYPE_STRING: "", _FD.TYPE_BYTES: b""}.get(field.type, 0)
    if field.type == _FD.TYPE_BOOL:
        return "true" if value else "false"
    if field.type in (_FD.TYPE_STRING, _FD.TYPE_BYTES):  # escaped as text format reads it (a newline as \n)
        return '"' + text_encoding.CEscape(value, as_utf8=field.type == _FD.TYPE_STRING) + '"'
    return repr(value) if isinstance(value, float) else str(value)


def example_config(config_type: type[pb_message.Message] | pb_descriptor.Descriptor, _indent: int = 0,
                   _seen: tuple[str, ...] = ()) -> str:
    """Every field of the configuration with its default, each commented with label, type and meaning.

    The text parses back into ``config_type`` and, as given, changes nothing that matters: fields that would alter
    behaviour just by being present are commented out (optional fields without a declared default, repeated
    fields, later members of a oneof, optional blocks that contain required fields).  Required fields stay.
    """
    descriptor = config_type if isinstance(config_type, pb_descriptor.Descriptor) else descriptor_of(config_type)
    pad = "  " * _indent
    lines: list[str] = []
    for field in descriptor.fields:
        label = "required" if _is_required(field) else "repeated" if _is_repeated(field) else "optional"
        comment = f"({label}) {_type_label(field)}"
        if field.has_default_value:
            comment += f", default {_example_value(field)}"
        oneof = field.containing_oneof
        off = "# " if _comment_out(field) else ""
        if oneof is not None:
            comment += f"; one of {oneof.name}"
        if field.type == _FD.TYPE_MESSAGE:
            sub = message_type_of(field)
            if sub.full_name in _seen or len(_seen) > 6:
                lines.append(f"{pad}# {field.name} {{ }}  # {comment} (recursive, not expanded)")
                continue
            lines.append(f"{pad}{off}{field.name} {{  # {comment}")
            body = example_config(sub, _indent + 1, (*_seen, descriptor.full_name))
            if off:
                body = "\n".join(f"{pad}# {line[len(pad):]}" for line in body.splitlines())
            if body:
                lines.append(body)
            lines.append(f"{pad}{off}}}")
        else:
            lines.append(f"{pad}{off}{field.name}: {_example_value(field)}  # {comment}")
    return "\n".join(lines)


def _comment_out(field: pb_descriptor.FieldDescriptor) -> bool:
    if _is_required(field):
        return False
    oneof = field.containing_oneof
    if oneof is not None and oneof.fields[0] is not field:
        return True
    if _is_repeated(field):
        return True
    if field.type == _FD.TYPE_MESSAGE:
        return any(_is_required(sub) for sub in message_type_of(field).fields)
    return not field.has_default_value


def debug_text(cfg: pb_message.Message) -> str:
    """The parsed configuration as text format (what ``app { debug_cfg: true }`` prints)."""
    return text_format.MessageToString(cfg)


def load_for_run(config_type: type[ConfigT], argv: list[str] | None, prog: str) -> LoadedConfig[ConfigT] | int:
    """The start-up every Goby-style program shares: parse, or handle ``--example_config``/``debug_cfg``.

    Returns the loaded configuration to run with, or the exit code to return at once: 0 after printing the
    example or the parsed configuration, 2 after printing a configuration error naming the cause.
    """
    try:
        loaded = load_config(config_type, argv, prog)
    except AppConfigError as exc:
        print(f"{prog}: configuration error: {exc}", file=sys.stderr)
        return 2
    if loaded.example_requested:
        print(example_config(config_type))
        return 0
    if loaded.debug_cfg:
        print(debug_text(loaded.cfg), end="")
        return 0
    return loaded
