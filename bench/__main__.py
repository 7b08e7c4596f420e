"""Run every benchmark (``bench/bench_*.py``) one after the other; each prints its own table.

Usage: ``python -m bench [NAME ...]`` where NAME filters by module name (e.g. ``moos``).
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path


def main(argv: list[str] | None = None) -> int:
    wanted = sys.argv[1:] if argv is None else argv
    modules = sorted(p.stem for p in Path(__file__).parent.glob("bench_*.py"))
    selected = [m for m in modules if not wanted or any(w in m for w in wanted)]
    status = 0
    for module in selected:
        print(f"\n=== {module} ===", flush=True)
        status |= subprocess.call([sys.executable, "-m", f"bench.{module}"])
    return status


if __name__ == "__main__":
    sys.exit(main())
