"""samvg: raster images to compact, editable SVG with Segment Anything (SAMVG)."""

from samvg.config import Config
from samvg.errors import InputError, SamvgError, WeightsError
from samvg.pipeline import run, vectorize
from samvg.vector_image import VectorImage, VectorPath

__all__ = [
    "Config",
    "InputError",
    "SamvgError",
    "VectorImage",
    "VectorPath",
    "WeightsError",
    "run",
    "vectorize",
]
__version__ = "0.1.0"
