"""Options that mean nothing for a sharded run are refused, not ignored: ``--format`` with
``--chunk-size`` (shards are always Parquet) on every command that writes shards."""

from __future__ import annotations

import pytest

SHARDED = {
    "study": ["study", "li-sunden-2016"],
    "monte-carlo": ["monte-carlo", "no-such-study.toml"],  # the options are checked before the file is read
    "design-study": ["design-study", "li-sunden-2016-design", "--sweep", "squash_ratio=0:0.3:2"],
}


@pytest.mark.parametrize("command", list(SHARDED))
@pytest.mark.parametrize("file_format", ["mat", "parquet"])
def test_format_with_chunk_size_is_refused(cli, tmp_path, command, file_format):
    out = tmp_path / "o"
    r = cli(*SHARDED[command], "--chunk-size", "5", "--format", file_format, "--out", out)
    assert r.code == 2, (r.code, r.stderr)
    assert r.stderr.strip().splitlines() == [
        f"error: command line: --format = '{file_format}': expected csv (the default) with --chunk-size: "
        "shards are always Parquet"
    ]
    assert not out.exists() and list(tmp_path.iterdir()) == []
