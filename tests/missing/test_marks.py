"""Small marks on flat areas: dashes of one colour form one group, two colours two groups;
one-pixel seams, speckle and misplaced edges are not marks; stage 4 paints the groups last."""

import numpy as np
from scipy import ndimage

from samvg.missing import MissingSettings, add_missing, missing_masks
from samvg.missing.marks import MarkSettings, mark_groups
from samvg.optimize import FitSettings
from samvg.scene import Scene
from samvg.segment.colour_split import lab_image
from samvg.trace.stage import TraceSettings

GREEN = (0.13, 0.6, 0.38)
LIGHT = (0.2, 0.78, 0.5)
DARK = (0.05, 0.35, 0.2)


def field(colours: dict[tuple[int, int], tuple[float, float, float]]) -> np.ndarray:
    """A 96 × 96 green field with a 2 × 10 dash of the given colour at each (row, col)."""
    image = np.empty((96, 96, 3), np.float32)
    image[:] = GREEN
    for (row, col), colour in colours.items():
        image[row : row + 2, col : col + 10] = colour
    return image


def flat_render() -> np.ndarray:
    render = np.empty((96, 96, 3), np.float32)
    render[:] = GREEN
    return render


def groups(target: np.ndarray, render: np.ndarray) -> list[np.ndarray]:
    return mark_groups(target, render, lab_image(target), MarkSettings())


DASHES = [(row, col) for row in range(8, 90, 16) for col in range(6, 80, 20)]


def test_dashes_of_one_colour_are_one_group_with_a_component_each():
    target = field({spot: LIGHT for spot in DASHES})
    found = groups(target, flat_render())
    assert len(found) == 1
    assert ndimage.label(found[0])[1] == len(DASHES)
    assert found[0].sum() == 20 * len(DASHES)


def test_two_colours_make_two_groups_the_larger_first():
    colours = {spot: (LIGHT if i % 3 else DARK) for i, spot in enumerate(DASHES)}
    found = groups(field(colours), flat_render())
    assert len(found) == 2
    assert found[0].sum() > found[1].sum()
    light = [spot for spot, colour in colours.items() if colour == LIGHT]
    assert all(found[0][row, col] for row, col in light)


def test_seams_and_speckle_are_not_marks():
    target = field({})
    target[20, 10:60] = LIGHT  # a one-pixel line
    target[50:53, 50:53] = LIGHT  # 9 pixels: speckle
    assert groups(target, flat_render()) == []


def test_without_the_opening_strokes_one_pixel_wide_are_marks():
    target = field({})
    target[20, 10:60] = LIGHT  # a star's arm, one pixel wide
    target[50:53, 50:53] = LIGHT  # still speckle
    found = mark_groups(target, flat_render(), lab_image(target), MarkSettings(opening=False))
    assert len(found) == 1 and found[0].sum() == 50 and found[0][20, 10:60].all()


def test_a_misplaced_edge_is_not_a_mark():
    target = field({})
    target[:, 48:] = DARK
    render = flat_render()
    render[:, 52:] = DARK  # the render's edge lies 4 pixels off: the strip borders it
    assert groups(target, render) == []


class NoSegmenter:
    """SAM's stand-in that finds nothing at any prompt."""

    def prompt(self, points: np.ndarray) -> list[list[np.ndarray]]:
        return [[] for _ in points]


MARKS = MarkSettings()


def stage_settings(marks: MarkSettings | None = MARKS) -> MissingSettings:
    """One round: radius 1, ω 0.5, impact 1e-5, the filter on, regions of 50 pixels or more."""
    return MissingSettings(1.0, 0.5, 1e-5, True, 50, 1, marks=marks)


def test_stage_four_offers_the_marks_and_paints_them_last():
    target = field({spot: LIGHT for spot in DASHES})
    settings = stage_settings()
    regions, marks = missing_masks(NoSegmenter(), np.zeros((0, 2)), target, flat_render(), settings)
    assert regions == [] and len(marks) == 1 and ndimage.label(marks[0])[1] == len(DASHES)
    without = missing_masks(
        NoSegmenter(), np.zeros((0, 2)), target, flat_render(), stage_settings(marks=None)
    )
    assert without == ([], [])


def test_regions_and_marks_come_apart():
    class SquareSegmenter:
        def prompt(self, points: np.ndarray) -> list[list[np.ndarray]]:
            mask = np.zeros((96, 96), bool)
            mask[84:96, 84:96] = True
            return [[mask] for _ in points]

    target = field({spot: LIGHT for spot in DASHES})
    target[84:96, 84:96] = DARK
    settings = stage_settings()
    prompts = np.array([[90.0, 90.0]])
    regions, marks = missing_masks(SquareSegmenter(), prompts, target, flat_render(), settings)
    assert [int(mask.sum()) for mask in regions] == [144]
    assert [int(mask.sum()) for mask in marks] == [20 * len(DASHES)]


def test_marks_are_traced_closely_and_kept_when_small():
    trace = TraceSettings(segments=4, min_pixels=50, tolerance=2.0)
    fine = MarkSettings(min_pixels=9).trace_settings(trace)
    assert (fine.min_pixels, fine.tolerance) == (9, 0.75)
    fixed = MarkSettings().trace_settings(TraceSettings(segments=5, min_pixels=50))
    assert fixed.tolerance is None and fixed.segments == 5


def test_a_round_of_stage_four_adds_a_path_for_each_mark():
    target = field({spot: LIGHT for spot in DASHES})
    settings = stage_settings()
    scene = Scene(96, 96, background=GREEN)
    trace = TraceSettings(4, 50, tolerance=2.0)
    done = add_missing(scene, target, NoSegmenter(), settings, trace, FitSettings(steps=0))
    assert done.added == len(DASHES) and done.scene.fixed_paths().all()
    assert np.abs(done.scene.render() - target).mean() < np.abs(scene.render() - target).mean() / 4
