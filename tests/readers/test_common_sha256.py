"""readers.common.sha256_of: hashlib's digest of the file; the same file asked again is not
read again, a changed file (other content, other modification time) is."""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

import pytest

from thermocal.readers import common


def test_sha256_of_is_hashlibs_and_follows_changes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    f = tmp_path / "log.bin"
    f.write_bytes(b"a" * 3_000_000)
    want = hashlib.sha256(b"a" * 3_000_000).hexdigest()
    assert common.sha256_of(f) == want
    opened: list[str] = []
    real_sha = hashlib.sha256

    def counted(*args: bytes) -> object:
        opened.append("hash")
        return real_sha(*args)

    monkeypatch.setattr(common.hashlib, "sha256", counted)
    assert common.sha256_of(f) == want
    assert common.sha256_of(str(f)) == want
    assert opened == []  # not hashed again
    f.write_bytes(b"b" * 3_000_000)  # same size, new content
    st = f.stat()
    os.utime(f, ns=(st.st_atime_ns, st.st_mtime_ns + 1_000_000_000))
    assert common.sha256_of(f) == real_sha(b"b" * 3_000_000).hexdigest()
    assert opened == ["hash"]
    assert common.sha256_of(tmp_path / "missing") is None
