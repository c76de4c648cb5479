"""Tests of samvg.svg.reader.read_svg: path commands, transforms, fills, the pixel canvas, exact
read-back of samvg's own SVG, refusals of what the scene cannot hold, and renders against resvg."""

import io
import re
from pathlib import Path

import numpy as np
import pytest

from samvg.errors import InputError
from samvg.scene import LinearGradient, RadialGradient
from samvg.svg.reader import ParsedSvg, read_svg

GOLDEN = Path(__file__).parents[1] / "data" / "golden"
TRIANGLE = 'd="M0 0 L5 5 L0 5 Z"'


def svg(body: str, width: object = 10, height: object = 10, extra: str = "") -> str:
    return (
        '<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" '
        f'width="{width}" height="{height}" {extra}>{body}</svg>'
    )


def only_path(text: str) -> tuple[np.ndarray, tuple[float, float, float, float]]:
    parsed = read_svg(text)
    assert len(parsed.paths) == 1
    return parsed.paths[0]


def samples(points: np.ndarray, per_segment: int = 32) -> np.ndarray:
    """Points along every cubic segment of a closed path."""
    count = points.shape[0]
    t = np.linspace(0.0, 1.0, per_segment)[:, None]
    out = []
    for k in range(count // 3):
        p0, p1, p2 = points[3 * k : 3 * k + 3]
        p3 = points[(3 * k + 3) % count]
        out.append(
            (1 - t) ** 3 * p0 + 3 * (1 - t) ** 2 * t * p1 + 3 * (1 - t) * t**2 * p2 + t**3 * p3
        )
    return np.concatenate(out)


def line_thirds(start, end) -> list[list[float]]:
    start, end = np.asarray(start, float), np.asarray(end, float)
    return [list(start), list(start + (end - start) / 3), list(start + 2 * (end - start) / 3)]


def render(parsed: ParsedSvg) -> np.ndarray:
    from samvg.render import rasterize

    colours = np.array([fill for _, fill in parsed.paths], dtype=np.float64).reshape(-1, 4)
    background = parsed.background if parsed.background is not None else (1.0, 1.0, 1.0)
    image = rasterize(
        [points for points, _ in parsed.paths], colours, parsed.width, parsed.height, background
    )
    return image.detach().cpu().numpy().astype(np.float64)


def resvg_render(text: str, width: int, height: int) -> np.ndarray:
    resvg_py = pytest.importorskip("resvg_py")
    from PIL import Image

    png = resvg_py.svg_to_bytes(svg_string=text, width=width, height=height, background="#ffffff")
    return np.asarray(Image.open(io.BytesIO(bytes(png))).convert("RGB"), np.float64) / 255.0


# ---------------------------------------------------------------------- samvg's own SVG
SAMVG_TEXT = """\
<svg xmlns="http://www.w3.org/2000/svg" width="512" height="280" viewBox="0 0 512 280">
<rect width="512" height="280" fill="#f2e6d0"/>
<path d="M10.5 20C30 40 50.25 60 70 80C1 2 3 4 10.5 20Z" fill="#123456" fill-opacity="0.93"/>
</svg>
"""


def test_samvg_written_svg_reads_back_exactly():
    parsed = read_svg(SAMVG_TEXT)
    assert (parsed.width, parsed.height) == (512, 280)
    assert parsed.background == (0xF2 / 255, 0xE6 / 255, 0xD0 / 255)
    points, fill = parsed.paths[0]
    assert points.dtype == np.float64
    # [M point, c1, c2, next start, c1, c2]; no zero-length closing segment.
    expected = [[10.5, 20], [30, 40], [50.25, 60], [70, 80], [1, 2], [3, 4]]
    assert np.array_equal(points, np.array(expected, dtype=np.float64))
    assert fill == (0x12 / 255, 0x34 / 255, 0x56 / 255, 0.93)


def test_subpaths_apart_or_one_way_round_read_as_one_compound_path():
    apart = read_svg(svg('<path d="M0 0 L5 5 L0 5 Z M6 6 L8 8 L6 8 Z" fill-opacity=".5"/>'))
    assert len(apart.paths) == 2 and apart.joined == [False, True]
    # opaque, overlapping, both clockwise on the screen: the union, which painting both gives
    overlapping = read_svg(svg('<path d="M0 0 L10 0 L10 10 Z M2 1 L9 1 L9 8 Z"/>'))
    assert overlapping.joined == [False, True]
    single = read_svg(svg('<path d="M0 0 L5 5 L0 5 Z"/><path d="M6 6 L8 8 L6 8 Z"/>'))
    assert single.joined == [False, False]


def _number(value: float) -> str:
    text = f"{value:.6f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def test_random_samvg_style_paths_read_back_to_the_numbers_in_the_text():
    rng = np.random.default_rng(7)
    lines = []
    for _ in range(20):
        points = rng.uniform(-30, 90, size=(3 * int(rng.integers(1, 6)), 2))
        pairs = [f"{_number(x)} {_number(y)}" for x, y in points]
        count = len(pairs)
        segments = "".join(
            f"C{pairs[3 * k + 1]} {pairs[3 * k + 2]} {pairs[(3 * k + 3) % count]}"
            for k in range(count // 3)
        )
        lines.append(f'<path d="M{pairs[0]}{segments}Z" fill="#0a0b0c" fill-opacity="0.5"/>')
    parsed = read_svg(svg("\n".join(lines), 64, 48, 'viewBox="0 0 64 48"'))
    assert len(parsed.paths) == 20
    for line, (points, fill) in zip(lines, parsed.paths, strict=True):
        numbers = [float(v) for v in re.findall(r"-?[\d.]+", line.split('"')[1])]
        in_order = np.array(numbers, dtype=np.float64).reshape(-1, 2)
        count = points.shape[0]
        # The text repeats the first point as the last segment's end; the points do not.
        assert in_order.shape[0] == count + 1
        assert np.array_equal(points, in_order[:count])
        assert fill == (10 / 255, 11 / 255, 12 / 255, 0.5)


@pytest.mark.parametrize("name", sorted(p.name for p in GOLDEN.glob("*.svg")))
def test_golden_samvg_files_read_back_exactly(name):
    text = (GOLDEN / name).read_text()
    parsed = read_svg(text)
    path_data = re.findall(r'<path d="([^"]+)"', text)
    assert len(parsed.paths) == len(path_data)
    for data, (points, _) in zip(path_data, parsed.paths, strict=True):
        # "M x y c" then relative cubics: offsets from each segment's start, in hundredths
        numbers = [round(100 * float(v)) for v in re.findall(r"-?(?:\d+(?:\.\d*)?|\.\d+)", data)]
        steps = np.array(numbers[2:], dtype=np.int64).reshape(-1, 3, 2)
        starts = numbers[:2] + np.cumsum(np.concatenate([[[0, 0]], steps[:-1, 2]]), axis=0)
        absolute = (steps + starts[:, None, :]).reshape(-1, 2)
        expected = np.concatenate([[numbers[:2]], absolute[:-1]]) / 100
        np.testing.assert_allclose(points, expected, rtol=0, atol=1e-9)
        assert np.array_equal(starts[-1] + steps[-1, 2], numbers[:2])  # closed at the start


# ---------------------------------------------------------------------- path commands
def test_relative_and_absolute_commands_agree():
    absolute = svg('<path d="M2 2 L10 2 C12 4 12 8 10 10 H2 V2 Z" fill="rgb(255,0,0)"/>', 20, 20)
    relative = svg('<path d="m2 2 l8 0 c2 2 2 6 0 8 h-8 v-8 z" fill="#f00"/>', 20, 20)
    (first, first_fill), (second, second_fill) = only_path(absolute), only_path(relative)
    np.testing.assert_allclose(first, second)
    assert first_fill == second_fill == (1.0, 0.0, 0.0, 1.0)
    # L, H and V become straight cubics with controls at thirds; V2 ends at the start, so Z
    # adds nothing: 4 segments.
    assert first.shape == (12, 2)
    np.testing.assert_allclose(first[:3], [[2, 2], [2 + 8 / 3, 2], [2 + 16 / 3, 2]])
    np.testing.assert_allclose(
        first[6:], line_thirds((10, 10), (2, 10)) + line_thirds((2, 10), (2, 2))
    )


def test_unclosed_path_gets_a_closing_line_and_quadratic_is_exact_cubic():
    text = (
        '<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 30 30">'
        '<path d="M0 0 Q 15 30 30 0" fill="blue" fill-opacity="0.5"/></svg>'
    )
    points, fill = only_path(text)
    np.testing.assert_allclose(points, [[0, 0], [10, 20], [20, 20]] + line_thirds((30, 0), (0, 0)))
    assert fill == (0.0, 0.0, 1.0, 0.5)


def test_explicit_line_back_to_start_is_one_cubic_without_extra_closing_segment():
    points, _ = only_path(svg('<path d="M0 0 L9 0 L9 9 L0 0 Z"/>'))
    expected = (
        line_thirds((0, 0), (9, 0)) + line_thirds((9, 0), (9, 9)) + line_thirds((9, 9), (0, 0))
    )
    np.testing.assert_allclose(points, expected, atol=1e-12)
    # An end within 1e-6 of the start counts as closed; a larger gap gets a closing line.
    assert only_path(svg('<path d="M0 0 L9 0 L9 9 L0 0.0000001"/>'))[0].shape == (9, 2)
    assert only_path(svg('<path d="M0 0 L9 0 L9 9 L0 0.001"/>'))[0].shape == (12, 2)


@pytest.mark.parametrize(
    "data",
    [
        "M0 0 C 2 0 4 2 4 4 S 6 8 8 8 Q 10 8 10 6 T 10 0 Z",
        "m0 0 c2 0 4 2 4 4 s2 4 4 4 q2 0 2 -2 t0 -6 z",
        "M0,0C2,0,4,2,4,4S6,8,8,8Q10,8,10,6T10,0z",
    ],
)
def test_smooth_cubic_and_smooth_quadratic_reflect_the_previous_control(data):
    points, _ = only_path(svg(f'<path d="{data}"/>', 12, 12))
    expected = [
        [0, 0], [2, 0], [4, 2],  # C
        [4, 4], [4, 6], [6, 8],  # S: first control reflects (4, 2) through (4, 4)
        [8, 8], [8 + 4 / 3, 8], [10, 6 + 4 / 3],  # Q 10 8 as an exact cubic
        [10, 6], [10, 6 - 4 / 3], [10, 8 / 3],  # T: reflected quadratic control (10, 4)
    ] + line_thirds((10, 0), (0, 0))  # fmt: skip
    np.testing.assert_allclose(points, expected, atol=1e-12)


def test_smooth_commands_without_a_previous_curve_use_the_current_point():
    points, _ = only_path(svg('<path d="M1 1 H9 V5 S7 9 5 9 T1 5 Z"/>', 12, 12))
    assert points.shape == (15, 2)
    np.testing.assert_allclose(points[6:9], [[9, 5], [9, 5], [7, 9]])  # S after V
    np.testing.assert_allclose(points[9:12], [[5, 9], [5, 9], [1 + 8 / 3, 5 + 8 / 3]])  # T


def test_smooth_commands_reflect_only_a_curve_of_their_own_kind():
    # T after C: the quadratic control is the current point; T after T reflects it.
    points, _ = only_path(svg('<path d="M0 0 C 0 4 4 4 4 0 T 8 0 T 12 0 Z"/>', 12, 12))
    expected = [[0, 0], [0, 4], [4, 4], [4, 0], [4, 0], [16 / 3, 0], [8, 0], [32 / 3, 0], [12, 0]]
    np.testing.assert_allclose(points[:9], expected, atol=1e-12)
    # S after Q: the first cubic control is the current point.
    points, _ = only_path(svg('<path d="M0 0 Q 2 4 4 0 S 6 2 8 0 Z"/>', 12, 12))
    expected = [[0, 0], [4 / 3, 8 / 3], [8 / 3, 8 / 3], [4, 0], [4, 0], [6, 2]]
    np.testing.assert_allclose(points[:6], expected, atol=1e-12)


@pytest.mark.parametrize(
    "data",
    [
        "M20 10 A10 10 0 0 1 0 10 A10 10 0 0 1 20 10 Z",
        "M20 10 a10 10 0 0 1 -20 0 a10 10 0 0 1 20 0 z",
        "M20 10a10 10 0 01-20 0a10 10 0 0120 0z",  # compact flags
        "M20 10 A10 10 0 1 1 10 0 A 10 10 0 0 1 20 10",  # large arc, implicit close
    ],
)
def test_arcs_become_cubics_on_the_circle(data):
    points, _ = only_path(svg(f'<path d="{data}"/>', 20, 20))
    assert points.shape[0] >= 12
    np.testing.assert_array_equal(points[0], [20, 10])
    radius = np.hypot(*(samples(points) - [10, 10]).T)
    np.testing.assert_allclose(radius, 10, rtol=5e-3)


def test_arc_under_non_uniform_scale_is_an_ellipse_and_zero_radius_arc_is_a_line():
    text = svg('<path d="M10 5 A5 5 0 1 1 10 4.999 Z" transform="scale(2 1)"/>', 20, 10)
    points, _ = only_path(text)
    x, y = samples(points).T
    np.testing.assert_allclose(((x - 10) / 10) ** 2 + ((y - 5) / 5) ** 2, 1, atol=1e-2)
    # Under a skew the ellipse axes stop being orthogonal (svgelements' own transformed arcs get
    # this wrong; the reader transforms the cubics instead).
    for shape in (
        '<ellipse cx="26" cy="22" rx="7" ry="3.5" transform="skewX(10)"/>',
        '<path d="M33 22 A7 3.5 0 0 1 19 22 A7 3.5 0 0 1 33 22 Z" transform="skewX(10)"/>',
    ):
        x, y = samples(only_path(svg(shape, 48, 32))[0]).T
        x = x - np.tan(np.radians(10)) * y
        np.testing.assert_allclose(((x - 26) / 7) ** 2 + ((y - 22) / 3.5) ** 2, 1, atol=1e-2)
    points, _ = only_path(svg('<path d="M0 0 A0 5 0 0 1 6 0 L3 6 Z"/>'))
    np.testing.assert_allclose(points[:3], line_thirds((0, 0), (6, 0)))


# ---------------------------------------------------------------------- transforms and shapes
def test_group_translate_scale_and_path_rotate_are_applied():
    text = svg(
        '<g transform="translate(10 5) scale(2)">'
        '<path d="M1 1 L3 1 L3 2 Z" transform="rotate(90)"/></g>',
        20,
        20,
    )
    points, _ = only_path(text)
    # rotate(90): (x, y) -> (-y, x); then scale 2, then translate (10, 5).
    np.testing.assert_allclose(points[[0, 3, 6]], [[8, 7], [8, 11], [6, 11]], atol=1e-12)
    np.testing.assert_allclose(points[1], [8, 7 + 4 / 3], atol=1e-12)  # still a straight cubic


def test_transformed_rect_and_use_reference():
    text = svg(
        '<defs><path id="tri" d="M0 0 L2 0 L0 2 Z"/></defs>'
        '<g transform="matrix(1 0 0 1 1 1)"><rect x="1" y="2" width="3" height="4" '
        'transform="scale(2)" fill="#00f"/></g>'
        '<use xlink:href="#tri" x="5" y="6" fill="red"/><use href="#tri" transform="skewX(45)"/>',
        20,
        20,
    )
    parsed = read_svg(text)
    assert parsed.background is None
    (rect, rect_fill), (used, used_fill), (skewed, _) = parsed.paths
    np.testing.assert_allclose(rect[[0, 3, 6, 9]], [[3, 5], [9, 5], [9, 13], [3, 13]])
    assert rect_fill == (0.0, 0.0, 1.0, 1.0)
    np.testing.assert_allclose(used[[0, 3, 6]], [[5, 6], [7, 6], [5, 8]])
    assert used_fill == (1.0, 0.0, 0.0, 1.0)
    np.testing.assert_allclose(skewed[[0, 3, 6]], [[0, 0], [2, 0], [2, 2]], atol=1e-12)


def test_circle_ellipse_polygon_and_polyline_become_closed_paths():
    text = svg(
        '<circle cx="10" cy="10" r="6"/><ellipse cx="10" cy="10" rx="8" ry="4"/>'
        '<polygon points="1,1 9,1 9,9"/><polyline points="1 1 9 1 9 9"/>',
        20,
        20,
    )
    (circle, _), (ellipse, _), (polygon, _), (polyline, _) = read_svg(text).paths
    np.testing.assert_allclose(np.hypot(*(samples(circle) - 10).T), 6, rtol=5e-3)
    x, y = (samples(ellipse) - 10).T
    np.testing.assert_allclose((x / 8) ** 2 + (y / 4) ** 2, 1, atol=1e-2)
    assert polygon.shape == polyline.shape == (9, 2)
    np.testing.assert_allclose(polygon, polyline)
    np.testing.assert_allclose(polygon[[0, 3, 6]], [[1, 1], [9, 1], [9, 9]])


# ---------------------------------------------------------------------- fills
def test_style_fill_and_fill_opacity():
    _, fill = only_path(svg(f'<path {TRIANGLE} style="fill:#ff0000;fill-opacity:0.5"/>'))
    assert fill == (1.0, 0.0, 0.0, 0.5)


def test_fill_is_inherited_from_groups_and_opacity_multiplies_into_alpha():
    text = svg(
        f'<g fill="#00ff00" fill-opacity="0.5" opacity="0.5"><path {TRIANGLE} opacity="0.8"/>'
        f'<g style="fill:blue"><path {TRIANGLE} fill="inherit"/></g></g>'
        f'<g color="red"><path {TRIANGLE} fill="currentColor"/></g><path {TRIANGLE}/>'
    )
    fills = [fill for _, fill in read_svg(text).paths]
    assert fills[0] == pytest.approx((0.0, 1.0, 0.0, 0.2))
    assert fills[1] == pytest.approx((0.0, 0.0, 1.0, 0.25))
    assert fills[2] == (1.0, 0.0, 0.0, 1.0)
    assert fills[3] == (0.0, 0.0, 0.0, 1.0)  # default fill: black


def test_css_style_sheet_applies():
    text = svg(
        f'<style>.warm {{ fill: #ff8000; opacity: 0.5 }}</style><path class="warm" {TRIANGLE}/>'
    )
    assert only_path(text)[1] == pytest.approx((1.0, 128 / 255, 0.0, 0.5))


@pytest.mark.parametrize(
    ("colour", "rgba"),
    [
        ("red", (1, 0, 0, 1)),
        ("RED", (1, 0, 0, 1)),
        ("#f00", (1, 0, 0, 1)),
        ("#FF0000", (1, 0, 0, 1)),
        ("rgb(255, 0, 0)", (1, 0, 0, 1)),
        ("rgb(100%,0%,0%)", (1, 0, 0, 1)),
        ("hsl(0, 100%, 50%)", (1, 0, 0, 1)),
        ("aliceblue", (240 / 255, 248 / 255, 1, 1)),
        ("rgba(0,0,255,0.25)", (0, 0, 1, 0.25)),
        ("#0000ff80", (0, 0, 1, 128 / 255)),
    ],
)
def test_colour_syntaxes(colour, rgba):
    assert only_path(svg(f'<path {TRIANGLE} fill="{colour}"/>'))[1] == pytest.approx(rgba)


# ---------------------------------------------------------------------- canvas and background
def test_viewbox_scales_to_pixel_canvas():
    text = svg(
        '<rect x="10" y="0" width="20" height="10" fill="#ffffff"/>'
        '<path d="M10 0 L30 10 L10 10 Z"/>',
        100,
        50,
        'viewBox="10 0 20 10"',
    )
    parsed = read_svg(text)
    assert (parsed.width, parsed.height) == (100, 50)
    assert parsed.background == (1.0, 1.0, 1.0)
    np.testing.assert_allclose(parsed.paths[0][0][[0, 3, 6]], [[0, 0], [100, 50], [0, 50]])


@pytest.mark.parametrize(
    ("aspect", "corner", "far"),
    [
        ("", (25, 0), (75, 50)),
        ('preserveAspectRatio="xMidYMid meet"', (25, 0), (75, 50)),
        ('preserveAspectRatio="xMinYMin"', (0, 0), (50, 50)),
        ('preserveAspectRatio="xMaxYMax meet"', (50, 0), (100, 50)),
        ('preserveAspectRatio="xMidYMid slice"', (0, -25), (100, 75)),
        ('preserveAspectRatio="none"', (0, 0), (100, 50)),
    ],
)
def test_preserve_aspect_ratio(aspect, corner, far):
    text = svg('<path d="M0 0 L10 0 L10 10 L0 10 Z"/>', 100, 50, f'viewBox="0 0 10 10" {aspect}')
    points, _ = only_path(text)
    np.testing.assert_allclose(points[[0, 6]], [corner, far])


@pytest.mark.parametrize(
    ("root", "size"),
    [
        ('viewBox="0 0 30 20"', (30, 20)),
        ('width="12.6px" height="7.4" viewBox="0 0 3 2"', (13, 7)),
        ('width="40" height="20"', (40, 20)),
        ('width="0.2" height="0.2"', (1, 1)),
    ],
)
def test_canvas_size(root, size):
    parsed = read_svg(f'<svg xmlns="http://www.w3.org/2000/svg" {root}><path {TRIANGLE}/></svg>')
    assert (parsed.width, parsed.height) == size


@pytest.mark.parametrize(
    ("root", "message"),
    [
        ('width="10"', "needs width and height, or a viewBox"),
        ('width="100%" height="10"', "only plain pixel lengths"),
        ('width="10mm" height="10"', "only plain pixel lengths"),
        ('viewBox="0 0 10"', "is not four numbers"),
        ('viewBox="0 0 0 10"', "has no area"),
        ('width="0" height="10"', "needs a positive width"),  # was a ZeroDivisionError
        ('width="-64" height="64"', "needs a positive width"),  # was a 1x64 canvas
        ('viewBox="0 0 10 10" height="0"', "needs a positive height"),
        ('xmlns:x="y" width="5" height="5" x:a="1"', ""),
    ],
)
def test_bad_canvas_is_a_clear_error(root, message):
    if not message:  # a foreign attribute on the root is harmless
        read_svg(f'<svg xmlns="http://www.w3.org/2000/svg" {root}><path {TRIANGLE}/></svg>')
        return
    with pytest.raises(InputError, match=re.escape(message)):
        read_svg(f'<svg xmlns="http://www.w3.org/2000/svg" {root}><path {TRIANGLE}/></svg>')


def test_partial_rect_becomes_a_path():
    parsed = read_svg(svg('<rect x="2" y="3" width="4" height="5" fill="#000"/>'))
    assert parsed.background is None
    points, _ = parsed.paths[0]
    # Corners top-left, top-right, bottom-right, bottom-left; straight segments.
    np.testing.assert_allclose(points[[0, 3, 6, 9]], [[2, 3], [6, 3], [6, 8], [2, 8]])
    np.testing.assert_allclose(points[1:3], [[2 + 4 / 3, 3], [2 + 8 / 3, 3]])


@pytest.mark.parametrize(
    ("body", "is_background"),
    [
        ('<rect width="10" height="10" fill="#808080"/>', True),
        ('<rect width="100%" height="100%" fill="#808080"/>', True),
        ('<rect x="-1" y="0.4" width="11" height="9.2" fill="#808080"/>', True),
        ('<g transform="scale(2)"><rect width="5" height="5" fill="#808080"/></g>', True),
        ('<rect width="10" height="9" fill="#808080"/>', False),
        ('<rect width="10" height="10" fill="#808080" fill-opacity="0.5"/>', False),
        ('<rect width="20" height="20" fill="#808080" transform="rotate(45 5 5)"/>', False),
        (f'<path {TRIANGLE}/><rect width="10" height="10" fill="#808080"/>', False),
    ],
)
def test_full_canvas_rect_drawn_first_is_the_background(body, is_background):
    parsed = read_svg(svg(body))
    assert (parsed.background == (128 / 255,) * 3) is is_background
    assert len(parsed.paths) == (0 if is_background else body.count("<"))


def test_second_full_canvas_rect_is_a_path():
    parsed = read_svg(
        svg('<rect width="10" height="10" fill="red"/><rect width="10" height="10"/>')
    )
    assert parsed.background == (1.0, 0.0, 0.0)
    assert len(parsed.paths) == 1


# ---------------------------------------------------------------------- ignored content
def test_metadata_definitions_and_editor_elements_are_ignored():
    text = (
        '<svg xmlns="http://www.w3.org/2000/svg" '
        'xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape" '
        'xmlns:sodipodi="http://sodipodi.sourceforge.net/DTD/sodipodi-0.dtd" '
        'width="10" height="10" inkscape:version="1.3">'
        "<title>t</title><desc>d</desc><metadata><rect width='3' height='3'/></metadata>"
        "<sodipodi:namedview><inkscape:grid/></sodipodi:namedview>"
        '<defs><linearGradient id="g"/><path id="unused" d="M0 0 L1 1 L0 1 Z"/></defs>'
        '<mask id="m"><rect width="3" height="3"/></mask><style>path { }</style>'
        f'<path {TRIANGLE} inkscape:label="layer" sodipodi:nodetypes="ccc"/>'
        f'<path {TRIANGLE} display="none"/><path {TRIANGLE} visibility="hidden"/>'
        "</svg>"
    )
    assert len(read_svg(text).paths) == 1


def test_svg_without_namespace_doctype_and_xml_declaration_are_read():
    text = (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<!DOCTYPE svg PUBLIC "-//W3C//DTD SVG 1.1//EN" '
        '"http://www.w3.org/Graphics/SVG/1.1/DTD/svg11.dtd">\n'
        f'<svg width="10" height="10"><!-- comment --><path {TRIANGLE}/></svg>'
    )
    assert len(read_svg(text).paths) == 1


# ---------------------------------------------------------------------- errors
@pytest.mark.parametrize(
    ("body", "message"),
    [
        ('<path d="M0 0 L10 0 L10 10 L0 10 Z M2 2 L2 8 L8 8 L8 2 Z"/>', "overlap (holes)"),
        ('<path d="M0 0 L10 0 L10 10 Z M2 1 L9 1 L9 8 Z" fill-opacity=".5"/>', "overlap (holes)"),
        ('<path d="M0 0 L5 5 L0 5 Z L3 3"/>', "a subpath after z must start with M"),
        (f'<path id="p1" {TRIANGLE} stroke="#000"/>', "svg/path[1] (id='p1'): strokes"),
        (f'<g style="stroke:red"><path {TRIANGLE}/></g>', "strokes are not supported"),
        (f'<path {TRIANGLE} fill="url(#g)"/>', "fill='url(#g)' names no gradient"),
        (
            '<linearGradient id="g"><stop offset="0"/><stop offset="1" stop-color="red"/>'
            f'</linearGradient><path {TRIANGLE} fill="url(#g)"/>',
            'only gradientUnits="userSpaceOnUse"',
        ),
        (
            '<linearGradient id="g" gradientUnits="userSpaceOnUse" '
            'gradientTransform="scale(2)">'
            '<stop offset="0"/><stop offset="1"/></linearGradient>'
            f'<path {TRIANGLE} fill="url(#g)"/>',
            "'gradientTransform' is not supported",
        ),
        (
            '<linearGradient id="g" gradientUnits="userSpaceOnUse"><stop offset="0"/>'
            '<stop offset="1" stop-opacity="0.5"/></linearGradient>'
            f'<path {TRIANGLE} fill="url(#g)"/>',
            "translucent gradient stops",
        ),
        (
            '<radialGradient id="g" gradientUnits="userSpaceOnUse" r="3"><stop offset="0"/>'
            '<stop offset="1"/></radialGradient>'
            f'<path {TRIANGLE} fill="url(#g)" transform="scale(2 1)"/>',
            "skewed or stretched transform",
        ),
        (
            '<radialGradient id="g" gradientUnits="userSpaceOnUse" r="3"><stop offset="0"/>'
            f'</radialGradient><path {TRIANGLE} fill="url(#g)"/>',
            "2 to 4 stops",
        ),
        (f'<path {TRIANGLE} fill="none"/>', "only solid fills"),
        (f'<path {TRIANGLE} fill="notacolour"/>', "cannot read fill colour 'notacolour'"),
        (f'<path {TRIANGLE} fill="#12345"/>', "cannot read fill colour"),
        (f'<path {TRIANGLE} fill-rule="evenodd"/>', "fill-rule='evenodd' is not supported"),
        (f'<path {TRIANGLE} fill-opacity="x"/>', "is not a number"),
        ('<path d="M0 0 L5 Z"/>', "command 'L' needs 2 numbers"),
        ('<path d="M0 0 C1 1 2 2 Z"/>', "command 'C' needs 6 numbers"),
        ('<path d="L5 5"/>', "must start with M"),
        ('<path d="M0 0 L5 5 x 3"/>', "cannot parse path data near 'x 3'"),
        ('<path d=""/>', "empty path data"),
        ('<path d="M1 1 Z"/>', "path has no segments"),
        ('<path d="M0 0 L5 5 L1e999 5 Z"/>', "non-finite"),
        ('<rect width="inf" height="5"/>', "is not a length"),
        ('<rect width="1e999" height="5"/>', "not a finite number"),
        ('<polygon points="0,0 5,0 5"/>', "must be pairs of numbers"),
        (f'<path {TRIANGLE} transform="translate(1"/>', "cannot read transform"),
        (f'<path {TRIANGLE} transform="scale(1e999)"/>', "non-finite"),
        ('<rect width="5" height="5" rx="1"/>', "rounded rectangles are not supported"),
        ('<line x1="0" y1="0" x2="5" y2="5"/>', "<line> has no area"),
        ('<polyline points="0 0 5 0 5 5" fill="none"/>', "only solid fills"),
        ('<image href="x.png" width="3" height="3"/>', "svg/image[1]: element <image> is not"),
        ("<text>hi</text>", "svg/text[1]: element <text> is not supported"),
        (f'<a href="#x"><path {TRIANGLE}/></a>', "element <a> is not supported"),
        (f"<switch><path {TRIANGLE}/></switch>", "element <switch> is not supported"),
        (f'<svg width="5" height="5"><path {TRIANGLE}/></svg>', "nested <svg>"),
        (f'<path {TRIANGLE} clip-path="url(#c)"/>', "attribute 'clip-path' is not supported"),
        (f'<g mask="url(#m)"><path {TRIANGLE}/></g>', "svg/g[1]: attribute 'mask'"),
        (f'<path {TRIANGLE} filter="url(#f)"/>', "attribute 'filter' is not supported"),
        (f'<path {TRIANGLE} style="clip-path:url(#c)"/>', "attribute 'clip-path'"),
        (f'<path {TRIANGLE} style="mix-blend-mode:multiply"/>', "'mix-blend-mode'"),
        (f'<path {TRIANGLE} marker-end="url(#m)"/>', "attribute 'marker-end'"),
        ('<use href="other.svg#x"/>', "must reference an element of this file"),
        ('<symbol id="s"><path d="M0 0 L1 1 L0 1 Z"/></symbol><use href="#s"/>', "<symbol>"),
        ('<g id="a"><use href="#a"/></g>', "circular <use> reference"),
    ],
)
def test_unrepresentable_svg_is_a_clear_error(body, message):
    with pytest.raises(InputError, match=re.escape(message)):
        read_svg(svg(body))


def test_error_names_the_nested_element_and_the_use_that_draws_it():
    text = svg(f'<g><path {TRIANGLE}/><path id="x" {TRIANGLE} stroke="red"/></g>')
    with pytest.raises(InputError, match=re.escape("svg/g[1]/path[2] (id='x'): strokes")):
        read_svg(text)
    text = svg(f'<defs><path id="p" {TRIANGLE} fill="none"/></defs><use href="#p"/>')
    with pytest.raises(InputError, match=re.escape("svg/use[1] -> svg/defs[1]/path[1] (id='p')")):
        read_svg(text)


def test_use_bomb_is_refused():
    layers = [f'<path id="l0" {TRIANGLE}/>']
    for level in range(1, 8):
        uses = "".join(f'<use href="#l{level - 1}"/>' for _ in range(10))
        layers.append(f'<g id="l{level}">{uses}</g>')
    with pytest.raises(InputError, match="expand to over"):
        read_svg(svg("<defs>" + "".join(layers) + "</defs>"))


def test_not_xml_and_not_svg_are_clear_errors():
    with pytest.raises(InputError, match="not valid SVG/XML"):
        read_svg("<svg")
    with pytest.raises(InputError, match="not valid SVG/XML"):
        read_svg(svg("<g></path>"))
    with pytest.raises(InputError, match=re.escape("root element is <html>, expected <svg>")):
        read_svg("<html/>")


def test_entity_declarations_are_refused_not_expanded():
    declarations = "".join(
        f'<!ENTITY {name} "{("&" + previous + ";") * 10}">'
        for previous, name in zip("abcdefg", "bcdefgh", strict=True)
    )
    bomb = (
        f'<?xml version="1.0"?><!DOCTYPE svg [<!ENTITY a "aaaaaaaaaa">{declarations}]>'
        '<svg xmlns="http://www.w3.org/2000/svg" width="10" height="10"><title>&h;</title></svg>'
    )
    with pytest.raises(InputError, match="entity"):
        read_svg(bomb)


# ---------------------------------------------------------------------- renders against resvg
RESVG_SCENE = """<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink"
     width="96" height="64" viewBox="-4 -2 48 32">
  <defs><path id="leaf" d="M0 0 Q 4 -6 8 0 Q 4 6 0 0 Z"/></defs>
  <rect x="-4" y="-2" width="100%" height="100%" fill="#f0e8d8"/>
  <g transform="translate(2 2) scale(1.5)" fill="#3366cc">
    <path d="M0 0 Q 6 10 12 0 T 12 8 S 4 6 0 8 Z"/>
  </g>
  <path d="M30 2 a 6 6 0 1 1 0 12 a 6 6 0 0 1 0 -12 z" fill="#cc3333" fill-opacity="0.7"
        transform="rotate(20 30 8)"/>
  <circle cx="8" cy="22" r="5" fill="green" opacity="0.8"/>
  <ellipse cx="26" cy="22" rx="7" ry="3.5" transform="skewX(10)" style="fill:#aa00aa"/>
  <polygon points="34,16 43,27 30,28" fill="orange"/>
  <use xlink:href="#leaf" transform="translate(14 -1) rotate(35) scale(1.2)" fill="#117733"/>
  <path d="M2 26 C 6 20 10 32 14 26 T 20 29 S 10 34 2 29 Z" fill="rgb(40%, 30%, 20%)"/>
</svg>"""


def test_render_matches_resvg_for_transforms_arcs_and_quadratics():
    parsed = read_svg(RESVG_SCENE)
    assert (parsed.width, parsed.height) == (96, 64)
    assert parsed.background == pytest.approx((0xF0 / 255, 0xE8 / 255, 0xD8 / 255))
    assert len(parsed.paths) == 7
    ours = render(parsed)
    theirs = resvg_render(RESVG_SCENE, 96, 64)
    assert ours.shape == theirs.shape == (64, 96, 3)
    assert np.abs(ours - theirs).mean() <= 2 / 255


def test_nesting_is_refused_beyond_500_levels_without_recursion():
    def nested(depth: int) -> str:
        return svg("<g>" * depth + f"<path {TRIANGLE}/>" + "</g>" * depth)

    assert len(read_svg(nested(498)).paths) == 1  # 498 groups: the path is at level 500
    for depth in (499, 100_000):  # 10^5 levels was a RecursionError
        with pytest.raises(InputError, match="nested over 500 levels"):
            read_svg(nested(depth))


def test_root_outside_the_svg_namespace_and_a_hidden_root():
    with pytest.raises(InputError, match="not in the SVG namespace"):
        read_svg(f'<svg xmlns="x" width="5" height="5"><path {TRIANGLE}/></svg>')
    hidden = read_svg(svg(f"<path {TRIANGLE}/>", extra='style="display:none"'))
    assert (hidden.width, hidden.height, hidden.paths) == (10, 10, [])


def test_font_relative_lengths_are_refused():
    with pytest.raises(InputError, match="em and ex lengths are not supported"):
        read_svg(svg('<circle cx="2em" cy="1" r="1"/>'))


def test_gradient_fills_read_back_in_canvas_pixels():
    text = (
        '<svg xmlns="http://www.w3.org/2000/svg" width="20" height="20" viewBox="0 0 10 10">'
        '<linearGradient id="a" gradientUnits="userSpaceOnUse" x1="1" y1="2" x2="9" y2="2">'
        '<stop offset="0" stop-color="#ff0000"/><stop offset="50%" style="stop-color:#00ff00"/>'
        '<stop offset="1" stop-color="blue"/></linearGradient>'
        '<radialGradient id="b" gradientUnits="userSpaceOnUse" cx="5" cy="5" r="2">'
        '<stop offset="0.2" stop-color="white"/><stop offset="0.1" stop-color="black"/>'
        "</radialGradient>"
        '<path d="M0 0 L8 0 L8 8 Z" fill="url(#a)" fill-opacity="0.5"/>'
        '<path d="M0 0 L4 0 L4 4 Z" fill="url(#b)" transform="translate(1 1) rotate(90)"/>'
        "</svg>"
    )
    (_, linear), (_, radial) = read_svg(text).paths
    assert isinstance(linear, LinearGradient) and isinstance(radial, RadialGradient)
    assert linear.start == pytest.approx((2, 4)) and linear.end == pytest.approx((18, 4))
    assert [offset for offset, _ in linear.stops] == [0.0, 0.5, 1.0] and linear.opacity == 0.5
    assert linear.stops[1][1] == pytest.approx((0, 1, 0))
    # rotate(90) maps (5, 5) to (-5, 5), translate(1 1) to (-4, 6): (-8, 12) in pixels
    assert radial.centre == pytest.approx((-8, 12)) and radial.radius == pytest.approx(4)
    assert [offset for offset, _ in radial.stops] == [0.2, 0.2]  # offsets never fall


@pytest.mark.parametrize(("opacity", "is_background"), [("1", True), ("0.5", False)])
def test_a_full_canvas_rect_with_an_opaque_gradient_is_a_gradient_background(
    opacity, is_background
):
    text = (
        '<svg xmlns="http://www.w3.org/2000/svg" width="20" height="10" viewBox="0 0 10 5">'
        '<rect width="10" height="5" fill="url(#bg)" fill-opacity="' + opacity + '"/>'
        '<defs><radialGradient id="bg" gradientUnits="userSpaceOnUse" cx="5" cy="2" r="4">'
        '<stop offset="0" stop-color="#ff0000"/><stop offset="1" stop-color="#0000ff"/>'
        "</radialGradient></defs>"
        f'<path {TRIANGLE} fill="#00ff00"/>'
        "</svg>"
    )
    parsed = read_svg(text)
    if not is_background:
        assert parsed.background_gradient is None and parsed.background is None
        assert len(parsed.paths) == 2 and isinstance(parsed.paths[0][1], RadialGradient)
        return
    gradient = parsed.background_gradient
    assert isinstance(gradient, RadialGradient) and len(parsed.paths) == 1
    assert gradient.centre == pytest.approx((10, 4)) and gradient.radius == pytest.approx(8)
    assert parsed.background == pytest.approx((0.5, 0.0, 0.5))  # the mean stop colour
