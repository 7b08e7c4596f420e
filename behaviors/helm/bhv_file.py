"""Reading .bhv files (Populator_BehaviorSet's grammar) and building the behaviours they declare.

Every problem raises :class:`BehaviorFileError` with the file, line and token, so the helm can go to
MALCONFIG with a message a mission author can act on.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

from util.extensions import ExtensionError

from .behavior import Behavior
from .errors import BehaviorFileError, ConditionError, ParamError, UnknownParamError
from .info_buffer import InfoBuffer, Value
from .ivp import IvPDomain
from .logic import is_number
from .modes import ModeEntry
from .registry import BEHAVIOR_POINT, behavior_class


@dataclass
class Initialize:
    var: str
    value: Value
    deferred: bool
    line: int


@dataclass
class BehaviorBlock:
    type_name: str
    line: int
    params: list[tuple[str, str, int]] = field(default_factory=list)


@dataclass
class BehaviorFile:
    path: str
    initializes: list[Initialize] = field(default_factory=list)
    blocks: list[BehaviorBlock] = field(default_factory=list)
    modes: list[ModeEntry] = field(default_factory=list)


def _logical_lines(text: str) -> list[tuple[int, str]]:
    """Lines with ``//`` comments removed, ``\\``-continuations joined, and braces split off as pHelmIvP does.

    Blank lines come back as ``""``: they end a ``set`` block's optional else-value.
    """
    out: list[tuple[int, str]] = []
    pending, pending_no = "", 0
    for number, raw in enumerate(text.splitlines(), start=1):
        cut = raw.find("//")
        line = (raw[:cut] if cut >= 0 else raw).rstrip()
        if pending:
            line, number = pending + line.lstrip(), pending_no
        if line.endswith("\\"):
            pending, pending_no = line[:-1], number
            continue
        pending = ""
        line = line.strip()
        if not line:
            out.append((number, ""))
            continue
        if not line.startswith("#"):
            if len(line) > 1 and line[0] in "{}":
                out.append((number, line[0]))
                line = line[1:].strip()
            if len(line) > 1 and line.endswith("{"):
                out.append((number, line[:-1].strip()))
                line = "{"
        out.append((number, line))
    if pending:
        out.append((pending_no, pending.strip()))
    return out


def _auto_type(value: str) -> Value:
    value = value.strip()
    if len(value) >= 2 and value[0] == '"' and value[-1] == '"':
        return value[1:-1]
    return float(value) if is_number(value) else value


def _split_quoted(text: str, sep: str = ",") -> list[str]:
    parts, current, quoted = [], "", False
    for ch in text:
        if ch == '"':
            quoted = not quoted
        if ch == sep and not quoted:
            parts.append(current)
            current = ""
        else:
            current += ch
    parts.append(current)
    return parts


def parse_bhv_text(text: str, path: str = "<string>") -> BehaviorFile:
    """Parse .bhv text (already nsplug-expanded) into initialize lines and behaviour blocks."""
    result = BehaviorFile(path)
    block: BehaviorBlock | None = None
    awaiting_brace: BehaviorBlock | None = None
    mode: ModeEntry | None = None  # a set block: declared, open, or closed and waiting for an else-value
    mode_state = ""
    for number, line in _logical_lines(text):
        if mode is not None and mode_state == "closed":
            head_word = line.split(None, 1)[0].lower() if line else ""
            if line and head_word not in ("initialize", "initialize_", "set") and not _is_behavior_line(line):
                try:
                    mode.set_else(line)
                except ParamError as exc:
                    raise BehaviorFileError(path, number, line, str(exc)) from exc
                line = ""
            result.modes.append(mode)
            mode, mode_state = None, ""
        if not line:
            continue
        if mode is not None:
            if mode_state == "declared":
                if line != "{":
                    raise BehaviorFileError(path, number, line, "expected '{' after the set line")
                mode_state = "open"
            elif line == "}":
                mode_state = "closed"
            else:
                try:
                    mode.add_condition(line)
                except (ParamError, ConditionError) as exc:
                    raise BehaviorFileError(path, number, line, str(exc)) from exc
            continue
        if awaiting_brace is not None:
            if line != "{":
                raise BehaviorFileError(path, number, line, "expected '{' after the Behavior line")
            block, awaiting_brace = awaiting_brace, None
            continue
        if block is not None:
            if line == "}":
                result.blocks.append(block)
                block = None
                continue
            if line == "{":
                raise BehaviorFileError(path, number, line, "'{' inside a behaviour block")
            param, sep, value = line.partition("=")
            if not sep or not param.strip():
                raise BehaviorFileError(path, number, line, "expected 'parameter = value'")
            block.params.append((param.strip(), value.strip(), number))
            continue
        head = line.split(None, 1)[0] if line.split() else line
        lowered = head.lower()
        if lowered in ("initialize", "initialize_"):
            deferred = lowered.endswith("_")
            body = line[len(head):].strip()
            for item in _split_quoted(body):
                var, sep, value = item.partition("=")
                var = var.strip()
                if not sep or not var or any(c.isspace() for c in var):
                    raise BehaviorFileError(path, number, item.strip() or line, "expected 'initialize VAR = value'")
                result.initializes.append(Initialize(var, _auto_type(value), deferred, number))
        elif _is_behavior_line(line):
            type_name = line.split("=", 1)[1].strip()
            if not type_name:
                raise BehaviorFileError(path, number, line, "missing behaviour type")
            awaiting_brace = BehaviorBlock(type_name, number)
        elif lowered == "set":
            var, sep, value = line[len(head):].partition("=")
            if not sep or not var.strip() or not value.strip() or any(c.isspace() for c in var.strip()):
                raise BehaviorFileError(path, number, line, "expected 'set VAR = value'")
            mode, mode_state = ModeEntry(var.strip(), value.strip(), number), "declared"
        elif line.startswith("#"):
            raise BehaviorFileError(path, number, head, "preprocessor line: run nsplug on the file first")
        elif line in ("{", "}"):
            raise BehaviorFileError(path, number, line, "brace outside a behaviour block")
        else:
            raise BehaviorFileError(path, number, head, "unknown line")
    if awaiting_brace is not None or block is not None:
        opened = (awaiting_brace or block).line  # type: ignore[union-attr]
        raise BehaviorFileError(path, opened, "Behavior", "behaviour block is not closed")
    if mode is not None:
        if mode_state != "closed":
            raise BehaviorFileError(path, mode.line, f"set {mode.var}", "set block is not closed")
        result.modes.append(mode)
    return result


def _is_behavior_line(line: str) -> bool:
    return line.replace(" ", "").replace("\t", "").lower().startswith("behavior=")


def read_bhv_file(path: str | os.PathLike[str]) -> BehaviorFile:
    try:
        text = Path(path).read_text(encoding="utf-8")
    except OSError as exc:
        raise BehaviorFileError(str(path), 0, str(path), f"cannot read behaviour file: {exc.strerror}") from exc
    except UnicodeDecodeError as exc:  # a binary or mis-encoded file: say where, not a traceback
        line = exc.object[:exc.start].count(b"\n") + 1
        raise BehaviorFileError(str(path), line, f"byte 0x{exc.object[exc.start]:02x}",
                                f"not a UTF-8 text behaviour file (byte offset {exc.start})") from None
    if "\x00" in text:
        line = text[:text.index("\x00")].count("\n") + 1
        raise BehaviorFileError(str(path), line, "NUL", "not a text behaviour file (it holds NUL bytes)")
    return parse_bhv_text(text, str(path))


def build_behaviors(bfile: BehaviorFile, domain: IvPDomain, info: InfoBuffer, ownship: str = "") -> list[Behavior]:
    """Instantiate and configure every block, in file order; any bad line raises BehaviorFileError."""
    behaviors: list[Behavior] = []
    for block in bfile.blocks:
        try:
            cls = behavior_class(block.type_name)
        except ExtensionError as exc:
            raise BehaviorFileError(bfile.path, block.line, block.type_name, str(exc)) from exc
        if cls is None:
            raise BehaviorFileError(bfile.path, block.line, block.type_name,
                                    f"unknown behaviour type (not built in, and no entry point of that name in "
                                    f"group {BEHAVIOR_POINT.group})")
        bhv = cls(domain, info, ownship)
        for param, value, number in block.params:
            try:
                bhv.set_param(param, value)
            except UnknownParamError as exc:
                raise BehaviorFileError(bfile.path, number, param, str(exc)) from exc
            except ConditionError as exc:
                raise BehaviorFileError(bfile.path, number, exc.token, str(exc)) from exc
            except ParamError as exc:
                raise BehaviorFileError(bfile.path, number, f"{param} = {value}", str(exc)) from exc
        try:
            bhv.check_config()
        except ParamError as exc:
            raise BehaviorFileError(bfile.path, block.line, block.type_name, f"{bhv.name}: {exc}") from exc
        for other in behaviors:
            if other.name == bhv.name or other.name.startswith(bhv.name) or bhv.name.startswith(other.name):
                raise BehaviorFileError(bfile.path, block.line, bhv.name,
                                        f"behaviour name clashes with '{other.name}' (names must be unique "
                                        "and none may be a prefix of another)")
        bhv.on_set_param_complete()
        behaviors.append(bhv)
    return behaviors
