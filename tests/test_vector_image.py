"""Tests of the scene model: SVG parsing, writing, round trips, errors for what it cannot hold."""

import numpy as np
import pytest

from samvg import InputError, VectorImage, VectorPath


def random_image(seed: int, paths: int = 5, segments: int = 4) -> VectorImage:
    rng = np.random.default_rng(seed)
    shapes = [
        VectorPath(rng.uniform(-10, 70, size=(3 * segments, 2)), tuple(rng.uniform(0, 1, 4)))
        for _ in range(paths)
    ]
    return VectorImage(64, 48, shapes, background=(0.2, 0.4, 0.6))


def test_round_trip_keeps_geometry_colours_and_background():
    image = random_image(0)
    again = VectorImage.from_svg(image.to_svg(precision=6))
    assert (again.width, again.height) == (64, 48)
    assert again.background == pytest.approx((51 / 255, 102 / 255, 153 / 255))
    assert len(again.paths) == len(image.paths)
    for before, after in zip(image.paths, again.paths, strict=True):
        np.testing.assert_allclose(after.points, before.points, atol=1e-6)
        np.testing.assert_allclose(after.fill[:3], before.fill[:3], atol=0.5 / 255)
        assert after.fill[3] == pytest.approx(before.fill[3], abs=5e-4)


def test_precision_rounds_coordinates():
    image = VectorImage(10, 10, [VectorPath(np.array([[1.23456, 2.5], [3, 4], [5, 6.789]]))])
    text = image.to_svg(precision=2)
    # relative steps between the rounded points: (3, 4) - (1.23, 2.5) = (1.77, 1.5), ...
    assert 'd="M1.23 2.5c1.77 1.5 3.77 4.29 0 0z"' in text
    assert 'width="10" height="10" viewBox="0 0 10 10"' in text


def test_invalid_paths_and_canvas_are_rejected():
    with pytest.raises(InputError, match=r"\(3K, 2\)"):
        VectorPath(np.zeros((4, 2)))
    with pytest.raises(InputError, match="RGBA"):
        VectorPath(np.zeros((3, 2)), (2.0, 0, 0, 1))
    with pytest.raises(InputError, match="width"):
        VectorImage(0, 10)


def test_paths_of_different_lengths_are_packed_in_one_scene():
    image = VectorImage(
        10,
        10,
        [VectorPath(np.arange(6.0).reshape(3, 2)), VectorPath(np.arange(12.0).reshape(6, 2))],
    )
    scene = image.scene
    assert scene.points.shape == (9, 2) and list(scene.offsets) == [0, 3, 9]
    assert list(scene.segment_counts()) == [1, 2] and scene.colours().shape == (2, 4)
    np.testing.assert_allclose(image.paths[1].points, np.arange(12.0).reshape(6, 2))


def test_nan_points_are_refused_at_construction():
    with pytest.raises(InputError, match="finite"):
        VectorPath(np.full((3, 2), np.nan))


def test_save_is_atomic(tmp_path, monkeypatch):
    target = tmp_path / "out.svg"
    target.write_text("old")
    image = random_image(1)

    def failing_replace(*_args):
        raise OSError("disk full")

    monkeypatch.setattr("os.replace", failing_replace)
    with pytest.raises(OSError, match="disk full"):
        image.save(target)
    assert target.read_text() == "old"
    assert list(tmp_path.iterdir()) == [target]
    monkeypatch.undo()
    image.save(target)
    assert VectorImage.load(target).to_svg() == image.to_svg()


def test_load_missing_file_is_a_clear_error(tmp_path):
    with pytest.raises(InputError, match="not found"):
        VectorImage.load(tmp_path / "missing.svg")


def test_real_svg_renders_like_resvg(bench_dir):
    import io

    import resvg_py
    from PIL import Image

    source = bench_dir / "emoji" / "twemoji_rainbow.svg"
    image = VectorImage.load(source)
    ours = image.render(scale=512 / image.width)
    png = resvg_py.svg_to_bytes(svg_path=str(source), width=512, height=512, background="#ffffff")
    theirs = np.asarray(Image.open(io.BytesIO(bytes(png))).convert("RGB"), np.float32) / 255.0
    assert ours.shape == theirs.shape == (512, 512, 3)
    assert np.abs(ours - theirs).mean() <= 1 / 255


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_points_are_refused_at_construction(bad):
    from samvg.scene import FlatPaint, Scene

    points = np.array([[0, 0], [5, 0], [5, bad]], float)
    with pytest.raises(InputError, match="finite"):
        VectorPath(points)
    with pytest.raises(InputError, match="finite"):
        Scene.from_paths(8, 8, [(points, FlatPaint((0.0, 0.0, 0.0)))])
    good = Scene.from_paths(8, 8, [(np.ones((3, 2)), FlatPaint((0.0, 0.0, 0.0)))])
    with pytest.raises(InputError, match="non-finite"):
        good.with_geometry(points)  # a diverged fit cannot become SVG either


@pytest.mark.parametrize("precision", [-1, 11, 2.5, True, "2"])
def test_precision_outside_0_to_10_is_refused(precision, tmp_path):
    image = random_image(1)
    with pytest.raises(InputError, match="precision must be an integer from 0 to 10"):
        image.to_svg(precision=precision)
    with pytest.raises(InputError, match="precision"):
        image.save(tmp_path / "x.svg", precision=precision)
    assert not (tmp_path / "x.svg").exists()
    assert image.to_svg(precision=0) and image.to_svg(precision=np.int64(10))
