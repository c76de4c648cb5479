"""File input and output: atomic writes (no half-written file), image reading with clear errors."""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path

import numpy as np
from PIL import Image, ImageOps

from samvg.errors import InputError


def replace_with_default_permissions(temporary: str | os.PathLike[str], target: Path) -> None:
    """Rename a finished temporary file onto ``target`` with the usual permissions (0666 less
    the umask; temporary files are created 0600)."""
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(temporary, 0o666 & ~umask)
    os.replace(temporary, target)


def atomic_write_bytes(path: str | os.PathLike[str], data: bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file in the same folder and a rename.

    A reader sees either the old file or the whole new one; a failure leaves no partial file.
    """
    target = Path(path)
    folder = target.parent if str(target.parent) else Path(".")
    if not folder.is_dir():
        raise InputError(f"cannot write {target}: folder {folder} does not exist")
    fd, tmp_name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=folder)
    try:
        with os.fdopen(fd, "wb") as handle:
            handle.write(data)
            handle.flush()
            os.fsync(handle.fileno())
        replace_with_default_permissions(tmp_name, target)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp_name)
        raise


def atomic_write_text(path: str | os.PathLike[str], text: str) -> None:
    """Write UTF-8 ``text`` to ``path`` atomically (see :func:`atomic_write_bytes`)."""
    atomic_write_bytes(path, text.encode("utf-8"))


MIN_SIDE = 2


def to_rgb_uint8(image: np.ndarray | Image.Image) -> np.ndarray:
    """Return an (H, W, 3) uint8 RGB copy of ``image``.

    Accepts PIL images of any mode and numpy arrays (H, W), (H, W, 1|2|3|4) of dtype uint8,
    uint16 (or other integers, scaled down from 16 bit when > 255), bool, or float (values in
    [0, 1], or [0, 255] if any value exceeds 1). Grayscale is replicated to RGB; an alpha
    channel is composited over white. Raises `InputError` for empty images, images smaller than
    2x2, non-finite float values, or unsupported shapes.
    """
    if isinstance(image, Image.Image):
        if image.mode in ("I;16", "I;16B", "I;16L", "I;16N", "I", "F"):
            arr = np.asarray(image)
        elif image.mode in ("RGBA", "LA", "PA") or (
            image.mode == "P" and "transparency" in image.info
        ):
            arr = np.asarray(image.convert("RGBA"))
        else:
            arr = np.asarray(image.convert("RGB"))
    else:
        arr = np.asarray(image)
    if arr.ndim == 3 and arr.shape[2] == 1:
        arr = arr[:, :, 0]
    if arr.ndim not in (2, 3) or (arr.ndim == 3 and arr.shape[2] not in (2, 3, 4)):
        raise InputError(f"unsupported image shape {arr.shape}; expected (H, W) or (H, W, 1-4)")
    h, w = arr.shape[:2]
    if h == 0 or w == 0:
        raise InputError(f"image is empty ({h}x{w} pixels)")
    if h < MIN_SIDE or w < MIN_SIDE:
        raise InputError(f"image is too small ({w}x{h} pixels); need at least 2x2")
    x = _to_unit_float(arr) if arr.dtype != np.uint8 else None
    if x is None:
        u8 = arr
        if u8.ndim == 2:
            return np.repeat(u8[:, :, None], 3, axis=2)
        if u8.shape[2] == 3:
            return np.ascontiguousarray(u8)
        x = u8.astype(np.float32) / 255.0
    if x.ndim == 2:
        x = np.repeat(x[:, :, None], 3, axis=2)
    elif x.shape[2] == 2:
        x = np.concatenate([np.repeat(x[:, :, :1], 3, axis=2), x[:, :, 1:]], axis=2)
    if x.shape[2] == 4:
        alpha = x[:, :, 3:4]
        x = x[:, :, :3] * alpha + (1.0 - alpha)
    return np.clip(np.rint(x * 255.0), 0, 255).astype(np.uint8)


def _to_unit_float(arr: np.ndarray) -> np.ndarray:
    """Scale any supported dtype to float32 in [0, 1]."""
    if arr.dtype == np.bool_:
        return arr.astype(np.float32)
    if np.issubdtype(arr.dtype, np.floating):
        x = arr.astype(np.float32)
        if not np.isfinite(x).all():
            raise InputError("image contains NaN or infinite values")
        if x.size and x.max() > 1.0:
            x = x / 255.0
        return np.clip(x, 0.0, 1.0)
    if np.issubdtype(arr.dtype, np.integer):
        x = arr.astype(np.float32)
        if arr.dtype == np.uint16 or (x.size and x.max() > 255):
            return np.clip(x / 65535.0, 0.0, 1.0)
        return np.clip(x / 255.0, 0.0, 1.0)
    raise InputError(f"unsupported image dtype {arr.dtype}")


def read_image(path: str | os.PathLike[str]) -> np.ndarray:
    """Read an image file as uint8 RGB (H, W, 3), turned upright by its EXIF orientation;
    transparency is composited over white, CMYK/palette/16-bit converted.

    Raises :class:`InputError` for a missing, unreadable, corrupt or empty file.
    """
    from PIL import UnidentifiedImageError

    source = Path(path)
    if not source.is_file():
        raise InputError(f"image file not found: {source}")
    try:
        with Image.open(source) as opened:
            opened.load()
            upright = ImageOps.exif_transpose(opened)
            return to_rgb_uint8(upright if upright is not None else opened)
    except (
        UnidentifiedImageError,
        Image.DecompressionBombError,
        OSError,
        SyntaxError,
        ValueError,
    ) as error:
        if isinstance(error, InputError):
            raise
        raise InputError(f"cannot read image {source}: {error}") from None


def write_png(path: str | os.PathLike[str], image: np.ndarray) -> None:
    """Write an (H, W, 3) image (uint8, or float in [0, 1]) as PNG, atomically."""
    import io

    array = np.asarray(image)
    if np.issubdtype(array.dtype, np.floating):
        array = np.round(np.clip(array, 0.0, 1.0) * 255.0).astype(np.uint8)
    buffer = io.BytesIO()
    Image.fromarray(array).save(buffer, format="PNG")
    atomic_write_bytes(path, buffer.getvalue())
