"""Output paths checked before any work starts: a file output is not a folder, its folder exists
and is writable, and it is not one of the inputs; a folder output is not a file and can be
created; a batch's outputs get names that never collide.

Every problem raises `OutputError` with one line naming the path, so that a long run never ends
in a write that could have been refused at the start.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

from samvg.errors import OutputError

__all__ = ["batch_outputs", "check_output_file", "check_output_folder", "same_file"]


def same_file(first: str | os.PathLike[str], second: str | os.PathLike[str]) -> bool:
    """Whether two paths name one file (links and other spellings included)."""
    try:
        return os.path.samefile(first, second)
    except OSError:  # one of them does not exist (yet): compare where they would be
        return os.path.realpath(first) == os.path.realpath(second)


def _check_writable_folder(folder: Path, what: str) -> None:
    if not folder.exists():
        raise OutputError(f"{what} folder {folder} does not exist")
    if not folder.is_dir():
        raise OutputError(f"{what} folder {folder} is a file, not a folder")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise OutputError(f"{what} folder {folder} is not writable")


def check_output_file(
    path: str | os.PathLike[str],
    suffixes: tuple[str, ...],
    inputs: Sequence[str | os.PathLike[str]] = (),
    what: str = "output",
) -> Path:
    """``path`` as a `Path` if a file can be written there (`OutputError` if not): a name ending
    in one of ``suffixes``, not a folder, in a writable folder, and none of ``inputs``."""
    text = os.fspath(path)
    if text.endswith(("/", os.sep)):
        raise OutputError(f"{what} {text} names a folder; give a file ending in {suffixes[0]}")
    target = Path(text)
    if target.suffix.lower() not in suffixes:
        raise OutputError(f"{what} {target} should end in {' or '.join(suffixes)}")
    if target.is_dir():
        raise OutputError(f"{what} {target} is a folder, not a file")
    if target.exists() and not target.is_file():
        raise OutputError(f"{what} {target} exists and is not a regular file")
    _check_writable_folder(target.parent if str(target.parent) else Path("."), what)
    for source in inputs:
        if same_file(target, source):
            raise OutputError(f"{what} {target} is the input {source}: choose another name")
    return target


def check_output_folder(path: str | os.PathLike[str], what: str = "output folder") -> Path:
    """``path`` as a `Path` if it is a writable folder or can be created as one."""
    folder = Path(path)
    if folder.exists():
        if not folder.is_dir():
            raise OutputError(f"{what} {folder} is a file, not a folder")
        if not os.access(folder, os.W_OK | os.X_OK):
            raise OutputError(f"{what} {folder} is not writable")
        return folder
    existing = folder.parent
    while not existing.exists() and existing != existing.parent:
        existing = existing.parent
    if not existing.is_dir():
        raise OutputError(f"cannot create {what} {folder}: {existing} is a file")
    if not os.access(existing, os.W_OK | os.X_OK):
        raise OutputError(f"cannot create {what} {folder}: {existing} is not writable")
    return folder


def batch_outputs(inputs: Sequence[Path], folder: Path) -> list[tuple[Path, Path]]:
    """(input, output SVG) pairs of a batch into ``folder``.

    An input's SVG is ``<stem>.svg``; inputs whose stems collide (``pic.jpg`` and ``pic.png``,
    compared ignoring case) keep their whole name instead (``pic.jpg.svg``, ``pic.png.svg``).
    The same file named twice is done once. Two inputs that would still share an output (one
    name in two folders), or an output that is an input, raise `OutputError` naming both.
    """
    unique: list[Path] = []
    seen: set[str] = set()
    for source in inputs:
        real = os.path.realpath(source)
        if real not in seen:
            seen.add(real)
            unique.append(source)
    stems: dict[str, int] = {}
    for source in unique:
        stems[source.stem.casefold()] = stems.get(source.stem.casefold(), 0) + 1
    pairs: list[tuple[Path, Path]] = []
    owners: dict[str, Path] = {}
    for source in unique:
        name = source.stem if stems[source.stem.casefold()] == 1 else source.name
        target = folder / f"{name}.svg"
        other = owners.setdefault(target.name.casefold(), source)
        if other is not source:
            raise OutputError(
                f"inputs {other} and {source} would both be written to {target}: "
                "rename one or run them as separate batches"
            )
        if os.path.realpath(target) in seen:
            raise OutputError(f"output {target} is an input of this batch: choose another -o")
        pairs.append((source, target))
    return pairs
