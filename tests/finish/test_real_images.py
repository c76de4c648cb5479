"""The finish stage on real optimized scenes: no path crosses itself afterwards, every control
point lies within the margin, and the render stays as close to the target as before."""

import time

import numpy as np
import pytest

import samvg
from samvg.finish import crossing_paths, finish_scene, margin_box

IMAGES = ["clipart/openclipart_sailing_sunset.png", "emoji/twemoji_butterfly.png"]


@pytest.mark.slow
@pytest.mark.parametrize("name", IMAGES)
def test_finishing_an_optimized_scene_untangles_it_at_the_same_error(
    name, bench_dir, sam_checkpoint
):
    result = samvg.run(bench_dir / name, samvg.Config.fast(checkpoint=str(sam_checkpoint)))
    scene, target = result.scene, result.target
    assert scene is not None and target is not None
    start = time.perf_counter()
    finished = finish_scene(scene)
    elapsed = time.perf_counter() - start
    before = float(np.mean((scene.render() - target) ** 2))
    after = float(np.mean((finished.scene.render() - target) ** 2))
    print(
        f"{name}: {scene.path_count} -> {finished.scene.path_count} paths, crossing "
        f"{len(crossing_paths(scene))} -> {len(crossing_paths(finished.scene))}, MSE "
        f"{before:.6f} -> {after:.6f} ({after / before - 1:+.2%}), {elapsed:.2f} s, "
        f"{finished.counts}"
    )
    assert len(crossing_paths(finished.scene)) == 0
    left, top, right, bottom = margin_box(scene.width, scene.height, 0.02 * max(target.shape))
    x, y = finished.scene.points[:, 0], finished.scene.points[:, 1]
    assert x.min() >= left and x.max() <= right and y.min() >= top and y.max() <= bottom
    assert after <= 1.05 * before
    assert elapsed < 5.0
