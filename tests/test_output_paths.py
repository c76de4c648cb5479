"""Output paths checked before any work: files, folders, a batch's names, the input itself."""

import os
from pathlib import Path

import pytest

from samvg.errors import OutputError
from samvg.output_paths import (
    batch_outputs,
    check_output_file,
    check_output_folder,
    same_file,
)


def test_a_writable_file_output_passes(tmp_path):
    assert check_output_file(tmp_path / "a.SVG", (".svg",)) == tmp_path / "a.SVG"


@pytest.mark.parametrize(
    ("name", "message"),
    [
        ("dir.svg", "is a folder, not a file"),
        ("new.svg/", "names a folder"),
        ("file.txt/a.svg", "is a file, not a folder"),
        ("missing/a.svg", "does not exist"),
        ("a.png", "should end in .svg"),
    ],
)
def test_file_outputs_that_cannot_be_written(tmp_path, name, message):
    (tmp_path / "dir.svg").mkdir()
    (tmp_path / "file.txt").write_text("x")
    with pytest.raises(OutputError, match=message):
        check_output_file(str(tmp_path) + "/" + name, (".svg",))


def test_a_folder_without_write_permission(tmp_path, monkeypatch):
    """As root a chmod'ed folder stays writable, so the permission answer is stubbed."""
    monkeypatch.setattr(os, "access", lambda *_args: False)
    with pytest.raises(OutputError, match="is not writable"):
        check_output_file(tmp_path / "a.svg", (".svg",))
    with pytest.raises(OutputError, match="is not writable"):
        check_output_folder(tmp_path / "new")


def test_the_input_is_never_the_output(tmp_path):
    source = tmp_path / "in.svg"
    source.write_text("png bytes")
    (tmp_path / "link.svg").symlink_to(source)
    (tmp_path / "sub").mkdir()
    for output in (source, tmp_path / "sub" / ".." / "in.svg", tmp_path / "link.svg"):
        with pytest.raises(OutputError, match="is the input"):
            check_output_file(output, (".svg",), [source])
    assert same_file(tmp_path / "nowhere" / ".." / "x", tmp_path / "x")


def test_folder_outputs(tmp_path):
    (tmp_path / "file").write_text("x")
    assert check_output_folder(tmp_path / "a" / "b") == tmp_path / "a" / "b"
    assert not (tmp_path / "a").exists()  # checked, not created
    with pytest.raises(OutputError, match="is a file, not a folder"):
        check_output_folder(tmp_path / "file")
    with pytest.raises(OutputError, match="cannot create .* is a file"):
        check_output_folder(tmp_path / "file" / "sub" / "deeper")


def test_batch_names_never_collide():
    inputs = [Path("x/pic.jpg"), Path("x/pic.png"), Path("x/Pic.gif"), Path("x/other.png")]
    names = [target.name for _, target in batch_outputs(inputs, Path("out"))]
    assert names == ["pic.jpg.svg", "pic.png.svg", "Pic.gif.svg", "other.svg"]


def test_batch_twice_the_same_file_is_done_once_and_true_collisions_are_refused(tmp_path):
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    one = tmp_path / "a" / "pic.png"
    pairs = batch_outputs([one, tmp_path / "a" / ".." / "a" / "pic.png"], tmp_path / "out")
    assert pairs == [(one, tmp_path / "out" / "pic.svg")]
    with pytest.raises(OutputError, match="a/pic.png and .*b/pic.png would both be written"):
        batch_outputs([one, tmp_path / "b" / "pic.png"], tmp_path / "out")
    with pytest.raises(OutputError, match="is an input of this batch"):
        batch_outputs([tmp_path / "x.svg", one], tmp_path)
