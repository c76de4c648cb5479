"""Numbers in SVG attribute text (``0.5``, ``50%``), checked: one owner for the reader and the
gradient parser."""

from __future__ import annotations

import math

from samvg.errors import InputError


def number(text: str, label: str) -> float:
    """``text`` as a finite number, a percentage as a fraction; `InputError` naming ``label``."""
    stripped = str(text).strip()
    try:
        value = float(stripped.rstrip("%")) / (100.0 if stripped.endswith("%") else 1.0)
    except ValueError:
        raise InputError(f"{label}: {text!r} is not a number") from None
    if not math.isfinite(value):
        raise InputError(f"{label}: {text!r} is not a finite number")
    return value
