"""samvg: raster images to compact, editable SVG with Segment Anything (SAMVG)."""

from samvg.errors import InputError, SamvgError, WeightsError
from samvg.vector_image import VectorImage, VectorPath

__all__ = ["InputError", "SamvgError", "VectorImage", "VectorPath", "WeightsError"]
__version__ = "0.1.0"
