"""Record Goby3's field set (message, field name, number, type) from Goby3's own ``.proto`` files.

``python -m tools.goby_field_set GOBY3_GIT_DIR [--rev 3.1.5] [-o tests/data/goby3_field_set.json]``

Why: our protos that claim a Goby3 package must declare only what Goby3 declares, and every config our launchers
write for a Goby app must be accepted by the real app. The tests check both against this recorded set instead of
against our own protos (which is what would drift). The input is a clone (or bare mirror) of GobySoft/goby3; the
files are read with ``git show REV:src/...`` (Goby installs ``src/X`` as ``goby/X``), compiled with the protoc
bundled in grpcio-tools, and every message, enum and extension of Goby's middleware, zeromq, moos, util and
acomms protos (plus the basic simulator driver's config) is written as JSON. DCCL's ``option_extensions.proto``
comes from ``gateway/goby/protobuf/include`` (an exact copy of DCCL's, tests/dccl/test_option_extensions.py).
"""

from __future__ import annotations

import argparse
import importlib.resources
import json
import re
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import NotRequired, TypedDict

from google.protobuf import descriptor_pb2

REPO_ROOT = Path(__file__).resolve().parents[1]
INCLUDE_ROOT = REPO_ROOT / "gateway" / "goby" / "protobuf" / "include"
DEFAULT_OUTPUT = REPO_ROOT / "tests" / "data" / "goby3_field_set.json"
DEFAULT_REV = "3.1.5"
# The Goby3 directories whose protos we record (src/test and app-private protos are left out).
RECORDED_DIRS = (
    "src/protobuf/", "src/util/protobuf/", "src/middleware/protobuf/", "src/zeromq/protobuf/", "src/moos/protobuf/",
    "src/acomms/protobuf/", "src/middleware/frontseat/simulator/basic/",
)
# needs DCCL's arithmetic codec extensions, which are not DCCL's option file; nothing of ours uses it
EXCLUDED = ("src/acomms/protobuf/network_header.proto",)
_IMPORT = re.compile(r'^\s*import\s+(?:public\s+|weak\s+)?"([^"]+)"\s*;', re.M)
_TYPES = {v: k[len("TYPE_"):].lower() for k, v in descriptor_pb2.FieldDescriptorProto.Type.items()}
_LABELS = {v: k[len("LABEL_"):].lower() for k, v in descriptor_pb2.FieldDescriptorProto.Label.items()}


class FieldEntry(TypedDict):
    """A field or an extension (extensions have ``extendee`` and a full ``name``)."""

    name: str
    number: int
    type: str
    label: str
    type_name: NotRequired[str]
    default: NotRequired[str]
    extendee: NotRequired[str]


class MessageEntry(TypedDict):
    file: str
    fields: list[FieldEntry]
    extension_ranges: list[list[int]]


class FieldSet(TypedDict):
    """The recorded JSON document."""

    source: str
    generated_by: str
    messages: dict[str, MessageEntry]
    enums: dict[str, dict[str, int]]
    extensions: list[FieldEntry]


def _git_show(git_dir: Path, rev: str, path: str) -> str | None:
    done = subprocess.run(["git", "--git-dir", str(git_dir), "show", f"{rev}:{path}"], capture_output=True, text=True)
    return done.stdout if done.returncode == 0 else None


def _list_files(git_dir: Path, rev: str) -> list[str]:
    done = subprocess.run(["git", "--git-dir", str(git_dir), "ls-tree", "-r", "--name-only", rev, "src"],
                          capture_output=True, text=True, check=True)
    return sorted(p for p in done.stdout.split() if p.endswith(".proto") and p.startswith(RECORDED_DIRS) and p not in EXCLUDED)


def extract(git_dir: Path, rev: str, dest: Path) -> list[str]:
    """Write the recorded files and everything they import under ``dest`` as ``goby/...``; return the roots."""
    roots = ["goby/" + p[len("src/"):] for p in _list_files(git_dir, rev)]
    todo, seen = list(roots), set()
    while todo:
        name = todo.pop()
        if name in seen or (INCLUDE_ROOT / name).exists() or name.startswith("google/protobuf/"):
            continue
        seen.add(name)
        text = _git_show(git_dir, rev, "src/" + name[len("goby/"):]) if name.startswith("goby/") else None
        if text is None:
            raise SystemExit(f"{name}: not found in {git_dir} at {rev}")
        target = dest / name
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(text)
        todo.extend(_IMPORT.findall(text))
    return roots


def compile_set(src: Path, roots: list[str]) -> descriptor_pb2.FileDescriptorSet:
    from grpc_tools import protoc

    out = src / "set.pb"
    well_known = importlib.resources.files("grpc_tools") / "_proto"
    args = ["protoc", f"-I{src}", f"-I{INCLUDE_ROOT}", f"-I{well_known}", "--include_imports",
            f"--descriptor_set_out={out}", *roots]
    if protoc.main(args) != 0:
        raise SystemExit("protoc failed on Goby's protos (see the messages above)")
    return descriptor_pb2.FileDescriptorSet.FromString(out.read_bytes())


def _field(f: descriptor_pb2.FieldDescriptorProto, scope: str) -> FieldEntry:
    entry: FieldEntry = {"name": f.name, "number": f.number, "type": _TYPES[f.type], "label": _LABELS[f.label]}
    if f.type_name:
        entry["type_name"] = f.type_name.lstrip(".")
    if f.HasField("default_value"):
        entry["default"] = f.default_value
    if f.extendee:
        entry["name"] = f"{scope}.{f.name}" if scope else f.name
        entry["extendee"] = f.extendee.lstrip(".")
    return entry


def field_set(files: descriptor_pb2.FileDescriptorSet, rev: str) -> FieldSet:
    """Goby's messages, enums and extensions as plain data (sorted, so the file diffs well)."""
    messages: dict[str, MessageEntry] = {}
    enums: dict[str, dict[str, int]] = {}
    extensions: list[FieldEntry] = []

    def walk(msg: descriptor_pb2.DescriptorProto, scope: str, path: str) -> None:
        full = f"{scope}.{msg.name}" if scope else msg.name
        messages[full] = {"file": path, "fields": [_field(f, full) for f in msg.field],
                          "extension_ranges": [[r.start, r.end - 1] for r in msg.extension_range]}
        extensions.extend(_field(f, full) for f in msg.extension)
        for nested in msg.nested_type:
            walk(nested, full, path)
        for enum in msg.enum_type:
            enums[f"{full}.{enum.name}"] = {v.name: v.number for v in enum.value}

    for fd in files.file:
        if not fd.name.startswith("goby/"):
            continue
        for msg in fd.message_type:
            walk(msg, fd.package, fd.name)
        for enum in fd.enum_type:
            enums[f"{fd.package}.{enum.name}"] = {v.name: v.number for v in enum.value}
        extensions.extend(_field(f, fd.package) for f in fd.extension)
    return {
        "source": f"GobySoft/goby3 {rev}",
        "generated_by": "python -m tools.goby_field_set",
        "messages": dict(sorted(messages.items())),
        "enums": dict(sorted(enums.items())),
        "extensions": sorted(extensions, key=lambda e: (e["extendee"], e["number"])),
    }


def dump(data: FieldSet) -> str:
    """JSON with one line per field, enum and extension: readable, and diffs line by line."""
    one = json.dumps
    out = ["{", f' "source": {one(data["source"])},', f' "generated_by": {one(data["generated_by"])},', ' "messages": {']
    messages = data["messages"]
    for i, (name, msg) in enumerate(messages.items()):
        fields = ",\n".join(f"   {one(f)}" for f in msg["fields"])
        head = f'  {one(name)}: {{"file": {one(msg["file"])}, "extension_ranges": {one(msg["extension_ranges"])}, '
        out.append(head + (f'"fields": [\n{fields}\n  ]}}' if fields else '"fields": []}') + ("," if i < len(messages) - 1 else ""))
    enums = data["enums"]
    out.append(" },")
    out.append(' "enums": {')
    out.append(",\n".join(f"  {one(name)}: {one(values)}" for name, values in enums.items()))
    out.append(" },")
    out.append(' "extensions": [')
    out.append(",\n".join(f"  {one(e)}" for e in data["extensions"]))
    out.append(" ]")
    out.append("}")
    return "\n".join(out) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m tools.goby_field_set", description=__doc__.splitlines()[0])
    parser.add_argument("goby_git_dir", type=Path, help="a GobySoft/goby3 clone's .git directory (or a bare mirror)")
    parser.add_argument("--rev", default=DEFAULT_REV, help=f"tag or commit (default {DEFAULT_REV})")
    parser.add_argument("-o", "--output", type=Path, default=DEFAULT_OUTPUT)
    args = parser.parse_args(argv)
    git_dir = args.goby_git_dir / ".git" if (args.goby_git_dir / ".git").is_dir() else args.goby_git_dir
    with tempfile.TemporaryDirectory() as tmp:
        roots = extract(git_dir, args.rev, Path(tmp))
        data = field_set(compile_set(Path(tmp), roots), args.rev)
    args.output.parent.mkdir(parents=True, exist_ok=True)
    text = dump(data)
    assert json.loads(text) == data
    args.output.write_text(text)
    print(f"{args.output}: {len(data['messages'])} messages, {len(data['enums'])} enums, "
          f"{len(data['extensions'])} extensions from GobySoft/goby3 {args.rev}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
