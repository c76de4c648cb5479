"""Tests of image reading (modes, bit depths, corrupt files) and atomic writing."""

import numpy as np
import pytest
from PIL import Image

from samvg import InputError, OutputError
from samvg.imaging import to_rgb_uint8
from samvg.io import read_image, write_png


def test_modes_and_depths_become_rgb_uint8(tmp_path):
    gray16 = (np.arange(64 * 32, dtype=np.uint16).reshape(32, 64) * 31).astype(np.uint16)
    Image.fromarray(gray16).save(tmp_path / "gray16.png")
    rgba = np.zeros((8, 8, 4), np.uint8)
    rgba[..., 0] = 255
    rgba[..., 3] = 128
    Image.fromarray(rgba, "RGBA").save(tmp_path / "rgba.png")
    Image.fromarray(np.full((8, 8), 77, np.uint8), "L").save(tmp_path / "gray.png")
    Image.fromarray(np.full((8, 8, 3), 9, np.uint8)).quantize(4).save(tmp_path / "pal.png")

    gray = read_image(tmp_path / "gray16.png")
    assert gray.dtype == np.uint8 and gray.shape == (32, 64, 3)
    assert gray[-1, -1, 0] == round(int(gray16[-1, -1]) / 65535 * 255)
    red = read_image(tmp_path / "rgba.png")
    assert tuple(red[0, 0]) == (255, 127, 127)  # half-transparent red over white
    assert tuple(read_image(tmp_path / "gray.png")[3, 3]) == (77, 77, 77)
    assert tuple(read_image(tmp_path / "pal.png")[0, 0]) == (9, 9, 9)


def test_arrays_of_floats_and_bools_convert():
    assert to_rgb_uint8(np.ones((4, 4)))[0, 0, 0] == 255
    assert to_rgb_uint8(np.zeros((4, 4), bool))[0, 0, 0] == 0
    with pytest.raises(InputError, match="NaN"):
        to_rgb_uint8(np.full((4, 4, 3), np.nan))
    assert to_rgb_uint8(np.full((1, 1, 3), 7, np.uint8)).shape == (1, 1, 3)  # one pixel is an image
    with pytest.raises(InputError, match="too small"):
        to_rgb_uint8(np.zeros((1, 1, 3), np.uint8), min_side=2)  # what SAM asks for
    with pytest.raises(InputError, match="shape"):
        to_rgb_uint8(np.zeros((4, 4, 5), np.uint8))


def test_corrupt_missing_and_truncated_files_are_clear_errors(tmp_path):
    (tmp_path / "junk.png").write_bytes(b"not an image at all")
    with pytest.raises(InputError, match="cannot read image"):
        read_image(tmp_path / "junk.png")
    with pytest.raises(InputError, match="not found"):
        read_image(tmp_path / "missing.png")
    Image.fromarray(np.zeros((64, 64, 3), np.uint8) + 100).save(tmp_path / "full.png")
    data = (tmp_path / "full.png").read_bytes()
    (tmp_path / "cut.png").write_bytes(data[: len(data) // 2])
    with pytest.raises(InputError, match="cannot read image"):
        read_image(tmp_path / "cut.png")


def test_write_png_round_trip_and_missing_folder(tmp_path):
    image = np.linspace(0, 1, 5 * 6 * 3).reshape(5, 6, 3).astype(np.float32)
    write_png(tmp_path / "a.png", image)
    np.testing.assert_array_equal(read_image(tmp_path / "a.png"), np.round(image * 255))
    with pytest.raises(OutputError, match="does not exist"):
        write_png(tmp_path / "no" / "a.png", image)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.png"]


def test_written_files_get_default_permissions(tmp_path):
    import os

    write_png(tmp_path / "p.png", np.zeros((4, 4, 3)))
    umask = os.umask(0)
    os.umask(umask)
    assert (tmp_path / "p.png").stat().st_mode & 0o777 == 0o666 & ~umask
