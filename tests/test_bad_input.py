"""Issue 15's matrix of bad inputs and faults, each run through the command line as a
subprocess (``python -m samvg``): a non-zero exit status, exactly one line on stderr and no
traceback, nothing on stdout, and no file left behind (the folder holds what it held before).

Every case fails before the long work: outputs, settings, the device and the weights are checked
before SAM runs, so no case needs to load a model; the weight files the run would use
(``$SAMVG_SAM_CHECKPOINT``, ``$SAMVG_LPIPS_WEIGHTS`` or ``../shared/models``) are passed on as a
user's would be, and the cache is an empty folder (no case downloads anything).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import pytest
import torch
from PIL import Image

from tests.conftest import SHARED

SAMPLE = Path(__file__).resolve().parents[1] / "samvg" / "samples" / "sailing_sunset.png"
SVG = '<svg xmlns="http://www.w3.org/2000/svg" {size}>{body}</svg>'

DISK_FULL = """
import errno, os, sys
def full(_fd):
    raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
os.fsync = full  # the atomic write's last step before the rename: the disk is full
from samvg.cli import main
sys.exit(main(sys.argv[1:]))
"""
NO_MATPLOTLIB = """
import sys
sys.modules["matplotlib"] = None  # as if the bench extra were not installed
from samvg.bench.cli import main
sys.exit(main(sys.argv[1:]))
"""


def svg(size: str = 'width="20" height="10"', body: str = "") -> str:
    return SVG.format(size=size, body=body)


@dataclass
class Case:
    """``samvg ARGS`` in a folder prepared by ``make``; ``message`` is part of the one line."""

    args: list[str]
    message: str
    make: Maker = lambda _folder: None
    env: dict[str, str | None] = field(default_factory=dict)
    code: int = 1
    script: str | None = None
    skip: Callable[[Path], str | None] = lambda _folder: None


# ---------------------------------------------------------------------- folder builders
Maker = Callable[[Path], None]


def mkdir(*names: str) -> Maker:
    def make(folder: Path) -> None:
        for name in names:
            (folder / name).mkdir(parents=True)

    return make


def text(name: str, content: str) -> Maker:
    def make(folder: Path) -> None:
        (folder / name).write_text(content)

    return make


def data(name: str, content: bytes) -> Maker:
    def make(folder: Path) -> None:
        (folder / name).write_bytes(content)

    return make


def copy(name: str) -> Maker:
    def make(folder: Path) -> None:
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(SAMPLE, folder / name)

    return make


def both(*makers: Maker) -> Maker:
    def make(folder: Path) -> None:
        for maker in makers:
            maker(folder)

    return make


def uniform(name: str) -> Maker:
    def make(folder: Path) -> None:
        Image.new("RGB", (20, 12), (40, 90, 200)).save(folder / name)

    return make


def link(name: str, target: str) -> Maker:
    def make(folder: Path) -> None:
        (folder / name).symlink_to(target)

    return make


def fifo(name: str) -> Maker:
    def make(folder: Path) -> None:
        os.mkfifo(folder / name)

    return make


def read_only(name: str) -> Maker:
    def make(folder: Path) -> None:
        (folder / name).mkdir()
        (folder / name).chmod(0o555)

    return make


def still_writable(name: str) -> Callable[[Path], str | None]:
    """A skip reason when ``name`` is writable although read-only (root writes anywhere)."""

    def check(folder: Path) -> str | None:
        if os.access(folder / name, os.W_OK):
            return "runs as root: a read-only folder is still writable (see the -is-a-file cases)"
        return None

    return check


def nested(depth: int) -> str:
    return svg(body="<g>" * depth + '<rect width="5" height="5"/>' + "</g>" * depth)


def device_present(device: str) -> Callable[[Path], str | None]:
    """A skip reason when ``device`` exists here (the case is about a machine without it)."""

    def check(_folder: Path) -> str | None:
        if device == "mps":
            present = torch.backends.mps.is_available()
        else:
            index = int(device.partition(":")[2] or 0)
            present = torch.cuda.is_available() and torch.cuda.device_count() > index
        return f"{device} exists on this machine" if present else None

    return check


IMG = copy("in.png")
VEC = ["in.png", "-o", "out.svg"]

CASES: dict[str, Case] = {
    # 1. outputs checked before any work
    "out-is-a-folder": Case(VEC, "out.svg is a folder", both(IMG, mkdir("out.svg"))),
    "out-names-a-folder": Case(["in.png", "-o", "new.svg/"], "names a folder", IMG),
    "out-folder-is-a-file": Case(
        ["in.png", "-o", "f.txt/out.svg"], "f.txt is a file", both(IMG, text("f.txt", "x"))
    ),
    "out-folder-missing": Case(["in.png", "-o", "no/out.svg"], "no does not exist", IMG),
    "out-folder-read-only": Case(
        ["in.png", "-o", "ro/out.svg"],
        "ro is not writable",
        both(IMG, read_only("ro")),
        skip=still_writable("ro"),
    ),
    "out-is-not-a-regular-file": Case(VEC, "not a regular file", both(IMG, fifo("out.svg"))),
    "out-wrong-suffix": Case(["in.png", "-o", "out.png"], "should end in .svg", IMG),
    "disk-full-vectorize": Case(
        ["flat.png", "-o", "out.svg"],
        "No space left on device",
        uniform("flat.png"),
        script=DISK_FULL,
    ),
    "disk-full-render": Case(
        ["render", "in.svg", "-o", "out.png"],
        "No space left on device",
        text("in.svg", svg()),
        script=DISK_FULL,
    ),
    "preview-is-a-folder": Case(
        [*VEC, "--preview", "p.png"], "preview p.png is a folder", both(IMG, mkdir("p.png"))
    ),
    "preview-folder-is-a-file": Case(
        [*VEC, "--preview", "f.txt/p.png"], "f.txt is a file", both(IMG, text("f.txt", "x"))
    ),
    "save-stages-is-a-file": Case(
        [*VEC, "--save-stages", "f.txt"], "f.txt is a file", both(IMG, text("f.txt", "x"))
    ),
    "save-stages-below-a-file": Case(
        [*VEC, "--save-stages", "f.txt/stages"], "cannot create", both(IMG, text("f.txt", "x"))
    ),
    "render-out-is-a-folder": Case(
        ["render", "in.svg", "-o", "r.png"],
        "r.png is a folder",
        both(text("in.svg", svg()), mkdir("r.png")),
    ),
    "render-out-folder-missing": Case(
        ["render", "in.svg", "-o", "no/r.png"], "does not exist", text("in.svg", svg())
    ),
    "segment-out-is-a-folder": Case(
        ["segment", "in.png", "-o", "m.png"], "m.png is a folder", both(IMG, mkdir("m.png"))
    ),
    "batch-out-is-a-file": Case(
        ["in.png", "two.png", "-o", "f.txt"],
        "f.txt is a file",
        both(IMG, copy("two.png"), text("f.txt", "x")),
    ),
    "batch-out-below-a-file": Case(
        ["in.png", "two.png", "-o", "f.txt/out"],
        "cannot create",
        both(IMG, copy("two.png"), text("f.txt", "x")),
    ),
    "batch-out-named-svg": Case(
        ["in.png", "two.png", "-o", "x.svg"], "-o must be a folder", both(IMG, copy("two.png"))
    ),
    "batch-with-preview": Case(
        ["in.png", "two.png", "-o", "out", "--preview", "p.png"],
        "--preview takes one input",
        both(IMG, copy("two.png")),
    ),
    # 3. batch outputs never collide
    "batch-same-name-in-two-folders": Case(
        ["a/pic.png", "b/pic.png", "-o", "out"],
        "would both be written to",
        both(copy("a/pic.png"), copy("b/pic.png")),
    ),
    "batch-output-is-an-input": Case(
        ["out/x.svg", "in.png", "-o", "out"],
        "is an input of this batch",
        both(IMG, copy("out/x.svg")),
    ),
    # 4. an output that is the input
    "same-file": Case(["same.svg", "-o", "same.svg"], "is the input", copy("same.svg")),
    "same-file-spelled-otherwise": Case(
        ["same.svg", "-o", "sub/../same.svg"], "is the input", both(copy("same.svg"), mkdir("sub"))
    ),
    "same-file-through-a-link": Case(
        ["same.svg", "-o", "link.svg"],
        "is the input",
        both(copy("same.svg"), link("link.svg", "same.svg")),
    ),
    "preview-is-the-input": Case([*VEC, "--preview", "in.png"], "is the input", IMG),
    "render-onto-its-input": Case(
        ["render", "pic.png", "-o", "pic.png"], "is the input", text("pic.png", svg())
    ),
    "segment-onto-its-input": Case(["segment", "in.png", "-o", "in.png"], "is the input", IMG),
    # 5. devices this machine lacks
    "device-cuda": Case(
        [*VEC, "--device", "cuda"], "not available", IMG, skip=device_present("cuda")
    ),
    "device-cuda-3": Case(
        [*VEC, "--device", "cuda:3"], "not available", IMG, skip=device_present("cuda:3")
    ),
    "device-mps": Case([*VEC, "--device", "mps"], "not available", IMG, skip=device_present("mps")),
    "device-unknown": Case([*VEC, "--device", "tpu"], "device must be cpu, cuda", IMG),
    "device-cudax": Case([*VEC, "--device", "cudax"], "device must be cpu, cuda", IMG),
    # 6. precision and seed
    "precision-negative": Case([*VEC, "--precision", "-1"], "precision must be an integer", IMG),
    "precision-absurd": Case([*VEC, "--precision", "99"], "from 0 to 10", IMG),
    "precision-not-a-number": Case([*VEC, "--precision", "abc"], "invalid int value", IMG, code=2),
    "seed-huge": Case([*VEC, "--seed", str(2**70)], "seed must be an integer from 0 to", IMG),
    "seed-negative": Case([*VEC, "--seed", "-1"], "seed must be an integer >= 0", IMG),
    # 7. checkpoints and the cache
    "checkpoint-empty": Case(
        [*VEC, "--checkpoint", "empty.pt"], "is empty (0 bytes)", both(IMG, data("empty.pt", b""))
    ),
    "checkpoint-empty-by-variable": Case(
        VEC,
        "is empty (0 bytes)",
        both(IMG, data("empty.pt", b"")),
        env={"SAMVG_SAM_CHECKPOINT": "empty.pt"},
    ),
    "checkpoint-corrupt": Case(
        [*VEC, "--checkpoint", "bad.pt", "--no-lpips"],
        "cannot read SAM checkpoint",
        both(IMG, data("bad.pt", b"not a checkpoint")),
    ),
    "checkpoint-missing": Case(
        [*VEC, "--checkpoint", "nowhere.pt"], "nowhere.pt does not exist", IMG
    ),
    "cache-below-a-file": Case(
        VEC,
        "cannot create the weight cache",
        both(IMG, text("f.txt", "x")),
        env={"SAMVG_CACHE": "f.txt/cache", "SAMVG_SAM_CHECKPOINT": None},
    ),
    "cache-read-only": Case(
        VEC,
        "weight cache ro is not writable",
        both(IMG, read_only("ro")),
        env={"SAMVG_CACHE": "ro", "SAMVG_SAM_CHECKPOINT": None},
        skip=still_writable("ro"),
    ),
    # 8. samvg render
    "render-width-0": Case(
        ["render", "in.svg", "-o", "o.png"],
        "positive width",
        text("in.svg", svg('width="0" height="10"')),
    ),
    "render-width-negative": Case(
        ["render", "in.svg", "-o", "o.png"],
        "positive width",
        text("in.svg", svg('width="-64" height="64"')),
    ),
    "render-height-0-with-viewbox": Case(
        ["render", "in.svg", "-o", "o.png"],
        "positive height",
        text("in.svg", svg('viewBox="0 0 10 10" height="0"')),
    ),
    "render-100000-nested-groups": Case(
        ["render", "in.svg", "-o", "o.png"], "nested over", text("in.svg", nested(100_000))
    ),
    "render-scale-0": Case(
        ["render", "in.svg", "-o", "o.png", "--scale", "0"],
        "--scale must be",
        text("in.svg", svg()),
    ),
    "render-scale-nan": Case(
        ["render", "in.svg", "-o", "o.png", "--scale", "nan"], "--scale must", text("in.svg", svg())
    ),
    "render-scale-absurd": Case(
        ["render", "in.svg", "-o", "o.png", "--scale", "1e6"],
        "lower --scale",
        text("in.svg", svg()),
    ),
    "render-not-svg": Case(
        ["render", "in.svg", "-o", "o.png"], "not valid SVG/XML", text("in.svg", "hello")
    ),
    "render-missing-input": Case(["render", "in.svg", "-o", "o.png"], "SVG file not found"),
    # 10. samvg-bench without matplotlib
    "bench-without-matplotlib": Case(
        ["--manifest", "m.csv", "--out", "bench"],
        "pip install 'samvg[bench]'",
        text("m.csv", "id,category,png\n"),
        script=NO_MATPLOTLIB,
    ),
    # 11. LPIPS weights named but unusable
    "lpips-corrupt": Case(
        [*VEC, "--lpips-weights", "bad.pt"],
        "cannot read LPIPS weights file",
        both(IMG, data("bad.pt", b"garbage")),
    ),
    "lpips-missing": Case(
        [*VEC, "--lpips-weights", "nowhere.pt"], "nowhere.pt does not exist", IMG
    ),
    "lpips-empty": Case(
        [*VEC, "--lpips-weights", "empty.pt"],
        "is empty (0 bytes)",
        both(IMG, data("empty.pt", b"")),
    ),
    "lpips-corrupt-by-variable": Case(
        VEC,
        "cannot read LPIPS weights file",
        both(IMG, data("bad.pt", b"garbage")),
        env={"SAMVG_LPIPS_WEIGHTS": "bad.pt"},
    ),
    # other bad inputs
    "image-corrupt": Case(
        [*VEC, "--no-lpips"], "cannot read image", data("in.png", b"\x89PNG\r\n\x1a\n junk")
    ),
    "image-empty-file": Case([*VEC, "--no-lpips"], "cannot read image", data("in.png", b"")),
    "image-missing": Case(VEC, "image file not found"),
    "glob-matches-nothing": Case(["*.png", "-o", "out"], "no images found"),
    "model-unknown": Case([*VEC, "--model", "vit_q"], "unknown SAM model", IMG),
    "max-paths-0": Case([*VEC, "--max-paths", "0"], "max paths must be a positive integer", IMG),
    "paths-0": Case([*VEC, "--paths", "0"], "paths must be an integer >= 1", IMG),
    "detail-above-1": Case([*VEC, "--detail", "2"], "detail must be a number from 0 to 1", IMG),
    "filter-speckle-0": Case(
        [*VEC, "--filter-speckle", "0"], "filter speckle must be an integer >= 1", IMG
    ),
    "size-too-small": Case([*VEC, "--size", "4"], "size must be an integer >= 8", IMG),
    "output-option-missing": Case(["in.png"], "required: -o/--output", IMG, code=2),
}


def _model(variable: str, relative: str) -> str | None:
    path = os.environ.get(variable) or str(SHARED / relative)
    return path if Path(path).is_file() else None


@pytest.fixture(scope="module")
def base_env(tmp_path_factory) -> dict[str, str]:
    env = dict(os.environ)
    env["SAMVG_CACHE"] = str(tmp_path_factory.mktemp("empty_cache"))  # never a real download
    for variable, relative in (
        ("SAMVG_SAM_CHECKPOINT", "models/mobile_sam.pt"),
        ("SAMVG_LPIPS_WEIGHTS", "models/lpips_alex.pt"),
    ):
        found = _model(variable, relative)
        if found is None:
            env.pop(variable, None)
        else:
            env[variable] = found
    return env


def _listing(folder: Path) -> list[str]:
    """Every path below ``folder``, hidden files (an atomic write's temporary) included."""
    return sorted(str(path.relative_to(folder)) for path in folder.rglob("*"))


@pytest.mark.parametrize("name", sorted(CASES))
def test_bad_input_is_one_line_and_leaves_nothing(name, tmp_path, base_env):
    case = CASES[name]
    case.make(tmp_path)
    reason = case.skip(tmp_path)
    if reason:
        pytest.skip(reason)
    env = dict(base_env)
    for variable, value in case.env.items():
        if value is None:
            env.pop(variable, None)
        else:
            env[variable] = value
    before = _listing(tmp_path)
    entry = ["-m", "samvg"] if case.script is None else ["-c", case.script]
    completed = subprocess.run(
        [sys.executable, *entry, *case.args],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    lines = completed.stderr.splitlines()
    assert completed.returncode == case.code, completed.stderr
    assert len(lines) == 1, completed.stderr
    assert "Traceback" not in completed.stderr
    assert lines[0].startswith("error: ") and case.message in lines[0], lines[0]
    assert completed.stdout == ""
    assert _listing(tmp_path) == before


def test_the_matrix_covers_every_defect_of_the_issue():
    """One case or more for each numbered defect that the command line can show."""
    prefixes = {
        1: ("out-", "preview-", "save-stages-", "render-out-", "batch-out-", "disk-full-"),
        3: ("batch-same-name",),
        4: ("same-file",),
        5: ("device-cuda", "device-mps"),
        6: ("precision-", "seed-"),
        7: ("checkpoint-empty", "cache-"),
        8: ("render-width-", "render-100000-"),
        10: ("bench-without-matplotlib",),
        11: ("lpips-",),
    }
    for defect, starts in prefixes.items():
        assert any(name.startswith(starts) for name in CASES), defect
    assert len(CASES) >= 60


def test_a_long_error_stays_on_one_line(tmp_path, base_env):
    """rich wraps at 80 columns unless told not to: a long path must not break the line."""
    deep = tmp_path / ("d" * 60) / ("e" * 60)
    deep.mkdir(parents=True)
    (deep / "out.svg").mkdir()
    shutil.copyfile(SAMPLE, deep / "in.png")
    completed = subprocess.run(
        [sys.executable, "-m", "samvg", str(deep / "in.png"), "-o", str(deep / "out.svg")],
        env={**base_env, "COLUMNS": "40"},
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert completed.returncode == 1
    assert completed.stderr.count("\n") == 1 and len(completed.stderr) > 160
