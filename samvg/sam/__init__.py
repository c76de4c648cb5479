"""Segment Anything in pure torch: MobileSAM (TinyViT) and SAM ViT-B/L/H, predictor, AMG."""

from samvg.sam.amg import SamAutomaticMaskGenerator
from samvg.sam.build import MODEL_NAMES, SPECS, build_sam, load_sam
from samvg.sam.fast_decoder import FastDecoder
from samvg.sam.image import to_rgb_uint8
from samvg.sam.model import Sam
from samvg.sam.predictor import SamPredictor

__all__ = [
    "MODEL_NAMES",
    "SPECS",
    "FastDecoder",
    "Sam",
    "SamAutomaticMaskGenerator",
    "SamPredictor",
    "build_sam",
    "load_sam",
    "to_rgb_uint8",
]
