"""Tests of trace_masks and its parts: traced paths, rendered by the project's rasterizer (and
resvg as a cross-check), reproduce the masks they came from."""

import io
import time

import numpy as np
import pytest
import resvg_py
from PIL import Image
from scipy import ndimage

from samvg.errors import InputError
from samvg.scene import Scene
from samvg.trace import (
    DEFAULT_MIN_AREA,
    fit_cubics,
    mask_contour,
    select_corners,
    trace_components,
    trace_masks,
    trace_masks_with_info,
)
from samvg.vector_image import VectorImage
from tests.trace.synthetic import (
    blob,
    disk,
    ellipse,
    iou,
    l_shape,
    random_blobs,
    render_coverage,
    rounded_rectangle,
    star,
)

SMOOTH = {
    "disk": disk(),
    "ellipse": ellipse(),
    "blob": blob(),
    **{f"rounded_rectangle_{d}deg": rounded_rectangle(128, d) for d in (0, 15, 30, 45)},
}


def traced_iou(mask: np.ndarray, segments: int, **options) -> float:
    paths = trace_components(mask, segments, **options)
    coverage = render_coverage([p.points for p in paths], mask.shape[1], mask.shape[0])
    return iou(coverage, mask)


def filled(mask: np.ndarray, min_area: float = DEFAULT_MIN_AREA) -> np.ndarray:
    """The mask as the tracer models it: components of min_area pixels or more, holes filled."""
    labels, count = ndimage.label(mask)
    result = np.zeros_like(mask)
    for label in range(1, count + 1):
        component = labels == label
        if component.sum() >= min_area:
            result |= ndimage.binary_fill_holes(component)
    return result


@pytest.mark.parametrize("name", sorted(SMOOTH))
def test_smooth_shapes_at_four_segments(name):
    assert traced_iou(SMOOTH[name], 4) >= 0.97


def test_resvg_agrees_with_the_project_rasterizer():
    mask = blob()
    image = trace_masks([mask], np.zeros((128, 128, 3), np.uint8))
    svg = VectorImage.from_scene(image).to_svg(precision=3)
    png = resvg_py.svg_to_bytes(svg_string=svg, background="#ffffff")
    coverage = 1.0 - np.asarray(Image.open(io.BytesIO(bytes(png))).convert("L"), float) / 255.0
    assert iou(coverage, mask) >= 0.97
    assert iou(coverage, mask) == pytest.approx(traced_iou(mask, 4), abs=0.005)


@pytest.mark.parametrize("make", [l_shape, star], ids=["l_shape", "star"])
def test_cornered_shapes_improve_with_more_segments(make):
    mask = make()
    scores = [traced_iou(mask, k) for k in (2, 3, 4, 6, 8)]
    assert all(b >= a - 0.005 for a, b in zip(scores, scores[1:], strict=False))
    assert scores[-1] >= scores[0] + 0.1
    assert scores[-1] >= 0.98


def test_star_corners_are_its_vertices():
    contour = mask_contour(star())
    corners = contour[select_corners(contour, 10)]
    angles = np.pi * np.arange(10) / 5 - np.pi / 2
    radii = np.where(np.arange(10) % 2 == 0, 0.4 * 128, 0.18 * 128)
    vertices = 64 + np.stack([radii * np.cos(angles), radii * np.sin(angles)], axis=1)
    distances = np.linalg.norm(vertices[:, None] - corners[None], axis=2).min(axis=1)
    assert distances.max() < 2.0


def test_every_component_becomes_a_path_largest_first():
    mask = np.zeros((128, 128), bool)
    yy, xx = np.mgrid[:128, :128]
    mask |= (xx - 30) ** 2 + (yy - 30) ** 2 < 20**2
    mask |= (xx - 90) ** 2 + (yy - 90) ** 2 < 30**2
    mask[100:120, 5:40] = True
    paths = trace_components(mask, 4)
    assert len(paths) == 3
    areas = [p.area for p in paths]
    assert areas == sorted(areas, reverse=True)
    labels, _ = ndimage.label(mask)
    assert sorted(areas) == sorted(np.bincount(labels.ravel())[1:].tolist())
    for path in paths:
        coverage = render_coverage([path.points], 128, 128)
        component = labels == np.bincount(labels[coverage > 0.5]).argmax()
        assert iou(coverage, component) >= 0.97


def test_holes_are_filled():
    yy, xx = np.mgrid[:128, :128]
    radius_squared = (xx - 64.5) ** 2 + (yy - 63.5) ** 2
    ring = (radius_squared < 40**2) & (radius_squared >= 15**2)
    (path,) = trace_components(ring, 4)
    assert path.area == int(ring.sum())
    coverage = render_coverage([path.points], 128, 128)
    assert iou(coverage, radius_squared < 40**2) >= 0.97


@pytest.mark.parametrize("where", ["left", "corner", "everywhere", "frame"])
def test_masks_touching_the_border(where):
    yy, xx = np.mgrid[:96, :128]
    if where == "left":  # a disk cut by the left edge: two sharp corners on the border
        mask = (xx + 10) ** 2 + (yy - 48) ** 2 < 40**2
    elif where == "corner":
        mask = (xx - 120) ** 2 + (yy - 90) ** 2 < 50**2
    elif where == "everywhere":
        mask = np.ones((96, 128), bool)
    else:  # a frame along all four borders: its hole is filled, the whole canvas is covered
        mask = ~((xx > 10) & (xx < 117) & (yy > 10) & (yy < 85))
    (path,) = trace_components(mask, 4)
    coverage = render_coverage([path.points], 128, 96)
    assert iou(coverage, filled(mask)) >= 0.97
    contour = mask_contour(mask)
    assert contour[:, 0].min() >= 0 and contour[:, 1].min() >= 0
    assert contour[:, 0].max() <= 128 and contour[:, 1].max() <= 96


def test_contour_is_closed_clockwise_on_screen_and_outer_only():
    mask = np.zeros((20, 20), bool)
    mask[3:15, 4:16] = True
    mask[6:9, 7:10] = False  # a hole: ignored
    contour = mask_contour(mask)
    x, y = contour[:, 0], contour[:, 1]
    signed_area = 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)
    assert signed_area == pytest.approx(144 - 4 * 0.125)  # corners cut by the 0.5 iso-line
    steps = np.linalg.norm(np.diff(np.vstack([contour, contour[:1]]), axis=0), axis=1)
    assert steps.max() <= 1.0 + 1e-12


def test_tiny_components_and_min_area():
    mask = np.zeros((64, 64), bool)
    mask[10:40, 10:40] = True
    mask[50:53, 50:53] = True  # 9 pixels
    mask[60, 2] = True  # 1 pixel
    assert [p.area for p in trace_components(mask, 4)] == [900]
    assert [p.area for p in trace_components(mask, 4, min_area=9)] == [900, 9]
    tiny = trace_components(mask, 8, min_area=1)
    assert [p.area for p in tiny] == [900, 9, 1]
    for path in tiny:
        assert path.points.shape == (24, 2) and np.all(np.isfinite(path.points))
    block = np.zeros((64, 64), bool)
    block[50:53, 50:53] = True
    assert iou(render_coverage([tiny[1].points], 64, 64), block) >= 0.75


def test_segment_counts_from_one_to_twelve():
    mask = blob()
    for segments in (1, 2, 3, 5, 7, 12):
        (path,) = trace_components(mask, segments)
        assert path.points.shape == (3 * segments, 2)
        assert np.all(np.isfinite(path.points))
    assert traced_iou(mask, 12) >= 0.99


def test_trace_masks_paints_in_order_with_mean_colours():
    image = np.zeros((64, 64, 3), np.uint8)
    image[:, :32] = (200, 40, 0)
    image[:, 32:] = (0, 100, 250)
    background = np.zeros((64, 64), bool)
    background[4:60, 4:60] = True
    left = np.zeros((64, 64), bool)
    left[10:50, 8:30] = True
    empty = np.zeros((64, 64), bool)
    scene, info = trace_masks_with_info([background, empty, left], image)
    assert isinstance(scene, Scene) and (scene.width, scene.height) == (64, 64)
    result = VectorImage.from_scene(scene)
    assert result.background is None
    assert [p.mask_index for p in info] == [0, 2]
    assert [p.area for p in info] == [56 * 56, 40 * 22]
    half = np.array([200, 40, 0]) / 255.0 * 0.5 + np.array([0, 100, 250]) / 255.0 * 0.5
    assert result.paths[0].fill == pytest.approx((*half, 1.0), abs=1e-5)
    assert result.paths[1].fill == pytest.approx((200 / 255, 40 / 255, 0.0, 1.0), abs=1e-5)
    for path, traced in zip(result.paths, info, strict=True):
        np.testing.assert_array_equal(path.points, traced.points)
    as_float = VectorImage.from_scene(
        trace_masks(np.stack([background, empty, left]), image / 255.0)
    )
    for a, b in zip(as_float.paths, result.paths, strict=True):
        np.testing.assert_allclose(a.points, b.points)
        assert a.fill == pytest.approx(b.fill, abs=1e-5)
    rendered = result.render()
    assert rendered[30, 20] == pytest.approx([200 / 255, 40 / 255, 0.0], abs=1e-3)


def test_masks_of_zeros_and_ones_are_accepted():
    mask = disk(64)
    reference = trace_masks([mask], np.zeros((64, 64, 3)))
    for dtype in (np.uint8, np.int64, np.float32, np.float64):
        other = trace_masks([mask.astype(dtype)], np.zeros((64, 64, 3)))
        np.testing.assert_array_equal(other.points, reference.points)
    assert trace_masks([], np.zeros((8, 8, 3))).path_count == 0


def test_fitting_error_is_reported():
    (round_path,) = trace_components(disk(), 4)
    assert 0.0 < round_path.rms_error <= round_path.max_error < 1.0
    (star_path,) = trace_components(star(), 4)
    assert star_path.max_error > 3.0  # ten tips cannot follow four cubics
    assert star_path.rms_error > round_path.rms_error


@pytest.mark.parametrize(
    ("masks", "image", "message"),
    [
        ([np.full((8, 8), 0.5)], np.zeros((8, 8, 3)), "boolean"),
        ([np.full((8, 8), np.nan)], np.zeros((8, 8, 3)), "boolean"),
        ([np.array([["a"] * 8] * 8)], np.zeros((8, 8, 3)), "boolean"),
        ([np.zeros((8, 8, 1), bool)], np.zeros((8, 8, 3)), "two-dimensional"),
        ([np.zeros((8, 9), bool)], np.zeros((8, 8, 3)), "same height and width"),
        (np.zeros((8, 8), bool), np.zeros((8, 8, 3)), "wrap a single mask in a list"),
        ("masks", np.zeros((8, 8, 3)), "list of"),
        ([np.zeros((8, 8), bool)], np.zeros((8, 8)), "RGB"),
        ([np.zeros((8, 8), bool)], np.full((8, 8, 3), 2.0), r"\[0, 1\]"),
        ([np.zeros((8, 8), bool)], np.zeros((8, 8, 3), np.int32), "uint8 or float"),
    ],
)
def test_bad_input_is_a_clear_error(masks, image, message):
    with pytest.raises(InputError, match=message):
        trace_masks(masks, image)


def test_bad_options_are_clear_errors():
    masks, image = [disk(32)], np.zeros((32, 32, 3))
    with pytest.raises(InputError, match="segments_per_path"):
        trace_masks(masks, image, segments_per_path=0)
    with pytest.raises(InputError, match="min_area"):
        trace_masks(masks, image, min_area=-1)
    with pytest.raises(InputError, match="segments"):
        trace_components(disk(32), 2.5)


def test_fit_recovers_a_cubic_from_unevenly_spaced_samples():
    controls = np.array([[[0.0, 0.0], [10.0, 30.0], [40.0, -10.0], [50.0, 20.0]]])
    t = np.sort(np.concatenate([[0.0, 1.0], np.random.default_rng(1).random(60) ** 2]))
    s = 1 - t
    basis = np.stack([s**3, 3 * t * s**2, 3 * t**2 * s, t**3], axis=1)
    points = basis @ controls[0]
    offsets = np.array([0, len(points)])
    errors = [fit_cubics(points, offsets, iterations=n).distances.max() for n in (0, 4, 16, 100)]
    assert errors == sorted(errors, reverse=True) and errors[0] > 0.3  # chord-length: poor
    fits = fit_cubics(points, offsets, iterations=100)
    np.testing.assert_allclose(fits.controls, controls, atol=1e-3)
    assert fits.distances.max() < 1e-3


def test_hundred_masks_at_512_px_are_fast():
    masks = random_blobs(100, 512)
    rng = np.random.default_rng(0)
    image = rng.integers(0, 256, (512, 512, 3), dtype=np.uint8)
    trace_masks(masks[:1], image)  # compile / load the numba kernel
    start = time.process_time()
    result = trace_masks(masks, image)
    elapsed = time.process_time() - start
    assert result.path_count == 100
    assert elapsed < 2.0  # typically ~0.2 s; generous for a shared machine


@pytest.mark.slow
def test_real_sam_masks(photo_sam_masks):
    image, masks = photo_sam_masks
    assert len(masks) >= 5
    result, info = trace_masks_with_info(masks, image, segments_per_path=4)
    height, width = image.shape[:2]
    scores = []
    for index, mask in enumerate(masks):
        points = [p.points for p in info if p.mask_index == index]
        coverage = render_coverage(points, width, height) if points else np.zeros(mask.shape)
        scores.append(iou(coverage, filled(mask)))
    assert np.mean(scores) >= 0.9
    assert result.path_count == len(info)
    traced = {p.mask_index for p in info}
    assert all(i in traced for i, m in enumerate(masks) if m.sum() >= DEFAULT_MIN_AREA)
