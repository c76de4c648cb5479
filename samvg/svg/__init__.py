"""SVG text in and out of a scene: `read_svg` (svgelements) and `scene_to_svg`."""

from samvg.svg.reader import ParsedSvg, read_svg
from samvg.svg.writer import scene_to_svg

__all__ = ["ParsedSvg", "read_svg", "scene_to_svg"]
