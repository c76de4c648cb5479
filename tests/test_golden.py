"""The SVG bytes of the paper's procedure, at full and at quick settings, on three images match
files written before the scene refactor (tests/data/golden), when that procedure was the default
and the quick one was ``--fast``: a refactor that changes behaviour fails here.

On 2026-12-02 only the path data of these files was rewritten, as text, to the writer's new
form (relative cubics between the same rounded points: tests/svg/test_writer.py). The runs
here pin the rasterizer to one thread: several threads sum colour gradients per band, which
moves the paper preset's learned colours, and through them its coordinates, in the last bits.

These bytes also depend on the CPU's floating point paths (torch, numba): on some machines
the sample's files differ in places although every stage is deterministic.
"""

from pathlib import Path

import pytest

import samvg
from samvg import Config
from samvg.render.threads import using_render_threads

GOLDEN = Path(__file__).parent / "data" / "golden"
SAMPLE = Path(samvg.__file__).parent / "samples" / "sailing_sunset.png"
IMAGES = {
    "sailing_sunset": None,
    "twemoji_grinning_face": "emoji/twemoji_grinning_face.png",
    "tango_weather_clear_night": "icon/tango_weather_clear_night.png",
}
QUICK = {"points_per_side": 16, "size": 384, "iterations": 120, "use_lpips": False}
"""The quick settings of the golden files (``--fast`` when they were written)."""
PRESETS = {
    "paper": Config.paper,
    "paper-fast": lambda **settings: Config.paper(**QUICK, **settings),
}


@pytest.mark.slow
@pytest.mark.parametrize("preset", sorted(PRESETS))
@pytest.mark.parametrize("name", sorted(IMAGES))
def test_svg_bytes_match_the_golden_files(name, preset, bench_dir, sam_checkpoint, lpips_weights):
    relative = IMAGES[name]
    source = SAMPLE if relative is None else bench_dir / relative
    config = PRESETS[preset](checkpoint=str(sam_checkpoint), lpips_weights=str(lpips_weights))
    expected = (GOLDEN / f"{name}.{preset}.svg").read_text(encoding="utf-8")
    with using_render_threads(1):
        assert samvg.vectorize(source, config).to_svg() == expected
