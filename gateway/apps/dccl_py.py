"""``dccl-py``: the C++ ``dccl`` tool's analyze/encode/decode, on our DCCL codec.

    dccl-py -a -f translators/trail/protobuf/nav_dccl.proto              field sizes (like dccl --analyze)
    dccl-py -a -l translators.usv.protobuf.command_dccl_pb2 -m goby3_course.dccl.USVCommand
    echo 'time: 1700000000 desired_state: WAYPOINTS' | dccl-py -e -l MODULE -m NAME        -> fc80380100
    dccl-py -d -l MODULE fc80380100                                       -> |goby3_course.dccl.USVCommand| ...
    dccl-py --source -l MODULE -m NAME                                    the generated encode/decode Python

Message types come from ``.proto`` files (``-f``, compiled with grpcio-tools' protoc; ``-I`` adds include
directories, DCCL's options are always found) or from generated Python modules (``-l``, where the C++ tool takes
a shared library). Encode reads protobuf text format, one message per line (``|Name| ...`` picks the type), from
the arguments or standard input; decode reads encoded messages the same way and prints ``|Name| text``. The
default ``--format`` is ``hex`` (the C++ tool's is ``bin``).
"""

from __future__ import annotations

import argparse
import base64
import importlib
import importlib.resources
import logging
import sys
import tempfile
from collections.abc import Iterable
from pathlib import Path

from google.protobuf import (
    descriptor_pb2,
    descriptor_pool,
    message_factory,
    text_encoding,
    text_format,
)
from google.protobuf.descriptor import Descriptor
from google.protobuf.message import Message

from gateway.goby.dccl import Codec, DcclError
from util.descriptors import descriptor_of
from util.logsetup import add_verbosity_argument, configure_logging

log = logging.getLogger(__name__)

PROG = "dccl-py"
DCCL_INCLUDE = Path(__file__).resolve().parents[1] / "goby" / "protobuf" / "include"
EXIT_OK, EXIT_FAILED, EXIT_USAGE = 0, 1, 2


class ToolError(Exception):
    """A problem the tool reports in one line and exits 1 for."""


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog=PROG, description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter,
                                     epilog=__doc__.split("\n\n", 1)[1])
    action = parser.add_mutually_exclusive_group(required=True)
    action.add_argument("-e", "--encode", dest="action", action="store_const", const="encode",
                        help="encode text-format messages (arguments or standard input)")
    action.add_argument("-d", "--decode", dest="action", action="store_const", const="decode",
                        help="decode messages (arguments or standard input)")
    action.add_argument("-a", "--analyze", dest="action", action="store_const", const="analyze",
                        help="field sizes of the message definitions")
    action.add_argument("-p", "--display_proto", dest="action", action="store_const", const="proto",
                        help="the .proto definition of the messages")
    action.add_argument("--source", dest="action", action="store_const", const="source",
                        help="the Python our codec generated for the messages")
    parser.add_argument("-f", "--proto_file", action="append", default=[], help=".proto file to load")
    parser.add_argument("-I", "--proto_path", action="append", default=[], help="search directory for imports")
    parser.add_argument("-l", "--load", action="append", default=[], metavar="MODULE",
                        help="Python module of generated messages to import (e.g. pkg.foo_pb2)")
    parser.add_argument("-m", "--message", action="append", default=[], help="message full name")
    parser.add_argument("--format", choices=["hex", "bin", "textformat", "base64"], default="hex",
                        help="encode output / decode input (default hex)")
    parser.add_argument("-o", "--omit_prefix", action="store_true", help="no |Name| before decoded messages")
    parser.add_argument("--strict", action="store_true", help="refuse out-of-range values instead of sending them "
                        "as not present")
    parser.add_argument("--now", type=float, help="receiver clock for time fields, seconds since 1970 (default: now)")
    parser.add_argument("items", nargs="*", help="messages to encode or decode (default: standard input)")
    add_verbosity_argument(parser)
    return parser


def compile_proto_files(files: list[str], includes: list[str]) -> list[descriptor_pb2.FileDescriptorProto]:
    """FileDescriptorProtos of ``files`` and their imports, from grpcio-tools' protoc (messages on stderr)."""
    try:
        from grpc_tools import protoc
    except ImportError as exc:
        raise ToolError("reading .proto files needs grpcio-tools (pip install grpcio-tools); or use -l MODULE") from exc
    well_known = importlib.resources.files("grpc_tools") / "_proto"
    roots = [str(Path(f).parent) for f in files]
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "set.pb"
        args = ["protoc", *(f"-I{d}" for d in [*includes, *roots, DCCL_INCLUDE, well_known]), "--include_imports",
                f"--descriptor_set_out={out}", *files]
        if protoc.main(args) != 0:
            raise ToolError(f"protoc could not read {', '.join(files)} (see its messages above)")
        return list(descriptor_pb2.FileDescriptorSet.FromString(out.read_bytes()).file)


class Types:
    """Message types by full name: from -f files (a pool of their own), -l modules and the default pool."""

    def __init__(self, files: list[str], includes: list[str], modules: list[str]) -> None:
        self.pool = descriptor_pool.DescriptorPool()
        self.from_files: list[str] = []
        for module in modules:
            try:
                importlib.import_module(module)
            except ImportError as exc:
                raise ToolError(f"cannot import {module}: {exc}") from exc
            self.from_files.extend(module_messages(module))
        if files:
            protos = compile_proto_files([str(Path(f).resolve()) for f in files], includes)
            for proto in protos:
                self.pool.Add(proto)
            wanted = {Path(f).name for f in files}
            for proto in protos:
                if Path(proto.name).name in wanted:
                    self.from_files.extend(f"{proto.package}.{m.name}".lstrip(".") for m in proto.message_type)

    def find(self, name: str) -> type[Message]:
        for pool in (self.pool, descriptor_pool.Default()):
            try:
                return message_factory.GetMessageClass(pool.FindMessageTypeByName(name))
            except KeyError:
                continue
        raise ToolError(f"No descriptor with name {name} found! Load its .proto file (-f) or module (-l), and give "
                        "the full name including the package")


def module_messages(module: str) -> list[str]:
    """Full names of the top-level messages a generated module defines."""
    descriptor = getattr(sys.modules[module], "DESCRIPTOR", None)
    if descriptor is None:
        return []
    return [m.full_name for m in descriptor.message_types_by_name.values()]


def read_items(items: list[str], binary: bool) -> Iterable[str | bytes]:
    """The command-line items, else standard input (whole, or by non-empty lines)."""
    if items:
        return items
    if binary:
        return [sys.stdin.buffer.read()]
    return [line.strip() for line in sys.stdin if line.strip()]


def to_bytes(item: str | bytes, fmt: str) -> bytes:
    if isinstance(item, bytes):
        return item
    if fmt == "hex":
        return bytes.fromhex(item)
    if fmt == "base64":
        return base64.b64decode(item)
    return text_encoding.CUnescape(item.strip().strip('"'))


def from_bytes(data: bytes, fmt: str) -> str | bytes:
    if fmt == "hex":
        return data.hex()
    if fmt == "base64":
        return base64.b64encode(data).decode()
    if fmt == "textformat":
        return '"' + text_encoding.CEscape(data, as_utf8=False) + '"'
    return data


def encode(codec: Codec, types: Types, names: list[str], items: Iterable[str | bytes], fmt: str) -> int:
    if len(names) > 1:
        raise ToolError("No more than one DCCL message can be specified with -m for encoding.")
    status = EXIT_OK
    for item in items:
        text = item.decode() if isinstance(item, bytes) else item
        name = names[0] if names else None
        if text.startswith("|"):
            name, _, text = text[1:].partition("|")
        if name is None:
            raise ToolError("Message name not given with -m or in the input (i.e. '|Name| field1: value').")
        message_type = types.find(name)
        try:
            codec.load(message_type)
            msg = text_format.Parse(text, message_type())
            out = from_bytes(codec.encode(msg), fmt)
        except (DcclError, text_format.ParseError) as exc:
            print(f"{PROG}: {name}: {exc}", file=sys.stderr)
            status = EXIT_FAILED
            continue
        if isinstance(out, bytes):
            sys.stdout.buffer.write(out)
            sys.stdout.buffer.flush()
        else:
            print(out)
    return status


def decode(codec: Codec, items: Iterable[str | bytes], fmt: str, omit_prefix: bool, now: float | None) -> int:
    data = b"".join(to_bytes(item, fmt) for item in items)
    try:
        messages = codec.decode_all(data, now=now)
    except DcclError as exc:
        print(f"{PROG}: {exc}" + "".join(f" {note}" for note in getattr(exc, "__notes__", [])), file=sys.stderr)
        return EXIT_FAILED
    for msg in messages:
        prefix = "" if omit_prefix else f"|{msg.DESCRIPTOR.full_name}| "
        print(prefix + text_format.MessageToString(msg, as_one_line=True))
    return EXIT_OK


def display_proto(descriptor: Descriptor) -> str:
    proto = descriptor_pb2.DescriptorProto()
    descriptor.CopyToProto(proto)
    return f"// {descriptor.full_name} (DescriptorProto, text format)\n" + text_format.MessageToString(proto)


def main(argv: list[str] | None = None) -> int:
    """Console script ``dccl-py``."""
    parser = build_parser()
    args = parser.parse_args(argv)
    configure_logging(args.verbose, PROG)
    try:
        fmt = args.format
        types = Types(args.proto_file, args.proto_path, args.load)
        codec = Codec(strict=args.strict)
        names = args.message or types.from_files
        if args.action == "encode" and not args.message and names:
            print(f"Encoding assuming message: {names[0]}", file=sys.stderr)
            names = names[:1]
        failed = False
        for name in names:
            try:
                codec.load(types.find(name))
            except DcclError as exc:
                print(f"Not a valid DCCL message: {name}\n\tWhy: {exc}", file=sys.stderr)
                failed = True
        if args.action == "encode":
            items = read_items(args.items, binary=False)
            return encode(codec, types, [n for n in names if n in codec_names(codec)], items, fmt) or int(failed)
        if args.action == "decode":
            return decode(codec, read_items(args.items, binary=fmt == "bin"), fmt, args.omit_prefix, args.now)
        if not names:
            raise ToolError("no messages: give -m NAME, -f FILE.proto or -l MODULE")
        for name in names:
            if name not in codec_names(codec):
                continue
            message_type = types.find(name)
            if args.action == "analyze":
                print(codec.info(message_type), end="")
            elif args.action == "source":
                print(f"# {name}\n{codec.source(message_type)}")
            else:
                print(display_proto(descriptor_of(message_type)))
        return EXIT_FAILED if failed else EXIT_OK
    except ToolError as exc:
        print(f"{PROG}: {exc}", file=sys.stderr)
        return EXIT_FAILED
    except ValueError as exc:  # bad hex/base64 input
        print(f"{PROG}: bad input: {exc}", file=sys.stderr)
        return EXIT_FAILED


def codec_names(codec: Codec) -> set[str]:
    return {compiled.name for compiled in codec.loaded()}


if __name__ == "__main__":
    raise SystemExit(main())
