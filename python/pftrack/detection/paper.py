"""The paper's detector: adaptive background, frame difference, threshold, morphology, blobs."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import asdict, dataclass, field

import cv2
import numpy as np
from numpy.typing import NDArray

from pftrack import _core
from pftrack._check import flag, instance, integer, number, option
from pftrack._stand_in import is_stand_in
from pftrack._warn import warn
from pftrack.detection.base import (
    BlobConfig,
    BlobExtractor,
    Detections,
    check_frame,
)
from pftrack.detection.crowd import split_crowds
from pftrack.detection.ghost import GHOST_STATISTICS
from pftrack.detection.hold import StopMemory
from pftrack.detection.light import (
    DARK_LEVEL,
    GAIN_SAMPLE_STEP,
    is_dark,
    levelled_median,
    looks_grey,
    sample_step,
    texture_changed,
)
from pftrack.detection.size_model import PersonSizeModel
from pftrack.particle_filter.colour import HsvBinning, hsv_bins

#: Frames after the light rose (the gain rule scaled the background up) whose blobs the
#: person-size model does not learn from: a brightening video's dim frames, and the frames
#: while the background catches up, give people in fragments, and a size model fitted to
#: them cut every person in two afterwards (a 2 s fade-in: MOTA -67 against 66 with the
#: pause; 10 and 30 frames gave the same on synthetic fades, 10 keeps most frames). Not after
#: the light fell: paused through a slow dimming, the model was not fitted when the blobs
#: needed it (a ramp to 0.7: MOTA 0.54 against 0.76).
LIGHT_SETTLE_FRAMES = 10

#: The noise level (median over the pixels of ``max_c |I_c - B_c|``, grey levels) at which the
#: detector warns, once a video, that the video is too noisy for it, when the frames stay at
#: it or above for `NOISY_FRAMES` frames in a row. The noise-adaptive threshold is `k_noise`
#: times that level: contrasts below it are lost and people come in fragments, and at `t_max`
#: the noise itself passes it. Steady video: 1-3 on PETS09-S2L1, 3-5 on TUD-Campus. Gaussian
#: sensor noise added to ``make_scene(150, rng=1)`` (MOTA 94.8): sigma 6 gives 8 levels (MOTA
#: 87.6), sigma 8 gives 11 (70.8), sigma 10 gives 13 (25.9).
NOISY_LEVEL = 9

#: Frames in a row at `NOISY_LEVEL` or above before the warning (a passing flash says nothing).
NOISY_FRAMES = 10

#: Dark frames in a row (`pftrack.detection.light.is_dark`: lights switched off, a fade to
#: black) before the detector warns, once a video, that it finds nothing on them. A dropout's
#: black frame or two is not said.
DARK_FRAMES = 10


@dataclass(frozen=True)
class PaperConfig:
    """Settings of `PaperDetector`'s per-pixel pass (thresholds in grey levels, 0-255).

    Attributes
    ----------
    alpha : float
        Running-average rate of the background where the pixel is background (the paper's
        selective update): ``B += alpha (I - B)``. 0.05 forgets in about 20 frames.
    alpha_fg : float
        Rate where the pixel is foreground: slowly absorbs objects that stop and the ghosts
        of objects present in the first frame (0 gives the purely selective update).
    n_learn : int
        Learning phase: the k-th frame, for k = 2 .. `n_learn`, updates every pixel at rate
        ``max(1 / k, alpha)`` (a running mean of the first frames), so that objects present in
        the first frame leave no lasting ghost. 0 or 1: the selective update from the start.
    k_noise : float
        Noise-adaptive threshold ``T = k_noise * median_pixels(max_c |I_c - B_c|)`` of the
        previous frame (most pixels are background, so the median measures the noise).
    t_min, t_max : float
        Bounds of `T`.
    low_ratio : float
        A pixel that also moved since the previous frame (``max_c |I_c - I'_c| > T``) is
        foreground from ``low_ratio * T`` on.
    shadow_lo, shadow_chroma : float
        Shadow test on foreground candidates: darker than the background with brightness
        ratio ``sum(I) / sum(B)`` in ``[shadow_lo, 1)`` and chromaticity ``I_c / sum(I)`` within
        `shadow_chroma` of the background's, for every channel: background, not learnt.
        ``shadow_lo=1`` turns it off.
    ghost_support : float
        Ghost test (`pftrack.detection.ghost.edge_support`): a blob whose boundary holds less
        than this share of the frame-plus-background edges is a ghost (uncovered background
        that the background still pictures as an object): dropped, and its pixels learnt at
        `ghost_rate`. 0 turns the test off.
    ghost_rate : float
        Per-pixel update rate of the background inside a ghost, per frame, for as long as
        those pixels stay foreground.
    ghost_statistic : {"vote", "ratio"}
        How the ghost test measures the boundary's support (`edge_support`'s `statistic`):
        ``"vote"``, the share of the boundary's pixels where the frame's edge is the stronger
        (a ghost that its owner has just left keeps the owner's silhouette on one side, which
        outweighs the rest of the boundary in summed magnitudes but is one side in a vote);
        ``"ratio"``, the summed magnitudes (the test before; issue 14's ghosts).
    leg_height : float
        Lost legs (the shadow test takes dark trousers on a grey path for shadow): once the
        person-size model is fitted, a box shorter than `leg_height` times the height of a
        person whose head is at its top is extended down through the rows below it that
        shadow or foreground fills (`leg_fill`), never past that person's expected foot row
        (`PersonSizeModel.extend_legs`). 0 turns it off.
    leg_fill : float
        Share of a box's columns that a row below it must fill (shadow or foreground) for the
        box to grow into it.
    grey_tolerance : float
        Grey video (`pftrack.detection.light.looks_grey`): the priming frames (or the first
        frame) count as grey when 99 % of their sampled pixels have channels within this many
        grey levels of each other. 0 never treats a video as grey.
    grey_shadow_lo : float
        The shadow test's `shadow_lo` on a grey video (1: no shadow test there). Every pixel
        of a grey video has the background's (grey) chromaticity, so with `shadow_lo` the
        test calls every darker pixel shadow, dark clothes included.
    grey_t_min : float or None
        The threshold's lower bound `t_min` on a grey video (None: `t_min`, the default). A
        grey pixel's difference from the background is ``|Y - Y_B|``, which is at most the
        colour test's ``max_c |I_c - B_c|`` and often well below it: at 25 grey levels 0.60-0.69
        of the synthetic walkers' pixels pass in grey against 0.85-1.00 in colour, and the
        people come in fragments. A lower bound finds more of them but also more of the
        shadows that the grey video's shadow test no longer removes: 20 with `grey_shadow_lo`
        0.8 lifts grey TUD-Campus from -11.1 to 1.9 MOTA and the grey `walkers` scene from
        36.3 to 64.2, but loses 1.5 on grey PETS09-S2L1 and 3.5 on grey `present`, so it is
        not the default (docs/detection.md, "Stop 67").
    grey_texture : float
        Grey video only: also foreground where the frame's local pattern no longer correlates
        with the background's (`pftrack.detection.light.texture_changed`: normalised
        cross-correlation over `grey_texture_window`-pixel boxes below this, eroded by
        `grey_texture_erode`), and the pixel's level is not the background's: a person of the
        ground's brightness hides its texture. 0 (the default) turns it off; colour video
        never runs it. 0.7 lifts grey TUD-Campus from -11.1 to 27.6 MOTA, `walkers` from 36.3
        to 84.4 and `groups` from -39.1 to 31.1, but loses 1.2 MOTA on the grey `overhead`
        scene, and the scenes' figures swing by tens of MOTA between neighbouring settings,
        so it is not the default (docs/detection.md, "Stop 68").
    grey_texture_window, grey_texture_erode : int
        Box side (odd, 3-31) and erosion side (0-31) of `grey_texture` and
        `grey_refine_texture`.
    grey_refine_texture : float
        `grey_texture`'s cue for :meth:`PaperDetector.foreground` alone: the foreground that
        refines another detector's boxes on grey video. 0 (the default) turns it off. 0.7
        refines given boxes on a grey scene of dark clothes as on its colour version (MOTA
        0.86 both, against 0.70 off), and lifts grey TUD-Campus with its public detections
        from 60.4 to 65.2 MOTA, but costs grey PETS09-S2L1 1.9 IDF1 and the grey `groups`
        scene 3.4, so it is not the default (docs/detection.md, "Stop 68").
    gain_band : float
        Global light change: before each frame, the frame's gain against the background
        (``BackgroundModel.global_gain``: the median ratio of pixel sums over every 8th row and
        column up to 640x480, sparser on larger frames: `pftrack.detection.light.sample_step`)
        is measured; outside ``[1 - gain_band, 1 + gain_band]`` the whole background is
        scaled by it (``BackgroundModel.scale``). `prime` also brings its frames to the first
        one's brightness first, leaving out what a brighter frame saturated
        (`pftrack.detection.light.levelled_median`). Dark frames
        (`pftrack.detection.light.is_dark`) are neither compared nor learnt, and do not prime
        or start the background. 0 turns all three off.
    hold_frames : int
        People who stop (`pftrack.detection.hold.StopMemory`): the detector follows its own
        boxes from frame to frame, and for this many frames after an object's box last moved
        by half its width, the next frame's candidate pixels inside that box are not learnt
        (instead of at `alpha_fg`): a person who walked and stopped stays foreground that
        long, then `alpha_fg` absorbs them as before. 0 (the default) turns it off: 1000
        finds a person standing 300-600 frames, but moves PETS09-S2L1 re-encoded as JPEG
        (quality 95) from 82.5 / 83.0 / 60.4 to 81.1 / 75.1 / 56.0 MOTA / IDF1 / HOTA, and a
        rule judging stillness over 50 frames still loses 0.4 MOTA there (docs/detection.md,
        "A person who stands for hundreds of frames").
    gain_thresholds : bool
        With the gain rule, scale the grey-level threshold bounds `t_min`, `t_max` by the
        accumulated gain since the first frame (``BackgroundModel.set_threshold_scale``), up
        to 1: people's contrast, and the noise, scale with the light when it dims; a video
        brighter than its first frame keeps the bounds as given (its first frame may have been
        dim: a fade-in).
    crowd_split : bool
        Once the person-size model is fitted, read a blob taller or wider than one person
        from its head tops into one box per person (`pftrack.detection.crowd.split_crowds`:
        people one behind the other, or side by side with no valley between them). Off by
        default (docs/detection.md, "Crowds: merged people read from their head tops").
    blobs : BlobConfig
        Morphology and blob filters.
    hsv : HsvBinning
        Colour binning of the frame (done in the same pass).
    """

    alpha: float = 0.05
    alpha_fg: float = 0.005
    n_learn: int = 30
    k_noise: float = 4.0
    t_min: float = 25.0
    t_max: float = 60.0
    low_ratio: float = 0.5
    shadow_lo: float = 0.5
    shadow_chroma: float = 0.03
    ghost_support: float = 0.3
    ghost_rate: float = 0.5
    ghost_statistic: str = "vote"
    leg_height: float = 0.8
    leg_fill: float = 0.2
    grey_tolerance: float = 3.0
    grey_shadow_lo: float = 1.0
    grey_t_min: float | None = None
    grey_texture: float = 0.0
    grey_texture_window: int = 5
    grey_refine_texture: float = 0.0
    grey_texture_erode: int = 5
    gain_band: float = 0.03
    gain_thresholds: bool = True
    hold_frames: int = 0
    crowd_split: bool = False
    blobs: BlobConfig = field(default_factory=BlobConfig)
    hsv: HsvBinning = field(default_factory=HsvBinning)

    def __post_init__(self) -> None:
        own = "PaperConfig"  # every message names the class, as the other configs' do
        for name in (
            "alpha", "alpha_fg", "k_noise", "t_min", "t_max", "low_ratio", "shadow_lo",
            "shadow_chroma", "ghost_support", "ghost_rate", "leg_height", "leg_fill",
            "grey_tolerance", "grey_shadow_lo", "gain_band",
        ):  # fmt: skip  # before the comparisons below ask an array for its truth
            number(
                getattr(self, name), f"{own}: {name}", finite=False
            )  # the first eight were taken
        integer(
            self.n_learn, f"{own}: n_learn", 0, 2**31 - 1
        )  # 0 or 1: the selective update at once
        integer(self.hold_frames, f"{own}: hold_frames", 0, 2**31 - 1)
        flag(self.gain_thresholds, f"{own}: gain_thresholds")
        flag(self.crowd_split, f"{own}: crowd_split")
        instance(self.blobs, f"{own}: blobs", BlobConfig)
        instance(self.hsv, f"{own}: hsv", HsvBinning)
        if not (0.0 <= self.ghost_support <= 1.0):
            raise ValueError(f"{own}: ghost_support is {self.ghost_support}, expected in [0, 1]")
        if not (0.0 < self.ghost_rate <= 1.0):
            raise ValueError(f"{own}: ghost_rate is {self.ghost_rate}, expected in (0, 1]")
        option(self.ghost_statistic, f"{own}: ghost_statistic", GHOST_STATISTICS)
        if self.ghost_statistic not in GHOST_STATISTICS:
            raise ValueError(
                f"{own}: ghost_statistic is {self.ghost_statistic!r}, expected 'vote' or 'ratio'"
            )
        if not (0.0 <= self.leg_height < np.inf):
            raise ValueError(
                f"{own}: leg_height is {self.leg_height}, expected a finite value >= 0"
            )
        if not (0.0 <= self.leg_fill <= 1.0):
            raise ValueError(f"{own}: leg_fill is {self.leg_fill}, expected in [0, 1]")
        if not (0.0 <= self.grey_tolerance <= 255.0):
            raise ValueError(
                f"{own}: grey_tolerance is {self.grey_tolerance}, expected in [0, 255]"
            )
        if not (0.0 <= self.grey_shadow_lo <= 1.0):
            raise ValueError(f"{own}: grey_shadow_lo is {self.grey_shadow_lo}, expected in [0, 1]")
        if not (0.0 <= self.gain_band < 1.0):
            raise ValueError(f"{own}: gain_band is {self.gain_band}, expected in [0, 1)")
        if self.grey_t_min is not None:
            number(self.grey_t_min, f"{own}: grey_t_min", finite=False)
            if not (0.0 <= self.grey_t_min <= self.t_max):
                raise ValueError(
                    f"{own}: grey_t_min is {self.grey_t_min}, expected None or in [0, t_max]"
                )
        number(self.grey_texture, f"{own}: grey_texture", finite=False)
        if not (0.0 <= self.grey_texture <= 1.0):
            raise ValueError(
                f"{own}: grey_texture is {self.grey_texture}, expected in [0, 1] (0: off)"
            )
        number(self.grey_refine_texture, f"{own}: grey_refine_texture", finite=False)
        if not (0.0 <= self.grey_refine_texture <= 1.0):
            raise ValueError(
                f"{own}: grey_refine_texture is {self.grey_refine_texture}, expected in [0, 1] "
                "(0: off)"
            )
        window = integer(self.grey_texture_window, f"{own}: grey_texture_window", 3, 31)
        if window % 2 == 0:
            raise ValueError(
                f"{own}: grey_texture_window is {window}, expected an odd number in [3, 31]"
            )
        integer(self.grey_texture_erode, f"{own}: grey_texture_erode", 0, 31)


class PaperDetector:
    """Background-subtraction detector of the paper, per-pixel pass in C++.

    Each frame: one C++ pass (`pftrack._core.BackgroundModel`) bins the pixels, compares them
    with the adaptive background and the previous frame, thresholds and updates the background
    where there is no foreground; OpenCV then opens and closes the mask and labels its
    connected components; blobs outside the area, aspect and fill limits are dropped.

    Parameters
    ----------
    config : PaperConfig, optional
        Settings; the defaults are documented on `PaperConfig`.

    Notes
    -----
    The background starts as the first frame (its first mask is empty), unless `prime` gave
    it a median of frames. Objects present in the first frame leave ghosts that `alpha_fg`
    absorbs over ``~1 / alpha_fg`` frames; `prime` avoids them.

    References
    ----------
    .. [1] The detection step of the first method's paper (multi-object tracking with background
       subtraction and colour particle filters; restated in English in the project's papers
       README): adaptive background and frame differences, thresholded, cleaned by morphology.
    """

    def __init__(self, config: PaperConfig | None = None) -> None:
        own = "PaperDetector: config"
        self.config = PaperConfig() if config is None else instance(config, own, PaperConfig)
        self._model = self._new_model(self.config.shadow_lo, self.config.t_min)
        self._blobs = BlobExtractor(self.config.blobs)
        self._ghost: NDArray[np.uint8] | None = None  # pixels of ghosts still being learnt
        self._grey: bool | None = None  # decided on the priming frames, else the first frame
        self._grey_unsaid = False  # a grey video's warning, given by the first detect/foreground
        self._shape: tuple[int, ...] | None = None  # of the video's frames (the first seen)
        self._light = 1.0  # the light's gain since the first frame (gain_thresholds)
        self._settling = 0  # frames left before blobs are again fit to learn person sizes
        self._noise = 0  # the noise said: median difference from the background (grey levels)
        self._noisy = 0  # frames in a row at NOISY_LEVEL or above (NOISY_FRAMES)
        self._noise_said = False  # the noise warning was given (once a video)
        self._noise_unsaid = False  # the noise warning, given by the next detect/foreground
        self._seen = 0  # frames given to detect/foreground since the start or reset()
        self._dark = 0  # dark frames in a row (DARK_FRAMES)
        self._dark_said = False  # the dark warning was given (once a video)
        self._dark_unsaid = False  # the dark warning, given by the next detect
        self._stops = StopMemory(self.config.hold_frames)  # boxes held out of the background

    def _new_model(self, shadow_lo: float, t_min: float) -> _core.BackgroundModel:
        c = self.config
        return _core.BackgroundModel(
            alpha=c.alpha,
            alpha_fg=c.alpha_fg,
            n_learn=c.n_learn,
            k_noise=c.k_noise,
            t_min=t_min,
            t_max=c.t_max,
            low_ratio=c.low_ratio,
            shadow_lo=shadow_lo,
            shadow_chroma=c.shadow_chroma,
            **asdict(c.hsv),
        )

    @property
    def grey(self) -> bool | None:
        """Whether the video was found grey (None before the first frame or `prime`)."""
        return self._grey

    def _decide_grey(self, frames: list[NDArray[np.uint8]]) -> None:
        """Look at the video's first frames once: on a grey video, the grey shadow bound."""
        c = self.config
        self._grey = c.grey_tolerance > 0 and looks_grey(frames, c.grey_tolerance)
        shadow_lo = c.grey_shadow_lo if self._grey else c.shadow_lo
        t_min = c.grey_t_min if self._grey and c.grey_t_min is not None else c.t_min
        if self._model.shadow_lo != shadow_lo or self._model.t_min != t_min:
            # before any frame: nothing learnt is lost
            self._model = self._new_model(shadow_lo, t_min)
        # said by the first detect() or foreground(), in the words of what the model is for
        self._grey_unsaid = bool(self._grey)

    def _say_grey(self, detecting: bool, stacklevel: int) -> None:
        """Warn, once, that the video is grey: what it costs the detector, or box refinement.

        The detector (:meth:`detect`) misses people as bright as the background. The
        foreground alone (:meth:`foreground`, which refines another detector's boxes) misses
        nobody: only its shadow test is off.
        """
        self._grey_unsaid = False
        lo = self.config.grey_shadow_lo
        test = "off" if lo >= 1 else f"bounded by {lo}"
        if detecting:
            text = (
                f"the video is grey (its colour channels are equal): the shadow test is {test} "
                "(every darker pixel has the background's grey chromaticity, dark clothes too), "
                "real shadows may be detected; without colour, people as bright as the "
                "background are missed and the trackers tell people apart by brightness alone"
            )
        else:
            text = (
                f"the video is grey (its colour channels are equal): box refinement's shadow "
                f"test is {test}, and the trackers tell people apart by brightness alone"
            )
        warn(text, UserWarning, stacklevel=stacklevel + 1)  # held inside a tracker's update

    def _count_noisy(self) -> None:
        """Count the frames in a row whose noise is at `NOISY_LEVEL` or above (`NOISY_FRAMES`).

        The noise is the median over the pixels of the frame's difference from the background
        (the model's ``difference_histogram``): most pixels are background.
        """
        hist = self._model.difference_histogram
        # the median at NOISY_LEVEL or above: fewer than half the pixels below it (one sum of a
        # few bins a frame; the median itself only for the warning)
        noisy = 2 * int(hist[:NOISY_LEVEL].sum()) < int(hist.sum())
        self._noisy = self._noisy + 1 if noisy else 0
        if self._noisy == NOISY_FRAMES and not self._noise_said:
            self._noise = int(np.searchsorted(np.cumsum(hist), hist.sum() / 2.0))
            self._noise_said = self._noise_unsaid = True  # said by the next detect/foreground

    def _say_noise(self, detecting: bool, stacklevel: int) -> None:
        """Warn, once, that the video is too noisy (`NOISY_LEVEL`): for detection, or refinement.

        The detector (:meth:`detect`) loses people; the foreground alone (:meth:`foreground`,
        which refines another detector's boxes) shrinks their boxes to what passes.
        """
        self._noise_unsaid = False
        high = min(self.config.t_max * self._model.threshold_scale, 255.0)
        at_max = self._model.threshold >= high * (1.0 - 1e-9)
        if detecting:
            cost = "people come in fragments or are missed"
            hint = "denoise the video, or give a person detector's boxes"
        else:
            cost = "the foreground that refines the detections' boxes is unreliable"
            hint = "take the boxes as given: --no-refine, Tracker(refine=False)"
        warn(
            "noisy or changing video: the frames differ from the background model by "
            f"{self._noise} grey levels at the median pixel, {NOISY_FRAMES} frames in a row at "
            f"{NOISY_LEVEL} or more (steady video: 1 to 5; sensor noise of a dark scene at high "
            "gain, heavy compression, a view or light the model does not follow, or "
            "people over most of the frame while it learnt?), so its noise-adaptive threshold "
            f"rose to {self._model.threshold:.3g}{' (its bound t_max)' if at_max else ''}: "
            f"contrasts below it are lost{', and the noise itself passes it' if at_max else ''}"
            f"; {cost} ({hint})",
            UserWarning,
            stacklevel=stacklevel + 1,  # held inside a tracker's update
        )

    def _apply(
        self, frame: NDArray[np.uint8], bins: bool, texture: float = 0.0
    ) -> tuple[_core.BinnedImage | None, NDArray[np.uint8]]:
        """The C++ pass, after the grey test (first frame) or the global gain (later ones)."""
        if self._shape is None:
            self._shape = frame.shape
        elif frame.shape != self._shape:  # as the model says for a lit frame, for a dark one too
            raise ValueError(
                f"PaperDetector: frame shape is {frame.shape}, expected {self._shape} (one size "
                "per video: reset() between videos)"
            )
        self._seen += 1
        step = sample_step(frame.shape, GAIN_SAMPLE_STEP)
        gain = 1.0
        if self.config.gain_band > 0:
            # is_dark(frame, step)'s test without its checks (the frame is checked, the step is
            # sample_step's), with the global gain of a model that has a background: one read
            # of the sampled pixels for both (mean_and_gain's mean is sampled_mean's double)
            if self._model.initialized:
                mean, gain = self._model.mean_and_gain(frame, step)
            else:
                mean = _core.sampled_mean(frame, step)
            if mean <= DARK_LEVEL:
                return self._unlit(frame, bins)  # no light to compare or learn (light.is_dark)
        if not self._model.initialized:
            if self._grey is None:
                self._decide_grey([frame])
        elif self.config.gain_band > 0:
            if gain <= 0.0:  # over half the sampled pixels black (not dark as a whole)
                return self._unlit(frame, bins)
            if abs(gain - 1.0) > self.config.gain_band:
                self._model.scale(gain)
                if self.config.gain_thresholds and self._model.frame_count > 0:
                    # contrasts (and noise) scale with the light: the grey-level thresholds
                    # follow the brightness relative to the first frame's (a primed model's
                    # first gain corrects the median's brightness, not a change of light),
                    # downward only: a video that starts dim (a fade-in, a camera's exposure
                    # settling, lights switched on) and brightens would otherwise raise them
                    # by as much, past every person's contrast (a fade-in from 5 % took them
                    # to 12 times t_min, and no track was found)
                    if gain > 1.0:  # brighter: the frames before were dim
                        self._settling = LIGHT_SETTLE_FRAMES
                    self._light *= gain
                    scale = min(self._light, 1.0)
                    if scale != self._model.threshold_scale:
                        self._model.set_threshold_scale(scale)
        self._dark = 0
        hold = self._stop_memory().hold_mask(frame.shape[:2])
        result = self._model.apply(frame, bins=bins, hold=hold)
        if self._grey and texture > 0:  # never on colour video
            result = result[0], self._texture(frame, result[1], texture)
        self._count_noisy()
        return result

    def _texture(
        self, frame: NDArray[np.uint8], raw: NDArray[np.uint8], ncc_max: float
    ) -> NDArray[np.uint8]:
        """The raw mask with the grey texture cue's pixels made foreground.

        `ncc_max` is `grey_texture` (detect) or `grey_refine_texture` (foreground). Read
        against the background the C++ pass has just updated; the cue's pixels were learnt
        there as background (at `alpha`), as the grey difference called them.
        """
        c = self.config
        background = self._model.background
        if background is None:  # pragma: no cover - apply() always leaves one
            return raw
        grey = frame[:, :, 1]  # B = G = R
        level = background[:, :, 1]
        cue = texture_changed(grey, level, ncc_max, c.grey_texture_window, c.grey_texture_erode)
        cue &= grey.astype(np.float32) != level
        out: NDArray[np.uint8] = raw.copy()
        out[cue & (raw == 0)] = 255
        return out

    def _unlit(
        self, frame: NDArray[np.uint8], bins: bool
    ) -> tuple[_core.BinnedImage | None, NDArray[np.uint8]]:
        """:meth:`_apply`'s result for a frame without light: no foreground, nothing learnt."""
        if not is_stand_in():  # a black frame in place of one that did not decode: not dark
            self._dark += 1  # footage (pftrack._stand_in)
        if self._dark == DARK_FRAMES and not self._dark_said:
            self._dark_said = self._dark_unsaid = True  # said by the next detect
        binned = hsv_bins(frame, None, self.config.hsv) if bins else None
        return binned, np.zeros(frame.shape[:2], np.uint8)

    #: a detector pickled before people who stop were held (`_stop_memory` makes one)
    _stops: StopMemory | None = None

    def _stop_memory(self) -> StopMemory:
        """The boxes followed from frame to frame (`pftrack.detection.hold`)."""
        if self._stops is None:
            self._stops = StopMemory(self.config.hold_frames)
        return self._stops

    @property
    def model(self) -> _core.BackgroundModel:
        """The C++ background model (read its ``background``, ``threshold``)."""
        return self._model

    @property
    def size_model(self) -> PersonSizeModel:
        """The person-size model learnt from this video's isolated blobs (see `BlobConfig`)."""
        return self._blobs.size_model

    def reset(self) -> None:
        """Forget the background; the next frame initialises it."""
        self._reset_model()
        self._blobs.reset()
        self._ghost = None
        self._grey = None
        self._grey_unsaid = False
        self._shape = None
        self._noise = self._noisy = 0
        self._noise_said = self._noise_unsaid = False
        self._seen = self._dark = 0
        self._dark_said = self._dark_unsaid = False
        self._stop_memory().reset()

    def _reset_model(self) -> None:
        """Forget the background model, and with it the light it has followed.

        The model's threshold scale goes back to 1, so the gain since the first frame starts
        again (and the size model's pause after a rise of the light ends).
        """
        self._model.reset()
        self._light = 1.0
        self._settling = 0

    def prime(self, frames: Iterable[NDArray[np.uint8]]) -> None:
        """Start from the per-pixel median of `frames` (e.g. frames spread over the video).

        Parameters
        ----------
        frames : iterable of (H, W, 3) uint8 arrays
            At least one frame; all of one size.
        """
        # numpy.median(stack, axis=0)'s values, in C++ without stacking the frames (tests hold
        # the two equal): 0.23 s instead of 1.4-1.7 s for 30 frames of 1280x720, no stack
        frames = list(frames)
        if self.config.gain_band > 0 and frames:
            lit = [f for f in frames if not is_dark(check_frame(f, "PaperDetector.prime"))]
            if not lit:  # no light to start from: the first frame that has some starts it
                self._reset_model()
                return
            frames = lit  # a black frame (dropout, fade) is no picture of the empty scene
        # under a light change, the median of frames at their own brightness is biased where
        # people stand often: the frames are brought to the first one's light
        median = levelled_median(frames, self.config.gain_band, "PaperDetector.prime")
        if self._grey is None:
            self._decide_grey(frames)
        self._reset_model()
        self._model.set_background(median)
        self._shape = median.shape

    def detect(self, frame: NDArray[np.uint8]) -> Detections:
        """Detect the moving objects of one frame.

        Parameters
        ----------
        frame : (H, W, 3) ndarray of uint8
            BGR frame, the same size as the earlier ones (call `reset` between videos).

        Returns
        -------
        Detections

        Warns
        -----
        UserWarning
            Once, on the first call, when the video is grey (`grey_tolerance`): the shadow
            test is off, people as bright as the background are missed, and trackers tell
            people apart by brightness alone. Once, when the video is noisy (`NOISY_LEVEL`
            for `NOISY_FRAMES` frames in a row): the threshold has risen with the noise. Once,
            after `DARK_FRAMES` dark frames in a row: nothing is found on them.
        """
        frame = check_frame(frame, "PaperDetector.detect")
        # bins below, of the foreground only
        _, raw = self._apply(frame, bins=False, texture=self.config.grey_texture)
        if self._grey_unsaid:
            self._say_grey(detecting=True, stacklevel=2)  # detect()'s caller
        if self._noise_unsaid:
            self._say_noise(detecting=True, stacklevel=2)
        if self._dark_unsaid:
            self._dark_unsaid = False
            first = self._seen - DARK_FRAMES + 1
            warn(
                f"the frames from {first} on are dark ({DARK_FRAMES} in a row so far at mean "
                f"level {DARK_LEVEL:g} or less: lights switched off, a fade to black, a covered "
                "lens?): the detector finds nothing on a dark frame, so tracks coast and end "
                "until the light returns",
                UserWarning,
                stacklevel=2,  # detect()'s caller; held inside a tracker's update
            )
        shaded = self._blobs.clean(raw)
        mask = foreground_only(shaded)
        if self.config.ghost_support > 0 and self._ghost is not None:
            # a ghost found earlier: its pixels still foreground keep being learnt fast
            carry = np.bitwise_and(mask, self._ghost)
            if cv2.countNonZero(carry):  # carry.any() in a third of its instructions
                self._model.blend(frame, carry, self.config.ghost_rate)
                mask = np.bitwise_xor(mask, carry)
                self._ghost = carry
            else:  # learnt: no full-frame AND on the next frames
                self._ghost = None
        # while the light changes, blobs come in fragments (a dim frame's contrast, a
        # background still catching up): not person sizes to learn from
        stops = self._stop_memory()
        boxes, scores = self._blobs.boxes(mask, learn=self._settling == 0, still=stops.still)
        self._settling = max(self._settling - 1, 0)
        if self.config.ghost_support > 0 and len(boxes):
            mask, boxes, scores = self._drop_ghosts(frame, mask, boxes, scores)
        size = self._blobs.size_model
        if self.config.crowd_split and len(boxes) and size.fitted:
            boxes, scores = split_crowds(mask, boxes, scores, size)
        if self.config.leg_height > 0 and len(boxes) and size.fitted:
            # after the size model observed the blobs' own boxes (it never learns from these);
            # no box grows into a ghost (this frame's ghost pixels are background being learnt)
            if self._ghost is not None:  # in place: `shaded` is this frame's own array
                # shaded[ghost != 0] = 0 by OpenCV: 255 where the ghost is 0, then and (under a
                # third of the boolean index's instructions: callgrind, 0.15 against 0.50 M at
                # 480x360)
                keep = cv2.threshold(self._ghost, 0, 255, cv2.THRESH_BINARY_INV)[1]
                cv2.bitwise_and(shaded, keep, dst=shaded)
            boxes = size.extend_legs(shaded, boxes, self.config.leg_height, self.config.leg_fill)
        stops.observe(boxes)  # the boxes whose pixels the next frame holds
        # the colours of the kept foreground only (the full frame's bins, which only a moving
        # camera needs, are binned by the tracker then)
        return Detections(boxes, scores, mask, hsv_bins(frame, mask, self.config.hsv))

    def _drop_ghosts(
        self,
        frame: NDArray[np.uint8],
        mask: NDArray[np.uint8],
        boxes: NDArray[np.float64],
        scores: NDArray[np.float64],
    ) -> tuple[NDArray[np.uint8], NDArray[np.float64], NDArray[np.float64]]:
        """Drop the ghost blobs and learn their pixels fast (C++ ``blend``).

        The support is `pftrack.detection.ghost.edge_support` computed in C++
        (``BackgroundModel.edge_support``: the same blur, Sobel and band, read from the model's
        own background without copying it; tests hold the two equal to 1e-5), with the
        statistic of ``ghost_statistic``.
        """
        support = self._model.edge_support(frame, mask, boxes, self.config.ghost_statistic)
        ghost = support < self.config.ghost_support
        if not ghost.any():
            return mask, boxes, scores
        gmask = np.zeros_like(mask)
        for x, y, w, h in boxes[ghost].astype(int):
            gmask[y : y + h, x : x + w] = mask[y : y + h, x : x + w]
        self._model.blend(frame, gmask, self.config.ghost_rate)
        self._ghost = gmask if self._ghost is None else np.bitwise_or(self._ghost, gmask)
        mask = np.bitwise_xor(mask, gmask)
        return mask, boxes[~ghost], scores[~ghost]

    def foreground(
        self, frame: NDArray[np.uint8], shadows: bool = False, bins: bool = True
    ) -> tuple[NDArray[np.uint8], _core.BinnedImage | None]:
        """The cleaned foreground mask and the frame's HSV bins, without blobs or boxes.

        The background model advances exactly as with :meth:`detect`; a tracker fed by another
        detector needs only these (to refine that detector's boxes) and skips the blob pass.
        With `shadows` the mask keeps the shadow pixels as 127 (255 foreground, 0 background).
        With `bins` False the background pass makes no bins (None in their place): for a
        caller that bins only the pixels it reads (``hsv_bins(..., lazy=True)``).

        Warns
        -----
        UserWarning
            Once, on the first call, when the video is grey (`grey_tolerance`): the shadow
            test of box refinement is off, and trackers tell people apart by brightness alone
            (the shorter warning: the boxes refined here come from another detector, so
            nobody is missed for being as bright as the background). Once, when the video is
            noisy (`NOISY_LEVEL` for `NOISY_FRAMES` frames in a row): the foreground that
            refines the boxes is unreliable.
        """
        shaded, binned = self._foreground(frame, "PaperDetector.foreground", bins)
        return (shaded if shadows else foreground_only(shaded)), binned

    def _foreground(
        self, frame: NDArray[np.uint8], fn: str, bins: bool = True
    ) -> tuple[NDArray[np.uint8], _core.BinnedImage | None]:
        """The cleaned mask with shadows (255, 127, 0) and the frame's bins (None without)."""
        binned, raw = self._apply(check_frame(frame, fn), bins, self.config.grey_refine_texture)
        if self._grey_unsaid:
            self._say_grey(detecting=False, stacklevel=3)  # foreground()'s caller
        if self._noise_unsaid:
            self._say_noise(detecting=False, stacklevel=3)
        return self._blobs.clean(raw), binned


def foreground_only(shaded: NDArray[np.uint8]) -> NDArray[np.uint8]:
    """The 0/255 foreground of a mask with shadows (255 foreground, 127 shadow, 0 background).

    Opening and closing are minima and maxima over a window, which commute with a threshold:
    the foreground of the cleaned mask with shadows is the cleaned foreground, bit for bit.
    """
    return np.asarray(cv2.threshold(shaded, 127, 255, cv2.THRESH_BINARY)[1], np.uint8)
