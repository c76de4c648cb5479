"""Reading a benchmark manifest: one CSV row per image (id, category, png, optional svg ...),
file paths relative to the manifest's folder."""

from __future__ import annotations

import csv
import os
import re
from dataclasses import dataclass
from pathlib import Path

from samvg.errors import InputError

REQUIRED_COLUMNS = ("id", "category", "png")
_SAFE_ID = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._-]*$")


@dataclass(frozen=True)
class BenchImage:
    """One benchmark image: its id (also its output file name), category and files."""

    id: str
    category: str
    png: Path
    svg: Path | None = None


def read_manifest(
    path: str | os.PathLike[str],
    categories: list[str] | None = None,
    limit: int | None = None,
) -> list[BenchImage]:
    """The manifest's images in file order, only ``categories`` if given, at most ``limit``.

    Raises :class:`InputError` for a missing or malformed manifest, duplicate or unsafe ids
    (they name output files) and categories the manifest does not have. Image files are not
    opened here: a missing one fails only that image's run.
    """
    source = Path(path)
    if not source.is_file():
        raise InputError(f"manifest not found: {source}")
    if limit is not None and (isinstance(limit, bool) or not isinstance(limit, int) or limit < 1):
        raise InputError(f"limit must be a positive integer, got {limit!r}")
    try:
        with source.open(newline="", encoding="utf-8") as handle:
            rows = list(csv.DictReader(handle))
            columns = rows[0].keys() if rows else []
    except (OSError, UnicodeDecodeError, csv.Error) as error:
        raise InputError(f"cannot read manifest {source}: {error}") from None
    missing = [column for column in REQUIRED_COLUMNS if column not in columns]
    if not rows:
        raise InputError(f"manifest {source} has no images")
    if missing:
        raise InputError(f"manifest {source} lacks the column(s) {', '.join(missing)}")
    folder = source.parent
    images: list[BenchImage] = []
    seen: set[str] = set()
    for line, row in enumerate(rows, start=2):
        image_id = (row["id"] or "").strip()
        if not _SAFE_ID.match(image_id):
            raise InputError(
                f"{source} line {line}: id {image_id!r} must be letters, digits, '.', '_' or '-'"
            )
        if image_id in seen:
            raise InputError(f"{source} line {line}: duplicate id {image_id!r}")
        seen.add(image_id)
        png = (row["png"] or "").strip()
        if not png:
            raise InputError(f"{source} line {line}: no png file for {image_id!r}")
        svg = (row.get("svg") or "").strip()
        images.append(
            BenchImage(
                id=image_id,
                category=(row["category"] or "").strip() or "uncategorized",
                png=folder / png,
                svg=folder / svg if svg else None,
            )
        )
    if categories:
        known = sorted({image.category for image in images})
        unknown = [name for name in categories if name not in known]
        if unknown:
            raise InputError(
                f"unknown categor{'y' if len(unknown) == 1 else 'ies'} {', '.join(unknown)}; "
                f"the manifest has {', '.join(known)}"
            )
        images = [image for image in images if image.category in categories]
    return images[:limit] if limit is not None else images
