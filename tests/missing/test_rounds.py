"""Stage 4 repeated: colour regions the render gets wrong, automatic rounds that stop when
nothing more helps, and a path budget's pool."""

from dataclasses import replace

import numpy as np

from samvg.missing.marks import MarkSettings
from samvg.missing.stage import (
    MissingSettings,
    add_missing_rounds,
    budget_pool,
    eased_settings,
    offer_wrong_regions,
    smaller_marks,
)
from samvg.optimize import FitSettings
from samvg.scene import Scene
from samvg.segment import ImpactCanvas
from samvg.segment.colour_split import ColourSplitSettings
from samvg.trace.stage import TraceSettings

RED, BLUE = (0.9, 0.1, 0.1), (0.1, 0.2, 0.8)
SPLIT = ColourSplitSettings(min_pixels=8)


class FaintSquareSegmenter:
    """SAM's stand-in that finds the faint square of `faint_target` at any prompt inside it."""

    def prompt(self, points: np.ndarray) -> list[list[np.ndarray]]:
        square = np.zeros((64, 64), bool)
        square[4:20, 40:56] = True
        return [[square] if square[int(y), int(x)] else [] for x, y in points]


def faint_target() -> np.ndarray:
    image = target()
    image[4:20, 40:56] = 0.93  # off white by 0.21 over RGB: below the bars of 0.5 and 0.25
    return image


class SilentSegmenter:
    """SAM's stand-in that finds nothing: only the colour regions can add paths."""

    def prompt(self, points: np.ndarray) -> list[list[np.ndarray]]:
        return [[] for _ in points]


def target() -> np.ndarray:
    image = np.ones((64, 64, 3), np.float32)
    image[6:26, 6:26] = RED
    image[36:50, 30:44] = BLUE
    image[40:46, 8:14] = RED
    return image


def settings(rounds: int | None = None, max_paths: int | None = None) -> MissingSettings:
    return MissingSettings(
        radius=1.0,
        threshold=0.5,
        impact_threshold=1e-4,
        filter_by_impact=True,
        min_pixels=8,
        rounds=rounds,
        max_paths=max_paths,
        colour_split=SPLIT,
    )


def blank_scene() -> Scene:
    return Scene(64, 64, background=(1.0, 1.0, 1.0))


STAGES = (settings(), TraceSettings(4, 8, tolerance=1.0), FitSettings(steps=0))


def test_wrong_regions_become_one_candidate_per_colour_coherent_area():
    image = target()
    canvas = ImpactCanvas(image, 1e-4, start=np.ones_like(image))
    kept = offer_wrong_regions(canvas, np.ones_like(image), 0.25, SPLIT)
    assert kept == 3
    for mask in canvas.kept_masks:
        colours = np.unique(image[mask], axis=0)
        assert len(colours) == 1  # never the blur of two colours


def test_automatic_rounds_stop_when_no_region_is_left():
    done = add_missing_rounds(blank_scene(), target(), SilentSegmenter(), STAGES)
    assert done.added == 3 and done.scene.path_count == 3
    assert done.rounds == 2 and "no region left" in done.stopped
    assert np.mean((done.scene.render() - target()) ** 2) < 1e-3


def test_a_set_number_of_rounds_runs_exactly_that_many():
    stages = (settings(rounds=1), *STAGES[1:])
    done = add_missing_rounds(blank_scene(), target(), SilentSegmenter(), stages)
    assert done.rounds == 1 and done.added == 3


def test_an_automatic_round_that_raises_the_error_is_rolled_back():
    wild = FitSettings(steps=4, point_learning_rate=40.0, colour_learning_rate=1.0)
    automatic = (replace(settings(), refit_scene=False), STAGES[1], wild)
    done = add_missing_rounds(blank_scene(), target(), SilentSegmenter(), automatic)
    assert "rolled back" in done.stopped
    assert done.added == 0 and done.scene.path_count == 0
    planned = (replace(settings(rounds=1), refit_scene=False), STAGES[1], wild)
    kept = add_missing_rounds(blank_scene(), target(), SilentSegmenter(), planned)
    assert kept.added == 3 and kept.scene.path_count == 3  # a set number of rounds keeps them


def test_a_budget_pool_stops_growing_when_full():
    done = add_missing_rounds(blank_scene(), target(), SilentSegmenter(), STAGES, pool=2)
    assert done.scene.path_count == 2 and "pool of 2 paths is full" in done.stopped


def test_rounds_fit_only_what_they_add_then_the_whole_scene_once():
    from dataclasses import replace

    from samvg.scene import FlatPaint
    from tests.paths import square

    misplaced = Scene.from_paths(64, 64, [(square(4, 4, 20), FlatPaint(RED))], (1.0, 1.0, 1.0))
    fit = FitSettings(steps=40)
    steps: list[int] = []
    one_round = (replace(settings(rounds=1), refit_scene=False), STAGES[1], fit)
    done = add_missing_rounds(
        misplaced, target(), SilentSegmenter(), one_round, on_step=lambda s, _: steps.append(s)
    )
    assert done.added >= 2 and steps.count(0) == 2  # the added paths' fit, then the scene's
    assert not np.allclose(done.scene.points[:12], misplaced.points)  # moved in the final fit
    assert np.mean((done.scene.render() - target()) ** 2) < 2e-3
    refit = (settings(rounds=1), STAGES[1], fit)
    steps.clear()
    add_missing_rounds(
        misplaced, target(), SilentSegmenter(), refit, on_step=lambda s, _: steps.append(s)
    )
    assert steps.count(0) == 1  # the paper's round fits the whole scene, once


def test_a_drafted_scene_is_fitted_in_full_even_when_no_round_adds_a_path():
    from dataclasses import replace

    from samvg.scene import FlatPaint
    from tests.paths import square

    image = np.ones((64, 64, 3), np.float32)
    image[6:26, 6:26] = RED
    drafted = Scene.from_paths(64, 64, [(square(4, 4, 20), FlatPaint(RED))], (1.0, 1.0, 1.0))
    stages = (replace(settings(), refit_scene=False), STAGES[1], FitSettings(steps=40))
    kept = add_missing_rounds(drafted, image, SilentSegmenter(), stages)
    assert kept.added == 0 and kept.fitted
    assert np.allclose(kept.scene.points, drafted.points)  # fitted before: left alone
    refitted = add_missing_rounds(drafted, image, SilentSegmenter(), stages, drafted=True)
    assert refitted.added == 0 and refitted.fitted
    assert not np.allclose(refitted.scene.points, drafted.points)
    error = np.mean((refitted.scene.render() - image) ** 2)
    assert error < np.mean((drafted.render() - image) ** 2)


def test_a_budget_pool_eases_the_error_bars_before_it_gives_up():
    image, segmenter = faint_target(), FaintSquareSegmenter()
    unbudgeted = add_missing_rounds(blank_scene(), image, segmenter, STAGES)
    assert unbudgeted.added == 3  # the faint square is left for a budget to fill
    done = add_missing_rounds(blank_scene(), image, segmenter, STAGES, pool=10)
    assert done.added == 4 and done.scene.path_count == 4
    assert "even at 1/8 of the error bars" in done.stopped
    faint = done.scene.render()[4:20, 40:56]
    assert np.abs(faint - 0.93).max() < 0.02


def test_paths_found_at_eased_error_bars_must_lower_the_error_by_the_tolerance():
    strict = (replace(settings(), gain_tolerance=1.0), *STAGES[1:])  # no round gains 100 %
    done = add_missing_rounds(
        blank_scene(), faint_target(), FaintSquareSegmenter(), strict, pool=10
    )
    assert done.added == 3 and done.scene.path_count == 3  # the faint square was rolled back
    assert "improves by 100%, even at 1/8 of the error bars" in done.stopped


def test_eased_settings_halve_the_prompts_and_marks_error_bars():
    eased = eased_settings(replace(settings(), marks=MarkSettings(pixel_error=0.15)))
    assert eased.threshold == 0.25 and eased.pixel_error == settings().pixel_error
    assert eased.marks is not None and eased.marks.pixel_error == 0.075
    assert eased.impact_threshold == settings().impact_threshold


def test_a_budget_pool_leaves_room_to_grow_a_scene_that_already_fills_it():
    assert budget_pool(64, 10) == 80  # the pool itself: 1.25 x the budget
    assert budget_pool(64, 133) == 149  # stages 1-3 gave more: a quarter of the budget on top
    assert budget_pool(16, 75) == 79
    # a budget of 1 whose scene has 2 paths already: stage 4 may still add one (of 3 regions)
    full = add_missing_rounds(blank_scene(), target(), SilentSegmenter(), STAGES, pool=2).scene
    done = add_missing_rounds(full, target(), SilentSegmenter(), STAGES, pool=budget_pool(1, 2))
    assert done.added == 1 and done.scene.path_count == 3


def starry_target() -> np.ndarray:
    """A dark 64 x 64 sky with twelve stars, each a cross of five pixels with one-pixel arms."""
    image = np.empty((64, 64, 3), np.float32)
    image[:] = (0.1, 0.15, 0.3)
    for row in range(8, 60, 16):
        for col in range(10, 60, 20):
            image[row - 1 : row + 2, col] = 0.95
            image[row, col - 1 : col + 2] = 0.95
    return image


def test_a_budget_pool_looks_for_smaller_marks_once_the_error_bars_are_spent():
    sky = Scene(64, 64, background=(0.1, 0.15, 0.3))
    starry = (replace(settings(), marks=MarkSettings()), *STAGES[1:])
    unbudgeted = add_missing_rounds(sky, starry_target(), SilentSegmenter(), starry)
    assert unbudgeted.added == 0  # five pixels: speckle at VTracer's 16
    done = add_missing_rounds(sky, starry_target(), SilentSegmenter(), starry, pool=20)
    assert done.added == 12 and "and marks of 4 px" in done.stopped
    error = np.mean((done.scene.render() - starry_target()) ** 2)
    assert error < np.mean((sky.render() - starry_target()) ** 2) / 4


def test_smaller_marks_halve_their_size_at_the_first_error_bar():
    first = MarkSettings(pixel_error=0.15)
    eased = eased_settings(eased_settings(replace(settings(), marks=first)))
    smaller = smaller_marks(eased, first)
    assert smaller.marks is not None and smaller.threshold == eased.threshold
    assert (smaller.marks.min_pixels, smaller.marks.pixel_error) == (8, 0.15)
    assert smaller.marks.opening and smaller.marks_only
    finest = smaller_marks(smaller, first, finest=True).marks
    assert finest is not None and (finest.min_pixels, finest.opening) == (4, False)
    assert smaller_marks(settings(), first) == settings()  # no marks: nothing to ease
