"""Dataset commands choose a video decoder that loads, without a traceback."""

import sys

from lerobot_tavis.dataset_tools.quiet import video_backend


def test_pyav_is_chosen_where_torchcodec_cannot_load(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "torchcodec.decoders", None)  # `import` now fails as a broken install does
    assert video_backend() == "pyav"
    assert capsys.readouterr() == ("", "")


def test_torchcodec_is_chosen_where_it_loads(monkeypatch):
    package, decoders = type(sys)("torchcodec"), type(sys)("torchcodec.decoders")
    package.decoders = decoders
    monkeypatch.setitem(sys.modules, "torchcodec", package)
    monkeypatch.setitem(sys.modules, "torchcodec.decoders", decoders)
    assert video_backend() == "torchcodec"
