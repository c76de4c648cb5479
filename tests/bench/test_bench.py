"""Tests of samvg-bench: manifest reading, the runner (outputs, resuming, failures) and the CLI."""

import csv
import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from samvg import Config, InputError, VectorImage, WeightsError
from samvg.baselines import random_init
from samvg.bench import METHODS, Method, MethodRun, read_manifest, run_bench, write_report
from samvg.bench.cli import main
from samvg.bench.runner import categories_in_turn, plan_methods

TINY = {"size": 64, "iterations": 3}


def stand_in_samvg(job: MethodRun):
    """A quick stand-in for samvg in the runner tests: four fitted random blobs."""
    job.progress("optimize", 1, 1)
    return VectorImage.from_scene(random_init(job.target, 4, steps=2, seed=job.config.seed))


def failing_on_folder(job: MethodRun):
    if job.image_id == "folder":
        raise RuntimeError("boom")
    return VectorImage.from_scene(random_init(job.target, 2, steps=1))


TABLE = {
    **METHODS,
    "samvg": Method("samvg", stand_in_samvg),
    "flaky": Method("flaky", failing_on_folder),
}


def read_rows(out: Path) -> list[dict]:
    with (out / "results.csv").open(newline="") as handle:
        return list(csv.DictReader(handle))


def test_manifest_of_the_bench_set(bench_dir):
    images = read_manifest(bench_dir / "manifest.csv")
    assert len(images) >= 70 and len({i.id for i in images}) == len(images)
    assert all(image.png.is_file() for image in images)
    emoji = read_manifest(bench_dir / "manifest.csv", ["emoji"], limit=3)
    assert [i.category for i in emoji] == ["emoji"] * 3
    with pytest.raises(InputError, match="unknown category emojis; the manifest has clipart"):
        read_manifest(bench_dir / "manifest.csv", ["emojis"])


def test_manifest_mistakes_are_plain_errors(tmp_path):
    with pytest.raises(InputError, match="manifest not found"):
        read_manifest(tmp_path / "none.csv")
    bad = tmp_path / "m.csv"
    bad.write_text("id,png\na,a.png\n")
    with pytest.raises(InputError, match="category"):
        read_manifest(bad)
    bad.write_text("id,category,png\na,x,a.png\na,x,b.png\n")
    with pytest.raises(InputError, match="duplicate id 'a'"):
        read_manifest(bad)
    bad.write_text("id,category,png\n../up,x,a.png\n")
    with pytest.raises(InputError, match="id '../up'"):
        read_manifest(bad)


def test_methods_are_planned_with_samvg_first():
    names = [m.name for m in plan_methods(["live", "vtracer"])]
    assert names == ["samvg", "live", "vtracer"]
    assert [m.name for m in plan_methods(["diffvg", "samvg-nofilter", "samvg"])] == [
        "samvg",
        "diffvg",
        "samvg-nofilter",
    ]
    with pytest.raises(InputError, match="unknown method"):
        plan_methods(["samvg", "potrace"])


def test_run_writes_results_resumes_and_records_failures(tiny_manifest, tmp_path, lpips_file):
    out = tmp_path / "out"
    methods = ["samvg", "diffvg", "live", "vtracer", "flaky"]
    config = Config(use_lpips=False)
    first = run_bench(
        tiny_manifest,
        out,
        methods,
        config=config,
        method_table=TABLE,
        lpips_weights=lpips_file,
        report=False,
        **TINY,
    )
    assert (first.done, first.failed, first.skipped) == (9, 6, 0)
    rows = read_rows(out)
    assert len(rows) == 15
    by_key = {(r["id"], r["method"]): r for r in rows}
    # the unreadable image fails for every method, with its reason
    assert all(by_key["broken", m]["status"] == "error" for m in methods)
    assert "cannot read image" in by_key["broken", "samvg"]["error"]
    # a method raising on one image is recorded; the run went on
    assert by_key["folder", "flaky"]["status"] == "error"
    assert "RuntimeError: boom" in by_key["folder", "flaky"]["error"]
    assert by_key["cactus", "flaky"]["status"] == "ok"
    for image in ("cactus", "folder"):
        assert by_key[image, "samvg"]["paths"] == "4"
        assert by_key[image, "diffvg"]["paths"] == "4" and by_key[image, "live"]["paths"] == "4"
        assert abs(int(by_key[image, "vtracer"]["paths"]) - 4) <= 2
        assert by_key[image, "diffvg"]["parameters"] == str(4 * 34)
        for method in ("samvg", "diffvg", "live", "vtracer"):
            row = by_key[image, method]
            assert row["status"] == "ok", row
            assert 0 < float(row["mse"]) < 0.2 and 0 <= float(row["lpips"]) < 1
            assert float(row["psnr"]) > 5 and -1 <= float(row["ssim"]) <= 1
            assert float(row["complexity"]) > 0 and float(row["time_s"]) >= 0
            svg = out / "svg" / method / f"{image}.svg"
            assert int(row["svg_bytes"]) == len(svg.read_bytes())
            assert (out / "renders" / method / f"{image}.png").is_file()
    assert json.loads(by_key["cactus", "diffvg"]["details"])["steps"] == 2 * 3

    # rerun: nothing is redone (failures are kept too), files untouched
    stamp = (out / "records" / "live" / "cactus.json").stat().st_mtime_ns
    again = run_bench(
        tiny_manifest,
        out,
        methods,
        config=config,
        method_table=TABLE,
        lpips_weights=lpips_file,
        report=False,
        **TINY,
    )
    assert (again.done, again.failed, again.skipped) == (0, 0, 15)
    assert (out / "records" / "live" / "cactus.json").stat().st_mtime_ns == stamp
    retry = run_bench(
        tiny_manifest,
        out,
        methods,
        config=config,
        method_table=TABLE,
        lpips_weights=lpips_file,
        report=False,
        retry_failed=True,
        **TINY,
    )
    assert (retry.done, retry.failed, retry.skipped) == (0, 6, 9)

    with pytest.raises(InputError, match="other settings.*iterations: 3 -> 4"):
        run_bench(
            tiny_manifest,
            out,
            methods,
            config=config,
            method_table=TABLE,
            lpips_weights=lpips_file,
            size=64,
            iterations=4,
        )

    # a run file from before a setting existed holds the value that behaves as samvg did then
    run_file = out / "run.json"
    info = json.loads(run_file.read_text())
    assert info["settings"].pop("lpips_colours") is True
    run_file.write_text(json.dumps(info))
    resumed = run_bench(tiny_manifest, out, methods, config=config, method_table=TABLE,
                        lpips_weights=lpips_file, report=False, **TINY)  # fmt: skip
    assert resumed.skipped == 15
    # the finish pass's options are compared only where it runs
    finish_off = config.replace(finish_pass=False)
    run_file.write_text(json.dumps(info))
    with pytest.raises(InputError, match="finish_pass: True -> False"):
        run_bench(tiny_manifest, out, methods, config=finish_off, method_table=TABLE,
                  lpips_weights=lpips_file, report=False, **TINY)  # fmt: skip
    info["settings"].update(finish_pass=False, whole_pixels=False)
    run_file.write_text(json.dumps(info))
    resumed = run_bench(tiny_manifest, out, methods, config=finish_off, method_table=TABLE,
                        lpips_weights=lpips_file, report=False, **TINY)  # fmt: skip
    assert resumed.skipped == 15
    with pytest.raises(InputError, match="lpips_colours: True -> False"):
        run_bench(tiny_manifest, out, methods, config=finish_off.replace(lpips_colours=False),
                  method_table=TABLE, lpips_weights=lpips_file, report=False, **TINY)  # fmt: skip


def test_report_in_the_papers_layout(tiny_manifest, tmp_path, lpips_file, fid_file):
    out = tmp_path / "out"
    run_bench(
        tiny_manifest,
        out,
        ["samvg", "diffvg", "vtracer"],
        config=Config(use_lpips=False),
        method_table=TABLE,
        lpips_weights=lpips_file,
        fid_weights=fid_file,
        command="samvg-bench --test",
        **TINY,
    )
    summary = (out / "summary.md").read_text()
    assert "| Metrics | samvg | diffvg | vtracer |" in summary
    for label in (
        "MSE ×10⁻³",
        "LPIPS",
        "FID",
        "Complexity",
        "Paths",
        "Num of parameters",
        "Time (s)",
        "SVG bytes",
        "PSNR",
        "SSIM",
    ):
        assert f"| {label}" in summary
    assert "### emoji" in summary and "### icon" in summary
    assert "samvg-bench --test" in summary
    assert "| broken | samvg | InputError: cannot read image" in summary
    assert "2 of 3 images have results from every method" in summary
    fid_line = next(line for line in summary.splitlines() if line.startswith("| FID"))
    assert "n/a" not in fid_line
    for name in ("time_vs_paths.png", "mse_vs_paths.png", "contact_sheet.png"):
        assert (out / name).stat().st_size > 1000
    # FID survives the loss of the renders and targets (not kept with committed results)
    stored = sorted(path.relative_to(out).as_posix() for path in (out / "fid").rglob("*.npy"))
    assert stored == [
        f"fid/{kind}/{image}.npy"
        for kind in ("renders/diffvg", "renders/samvg", "renders/vtracer", "targets")
        for image in ("cactus", "folder")
    ]
    for folder in ("renders", "targets"):
        shutil.rmtree(out / folder)
    assert main(["--out", str(out), "--report-only", "--fid-weights", str(fid_file)]) == 0
    again = (out / "summary.md").read_text()
    assert next(line for line in again.splitlines() if line.startswith("| FID")) == fid_line
    # the report can be rewritten from the folder alone, by the CLI too (results.csv with it)
    rows = read_rows(out)
    (out / "results.csv").unlink()
    assert main(["--out", str(out), "--report-only", "--no-fid"]) == 0
    assert read_rows(out) == rows
    assert write_report(out, fid=False) == out / "summary.md"
    assert "| FID ↓ | n/a | n/a | n/a |" in (out / "summary.md").read_text()


def test_cli_runs_and_resumes(tiny_manifest, tmp_path, lpips_file, monkeypatch, capsys):
    monkeypatch.setitem(METHODS, "samvg", Method("samvg", stand_in_samvg))
    out = tmp_path / "cli"
    arguments = [
        "--manifest",
        str(tiny_manifest),
        "--out",
        str(out),
        "--methods",
        "vtracer",
        "--size",
        "64",
        "--iterations",
        "2",
        "--limit",
        "2",
        "--categories",
        "emoji,icon",
        "--lpips-weights",
        str(lpips_file),
        "--no-fid",
    ]
    assert main(arguments) == 0
    assert "4 results made, 0 already there, 0 failed" in capsys.readouterr().err
    assert {(r["id"], r["method"]) for r in read_rows(out)} == {
        (i, m) for i in ("cactus", "folder") for m in ("samvg", "vtracer")
    }
    summary = (out / "summary.md").read_text()
    assert "--methods vtracer" in summary and "FID not computed (--no-fid)" in summary
    assert main(arguments) == 0
    assert "0 results made, 4 already there" in capsys.readouterr().err


def test_cli_preset_paper_runs_the_papers_procedure(
    tiny_manifest, tmp_path, lpips_file, monkeypatch, capsys
):
    """``--preset paper`` (Tables 1 and 2) starts from Config.paper; resuming the folder with
    another preset is refused with the settings that differ."""
    seen: list[Config] = []

    def recording_samvg(job: MethodRun):
        seen.append(job.config)
        return stand_in_samvg(job)

    monkeypatch.setitem(METHODS, "samvg", Method("samvg", recording_samvg))
    out = tmp_path / "paper"
    arguments = ["--manifest", str(tiny_manifest), "--out", str(out), "--methods", "samvg"]
    arguments += ["--size", "64", "--iterations", "2", "--limit", "1", "--no-fid"]
    arguments += ["--lpips-weights", str(lpips_file)]
    assert main([*arguments, "--preset", "paper"]) == 0
    paper = Config.paper()
    assert [config.segment.points_per_side for config in seen] == [32]
    assert seen[0].trace == paper.trace and seen[0].missing == paper.missing
    settings = json.loads((out / "run.json").read_text())["settings"]
    assert settings["finish_pass"] is False and settings["translucent"] is True
    capsys.readouterr()
    assert main(arguments) == 1
    assert "points_per_side: 32 -> 16" in capsys.readouterr().err


def test_a_run_takes_the_categories_in_turn(tmp_path):
    rows = [("p1", "photo"), ("p2", "photo"), ("p3", "photo"), ("e1", "emoji"), ("i1", "icon")]
    manifest = tmp_path / "manifest.csv"
    manifest.write_text(
        "id,category,png\n" + "".join(f"{i},{c},{i}.png\n" for i, c in rows), encoding="utf-8"
    )
    images = read_manifest(manifest)
    order = [image.id for image in categories_in_turn(images)]
    assert order == ["p1", "e1", "i1", "p2", "p3"]


def test_cli_reports_mistakes_plainly(tmp_path, capsys):
    assert main(["--out", str(tmp_path / "o"), "--manifest", str(tmp_path / "no.csv")]) == 1
    assert "manifest not found" in capsys.readouterr().err
    assert main(["--out", str(tmp_path / "o")]) == 1
    assert "--manifest is required" in capsys.readouterr().err
    assert main(["--out", str(tmp_path / "empty"), "--report-only"]) == 1


@pytest.mark.slow
def test_real_methods_on_a_tiny_image(tiny_manifest, tmp_path, lpips_file, sam_checkpoint):
    """The real samvg pipeline and its ablation, then the baselines at its path count."""
    out = tmp_path / "out"
    config = Config(points_per_side=4, use_lpips=False, checkpoint=str(sam_checkpoint))
    outcome = run_bench(
        tiny_manifest,
        out,
        ["samvg", "samvg-nofilter", "diffvg", "live"],
        config=config,
        limit=1,
        lpips_weights=lpips_file,
        report=False,
        **TINY,
    )
    assert outcome.failed == 0, read_rows(out)
    rows = {r["method"]: r for r in read_rows(out)}
    paths = int(rows["samvg"]["paths"])
    assert paths >= 1 and rows["diffvg"]["paths"] == rows["live"]["paths"] == str(paths)
    assert float(rows["samvg"]["mse"]) < 0.1
    assert np.isfinite(float(rows["samvg-nofilter"]["lpips"]))


def test_a_missing_optional_module_is_a_one_line_install_hint(tmp_path, capsys, monkeypatch):
    """samvg-bench on a plain install (no bench extra) names the extra before any work."""
    import importlib.util

    real = importlib.util.find_spec
    monkeypatch.setattr(
        importlib.util,
        "find_spec",
        lambda name, *a: None if name == "matplotlib" else real(name, *a),
    )
    assert main(["--manifest", str(tmp_path / "m.csv"), "--out", str(tmp_path / "out")]) == 1
    err = capsys.readouterr().err
    assert err.splitlines() == [
        "error: samvg-bench needs matplotlib for the report's plots, and it is not installed: "
        "pip install 'samvg[bench]'"
    ]
    assert not (tmp_path / "out").exists()


def test_stored_fid_features_match_a_batched_pass(tmp_path, fid_file, bench_dir):
    from samvg import metrics
    from samvg.bench.features import FeatureStore
    from samvg.bench.layout import Layout
    from samvg.bench.runner import load_target

    images = [
        load_target(bench_dir / "emoji" / "noto_cactus.png", 128),
        load_target(bench_dir / "icon" / "tango_folder_open.png", 128),
    ]
    store = FeatureStore(Layout(tmp_path), fid_file)
    for index, image in enumerate(images):
        store.save_target(f"image{index}", image)
    batched = metrics.fid_features(metrics.load_fid_inception(fid_file), images)
    stored = np.stack([store.target(f"image{index}") for index in range(2)])
    assert stored.shape == (2, 2048) and np.abs(batched).max() > 0.1
    np.testing.assert_allclose(stored, batched, rtol=1e-4, atol=1e-5)
    assert store.target("never_run") is None


def test_a_run_without_fid_weights_stops_before_work(tiny_manifest, tmp_path, lpips_file):
    out = tmp_path / "out"
    missing = tmp_path / "absent.pt"
    with pytest.raises(WeightsError, match="pass --no-fid to run without FID"):
        run_bench(tiny_manifest, out, ["samvg"], method_table=TABLE, lpips_weights=lpips_file,
                  fid_weights=missing, **TINY)  # fmt: skip
    assert not (out / "records").exists()
