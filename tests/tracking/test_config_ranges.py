"""Settings out of range are refused when the config is made, naming the class and the field.

Each case ran before the check, then failed mid-run or gave no rows (trial H).
"""

from __future__ import annotations

import math

import pytest

from pftrack.tracking.config import (
    AssociationConfig,
    LifecycleConfig,
    MotionConfig,
    RefineConfig,
    TrackerConfig,
)

NAN = math.nan

# (class, field, value, error, message); "# was: ..." what happened before the check
REFUSED = [
    # was: linear_sum_assignment's "matrix contains invalid numeric entries" mid-run
    (AssociationConfig, "match_distance", NAN, ValueError, "expected a finite value > 0"),
    (AssociationConfig, "match_distance", 0.0, ValueError, "expected a finite value > 0"),
    (AssociationConfig, "match_distance", -1.0, ValueError, "expected a finite value > 0"),
    (AssociationConfig, "colour_weight", NAN, ValueError, "expected a finite value >= 0"),
    (AssociationConfig, "colour_weight", -1.0, ValueError, "expected a finite value >= 0"),
    # was: accepted (NaN: no detection ever a merged blob)
    (AssociationConfig, "merge_ratio", NAN, ValueError, "expected a value >= 1"),
    (AssociationConfig, "merge_ratio", -1.0, ValueError, "expected a value >= 1"),
    # was: "velocity is [nan, nan]" mid-run; accel NaN: 0 rows
    (MotionConfig, "detection_noise", NAN, ValueError, r"expected a value in \[1e-06, 1e\+06\]"),
    (MotionConfig, "detection_noise", 0.0, ValueError, r"expected a value in \[1e-06, 1e\+06\]"),
    (MotionConfig, "colour_noise", -1.0, ValueError, r"expected a value in \[1e-06, 1e\+06\]"),
    (MotionConfig, "colour_noise", math.inf, ValueError, r"expected a value in \[1e-06, 1e\+06\]"),
    (MotionConfig, "accel", NAN, ValueError, r"expected a value in \[0, 1e\+06\]"),
    (MotionConfig, "accel", -1.0, ValueError, r"expected a value in \[0, 1e\+06\]"),
    (MotionConfig, "accel", "0.1", TypeError, "must be a number"),
    (MotionConfig, "smooth_external", "no", TypeError, "must be True or False"),
    # was: 0 rows (-5), a TypeError mid-run ("x"), the birth quantile never learned (0)
    (LifecycleConfig, "tentative_coast", -5, ValueError, r"integer in \[0, 2147483647\]"),
    # a wrong type: TypeError (was ValueError)
    (LifecycleConfig, "tentative_coast", "x", TypeError, r"integer in \[0, 2147483647\], got str"),
    (LifecycleConfig, "tentative_coast", 1.0, TypeError, r"integer in \[0, 2147483647\], got"),
    (LifecycleConfig, "birth_window", 0, ValueError, r"integer in \[1, 2147483647\]"),
    (LifecycleConfig, "min_hits", True, TypeError, r"integer in \[0, 2147483647\], got bool"),
    (LifecycleConfig, "max_coast", 2**31, ValueError, r"integer in \[0, 2147483647\]"),
    (LifecycleConfig, "relink_coast", 0, ValueError, r"integer in \[1, 2147483647\]"),
    (LifecycleConfig, "blind_coast", -1, ValueError, r"integer in \[0, 2147483647\]"),
    # was: refused only at run time (5), accepted (NaN, negative)
    (RefineConfig, "fraction", 5.0, ValueError, r"expected a value in \[0, 1\)"),
    (RefineConfig, "fraction", 1.0, ValueError, r"expected a value in \[0, 1\)"),
    (RefineConfig, "fraction", NAN, ValueError, r"expected a value in \[0, 1\)"),
    (RefineConfig, "fraction", -0.1, ValueError, r"expected a value in \[0, 1\)"),
    (RefineConfig, "enabled", "no", TypeError, "must be True or False"),
]


@pytest.mark.parametrize(
    ("cls", "name", "value", "error", "message"),
    REFUSED,
    ids=[f"{c.__name__}.{n}={v!r}" for c, n, v, _, _ in REFUSED],
)
def test_a_setting_out_of_range_is_refused_at_construction(cls, name, value, error, message):
    with pytest.raises(error, match=rf"^{cls.__name__}: {name} .*{message}") as info:
        cls(**{name: value})
    assert "\n" not in str(info.value)


@pytest.mark.parametrize(
    ("cls", "name", "value"),
    [
        (AssociationConfig, "merge_ratio", math.inf),  # off
        (AssociationConfig, "merge_ratio", 1.0),
        (AssociationConfig, "colour_weight", 0.0),
        (MotionConfig, "accel", 0.0),  # a constant velocity
        (LifecycleConfig, "tentative_coast", 0),
        (LifecycleConfig, "min_hits", 0),
        (LifecycleConfig, "relink_coast", None),
        (LifecycleConfig, "blind_coast", None),
        (LifecycleConfig, "blind_coast", 0),
        (RefineConfig, "fraction", 0.0),
    ],
)
def test_the_ends_of_the_ranges_are_taken(cls, name, value):
    assert getattr(cls(**{name: value}), name) == value


def test_the_defaults_are_valid_and_unchanged():
    c = TrackerConfig()
    a, m, life, r = c.association, c.motion, c.lifecycle, c.refine
    assert (a.match_distance, a.colour_weight, a.merge_ratio) == (0.3, 0.5, 1.8)
    assert (m.accel, m.detection_noise, m.colour_noise) == (0.01, 0.05, 0.15)
    lc = (life.tentative_coast, life.birth_window, life.min_hits, life.max_coast)
    assert lc == (0, 50, 4, 10)
    assert r.fraction == 0.05
