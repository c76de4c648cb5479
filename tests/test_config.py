"""Config: settings grouped by stage, set by group or by name, presets as constructors."""

import dataclasses
import re

import pytest

from samvg import Config, InputError
from samvg.config import FitOptions, MissingOptions, SegmentOptions, TraceOptions
from samvg.optimize import FitSettings


def test_settings_by_name_land_in_their_stage_group():
    config = Config(iterations=300, points_per_side=8, segments=4, missing_rounds=2, size=256)
    assert config.fit.iterations == 300 and config.segment.points_per_side == 8
    assert config.trace.segments == 4 and config.missing.rounds == 2 and config.size == 256
    assert config == Config(
        SegmentOptions(points_per_side=8),
        TraceOptions(segments=4),
        FitOptions(iterations=300),
        MissingOptions(missing_rounds=2),
        size=256,
    )


def test_presets_and_replace():
    assert Config.paper() != Config() and Config.paper().trace.segments == 5
    assert Config.paper().segment.crop_n_layers == 1 and Config().segment.crop_n_layers == 0
    assert Config().trace.segments is None and not Config().fit.translucent
    fast = Config.fast(seed=3)
    assert fast.segment.points_per_side == 8 and not fast.fit.use_lpips and fast.seed == 3
    changed = fast.replace(iterations=7, size=64)
    assert changed.fit.iterations == 7 and changed.size == 64
    assert changed.segment == fast.segment and fast.fit.iterations == 120
    assert dataclasses.replace(fast, seed=9).seed == 9
    assert Config(missing_components=False).missing.rounds == 0
    assert Config().as_dict()["iterations"] == 500


def test_unknown_and_bad_settings_are_clear_errors():
    with pytest.raises(InputError, match="unknown setting 'iteration'"):
        Config(iteration=5)
    with pytest.raises(InputError, match="missing rounds"):
        Config(missing_rounds=-1)
    with pytest.raises(InputError, match="segments"):
        Config(segments=0)
    with pytest.raises(InputError, match="device"):
        Config(device="tpu")


def test_fractions_become_pixels_once_per_canvas():
    options = SegmentOptions(min_area=0.001)
    assert options.min_pixels(200, 100) == 20.0
    assert SegmentOptions().min_pixels(10, 10) == 4.0


@pytest.mark.parametrize(
    ("settings", "message"),
    [
        ({"device": 0}, "device must be cpu, cuda, cuda:N or mps, got 0"),  # was AttributeError
        ({"device": "cudax"}, "device must be"),
        ({"device": "tpu"}, "device must be"),
        ({"seed": 2**32}, "seed must be an integer from 0 to 4294967295"),
        ({"seed": 10**30}, "2**32 - 1"),
        ({"seed": -1}, "seed must be an integer >= 0"),
    ],
)
def test_device_and_seed_are_checked_up_front(settings, message):
    with pytest.raises(InputError, match=re.escape(message)):
        Config(**settings)


def test_largest_seed_and_cuda_index_are_accepted():
    assert Config(seed=2**32 - 1, device="cuda:3").seed == 2**32 - 1


def test_setting_names_are_unique_and_never_a_group_name():
    from samvg.config import _GROUP_OF, _GROUPS, _RUN

    assert not set(_GROUP_OF) & (set(_GROUPS) | set(_RUN))
    assert not Config.paper().finish.finish_pass and Config().finish.finish_pass


def test_detail_and_paths_are_checked_and_the_paper_runs_one_round():
    assert Config().missing.rounds is None and Config.paper().missing.rounds == 1
    assert Config.paper().segment.colour_split is False and Config().segment.colour_split
    tolerances = [Config(detail=d).missing.gain_tolerance for d in (0.0, 0.5, 1.0)]
    assert tolerances == pytest.approx([0.1, 0.01, 0.001])
    assert Config(paths=64).missing.paths == 64
    for bad in ({"detail": 1.5}, {"detail": -0.1}, {"detail": "high"}, {"paths": 0}):
        with pytest.raises(InputError, match="detail|paths"):
            Config(**bad)


def test_gradient_fills_are_the_default_and_the_paper_keeps_flat_fills():
    assert Config().fit.gradients and not Config.paper().fit.gradients
    assert not Config(gradients=False).fit.gradients
    assert Config.paper(gradients=True).fit.gradients


def test_rounds_fit_their_new_paths_except_in_the_paper():
    assert not Config().missing.refit_scene and Config.paper().missing.refit_scene


def test_speed_settings_are_checked_and_the_paper_fits_exactly():
    default, paper = Config().fit, Config.paper().fit
    assert default.lpips_every == 1 and default.coarse_fraction == 0.6
    assert default.plateau_steps == 50 and not default.coarse_lpips
    assert FitSettings.from_options(default).coarse_perceptual is False
    assert paper.lpips_every == 1 and paper.coarse_fraction == 0 and paper.plateau_steps is None
    for bad in ({"lpips_every": 0}, {"coarse_fraction": 1.5}, {"coarse_fraction": -0.1}):
        with pytest.raises(InputError, match="lpips every|coarse fraction"):
            Config(**bad)


def test_marks_are_the_default_and_not_the_papers():
    assert Config().missing.marks and not Config.paper().missing.marks
    assert Config().missing.filter_speckle == 4
