"""examples/python/plot_robodoc.py runs headless and draws a PNG of robodoc's force and states."""

import os
import subprocess
import sys

from conftest import ROOT


def test_the_plot_example_writes_a_png_of_the_recording(tmp_path):
    out = tmp_path / "robodoc.png"
    subprocess.run([sys.executable, str(ROOT / "examples/python/plot_robodoc.py"), str(out)], check=True,
                   env=dict(os.environ, MPLBACKEND="Agg", MPLCONFIGDIR=str(tmp_path)), timeout=120)
    data = out.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    width, height = int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big")
    assert (width, height) == (900, 500) and len(data) > 20000
