"""Stage 3 (and the fitting half of stage 4): path geometry and colours fitted to the target
image by differentiable rendering."""

from samvg.optimize.fit import FitResult, FitSettings, fit_scene, single_torch_thread
from samvg.optimize.losses import PerceptualLoss, lpips_loss, xing_loss

__all__ = [
    "FitResult",
    "FitSettings",
    "PerceptualLoss",
    "fit_scene",
    "lpips_loss",
    "single_torch_thread",
    "xing_loss",
]
