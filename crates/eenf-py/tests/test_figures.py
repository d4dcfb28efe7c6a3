"""`Trace.save_figure` draws the command line's figure of a trace (eenf-figures): a PNG at the
canvas' size, an SVG holding the title, and a refused extension that raises and leaves nothing."""

import struct

import numpy as np
import pytest

import eenf


def test_a_trace_is_drawn_as_png_and_svg(tmp_path):
    t = np.arange(600.0)
    trace = eenf.Trace.from_values(50 + 0.02 * np.sin(2 * np.pi * t / 200), step_s=1.0)
    png = tmp_path / "trace.png"
    trace.save_figure(png, title="a known wander")
    head = png.read_bytes()
    assert head[:8] == b"\x89PNG\r\n\x1a\n"
    assert struct.unpack(">II", head[16:24]) == (1100, 720)
    assert len(head) > 10_000  # axes, labels and the line, not a blank canvas
    svg = tmp_path / "trace.svg"
    trace.save_figure(str(svg))
    text = svg.read_text()
    assert text.startswith("<svg") and "ENF trace" in text and "ENF (Hz)" in text
    with pytest.raises(ValueError, match=r"\.png or \.svg"):
        trace.save_figure(tmp_path / "trace.jpg")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["trace.png", "trace.svg"]
