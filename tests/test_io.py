"""Files appear complete or not at all."""

import pytest

from tumble.io import atomic_write, write_json


def test_atomic_write_leaves_no_file_when_the_writer_crashes(tmp_path):
    def crash(path):
        path.write_text("half a fil")
        raise RuntimeError("disk full")

    with pytest.raises(RuntimeError, match="disk full"):
        atomic_write(tmp_path / "data.json", crash)
    assert list(tmp_path.iterdir()) == []


def test_atomic_write_keeps_the_old_file_when_the_writer_crashes(tmp_path):
    write_json(tmp_path / "summary.json", {"a": 1})

    def crash(path):
        path.write_text("{")
        raise RuntimeError("killed")

    with pytest.raises(RuntimeError):
        atomic_write(tmp_path / "summary.json", crash)
    assert (tmp_path / "summary.json").read_text() == '{\n  "a": 1\n}\n'
    assert [p.name for p in tmp_path.iterdir()] == ["summary.json"]
