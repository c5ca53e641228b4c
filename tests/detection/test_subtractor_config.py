"""OpenCV subtractors' settings are refused when made (``make_detector``: "a setting out of range").

Each case ran before the check (trial H), or failed in OpenCV without naming the setting.
"""

from __future__ import annotations

import math

import pytest

from pftrack.detection import make_detector
from pftrack.detection.opencv_bg import KnnConfig, Mog2Config

NAN = math.nan

# (name, setting, value, error, message); "# was: ..." what happened before the check
REFUSED = [
    # was: ran (history=-1, var_threshold=-1, dist2_threshold=nan)
    ("mog2", "history", -1, ValueError, r"integer in \[1, 2147483647\]"),
    ("knn", "history", 0, ValueError, r"integer in \[1, 2147483647\]"),
    # was: OpenCV's TypeError, not naming the setting (then ValueError: a wrong type is a
    # TypeError, as a number setting's)
    ("knn", "history", 1.5, TypeError, r"integer in \[1, 2147483647\], got float 1.5"),
    ("mog2", "history", True, TypeError, r"integer in \[1, 2147483647\], got bool True"),
    ("mog2", "var_threshold", -1.0, ValueError, "expected a finite value > 0"),
    ("mog2", "var_threshold", NAN, ValueError, "expected a finite value > 0"),
    ("knn", "dist2_threshold", NAN, ValueError, "expected a finite value > 0"),
    ("knn", "dist2_threshold", "400", TypeError, "must be a number"),
    # was: silently no detection at all
    ("mog2", "learning_rate", NAN, ValueError, r"-1 \(OpenCV's choice\) or a value in \[0, 1\]"),
    ("mog2", "learning_rate", 5.0, ValueError, r"-1 \(OpenCV's choice\) or a value in \[0, 1\]"),
    ("knn", "learning_rate", -0.5, ValueError, r"-1 \(OpenCV's choice\) or a value in \[0, 1\]"),
]


@pytest.mark.parametrize(
    ("name", "setting", "value", "error", "message"),
    REFUSED,
    ids=[f"{n}.{s}={v!r}" for n, s, v, _, _ in REFUSED],
)
def test_a_subtractor_setting_out_of_range_is_refused(name, setting, value, error, message):
    owner = {"mog2": "Mog2Config", "knn": "KnnConfig"}[name]
    with pytest.raises(error, match=rf"^{owner}: {setting} .*{message}") as info:
        make_detector(name, **{setting: value})
    assert "\n" not in str(info.value)


def test_the_defaults_and_the_ends_of_the_ranges_are_taken():
    assert (Mog2Config().history, Mog2Config().learning_rate) == (500, -1.0)
    assert KnnConfig().dist2_threshold == 400.0
    for rate in (-1, 0.0, 1.0):
        make_detector("mog2", learning_rate=rate)
        make_detector("knn", learning_rate=rate, history=1)
