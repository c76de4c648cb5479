"""Ctrl-C (SIGINT) or SIGTERM during the final write leaves the old file or the whole new one,
never a part, and no temporary file: in-process (KeyboardInterrupt raised inside the atomic
write) and through the command line, a subprocess signalled while it is inside the write."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from samvg import VectorImage, VectorPath
from samvg.io import read_image, write_png

SVG = (
    '<svg xmlns="http://www.w3.org/2000/svg" width="20" height="10">'
    '<rect width="20" height="10" fill="#00ff00"/><path d="M0 0 H10 V10 H0 Z" fill="red"/></svg>'
)
# Runs `samvg ARGS` with the write held up at one point: before the rename (the temporary file
# written, the target untouched) or after it (the new file in place); a marker file says when.
HELD_WRITE = """
import os, sys, time
marker, where = sys.argv[1], sys.argv[2]
real_fsync, real_replace = os.fsync, os.replace
def hold():
    open(marker, "w").close()
    time.sleep(60)
def fsync(fd):
    real_fsync(fd)
    if where == "before-rename":
        hold()
def replace(source, target):
    real_replace(source, target)
    if where == "after-rename":
        hold()
os.fsync, os.replace = fsync, replace
from samvg.cli import main
sys.exit(main(sys.argv[3:]))
"""


def _interrupt(*_args: object) -> None:
    raise KeyboardInterrupt


@pytest.mark.parametrize("where", ["os.fsync", "os.replace"])
def test_keyboard_interrupt_inside_a_write_keeps_the_old_file(tmp_path, monkeypatch, where):
    target = tmp_path / "out.svg"
    target.write_text("old")
    image = VectorImage(8, 8, [VectorPath(np.array([[0, 0], [8, 0], [8, 8]], float))])
    monkeypatch.setattr(where, _interrupt)
    with pytest.raises(KeyboardInterrupt):
        image.save(target)
    assert target.read_text() == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.svg"]  # no temporary file


def test_keyboard_interrupt_inside_a_png_write_leaves_no_file(tmp_path, monkeypatch):
    monkeypatch.setattr("os.fsync", _interrupt)
    with pytest.raises(KeyboardInterrupt):
        write_png(tmp_path / "new.png", np.zeros((4, 4, 3)))
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("where", ["before-rename", "after-rename"])
@pytest.mark.parametrize(("signum", "code"), [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_a_signal_during_the_final_write_leaves_old_or_new(tmp_path, where, signum, code):
    folder, marker = tmp_path / "out", tmp_path / "writing"
    folder.mkdir()
    (folder / "in.svg").write_text(SVG)
    write_png(folder / "out.png", np.zeros((3, 3, 3)))  # the old file
    old = (folder / "out.png").read_bytes()
    command = [sys.executable, "-c", HELD_WRITE, str(marker), where]
    command += ["render", str(folder / "in.svg"), "-o", str(folder / "out.png")]
    process = subprocess.Popen(command, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while not marker.exists() and process.poll() is None and time.monotonic() < deadline:
        time.sleep(0.05)
    assert marker.exists(), "the command never reached the write"
    process.send_signal(signum)
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == code
    assert stderr.splitlines() == ["interrupted"]
    assert sorted(p.name for p in folder.iterdir()) == ["in.svg", "out.png"]  # no temporary
    if where == "before-rename":
        assert (folder / "out.png").read_bytes() == old
    else:
        assert read_image(folder / "out.png").shape == (10, 20, 3)  # the whole new file
        assert tuple(read_image(folder / "out.png")[5, 15]) == (0, 255, 0)


def test_sigterm_handler_is_restored_after_main(tmp_path):
    from samvg.cli import main

    before = signal.getsignal(signal.SIGTERM)
    (tmp_path / "in.svg").write_text(SVG)
    assert main(["render", str(tmp_path / "in.svg"), "-o", str(tmp_path / "o.png")]) == 0
    assert signal.getsignal(signal.SIGTERM) == before
    assert os.path.getsize(tmp_path / "o.png") > 0
    assert Path(tmp_path / "o.png").is_file()
