"""File input and output: atomic writes (no half-written file), image files read with clear
errors (the conversion of what was read is `samvg.imaging`'s)."""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path

import numpy as np
from PIL import Image, ImageOps

from samvg.errors import InputError, OutputError
from samvg.imaging import alpha_channel, to_rgb_uint8


def replace_with_default_permissions(temporary: str | os.PathLike[str], target: Path) -> None:
    """Rename a finished temporary file onto ``target`` with the usual permissions (0666 less
    the umask; temporary files are created 0600)."""
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(temporary, 0o666 & ~umask)
    os.replace(temporary, target)


def atomic_write_bytes(path: str | os.PathLike[str], data: bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file in the same folder and a rename.

    A reader sees either the old file or the whole new one; a failure (a full disk, no
    permission) or an interruption (Ctrl-C, or SIGTERM turned into an exception by the command
    line) removes the temporary file. Raises `OutputError` with one line when the write fails.
    """
    target = Path(path)
    folder = target.parent if str(target.parent) else Path(".")
    if not folder.is_dir():
        raise OutputError(f"cannot write {target}: folder {folder} does not exist")
    try:
        fd, tmp_name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=folder)
    except OSError as error:
        raise OutputError(f"cannot write {target}: {error.strerror or error}") from None
    try:
        with os.fdopen(fd, "wb") as handle:
            handle.write(data)
            handle.flush()
            os.fsync(handle.fileno())
        replace_with_default_permissions(tmp_name, target)
    except BaseException as error:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp_name)
        if isinstance(error, OSError):
            raise OutputError(f"cannot write {target}: {error.strerror or error}") from None
        raise


def atomic_write_text(path: str | os.PathLike[str], text: str) -> None:
    """Write UTF-8 ``text`` to ``path`` atomically (see :func:`atomic_write_bytes`)."""
    atomic_write_bytes(path, text.encode("utf-8"))


def read_image(path: str | os.PathLike[str]) -> np.ndarray:
    """Read an image file as uint8 RGB (H, W, 3), turned upright by its EXIF orientation;
    transparency is composited over white, CMYK/palette/16-bit converted.

    Raises :class:`InputError` for a missing, unreadable, corrupt or empty file.
    """
    return read_image_with_alpha(path)[0]


def read_image_with_alpha(path: str | os.PathLike[str]) -> tuple[np.ndarray, np.ndarray | None]:
    """:func:`read_image`, and the image's opacity as float32 (H, W) in [0, 1] when it has an
    alpha channel with any pixel not fully opaque (else None)."""
    from PIL import UnidentifiedImageError

    source = Path(path)
    if not source.is_file():
        raise InputError(f"image file not found: {source}")
    if source.stat().st_size == 0:
        raise InputError(f"cannot read image {source}: the file is empty (0 bytes)")
    try:
        with Image.open(source) as opened:
            opened.load()
            upright = ImageOps.exif_transpose(opened)
            picture = upright if upright is not None else opened
            return to_rgb_uint8(picture), alpha_channel(picture)
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
