"""Tests of path fitting: the optimiser moves a misplaced shape onto its target and fixes colour."""

from dataclasses import replace

import numpy as np
import pytest
import torch

from samvg import InputError, SamvgError
from samvg.optimize import FitSettings, fit_scene
from samvg.scene import FlatPaint, Scene
from tests.paths import square


def scene_of(paths, size=64) -> Scene:
    return Scene.from_paths(size, size, [(points, FlatPaint(fill)) for points, fill in paths])


def test_fit_moves_shape_and_colour_onto_target():
    target = scene_of([(square(20, 24, 24), (0.9, 0.2, 0.1, 1.0))]).render()
    start = scene_of([(square(14, 18, 20), (0.5, 0.5, 0.5, 1.0))])
    result = fit_scene(start, target, FitSettings(steps=150))
    assert result.losses[-1] < result.losses[0] / 20
    np.testing.assert_allclose(result.scene.colours()[0, :3], (0.9, 0.2, 0.1), atol=0.05)
    assert np.abs(result.scene.render() - target).mean() < 0.01
    assert np.abs(result.scene.points[6] - (44, 48)).max() < 1.0  # the far corner found its place


def test_fit_handles_paths_of_different_lengths():
    triangle = square(30, 30, 20)[:9]  # three of the square's segments, closed
    target = scene_of([(square(8, 8, 16), (0.1, 0.6, 0.2, 1.0)), (triangle, (0, 0, 1, 1))])
    start = scene_of([(square(10, 10, 12), (0.5, 0.5, 0.5, 1.0)), (triangle + 3, (0, 0, 1, 1))])
    settings = FitSettings(steps=120, xing_weight=0.01)
    result = fit_scene(start, target.render(), settings)
    assert list(result.scene.segment_counts()) == [4, 3]
    assert result.losses[-1] < result.losses[0] / 10


def test_fit_rejects_bad_target_and_accepts_no_paths():
    one = scene_of([(square(1, 1, 4), (0, 0, 0, 1))], size=8)
    with pytest.raises(InputError, match="target"):
        fit_scene(one, np.zeros((8, 8)), FitSettings())
    with pytest.raises(InputError, match="scene is 8x8"):
        fit_scene(one, np.zeros((9, 8, 3)), FitSettings())
    empty = fit_scene(Scene(8, 8), np.zeros((8, 8, 3)), FitSettings(steps=5))
    assert empty.scene.path_count == 0 and empty.losses == []


def test_diverging_fit_is_a_clear_error():
    one = scene_of([(square(1, 1, 4), (0, 0, 0, 1))], size=8)
    with pytest.raises(SamvgError, match="diverged"):
        fit_scene(one, np.zeros((8, 8, 3)), FitSettings(steps=3, point_learning_rate=float("inf")))


def test_a_gradient_paint_is_fitted_with_the_geometry():
    from samvg.scene import LinearGradient, RadialGradient

    square = np.array([[2, 2], [14, 2], [26, 2], [30, 2], [30, 14], [30, 30],
                       [30, 30], [16, 30], [2, 30], [2, 30], [2, 16], [2, 2]], float)  # fmt: skip
    stops = ((0.0, (0.9, 0.2, 0.1)), (1.0, (0.1, 0.3, 0.9)))
    truth = LinearGradient(stops, 1.0, (6.0, 4.0), (26.0, 28.0))
    target = Scene.from_paths(32, 32, [(square, truth)], background=(1, 1, 1)).render()
    guess_stops = ((0.1, (0.5, 0.5, 0.5)), (0.9, (0.4, 0.4, 0.4)))
    for guess in (
        LinearGradient(guess_stops, 1.0, (4.0, 16.0), (28.0, 16.0)),
        RadialGradient(guess_stops, 1.0, (16.0, 16.0), 20.0),
    ):
        start = Scene.from_paths(32, 32, [(square, guess)], background=(1, 1, 1))
        settings = FitSettings(steps=150, point_learning_rate=0.2, colour_learning_rate=0.02)
        result = fit_scene(start, target, settings)
        fitted = result.scene.paints[0]
        assert type(fitted) is type(guess)  # the paint kind is kept
        before = np.mean((start.render() - target) ** 2)
        after = np.mean((result.scene.render() - target) ** 2)
        assert after < before / 3
    assert after < before  # the radial one does what it can


def test_reused_lpips_gradient_is_exact_where_evaluated_and_stale_between(lpips_weights):
    import torch

    from samvg.optimize.fit import _Objective
    from samvg.optimize.losses import lpips_loss, segment_indices

    rng = np.random.default_rng(0)
    target = rng.random((40, 48, 3)).astype(np.float32)
    perceptual = lpips_loss(target, 48, str(lpips_weights))
    settings = FitSettings(perceptual=perceptual, perceptual_weight=0.5, perceptual_every=3)
    points = torch.zeros((3, 2), requires_grad=True)
    objective = _Objective(torch.from_numpy(target), settings, segment_indices(np.array([0, 3])))

    def gradients(render: np.ndarray, step: int) -> tuple[torch.Tensor, float]:
        image = torch.from_numpy(render).requires_grad_(True)
        loss, linear_term, reported = objective(image, points, step)
        (loss + linear_term).backward()
        return image.grad, reported

    first = rng.random((40, 48, 3)).astype(np.float32)
    image = torch.from_numpy(first).requires_grad_(True)
    exact = torch.mean((image - torch.from_numpy(target)) ** 2) + 0.5 * perceptual(image)
    exact.backward()
    at_zero, reported = gradients(first, 0)
    torch.testing.assert_close(at_zero, image.grad)
    assert reported == pytest.approx(float(exact.detach()), rel=1e-5)
    second = np.clip(first + 0.2, 0, 1)
    stale, _ = gradients(second, 1)  # LPIPS's part is step 0's; the MSE part is this render's
    mse_part = 2 * (torch.from_numpy(second) - torch.from_numpy(target)) / second.size
    first_mse = 2 * (image.detach() - torch.from_numpy(target)) / first.size
    torch.testing.assert_close(stale - mse_part, at_zero - first_mse)
    fresh, _ = gradients(second, 3)
    assert not torch.allclose(fresh, stale)


def test_without_perceptual_colours_lpips_moves_shapes_but_not_colours():
    target = scene_of([(square(20, 24, 24), (0.9, 0.2, 0.1, 1.0))]).render()
    start = scene_of([(square(20, 24, 24), (0.9, 0.2, 0.1, 1.0))])

    def wants_blue(rendered: torch.Tensor) -> torch.Tensor:
        return 1.0 - rendered[..., 2].mean()  # a stand-in for LPIPS that rewards blue

    def fitted(**perceptual: object) -> Scene:
        return fit_scene(start, target, FitSettings(steps=120, **perceptual)).scene

    plain = fitted()
    tinted = fitted(perceptual=wants_blue, perceptual_weight=0.5)
    shaped = fitted(perceptual=wants_blue, perceptual_weight=0.5, perceptual_colours=False)
    assert tinted.colours()[0, 2] > 0.5  # LPIPS on colours tints the red square blue
    red, green, blue = shaped.colours()[0, :3]
    assert red > 0.85 and green < 0.2 and blue < 0.1  # MSE keeps it red (edges shift it a bit)
    # the shape still feels the term: the square shrinks to show more of the white (blue) ground
    red_area = lambda scene: int((scene.render()[..., 2] < 0.5).sum())  # noqa: E731
    assert red_area(plain) == 24 * 24 and red_area(shaped) < 24 * 24 - 80


def test_coarse_to_fine_fit_lands_on_the_full_canvas():
    size = 160
    target = scene_of([(square(60, 64, 60), (0.9, 0.2, 0.1, 1.0))], size=size).render()
    start = scene_of([(square(40, 50, 50), (0.5, 0.5, 0.5, 1.0))], size=size)
    settings = FitSettings(steps=160, coarse_fraction=0.5, bounds=(-4, -4, 164, 164))
    result = fit_scene(start, target, settings)
    assert (result.scene.width, result.scene.height) == (size, size)
    assert len(result.losses) == 160
    assert np.abs(result.scene.points[6] - (120, 124)).max() < 1.0
    assert np.abs(result.scene.render() - target).mean() < 0.01
    small = fit_scene(scene_of([(square(1, 1, 4), (0, 0, 0, 1))], size=16), np.ones((16, 16, 3)),
                      FitSettings(steps=4, coarse_fraction=0.5))  # fmt: skip
    assert len(small.losses) == 4  # too small to halve: all steps at full size


def test_the_coarse_level_leaves_lpips_out_when_asked():
    size = 160
    target = scene_of([(square(60, 64, 60), (0.9, 0.2, 0.1, 1.0))], size=size).render()
    start = scene_of([(square(40, 50, 50), (0.5, 0.5, 0.5, 1.0))], size=size)
    sizes: list[tuple[int, ...]] = []

    def perceptual(rendered: torch.Tensor) -> torch.Tensor:
        sizes.append(tuple(rendered.shape))
        return rendered.mean()

    for coarse_perceptual, expected in ((True, 60), (False, 24)):
        sizes.clear()
        settings = FitSettings(
            steps=60,
            coarse_fraction=0.6,
            perceptual=perceptual,
            perceptual_weight=0.01,
            coarse_perceptual=coarse_perceptual,
        )
        result = fit_scene(start, target, settings)
        assert len(result.losses) == 60 and len(sizes) == expected
        assert (size, size, 3) in sizes and ((80, 80, 3) in sizes) == coarse_perceptual


def test_a_fit_stops_once_its_loss_stops_improving():
    target = scene_of([(square(20, 24, 24), (0.9, 0.2, 0.1, 1.0))]).render()
    start = scene_of([(square(14, 18, 20), (0.5, 0.5, 0.5, 1.0))])
    steps: list[int] = []
    result = fit_scene(
        start, target, FitSettings(steps=600, plateau_steps=25), lambda s, _: steps.append(s)
    )
    assert 50 <= len(result.losses) < 600 and steps[-1] == 599  # progress completes
    assert np.abs(result.scene.render() - target).mean() < 0.01
    assert len(fit_scene(start, target, FitSettings(steps=60)).losses) == 60


def test_a_background_gradient_is_fitted_with_the_paths():
    from samvg.scene import LinearGradient, RadialGradient

    _, cols = np.mgrid[:32, :40]
    along = (cols + 0.5) / 40
    target = np.stack([0.9 - 0.8 * along, 0.2 + 0 * along, 0.1 + 0.8 * along], axis=2)
    target[8:20, 10:22] = (0.1, 0.6, 0.2)  # one flat square on the ramp
    grey = ((0.0, (0.5, 0.5, 0.5)), (1.0, (0.4, 0.4, 0.4)))
    settings = FitSettings(steps=150, point_learning_rate=0.3, colour_learning_rate=0.02)
    path = [(square(11, 9, 10), FlatPaint((0.3, 0.3, 0.3)))]
    for guess, paths, most in (
        (LinearGradient(grey, 1.0, (10.0, 4.0), (30.0, 20.0)), path, 1e-5),  # exact
        (RadialGradient(grey, 1.0, (20.0, 16.0), 20.0), path, 3e-3),  # the best it can
        (LinearGradient(grey, 1.0, (10.0, 4.0), (30.0, 20.0)), [], 0.02),  # no path: the square
    ):
        start = Scene.from_paths(40, 32, paths, background_gradient=guess)
        result = fit_scene(start, target, settings)
        fitted = result.scene.background_gradient
        assert type(fitted) is type(guess) and fitted.opacity == 1.0
        offsets = [offset for offset, _ in fitted.stops]
        assert offsets == sorted(offsets) and offsets[0] >= 0.0 and offsets[-1] <= 1.0
        assert np.mean((start.render() - target) ** 2) > 0.05
        assert np.mean((result.scene.render() - target) ** 2) < most
        assert len(result.losses) == 150


def test_a_fit_over_an_underlay_leaves_the_background_gradient_alone():
    from samvg.scene import LinearGradient

    ramp = LinearGradient(((0.0, (1, 0, 0)), (1.0, (0, 0, 1))), 1.0, (0.0, 0.0), (32.0, 0.0))
    scene = Scene.from_paths(32, 32, [(square(4, 4, 10), FlatPaint((0.5, 0.5, 0.5)))],
                             background_gradient=ramp)  # fmt: skip
    target = np.full((32, 32, 3), 0.2)
    result = fit_scene(scene, target, FitSettings(steps=5), underlay=np.ones((32, 32, 3)))
    assert result.scene.background_gradient == ramp


def test_the_gradient_choice_gives_a_ramp_background_a_gradient_before_fitting():
    rows, cols = np.mgrid[:32, :32]
    ramp = ((cols + 0.5) / 32)[:, :, None].repeat(3, axis=2)
    start = Scene.from_paths(32, 32, [(square(4, 4, 5), FlatPaint((0.5, 0.5, 0.5)))],
                             background=(0.5, 0.5, 0.5))  # fmt: skip
    result = fit_scene(start, ramp, FitSettings(steps=20, gradient_cost=1e-6))
    assert result.scene.background_gradient is not None
    assert np.mean((result.scene.render() - ramp) ** 2) < 1e-3


def test_fixed_paths_keep_their_outline_and_fit_their_colour():
    target = scene_of([(square(20, 24, 24), (0.9, 0.2, 0.1, 1.0)), (square(5, 5, 6), (0, 0, 1, 1))])
    start = scene_of(
        [(square(14, 18, 20), (0.5, 0.5, 0.5, 1.0)), (square(5, 5, 6), (0.5, 0.5, 0.5, 1.0))]
    )
    fixed = replace(start, fixed=np.array([False, True]))
    result = fit_scene(fixed, target.render(), FitSettings(steps=100))
    assert list(result.scene.fixed_paths()) == [False, True]
    small = slice(start.offsets[1], start.offsets[2])
    np.testing.assert_array_equal(result.scene.points[small], start.points[small])
    np.testing.assert_allclose(result.scene.colours()[1, :3], (0, 0, 1), atol=0.1)
    np.testing.assert_allclose(result.scene.colours()[0, :3], (0.9, 0.2, 0.1), atol=0.05)
    assert np.abs(result.scene.points[6] - (44, 48)).max() < 1.0  # the large one still moves
    moving = fit_scene(start, target.render(), FitSettings(steps=100)).scene.points[small]
    assert not np.array_equal(moving, start.points[small])
