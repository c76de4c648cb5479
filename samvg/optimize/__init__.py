"""Stage 3 (and the fitting half of stage 4): path geometry and colours fitted to the target
image by differentiable rendering."""

from samvg.optimize.fit import FitResult, FitSettings, fit_scene, fit_torch_threads
from samvg.optimize.losses import PerceptualLoss, lpips_loss, xing_loss

__all__ = [
    "FitResult",
    "FitSettings",
    "PerceptualLoss",
    "fit_scene",
    "lpips_loss",
    "fit_torch_threads",
    "xing_loss",
]
