"""Stage 3: fitting path geometry and colours to the target image by differentiable rendering."""

from samvg.optimize.fit import FitResult, fit_paths

__all__ = ["FitResult", "fit_paths"]
