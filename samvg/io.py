"""File input and output: atomic writes (no half-written file), image reading with clear errors."""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path

import numpy as np

from samvg.errors import InputError


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
        os.replace(tmp_name, target)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp_name)
        raise


def atomic_write_text(path: str | os.PathLike[str], text: str) -> None:
    """Write UTF-8 ``text`` to ``path`` atomically (see :func:`atomic_write_bytes`)."""
    atomic_write_bytes(path, text.encode("utf-8"))


def to_rgb_uint8(
    image: np.ndarray, background: tuple[int, int, int] = (255, 255, 255)
) -> np.ndarray:
    """Convert an image array of any common layout to contiguous uint8 RGB (H, W, 3).

    Accepts grayscale (H, W) or (H, W, 1), RGB, RGBA (composited over ``background``),
    uint8, 16-bit integers (scaled by 1/257), bool, and floats in [0, 1].
    """
    array = np.asarray(image)
    if array.ndim == 3 and array.shape[2] == 1:
        array = array[:, :, 0]
    if array.ndim not in (2, 3) or (array.ndim == 3 and array.shape[2] not in (3, 4)):
        raise InputError(
            f"expected an image of shape (H, W), (H, W, 3) or (H, W, 4), got {array.shape}"
        )
    if array.shape[0] < 2 or array.shape[1] < 2:
        raise InputError(f"image is too small ({array.shape[1]}x{array.shape[0]} pixels)")
    if array.dtype == np.bool_:
        values = array.astype(np.float64)
    elif np.issubdtype(array.dtype, np.floating):
        if not np.all(np.isfinite(array)):
            raise InputError("image contains NaN or infinite values")
        values = np.clip(array.astype(np.float64), 0.0, 1.0)
    elif array.dtype == np.uint8:
        values = array.astype(np.float64) / 255.0
    elif np.issubdtype(array.dtype, np.integer):
        top = 65535.0 if array.max(initial=0) > 255 or array.dtype.itemsize >= 2 else 255.0
        values = np.clip(array.astype(np.float64) / top, 0.0, 1.0)
    else:
        raise InputError(f"unsupported image data type {array.dtype}")
    if values.ndim == 2:
        values = np.repeat(values[:, :, None], 3, axis=2)
    if values.shape[2] == 4:
        alpha = values[:, :, 3:4]
        back = np.asarray(background, dtype=np.float64) / 255.0
        values = values[:, :, :3] * alpha + back * (1.0 - alpha)
    return np.ascontiguousarray(np.round(values * 255.0).astype(np.uint8))


def read_image(path: str | os.PathLike[str]) -> np.ndarray:
    """Read an image file as uint8 RGB (H, W, 3); transparency is composited over white.

    Raises :class:`InputError` for a missing, unreadable, corrupt or empty file.
    """
    from PIL import Image, UnidentifiedImageError

    source = Path(path)
    if not source.is_file():
        raise InputError(f"image file not found: {source}")
    try:
        with Image.open(source) as opened:
            opened.load()
            image = opened
            if image.mode in ("I;16", "I;16B", "I;16L", "I"):
                array = np.asarray(image, dtype=np.int64).clip(0, 65535).astype(np.uint16)
            elif image.mode == "F":
                array = np.asarray(image, dtype=np.float32) / 255.0
            else:
                has_alpha = image.mode in ("RGBA", "LA", "PA") or "transparency" in image.info
                array = np.asarray(image.convert("RGBA" if has_alpha else "RGB"))
    except (UnidentifiedImageError, OSError, SyntaxError, ValueError) as error:
        raise InputError(f"cannot read image {source}: {error}") from None
    return to_rgb_uint8(array)


def write_png(path: str | os.PathLike[str], image: np.ndarray) -> None:
    """Write an (H, W, 3) image (uint8, or float in [0, 1]) as PNG, atomically."""
    import io

    from PIL import Image

    array = np.asarray(image)
    if np.issubdtype(array.dtype, np.floating):
        array = np.round(np.clip(array, 0.0, 1.0) * 255.0).astype(np.uint8)
    buffer = io.BytesIO()
    Image.fromarray(array).save(buffer, format="PNG")
    atomic_write_bytes(path, buffer.getvalue())
