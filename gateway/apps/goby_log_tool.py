"""``goby-log-tool``: convert a ``.goby`` log to text or JSON (goby_log_tool's role and command line).

``goby-log-tool [-c cfg] input_file [output_file] [--format DEBUG_TEXT|JSON|HDF5|MCAP]`` (or ``--input_file``,
``--output_file``; ``-`` is stdout; the default output is the input's name without directory or extension plus
``.txt``/``.json``/``.h5``/``.mcap``, in the current directory, as Goby names it), ``--type_regex``,
``--group_regex``, ``--exclude_type_regex``, ``--exclude_group_regex``, ``--load_shared_library`` (Python modules
whose protobuf types decode entries the log does not describe).

HDF5 (Goby's layout, :mod:`gateway.goby.log.hdf5_export`; ``--write_hdf5_zero_length_dim``,
``--hdf5_chunk_length``, ``--hdf5_compression_level``) and MCAP (:mod:`gateway.goby.log.mcap_export`, for
Foxglove) need the ``log`` extra (h5py, mcap); without it they exit 1 saying so.  MCAP may go to stdout (``-``),
HDF5 may not.

Each span of the input that is not a whole valid entry is reported on stderr with its byte offset, and the
reading goes on at the next ``GBY3``.  Exit codes: 0 everything was read; 3 some bytes were skipped (the output
holds every readable entry); 1 the input cannot be read, the output cannot be written or the format's library is
missing; 2 a bad command line.
"""

from __future__ import annotations

import logging
import re
import sys
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import IO

from google.protobuf import message as pb_message

from gateway.goby.log.entry import LogEntry
from gateway.goby.log.errors import ExportUnavailable, LogFormatError
from gateway.goby.log.hdf5_export import export_hdf5, import_h5py  # h5py: imported when used
from gateway.goby.log.mcap_export import McapExporter, import_mcap_writer  # mcap: likewise
from gateway.goby.log.protobuf.log_tool_config_pb2 import LogToolConfig
from gateway.goby.log.reader import LogReader
from gateway.goby.log.render import EntryDecoder, debug_text_line, json_dump, json_objects
from gateway.goby.portal.config import build_parser, load_for_run
from util.extensions import ExtensionError, ExtensionPoint, load_module
from util.logsetup import configure_logging

log = logging.getLogger(__name__)

EXIT_SKIPPED = 3
PROTO_MODULES = ExtensionPoint(group="goby_log.protobuf", what="library", source="load_shared_library")
_EXTENSIONS = {LogToolConfig.DEBUG_TEXT: ".txt", LogToolConfig.HDF5: ".h5", LogToolConfig.JSON: ".json",
               LogToolConfig.MCAP: ".mcap"}


def positional_argv(config_type: type[pb_message.Message], argv: list[str], names: list[str],
                    prog: str) -> list[str]:
    """Goby's positional fields (``(goby.field).cfg.position``): the bare arguments of ``argv`` become
    ``--<name> VALUE`` for ``names`` in order (the config file is then given with ``-c``, as in Goby).

    Exits 2 (argparse's usage error) when there are more bare arguments than names.
    """
    parser = build_parser(config_type, prog)
    takes_value = {opt: action.nargs != 0 for opt, action in parser._option_string_actions.items()}
    options: list[str] = []
    bare: list[str] = []
    i = 0
    while i < len(argv):
        token = argv[i]
        if token == "--":
            bare.extend(argv[i + 1:])
            break
        if token.startswith("-") and token != "-":
            options.append(token)
            if "=" not in token and takes_value.get(token, token.startswith("--")) and i + 1 < len(argv):
                options.append(argv[i + 1])
                i += 1
        else:
            bare.append(token)
        i += 1
    if len(bare) > len(names):
        parser.error(f"unexpected argument(s): {' '.join(bare[len(names):])} (give the configuration file with -c)")
    for name, value in zip(names, bare, strict=False):
        options += [f"--{name}", value]
    return options


def output_path(cfg: LogToolConfig) -> str:
    """``output_file`` (``-``: stdout), else Goby's default: the input's stem plus the format's extension."""
    if cfg.HasField("output_file"):
        return cfg.output_file
    return Path(cfg.input_file).stem + _EXTENSIONS[cfg.format]


class EntryFilter:
    """The four regexes of LogToolConfig, each applied only when set (as goby_log_tool's ``check_regexes``)."""

    def __init__(self, cfg: LogToolConfig) -> None:
        def pattern(name: str) -> re.Pattern[str] | None:
            if not cfg.HasField(name):  # type: ignore[arg-type]
                return None
            try:
                return re.compile(getattr(cfg, name))
            except re.error as exc:
                raise LogFormatError(f"--{name} {getattr(cfg, name)!r}: {exc}") from None

        self.type_re, self.group_re = pattern("type_regex"), pattern("group_regex")
        self.exclude_type_re, self.exclude_group_re = pattern("exclude_type_regex"), pattern("exclude_group_regex")

    def __call__(self, type_name: str, group: str) -> bool:
        if self.type_re is not None and not self.type_re.fullmatch(type_name):
            return False
        if self.group_re is not None and not self.group_re.fullmatch(group):
            return False
        if self.exclude_type_re is not None and self.exclude_type_re.fullmatch(type_name):
            return False
        return not (self.exclude_group_re is not None and self.exclude_group_re.fullmatch(group))


@contextmanager
def open_output(path: str) -> Iterator[IO[str]]:
    if path == "-":
        yield sys.stdout
        sys.stdout.flush()
        return
    with open(path, "w", encoding="utf-8", newline="\n") as f:
        yield f


@contextmanager
def open_binary_output(path: str) -> Iterator[IO[bytes]]:
    if path == "-":
        yield sys.stdout.buffer
        sys.stdout.buffer.flush()
        return
    with open(path, "wb") as f:
        yield f


def convert_text(cfg: LogToolConfig, out: IO[str], entries: Iterable[LogEntry], decoder: EntryDecoder) -> int:
    """Write ``entries`` as DEBUG_TEXT lines or JSON objects to ``out``; returns their count."""
    count = 0
    for entry in entries:
        value = decoder.decode(entry)
        if cfg.format == LogToolConfig.DEBUG_TEXT:
            out.write(debug_text_line(entry, value) + "\n")
        else:
            for obj in json_objects(entry, value):
                out.write(json_dump(obj) + "\n")
        count += 1
    return count


def convert(cfg: LogToolConfig, target: str, reader: LogReader, keep: EntryFilter) -> int:
    """Write the entries of ``reader`` that ``keep`` accepts to ``target`` in ``cfg.format``; returns their count.

    Raises ``OSError`` when the output cannot be written, ``ExportUnavailable`` without the
    format's library, ``LogFormatError`` for HDF5 to stdout.
    """
    decoder = EntryDecoder(reader.descriptors)
    counted = [0]

    def entries() -> Iterator[LogEntry]:
        for entry in reader:
            if keep(entry.type_name, entry.group):
                counted[0] += 1
                yield entry

    if cfg.format == LogToolConfig.HDF5:
        import_h5py()
        if target == "-":
            raise LogFormatError("HDF5 output cannot go to stdout: name an output file")
        export_hdf5(entries(), decoder, target, zero_length_dim=cfg.write_hdf5_zero_length_dim,
                    chunk_length=cfg.hdf5_chunk_length if cfg.HasField("hdf5_chunk_length") else None,
                    compression_level=cfg.hdf5_compression_level if cfg.HasField("hdf5_compression_level") else None)
    elif cfg.format == LogToolConfig.MCAP:
        import_mcap_writer()
        with open_binary_output(target) as out:
            exporter = McapExporter(out, decoder, metadata={"input_file": cfg.input_file,
                                                            "goby_log_version": str(reader.version)})
            exporter.add_all(entries())
            exporter.finish()
    else:
        with open_output(target) as text:
            convert_text(cfg, text, entries(), decoder)
    return counted[0]


def main(argv: list[str] | None = None) -> int:
    prog = "goby-log-tool"
    short = {"-i": "--input_file", "-o": "--output_file"}  # Goby's cli_short letters
    args = [short.get(a, a) for a in (sys.argv[1:] if argv is None else argv)]
    args = positional_argv(LogToolConfig, args, ["input_file", "output_file"], prog)
    loaded = load_for_run(LogToolConfig, args, prog)
    if isinstance(loaded, int):
        return loaded
    cfg = loaded.cfg
    configure_logging(loaded.verbosity, prog)
    try:
        for spec in cfg.load_shared_library:
            load_module(PROTO_MODULES, spec)
        keep = EntryFilter(cfg)
        with LogReader(cfg.input_file) as reader:
            target = output_path(cfg)
            try:
                count = convert(cfg, target, reader, keep)
            except OSError as exc:
                print(f"{prog}: cannot write {target}: {exc.strerror or exc}", file=sys.stderr)
                return 1
            except ExportUnavailable as exc:
                print(f"{prog}: {exc}", file=sys.stderr)
                return 1
            if count == 0 and not reader.skipped:
                log.warning("input_file: %s has no message entries", cfg.input_file)
            if reader.skipped:
                total = sum(span.length for span in reader.skipped)
                print(f"{prog}: {cfg.input_file}: skipped {len(reader.skipped)} span(s), {total} byte(s) in all; "
                      f"{count} entries written to {target}", file=sys.stderr)
                return EXIT_SKIPPED
            return 0
    except (LogFormatError, ExtensionError) as exc:
        print(f"{prog}: {exc}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
