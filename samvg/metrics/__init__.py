"""Image quality metrics: LPIPS, FID, MSE / PSNR / SSIM and JPEG-based image complexity."""

from samvg.metrics.fid import (
    fid,
    fid_features,
    frechet_distance,
    frechet_distance_from_stats,
    load_fid_inception,
)
from samvg.metrics.image_metrics import complexity, jpeg_compression, mse, psnr, ssim
from samvg.metrics.lpips import LPIPS, load_lpips, lpips_distance

__all__ = [
    "LPIPS",
    "complexity",
    "fid",
    "fid_features",
    "frechet_distance",
    "frechet_distance_from_stats",
    "jpeg_compression",
    "load_fid_inception",
    "load_lpips",
    "lpips_distance",
    "mse",
    "psnr",
    "ssim",
]
