"""Files written whole or not at all."""

import pytest

from lerobot_tavis.atomic import atomic_path, write_text


def test_the_file_appears_only_when_complete(tmp_path):
    target = tmp_path / "sub" / "result.json"
    with atomic_path(target) as partial:
        partial.write_text("new")
        assert not target.exists() and partial.name == ".result.json.partial"
    assert target.read_text() == "new" and not partial.exists()


def test_a_failure_keeps_the_old_file_and_leaves_no_partial(tmp_path):
    target = write_text(tmp_path / "result.md", "old")
    with pytest.raises(RuntimeError):
        with atomic_path(target) as partial:
            partial.write_text("half")
            raise RuntimeError("interrupted")
    assert target.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["result.md"]


def test_a_suffix_keeps_the_extension_for_writers_that_need_it(tmp_path):
    with atomic_path(tmp_path / "plot.png", suffix=".png") as partial:
        assert partial.suffix == ".png"
        partial.write_bytes(b"png")
    assert (tmp_path / "plot.png").read_bytes() == b"png"
