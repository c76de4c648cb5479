"""Tests of the command line: real runs, plain one-line errors, no half-written outputs."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from samvg import Config, VectorImage
from samvg.cli import main
from samvg.io import read_image

SAMPLE = Path(__file__).resolve().parents[1] / "samvg" / "samples" / "sailing_sunset.png"


def test_render_writes_png(tmp_path):
    svg = tmp_path / "a.svg"
    svg.write_text(
        '<svg xmlns="http://www.w3.org/2000/svg" width="20" height="10">'
        '<rect width="20" height="10" fill="#00ff00"/>'
        '<path d="M0 0 H10 V10 H0 Z" fill="red"/></svg>'
    )
    assert main(["render", str(svg), "-o", str(tmp_path / "a.png"), "--scale", "2"]) == 0
    pixels = read_image(tmp_path / "a.png")
    assert pixels.shape == (20, 40, 3)
    assert tuple(pixels[5, 5]) == (255, 0, 0) and tuple(pixels[5, 35]) == (0, 255, 0)


def test_bad_svg_is_one_line_error_and_no_output(tmp_path, capsys):
    svg = tmp_path / "bad.svg"
    svg.write_text(
        '<svg xmlns="http://www.w3.org/2000/svg" width="9" height="9"><text>hi</text></svg>'
    )
    assert main(["render", str(svg), "-o", str(tmp_path / "bad.png")]) == 1
    error = capsys.readouterr().err
    assert "error:" in error and "svg/text[1]" in error and "Traceback" not in error
    assert not (tmp_path / "bad.png").exists()


def test_corrupt_image_is_a_clear_error(tmp_path, capsys):
    broken = tmp_path / "broken.png"
    broken.write_bytes(b"\x89PNG\r\n\x1a\n garbage")
    assert main(["vectorize", str(broken), "-o", str(tmp_path / "out.svg")]) == 1
    assert "cannot read image" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["broken.png"]


def test_wrong_output_suffix_and_missing_folder(tmp_path, capsys):
    assert main(["vectorize", str(SAMPLE), "-o", str(tmp_path / "out.png")]) == 1
    assert main(["vectorize", str(SAMPLE), "-o", str(tmp_path / "no" / "out.svg")]) == 1
    err = capsys.readouterr().err
    assert "should end in .svg" in err and "does not exist" in err


def test_missing_checkpoint_is_a_clear_error(tmp_path):
    completed = subprocess.run(
        [
            sys.executable,
            "-m",
            "samvg.cli",
            "vectorize",
            str(SAMPLE),
            "-o",
            str(tmp_path / "o.svg"),
            "--checkpoint",
            str(tmp_path / "nowhere.pt"),
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert completed.returncode == 1
    assert "nowhere.pt" in completed.stderr and "Traceback" not in completed.stderr
    assert not (tmp_path / "o.svg").exists()


@pytest.mark.slow
def test_vectorize_bundled_sample_end_to_end(tmp_path, sam_checkpoint):
    output, preview = tmp_path / "sample.svg", tmp_path / "sample.png"
    code = main(
        [
            "vectorize",
            str(SAMPLE),
            "-o",
            str(output),
            "--preview",
            str(preview),
            "--checkpoint",
            str(sam_checkpoint),
            "--iterations",
            "60",
            "--no-lpips",
            "--save-stages",
            str(tmp_path / "stages"),
        ]
    )
    assert code == 0
    stages = sorted(p.name for p in (tmp_path / "stages").iterdir())
    assert {"1_masks.png", "2_initial.svg", "3_optimized.svg", "5_final.svg"} <= set(stages)
    assert "comparison.png" in stages
    assert (
        VectorImage.load(tmp_path / "stages" / "5_final.svg").to_svg()
        == VectorImage.load(output).to_svg()
    )
    result = VectorImage.load(output)
    target = read_image(SAMPLE).astype(np.float32) / 255.0
    assert (result.width, result.height) == (512, 280)
    assert 5 <= result.scene.element_count <= 150
    # issue 11's size goal: at most a third of VTracer's default SVG (191 KB, 100 paths)
    assert output.stat().st_size <= 191_000 / 3
    mse = float(np.mean((result.render() - target) ** 2))
    flat_fill_mse = float(np.mean((target - target.mean(axis=(0, 1))) ** 2))
    assert mse < 0.02 and mse < flat_fill_mse / 3, (mse, flat_fill_mse)
    assert read_image(preview).shape == target.shape


@pytest.mark.parametrize(
    ("option", "message"),
    [
        (["--model", "vit_q"], "unknown SAM model 'vit_q'"),
        (["--iterations", "-3"], "iterations must be an integer >= 0"),
        (["--segments", "0"], "segments must be an integer >= 1"),
        (["--size", "4"], "size must be an integer >= 8"),
    ],
)
def test_bad_settings_are_clear_errors(tmp_path, capsys, option, message):
    assert main(["vectorize", str(SAMPLE), "-o", str(tmp_path / "o.svg"), *option]) == 1
    assert message in capsys.readouterr().err
    assert not (tmp_path / "o.svg").exists()


def test_batch_skips_done_images_and_survives_failures(tmp_path, capsys):
    from PIL import Image

    inputs, outputs = tmp_path / "in", tmp_path / "out"
    inputs.mkdir()
    outputs.mkdir()
    Image.new("RGB", (30, 20), (250, 10, 10)).save(inputs / "red.png")
    Image.new("L", (30, 20), 90).save(inputs / "grey.png")  # grayscale input
    Image.new("RGB", (30, 20), (0, 0, 255)).save(inputs / "done.png")
    (outputs / "done.svg").write_text("<svg/>")
    (inputs / "broken.jpg").write_bytes(b"\xff\xd8 not a jpeg")
    (inputs / "notes.txt").write_text("ignored: not an image")
    code = main([str(inputs), "-o", str(outputs), "--quiet"])
    assert code == 1
    err = capsys.readouterr().err
    assert "2 vectorized, 1 skipped (already done), 1 failed" in err
    assert "broken.jpg" in err and "Traceback" not in err
    assert (outputs / "done.svg").read_text() == "<svg/>"
    assert sorted(p.name for p in outputs.iterdir()) == ["done.svg", "grey.svg", "red.svg"]
    grey = VectorImage.load(outputs / "grey.svg")
    assert grey.paths == [] and np.allclose(grey.background, (90 / 255,) * 3, atol=1 / 255)
    # a glob selects the same images; everything is done now, so nothing fails
    assert main([str(inputs / "*.png"), "-o", str(outputs), "--quiet"]) == 0


def test_batch_needs_an_output_folder(tmp_path, capsys):
    assert main([str(SAMPLE), str(SAMPLE), "-o", str(tmp_path / "x.svg")]) == 1
    assert "-o must be a folder" in capsys.readouterr().err


def test_batch_names_inputs_whose_stems_collide_by_their_whole_name(tmp_path, sam_checkpoint):
    from PIL import Image

    inputs, outputs = tmp_path / "in", tmp_path / "out"
    inputs.mkdir()
    Image.new("RGB", (30, 20), (250, 10, 10)).save(inputs / "pic.png")
    Image.new("RGB", (30, 20), (10, 10, 250)).save(inputs / "pic.jpg", quality=100)
    Image.new("RGB", (30, 20), (10, 250, 10)).save(inputs / "other.png")
    options = ["-o", str(outputs), "--quiet", "--no-lpips", "--checkpoint", str(sam_checkpoint)]
    assert main([str(inputs), *options]) == 0
    assert sorted(p.name for p in outputs.iterdir()) == ["other.svg", "pic.jpg.svg", "pic.png.svg"]
    assert VectorImage.load(outputs / "pic.png.svg").background[0] > 0.9  # red, not the blue
    assert VectorImage.load(outputs / "pic.jpg.svg").background[2] > 0.9
    # the same file named twice is done once
    assert (
        main([str(inputs / "other.png"), str(inputs / "other.png"), *options, "--overwrite"]) == 0
    )


def test_a_one_pixel_image_becomes_a_one_colour_svg(tmp_path, sam_checkpoint):
    from PIL import Image

    Image.new("RGB", (1, 1), (12, 34, 56)).save(tmp_path / "one.png")
    code = main([str(tmp_path / "one.png"), "-o", str(tmp_path / "one.svg"), "--quiet"])
    assert code == 0
    image = VectorImage.load(tmp_path / "one.svg")
    assert (image.width, image.height) == (1, 1) and image.paths == []
    assert np.allclose(image.background, np.array((12, 34, 56)) / 255.0, atol=1e-6)


def test_a_full_disk_stops_a_batch_with_one_line(tmp_path, capsys, monkeypatch, sam_checkpoint):
    import errno

    from PIL import Image

    inputs = tmp_path / "in"
    inputs.mkdir()
    for name in ("a.png", "b.png"):
        Image.new("RGB", (30, 20), (250, 10, 10)).save(inputs / name)

    def full(_fd):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr("os.fsync", full)
    options = ["-o", str(tmp_path / "out"), "--quiet", "--checkpoint", str(sam_checkpoint)]
    assert main([str(inputs), *options]) == 1
    err = capsys.readouterr().err
    assert err.splitlines() == [
        f"error: cannot write {tmp_path / 'out' / 'a.svg'}: No space left on device"
    ]
    assert list((tmp_path / "out").iterdir()) == []


def test_several_line_messages_are_joined_into_one():
    from samvg.cli import one_line

    message = "could not find x. Tried:\n  cache: not found\n  download: failed\nTo fix: put it"
    assert one_line(message) == (
        "could not find x. Tried: cache: not found; download: failed; To fix: put it"
    )


def test_gradient_fills_can_be_asked_for_or_refused():
    from samvg.cli import _config, build_parser

    def config(*options: str):
        return _config(build_parser().parse_args(["vectorize", "in.png", "-o", "o.svg", *options]))

    assert config("--gradients").fit.gradients is True
    assert config("--no-gradients").fit.gradients is False
    assert config().fit.gradients == Config().fit.gradients
    assert config("--preset", "paper", "--gradients").fit.gradients is True


def test_texture_layers_can_be_refused():
    from samvg.cli import _config, build_parser

    def config(*options: str):
        return _config(build_parser().parse_args(["vectorize", "in.png", "-o", "o.svg", *options]))

    assert config("--paths", "16").missing.texture_layers is True
    assert config("--paths", "16", "--no-texture").missing.texture_layers is False
