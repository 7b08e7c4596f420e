"""Regenerate (or check) the committed ``*_pb2.py`` and ``*_pb2.pyi`` files from the repository's ``.proto`` files.

Run ``python -m tools.generate_protos`` after editing a ``.proto``; ``--check`` exits 1 when the committed
output is stale (the test suite runs it).  The ``.pyi`` stubs come from mypy-protobuf (pinned in pyproject.toml,
since its output is committed): unlike protoc's own ``--pyi_out`` they type enums, extensions and descriptors
in a way mypy accepts.

Why a script and not plain ``protoc``: our ``.proto`` files live inside our Python packages and import each
other by repository-relative path (``import "frontseat/protobuf/frontseat_data.proto";``), which makes the
generated imports valid package imports.  Files that third-party ``.proto`` files expect at a fixed path
(DCCL's ``dccl/option_extensions.proto``) live under ``gateway/goby/protobuf/include``, which is searched first;
their generated modules are imported as ``gateway.goby.protobuf.include.<...>``, so the script rewrites those imports.
"""

from __future__ import annotations

import argparse
import importlib.resources
import re
import shutil
import sys
import sysconfig
import tempfile
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[1]
INCLUDE_ROOT = REPO_ROOT / "gateway" / "goby" / "protobuf" / "include"
PACKAGES = ("util", "gateway", "translators", "frontseat", "behaviors", "launch", "tests")


def proto_files() -> list[Path]:
    """Every ``.proto`` in our packages, sorted for reproducible output."""
    found: list[Path] = []
    for package in PACKAGES:
        found.extend((REPO_ROOT / package).rglob("*.proto"))
    return sorted(p for p in found if ".venv" not in p.parts)


def _virtual_path(path: Path) -> Path:
    """The path protoc knows a file by: relative to the include root if inside it, else to the repo."""
    if path.is_relative_to(INCLUDE_ROOT):
        return path.relative_to(INCLUDE_ROOT)
    return path.relative_to(REPO_ROOT)


def _real_output(generated: Path) -> Path:
    """Where a generated file (relative to protoc's output dir) is committed."""
    top = generated.parts[0]
    if (INCLUDE_ROOT / top).is_dir():
        return INCLUDE_ROOT / generated
    return REPO_ROOT / generated


def _rewrite_imports(text: str) -> str:
    """Point imports of include-root modules at their place inside ``gateway.goby.protobuf.include``."""
    for top in sorted(p.name for p in INCLUDE_ROOT.iterdir() if p.is_dir() and not p.name.startswith("_")):
        text = re.sub(rf"^from {top}(\.| import)", rf"from gateway.goby.protobuf.include.{top}\1", text, flags=re.M)
        text = re.sub(rf"^import {top}\.", f"import gateway.goby.protobuf.include.{top}.", text, flags=re.M)
    return text


def _mypy_plugin() -> str:
    """The ``protoc-gen-mypy`` executable installed beside this interpreter (or on ``PATH``)."""
    beside = Path(sysconfig.get_path("scripts")) / "protoc-gen-mypy"
    found = str(beside) if beside.is_file() else shutil.which("protoc-gen-mypy")
    if found is None:
        raise SystemExit("mypy-protobuf is needed to generate the .pyi stubs: pip install -e '.[test]'")
    return found


def run_protoc(files: list[Path], out_dir: Path) -> None:
    """Compile ``files`` into ``out_dir`` with the protoc bundled in grpcio-tools."""
    try:
        from grpc_tools import protoc
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise SystemExit("grpcio-tools is needed to generate protobuf code: pip install -e '.[test]'") from exc
    well_known = importlib.resources.files("grpc_tools") / "_proto"
    args = [
        "protoc",
        f"-I{INCLUDE_ROOT}",
        f"-I{REPO_ROOT}",
        f"-I{well_known}",
        f"--python_out={out_dir}",
        f"--plugin=protoc-gen-mypy={_mypy_plugin()}",
        f"--mypy_out=quiet:{out_dir}",
        *(str(_virtual_path(f)) for f in files),
    ]
    if protoc.main(args) != 0:
        raise SystemExit("protoc failed (see the messages above)")


def generate(check: bool = False) -> list[Path]:
    """Generate all code; return the files that differ from what is on disk (written unless ``check``)."""
    files = proto_files()
    if not files:
        return []
    stale: list[Path] = []
    with tempfile.TemporaryDirectory() as tmp:
        out_dir = Path(tmp)
        run_protoc(files, out_dir)
        for generated in sorted(p for p in out_dir.rglob("*") if p.is_file()):
            rel = generated.relative_to(out_dir)
            target = _real_output(rel)
            text = _rewrite_imports(generated.read_text())
            if not target.exists() or target.read_text() != text:
                stale.append(target)
                if not check:
                    target.parent.mkdir(parents=True, exist_ok=True)
                    target.write_text(text)
    return stale


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="exit 1 if any committed output is stale")
    args = parser.parse_args(argv)
    stale = generate(check=args.check)
    for path in stale:
        print(("stale: " if args.check else "wrote: ") + str(path.relative_to(REPO_ROOT)))
    return 1 if (args.check and stale) else 0


if __name__ == "__main__":
    sys.exit(main())
