"""samvg: raster images to compact, editable SVG with Segment Anything (SAMVG)."""

from typing import TYPE_CHECKING, Any

from samvg.config import Config
from samvg.errors import InputError, OutputError, SamvgError, WeightsError
from samvg.vector_image import VectorImage, VectorPath

if TYPE_CHECKING:
    from samvg.pipeline import run, vectorize

__all__ = [
    "Config",
    "InputError",
    "OutputError",
    "SamvgError",
    "VectorImage",
    "VectorPath",
    "WeightsError",
    "run",
    "vectorize",
]
__version__ = "0.1.0"


def __getattr__(name: str) -> Any:
    """`run` and `vectorize` on first use: the pipeline loads torch and numba (seconds), which
    the command line's checks and ``--help`` do without."""
    if name in ("run", "vectorize"):
        from samvg import pipeline

        return getattr(pipeline, name)
    raise AttributeError(f"module 'samvg' has no attribute {name!r}")
