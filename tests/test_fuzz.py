"""Fuzzing the two readers of user files with hypothesis: generated SVG text (structured from
SVG's elements and attributes with odd values, and free text) and image bytes (valid files of
every format Pillow writes, mutated, and random bytes). Whatever comes in, the readers either
succeed or raise samvg's own errors, and no case takes over 5 s.

Bounded and reproducible: 200 examples per property, derandomized, no example database. Set
``SAMVG_FUZZ_EXAMPLES`` (and ``SAMVG_FUZZ_RANDOM=1`` for fresh examples) to search longer.
"""

from __future__ import annotations

import contextlib
import io
import os
import signal
import tempfile
from collections.abc import Iterator
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from PIL import Image

from samvg.errors import SamvgError
from samvg.io import read_image
from samvg.vector_image import VectorImage

EXAMPLES = int(os.environ.get("SAMVG_FUZZ_EXAMPLES", "200"))
FUZZ = settings(
    max_examples=EXAMPLES,
    deadline=5000,  # ms: no single case may take longer
    derandomize=not os.environ.get("SAMVG_FUZZ_RANDOM"),
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)
HARD_LIMIT_S = 30  # a hang is stopped here (hypothesis only measures a case once it returns)
# Pillow warns about the corrupt files it still reads (truncated tags, huge sizes): expected here.
pytestmark = pytest.mark.filterwarnings("ignore::UserWarning", "ignore::RuntimeWarning")


@contextlib.contextmanager
def hard_limit(seconds: int) -> Iterator[None]:
    """Raise TimeoutError in the main thread if the block runs past ``seconds``."""

    def stop(_signum: int, _frame: object) -> None:
        raise TimeoutError(f"over {seconds} s")

    previous = signal.signal(signal.SIGALRM, stop)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


# ---------------------------------------------------------------------- SVG text
def mostly(good: list[str], odd: list[str]) -> st.SearchStrategy[str]:
    """Usually a sensible value (so that the reader gets deep), sometimes an odd one."""
    return st.sampled_from(good * 6 + odd)  # one list: repeated elements weigh more


ODD_NUMBERS = ["-1", "1e308", "-1e308", "1e-320", "nan", "inf", "-0", "", " ", "auto", "1,2",
               "1e", "0x10", "\u0663", "2em", "1mm", "3px", "5%"]  # fmt: skip
LENGTH = mostly(["0", "1", "3", "10", "2.5", "15", "20"], ODD_NUMBERS)
FILL = mostly(
    ["red", "#fff", "#12345678", "rgb(1,2,3)", "rgba(1,2,3,0.5)", "hsl(120,50%,50%)", "navy"],
    ["none", "url(#g)", "inherit", "currentColor", "transparent", "#ff", "rgb(1,2)", "bogus"],
)
TRANSFORM = mostly(
    ["translate(3)", "scale(2)", "rotate(45 1 1)", "matrix(1 0 0 1 0 0)", "skewX(30)"],
    ["scale(0)", "scale(1e308)", "matrix(0 0 0 0 0 0)", "skewX(90)", "rotate()", "translate(a)"],
)
PATH_DATA = mostly(
    ["M0 0 L10 0 L10 10 Z", "M0 0 C1 1 2 2 3 3 Z", "m1 1 h5 v5 h-5 z", "M0 0 Q5 5 10 0 T20 0 Z",
     "M0 0 A5 5 0 1 1 10 0 Z", "M0 0 A0 0 0 0 0 10 0", "M0 0 S5 5 10 0", "M0,0,1,1,2,0z"],
    ["M0 0 Z M5 5 L6 6 Z", "M0 0", "L1 1", "M nan 0 L 1 1", "M0 0 L1e308 1e308 L-1e308 0 Z", "",
     "M0 0 A5 5 0 2 1 10 0", "M0 0 L", "M0 0 C1 1 2 2", "M1e400 0 L1 1 Z"],
)  # fmt: skip
FREE = st.text(alphabet="<>/=\"' #%()0123456789.-eMLCZz,;:&!svgpathrect", max_size=12)
ATTRIBUTES: dict[str, st.SearchStrategy[str]] = {
    **{name: LENGTH for name in ("width", "height", "x", "y", "r", "cx", "cy", "rx", "ry")},
    **{name: LENGTH for name in ("x1", "y1", "x2", "y2")},
    "opacity": mostly(["0.5", "1", "0"], ["2", "-1", "50%", "nan"]),
    "fill-opacity": mostly(["0.5", "1"], ["2", "-1", "50%", "x"]),
    "d": PATH_DATA,
    "points": mostly(["0 0 5 5 5 0", "1,1 9,1 9,9"], ["1", "", "0 0 nan 1", "1 2 3"]),
    "transform": st.one_of(TRANSFORM, FREE.filter(lambda text: text.startswith(("sc", "tr")))),
    "fill": FILL,
    "stroke": mostly(["none"], ["red", "inherit"]),
    "fill-rule": st.sampled_from(["nonzero", "evenodd", "inherit", "x"]),
    "visibility": st.sampled_from(["visible", "hidden", "collapse", "inherit"]),
    "display": st.sampled_from(["inline", "none"]),
    "href": st.sampled_from(["#r", "#g", "#x", "#missing", "", "http://example.com/a.svg#r"]),
    "id": st.sampled_from(["r", "g", "x"]),
    "style": st.sampled_from(
        [
            "fill:red",
            "fill:url(#g)",
            "opacity:0.5",
            "display:none",
            ";;",
            "fill: inherit",
            "transform: scale(2)",
        ]
    ),  # fmt: skip
    "clip-path": st.sampled_from(["none", "url(#c)"]),
    "preserveAspectRatio": st.sampled_from(["none", "xMinYMax slice", "bogus", "xMidYMid"]),
}
#: Each shape with the attributes that give it an area (others are added at random).
SHAPES = {
    "rect": ("x", "y", "width", "height"),
    "circle": ("cx", "cy", "r"),
    "ellipse": ("cx", "cy", "rx", "ry"),
    "path": ("d",),
    "polygon": ("points",),
    "polyline": ("points",),
    "use": ("href", "x"),
}
OTHERS = ["line", "text", "image", "title", "defs", "linearGradient", "symbol", "foreignObject",
          "style", "switch", "a", "metadata", "bogus"]  # fmt: skip
TAGS = st.sampled_from(sorted(SHAPES) * 4 + OTHERS)
ROOT_EXTRAS = sorted(set(ATTRIBUTES) - {"width", "height"})


@st.composite
def attributes(
    draw: st.DrawFn, required: tuple[str, ...] = (), pool: list[str] | None = None
) -> str:
    chosen = draw(st.lists(st.sampled_from(pool or sorted(ATTRIBUTES)), max_size=4, unique=True))
    names = list(required) + [name for name in chosen if name not in required]
    return "".join(f" {name}={quoteattr(draw(ATTRIBUTES[name]))}" for name in names)


@st.composite
def leaves(draw: st.DrawFn) -> str:
    tag = draw(TAGS)
    return f"<{tag}{draw(attributes(SHAPES.get(tag, ())))}/>"


def element(children: st.SearchStrategy[str]) -> st.SearchStrategy[str]:
    return st.builds(
        lambda tag, attrs, inner: f"<{tag}{attrs}>{''.join(inner)}</{tag}>",
        st.sampled_from(["g"] * 8 + ["svg", "a", "defs", "symbol", "switch"]),
        attributes(),
        st.lists(children, max_size=4),
    )


BODY = st.recursive(leaves(), element, max_leaves=12)
NAMESPACE = ' xmlns="http://www.w3.org/2000/svg"'


@st.composite
def svg_documents(draw: st.DrawFn) -> str:
    size = draw(
        mostly(
            [' width="20" height="10"', ' viewBox="0 0 10 10"', ' width="8" viewBox="1 1 4 8"'],
            ["", ' viewBox="0 0 0 5"', ' viewBox="a b c d"', ' width="0" height="3"'],
        )
    )
    namespace = draw(mostly([NAMESPACE], ["", ' xmlns="x"', NAMESPACE + ' xmlns:x="y"']))
    extra = draw(attributes(pool=ROOT_EXTRAS)) if draw(st.booleans()) else ""
    body = "".join(draw(st.lists(BODY, max_size=5)))
    return f"<svg{namespace}{size}{extra}>{body}</svg>"


def read_svg_text(text: str) -> None:
    with hard_limit(HARD_LIMIT_S), contextlib.suppress(SamvgError):
        VectorImage.from_svg(text)


@FUZZ
@given(svg_documents())
def test_generated_svg_documents_give_a_scene_or_a_samvg_error(text):
    read_svg_text(text)


@FUZZ
@given(st.one_of(st.text(max_size=300), st.lists(FREE, max_size=30).map("".join)))
def test_free_text_as_svg_gives_a_scene_or_a_samvg_error(text):
    read_svg_text(text)


# ---------------------------------------------------------------------- image bytes
FORMATS = {
    "PNG": {}, "JPEG": {"quality": 80}, "GIF": {}, "BMP": {}, "TIFF": {}, "WEBP": {},
    "PPM": {}, "ICO": {}, "TGA": {}, "PCX": {},
}  # fmt: skip
MODES = ("RGB", "L", "RGBA", "P", "1", "I;16", "LA", "CMYK")


def _encoded(fmt: str, mode: str, width: int, height: int) -> bytes | None:
    pixels = np.random.default_rng(width * 31 + height).integers(0, 255, (height, width, 3))
    image = Image.fromarray(pixels.astype(np.uint8), "RGB")
    image = image.convert(mode) if mode != "I;16" else image.convert("I").convert("I;16")
    buffer = io.BytesIO()
    try:
        image.save(buffer, format=fmt, **FORMATS[fmt])
    except (OSError, ValueError, KeyError):
        return None  # this format cannot hold this mode
    return buffer.getvalue()


VALID = [
    data
    for fmt in FORMATS
    for mode in MODES
    for size in ((1, 1), (7, 3))
    if (data := _encoded(fmt, mode, *size)) is not None
]


@st.composite
def mutated_images(draw: st.DrawFn) -> bytes:
    data = bytearray(draw(st.sampled_from(VALID)))
    for _ in range(draw(st.integers(0, 6))):
        action = draw(st.sampled_from(["flip", "cut", "insert", "big"]))
        at = draw(st.integers(0, max(0, len(data) - 1)))
        if action == "flip" and data:
            data[at] = draw(st.integers(0, 255))
        elif action == "cut":
            del data[at:]
        elif action == "insert":
            data[at:at] = draw(st.binary(max_size=8))
        elif data:  # a large number where a size might be
            data[at : at + 4] = draw(st.sampled_from([b"\xff\xff\xff\xff", b"\x00\x00\x7f\xff"]))
    return bytes(data)


FOLDER = Path(tempfile.mkdtemp(prefix="samvg_fuzz_"))


def read_image_bytes(data: bytes) -> None:
    path = FOLDER / "case.img"
    path.write_bytes(data)
    with hard_limit(HARD_LIMIT_S):
        try:
            image = read_image(path)
        except SamvgError:
            return
    assert image.dtype == np.uint8 and image.ndim == 3 and image.shape[2] == 3


@FUZZ
@given(mutated_images())
def test_mutated_image_files_give_pixels_or_a_samvg_error(data):
    read_image_bytes(data)


@FUZZ
@given(st.binary(max_size=2000))
def test_random_bytes_as_an_image_give_a_samvg_error(data):
    read_image_bytes(data)


def test_the_valid_seeds_cover_the_formats():
    assert len({Image.open(io.BytesIO(data)).format for data in VALID}) >= 8
