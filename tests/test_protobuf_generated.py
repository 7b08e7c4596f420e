"""The committed ``*_pb2.py`` files must match what the ``.proto`` files generate."""

from __future__ import annotations

from tools.generate_protos import REPO_ROOT, generate


def test_generated_protobuf_code_is_up_to_date() -> None:
    stale = generate(check=True)
    assert not stale, "regenerate with `python -m tools.generate_protos`: " + ", ".join(
        str(p.relative_to(REPO_ROOT)) for p in stale
    )
