"""Image quality metrics: LPIPS, FID, MSE / PSNR / SSIM and JPEG-based image complexity."""

from samvg.metrics.lpips import LPIPS, load_lpips, lpips_distance

__all__ = ["LPIPS", "load_lpips", "lpips_distance"]
