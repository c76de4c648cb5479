"""The finish stage as a whole: settings, counts, an empty scene, speed, a second pass."""

import time

import numpy as np
import pytest

from samvg import InputError
from samvg.finish import FinishSettings, crossing_paths, finish_scene, margin_box
from samvg.scene import FlatPaint, Scene
from tests.finish.shapes import RED, figure_eight, is_simple, scene_of


def test_an_empty_scene_is_unchanged():
    scene = Scene(64, 48, background=(0.2, 0.3, 0.4))
    result = finish_scene(scene, FinishSettings(colours=3))
    assert result.scene.path_count == 0
    assert result.scene.background == (0.2, 0.3, 0.4)
    assert (result.scene.width, result.scene.height) == (64, 48)
    assert result.counts["finish_paths_in"] == result.counts["finish_paths_out"] == 0
    assert all(value == 0 for value in result.counts.values())


def test_steps_switched_off_report_nothing_and_change_nothing():
    scene = scene_of((figure_eight(), RED))
    settings = FinishSettings(simplify=False, remove_hidden=False, merge=False)
    result = finish_scene(scene, settings)
    assert "simple_repaired" not in result.counts and "merged" not in result.counts
    assert np.array_equal(result.scene.points, scene.points)


@pytest.mark.parametrize(
    ("field", "value", "message"),
    [
        ("tolerance", 0, "tolerance must be > 0"),
        ("tolerance", float("nan"), "tolerance must be a finite number"),
        ("margin", -1.0, "margin must be >= 0"),
        ("merge_delta_e", "2", "merge_delta_e must be a finite number"),
        ("colours", 0, "number of colours"),
        ("colours", 1.5, "number of colours"),
        ("simplify", 1, "simplify must be True or False"),
        ("min_part_area", -4, "min_part_area must be >= 0"),
    ],
)
def test_bad_settings_are_input_errors(field, value, message):
    with pytest.raises(InputError, match=message):
        FinishSettings(**{field: value})


def tangled_scene(count: int, seed: int = 0) -> Scene:
    """Blobs of five cubics with jittered control points: most cross themselves, some reach
    beyond the canvas, some overlap in near-equal colours, like an optimizer's output."""
    rng = np.random.default_rng(seed)
    paths = []
    angles = np.linspace(0, 2 * np.pi, 15, endpoint=False)
    palette = rng.uniform(0, 1, (12, 3))
    for _ in range(count):
        centre, radius = rng.uniform(-20, 532, 2), rng.uniform(10, 90)
        ring = centre + radius * np.stack([np.cos(angles), np.sin(angles)], 1)
        points = ring + rng.normal(0, 0.35 * radius, ring.shape)
        colour = np.clip(palette[rng.integers(12)] + rng.normal(0, 0.003, 3), 0, 1)
        paths.append((points, FlatPaint((*colour, 1.0 if rng.uniform() < 0.7 else 0.8))))
    return Scene.from_paths(512, 512, paths)


def test_a_hundred_tangled_paths_finish_simple_and_bounded_in_well_under_seconds():
    scene = tangled_scene(100)
    assert len(crossing_paths(scene)) > 30
    start = time.perf_counter()
    result = finish_scene(scene)
    elapsed = time.perf_counter() - start
    assert len(crossing_paths(result.scene)) == 0
    left, top, right, bottom = margin_box(512, 512, 0.02 * 512)
    x, y = result.scene.points[:, 0], result.scene.points[:, 1]
    assert x.min() >= left and x.max() <= right and y.min() >= top and y.max() <= bottom
    assert result.counts["finish_paths_out"] == result.scene.path_count
    assert elapsed < 2.0  # about 0.3 s on one core; generous for a shared machine


def test_a_finished_scene_finishes_unchanged():
    first = finish_scene(tangled_scene(40, seed=1)).scene
    second = finish_scene(first)
    assert second.counts["simple_repaired"] == second.counts["bounds_clipped"] == 0
    assert second.counts["hidden_removed"] == 0
    assert all(is_simple(points) for points, _ in second.scene.paths())
    assert second.scene.path_count == first.path_count - second.counts["merged"]


def test_the_finish_keeps_a_background_gradient():
    from dataclasses import replace

    from samvg.scene import RadialGradient

    glow = RadialGradient(((0.0, (1, 1, 0)), (1.0, (0, 0, 1))), 1.0, (256.0, 256.0), 300.0)
    scene = replace(tangled_scene(20, seed=2), background_gradient=glow)
    result = finish_scene(scene, FinishSettings(colours=3)).scene
    assert result.background_gradient == glow and result.background == scene.background
