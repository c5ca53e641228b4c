"""People who stop: the detector's own boxes followed frame to frame, held out of the background.

The paper's selective update learns a foreground pixel at the slow `PaperConfig.alpha_fg`
(0.005 a frame), so that objects which stop are absorbed: a person who stands still is
background after about 250 frames, and found no more. `StopMemory` follows the detector's
boxes from frame to frame (overlap, no tracker needed: the result of a frame still depends on
the frames alone, so detection can run a frame ahead on its own thread). A box whose centre
has moved by half its width since it was first seen, or since it last moved so, is an object
that walked; for `PaperConfig.hold_frames` frames after it last moved, its box is **held**:
the next frame's candidate pixels inside it are not learnt at all
(``BackgroundModel.apply(hold=...)``), so a person who stops stays foreground. After that time
the slow update absorbs it as before (a parked car, a bag left behind). Objects that never
moved (a patch of changed light, a ghost, noise) are never held. An object standing is also
matched by the box where it stands (its last box of its own size before it stood): a
passer-by who merges with it and walks on takes the merged box along, and the part left where
it stands is still the person standing.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from pftrack._typing import F64
from pftrack.boxes import _iou_matrix

__all__ = ["StopMemory"]

#: A box is the same object as one of the previous frame's (or of an object missed for a few
#: frames) when their IoU is at least this.
HOLD_IOU = 0.5
#: An object moved when its box's centre is this many box widths from where it last moved
#: (or was first seen).
HOLD_MOVE = 0.5
#: ... with its width and height within this factor of that box's.
HOLD_SIZE = 1.25
#: An object whose box has not moved for this many frames is standing: the person-size model
#: does not learn from its boxes (one person's box, repeated frame after frame, is one sample;
#: a person standing 300 frames filled the model's 200 samples and set every walker's width).
STILL_FRAMES = 50
#: Frames an object may go unmatched (merged with a passer-by, a frame where its blob broke)
#: before it is forgotten; its last box stays held meanwhile.
HOLD_MISSES = 25
#: `StopMemory._stand_at` when no object has walked: no frame reaches it.
_NEVER = 2**62


class StopMemory:
    """The detector's boxes followed frame to frame: which objects walked, which to hold.

    Parameters
    ----------
    hold_frames : int
        Frames after an object last moved during which its box is held (0: nothing is held).
    """

    #: the first frame at which an object that walked can have stood `STILL_FRAMES` (`observe`
    #: sets it; before it, `held` and `still` are empty without a test per object: most frames
    #: of a video of walkers). 0, as in a memory pickled before it was kept: test every time.
    _stand_at = 0

    def __init__(self, hold_frames: int) -> None:
        self.hold_frames = hold_frames
        self.reset()

    def reset(self) -> None:
        """Forget every object (before a new video)."""
        self._frame = 0
        self._boxes: F64 = np.zeros((0, 4))
        self._anchors: F64 = np.zeros((0, 4))  # box where each last moved (or was first seen)
        self._since = np.zeros(0, np.int64)  # frame its anchor was set (first seen or moved)
        self._walked = np.zeros(0, bool)  # whether it ever moved
        self._missed = np.zeros(0, np.int64)  # frames since last matched
        self._own: F64 = np.zeros((0, 4))  # its own size's last box (where it stands)
        self._stand_at = _NEVER  # nobody walked

    @property
    def held(self) -> F64:
        """(K, 4) ``left, top, width, height`` of the boxes held now."""
        if self._frame < self._stand_at:
            return self._boxes[:0]
        still = self._frame - self._since
        keep = self._walked & (still >= STILL_FRAMES) & (still <= self.hold_frames)
        out: F64 = self._boxes[keep]
        return out

    @property
    def still(self) -> F64:
        """(K, 4) boxes of the objects seen this frame that have not moved for `STILL_FRAMES`."""
        if self._frame < self._stand_at:
            return self._boxes[:0]
        keep = self._walked & (self._missed == 0) & (self._frame - self._since >= STILL_FRAMES)
        out: F64 = self._boxes[keep]
        return out

    def observe(self, boxes: F64) -> None:
        """Take one frame's boxes (K, 4): match them to the objects, mark those that moved."""
        self._frame += 1
        if self.hold_frames <= 0:
            return
        k = len(boxes)
        centres = boxes[:, :2] + 0.5 * boxes[:, 2:]
        match = np.full(k, -1, np.int64)
        if k and len(self._boxes):
            # against its last box or, for an object standing, the box where it stands: when
            # a passer-by who merged with a person standing walks on, the part left where the
            # person stands is the person, though the merged box followed the passer-by
            iou = _iou_matrix(boxes, self._boxes)
            standing = self._walked & (self._frame - self._since >= STILL_FRAMES)
            if standing.any():
                iou[:, standing] = np.maximum(
                    iou[:, standing], _iou_matrix(boxes, self._own[standing])
                )
            pairs = np.argwhere(iou >= HOLD_IOU)
            # greedy, one to one: objects that walked first (a box left by a passer-by who
            # merged with a person standing is not taken for them), then best overlap first
            walked = self._walked[pairs[:, 1]]
            order = np.lexsort((-iou[pairs[:, 0], pairs[:, 1]], ~walked))
            taken = np.zeros(len(self._boxes), bool)
            for i, j in pairs[order]:
                if match[i] < 0 and not taken[j]:
                    match[i], taken[j] = j, True
        else:
            taken = np.zeros(len(self._boxes), bool)
        anchors = boxes.copy()
        own = boxes.copy()
        since = np.full(k, self._frame, np.int64)
        walked = np.zeros(k, bool)
        old = match >= 0
        if old.any():
            j = match[old]
            anchors[old], since[old], walked[old] = (
                self._anchors[j],
                self._since[j],
                self._walked[j],
            )
            a = anchors[old]
            far = np.hypot(*(centres[old] - a[:, :2] - 0.5 * a[:, 2:]).T) >= HOLD_MOVE * a[:, 2]
            # of the same size: a box that grew or shrank (merged with a passer-by, split from
            # them, entering the frame) is not the object moving: the anchor takes its new size
            ratio = boxes[old, 2:] / a[:, 2:]
            same = np.all((ratio >= 1 / HOLD_SIZE) & (ratio <= HOLD_SIZE), axis=1)
            # its own box follows it while it walks, in boxes of about its size frame to frame
            # (not a jump: a merge), and stays where it stood once it stands: a passer-by
            # merging with it step by step does not take it along
            grown = boxes[old, 2:] / self._own[j, 2:]
            alone = np.all((grown >= 1 / HOLD_SIZE) & (grown <= HOLD_SIZE), axis=1)
            alone &= self._frame - self._since[j] < STILL_FRAMES
            own[np.flatnonzero(old)[~alone]] = self._own[j][~alone]
            anchors[np.flatnonzero(old)[~same]] = boxes[old][~same]
            far &= same
            idx = np.flatnonzero(old)[far]
            anchors[idx], since[idx], walked[idx] = boxes[idx], self._frame, True
        missed = self._missed[~taken] + 1
        kept = missed <= HOLD_MISSES  # the others are forgotten
        self._boxes = np.vstack([boxes, self._boxes[~taken][kept]])
        self._anchors = np.vstack([anchors, self._anchors[~taken][kept]])
        self._since = np.concatenate([since, self._since[~taken][kept]])
        self._walked = np.concatenate([walked, self._walked[~taken][kept]])
        self._missed = np.concatenate([np.zeros(k, np.int64), missed[kept]])
        self._own = np.vstack([own, self._own[~taken][kept]])
        # frame - since >= STILL_FRAMES for an object that walked from this frame on, not before
        walked_since = self._since[self._walked]
        self._stand_at = int(walked_since.min()) + STILL_FRAMES if len(walked_since) else _NEVER

    def hold_mask(self, shape: tuple[int, int]) -> NDArray[np.uint8] | None:
        """(H, W) uint8 mask of the held boxes (1 inside), or None when none is held."""
        held = self.held
        if not len(held):
            return None
        mask = np.zeros(shape, np.uint8)
        rows, cols = shape
        for x, y, w, h in held:
            x0, y0 = max(int(np.floor(x)), 0), max(int(np.floor(y)), 0)
            x1, y1 = min(int(np.ceil(x + w)), cols), min(int(np.ceil(y + h)), rows)
            if x1 > x0 and y1 > y0:
                mask[y0:y1, x0:x1] = 1
        return mask
