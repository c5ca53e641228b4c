"""The C++ ghost test (BackgroundModel.edge_support) against NumPy and the OpenCV version."""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from pftrack import _core
from pftrack.detection.ghost import edge_support
from tests.reference.detection import edge_support_reference


def scene(
    rng: np.random.Generator, shape: tuple[int, int] = (60, 80), n: int = 6
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A textured frame and background, a mask of `n` random blobs and boxes about them."""
    rows, cols = shape
    frame = rng.integers(0, 256, (rows, cols, 3), dtype=np.uint8)
    frame = (frame // 32 * 32).astype(np.uint8)  # steps: strong edges
    background = rng.uniform(0, 255, (rows, cols, 3)).astype(np.float32)
    mask = np.zeros(shape, np.uint8)
    boxes = []
    for _ in range(n):
        w, h = int(rng.integers(1, 20)), int(rng.integers(1, 25))
        x, y = int(rng.integers(0, cols - w)), int(rng.integers(0, rows - h))
        mask[y : y + h, x : x + w] = np.where(rng.random((h, w)) < 0.8, 255, 0)
        boxes.append([x, y, w, h])
    boxes.append([cols - 2, rows - 2, 5.7, 9.2])  # reaching past the corner: clipped
    boxes.append([-3.5, 10.2, 1.0, 1.0])  # a region under 3 px wide: 0.5
    return frame, background, mask, np.array(boxes, np.float64)


def model_with(background: np.ndarray) -> _core.BackgroundModel:
    model = _core.BackgroundModel()
    model.set_background(background)
    return model


@pytest.mark.parametrize("seed", range(5))
def test_edge_support_matches_numpy_reference(seed: int) -> None:
    frame, background, mask, boxes = scene(np.random.default_rng(seed))
    got = model_with(background).edge_support(frame, mask, boxes)
    want = edge_support_reference(frame, background, mask, boxes)
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-5)
    assert got[-1] == 0.5
    assert np.all((got >= 0) & (got <= 1))


@pytest.mark.parametrize("seed", range(3))
def test_edge_support_matches_opencv_version(seed: int) -> None:
    frame, background, mask, boxes = scene(np.random.default_rng(10 + seed), (90, 120), 10)
    got = model_with(background).edge_support(frame, mask, boxes)
    np.testing.assert_allclose(got, edge_support(frame, background, mask, boxes), atol=1e-5)


def test_edge_support_of_strided_frame_and_no_boxes() -> None:
    frame, background, mask, boxes = scene(np.random.default_rng(7))
    model = model_with(background)
    wide = np.zeros((60, 90, 3), np.uint8)
    wide[:, 5:85] = frame
    view = wide[:, 5:85]  # rows strided
    np.testing.assert_array_equal(
        model.edge_support(view, mask, boxes), model.edge_support(frame, mask, boxes)
    )
    assert model.edge_support(frame, mask, np.zeros((0, 4))).shape == (0,)


def test_edge_support_checks_its_arguments() -> None:
    frame, background, mask, boxes = scene(np.random.default_rng(1))
    with pytest.raises(ValueError, match="no background yet"):
        _core.BackgroundModel().edge_support(frame, mask, boxes)
    model = model_with(background)
    with pytest.raises(ValueError, match=r"boxes must have shape \(K, 4\)"):
        model.edge_support(frame, mask, boxes[:, :3])
    bad = boxes.copy()
    bad[0, 2] = np.nan
    with pytest.raises(ValueError, match="box value is nan"):
        model.edge_support(frame, mask, bad)
    with pytest.raises(ValueError, match="frame shape"):
        model.edge_support(frame[:-1], mask, boxes)
    with pytest.raises(ValueError, match="mask"):
        model.edge_support(frame, mask[:-1], boxes)


def test_edge_support_threads_give_serial_result() -> None:
    frame, background, mask, boxes = scene(np.random.default_rng(2), (120, 160), 30)
    model = model_with(background)
    want = model.edge_support(frame, mask, boxes)
    with ThreadPoolExecutor(4) as pool:
        out = list(pool.map(lambda _: model.edge_support(frame, mask, boxes), range(80)))
    assert len(out) == 80
    for o in out:
        np.testing.assert_array_equal(o, want)


@pytest.mark.parametrize("seed", range(5))
def test_edge_support_vote_matches_numpy_reference(seed: int) -> None:
    frame, background, mask, boxes = scene(np.random.default_rng(seed))
    got = model_with(background).edge_support(frame, mask, boxes, "vote")
    want = edge_support_reference(frame, background, mask, boxes, "vote")
    # a vote flips where the two magnitudes agree to float32 rounding: at most a band pixel
    # (the smallest band here has 8)
    np.testing.assert_allclose(got, want, rtol=0, atol=0.13)
    assert np.mean(got == want) > 0.9
    assert got[-1] == 0.5
    assert np.all((got >= 0) & (got <= 1))


@pytest.mark.parametrize("seed", range(3))
def test_edge_support_vote_matches_opencv_version(seed: int) -> None:
    frame, background, mask, boxes = scene(np.random.default_rng(20 + seed), (90, 120), 10)
    got = model_with(background).edge_support(frame, mask, boxes, "vote")
    want = edge_support(frame, background, mask, boxes, "vote")
    np.testing.assert_allclose(got, want, rtol=0, atol=0.13)
    assert np.mean(got == want) > 0.9


def owner_ghost() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A ghost whose owner stands against its right side (the owner has just walked out of it).

    The background's picture of the owner has moderate edges (a median of a person who swayed)
    on the blob's left, top and bottom; on its right the frame has the owner's own silhouette,
    at full contrast; elsewhere the frame is flat floor.
    """
    rows, cols = 60, 80
    background = np.full((rows, cols, 3), 100.0, np.float32)
    background[10:50, 20:60] = 130.0  # the picture: +30 grey levels
    frame = np.full((rows, cols, 3), 100, np.uint8)
    frame[10:50, 60:75] = 250  # the owner, sharp: +150, beside the right side
    mask = np.zeros((rows, cols), np.uint8)
    mask[10:50, 20:60] = 255
    return frame, background, mask, np.array([[20.0, 10.0, 40.0, 40.0]])


def test_owner_beside_its_ghost_outweighs_the_sums_not_the_vote() -> None:
    # the issue-14 ghosts the summed test missed: the owner's strong edge on one side outweighs
    # the three others in E_frame / (E_frame + E_background); a vote counts it as one side
    frame, background, mask, boxes = owner_ghost()
    model = model_with(background)
    ratio = model.edge_support(frame, mask, boxes, "ratio")[0]
    vote = model.edge_support(frame, mask, boxes, "vote")[0]
    assert ratio > 0.5
    assert vote < 0.3
    np.testing.assert_allclose(
        ratio, edge_support_reference(frame, background, mask, boxes)[0], atol=1e-5
    )
    assert vote == edge_support_reference(frame, background, mask, boxes, "vote")[0]
    # a real object (its edges in the frame, a flat background) wins both
    obj = np.where(mask[..., None] > 0, np.uint8(180), frame)
    flat = np.full_like(background, 100.0)
    assert model_with(flat).edge_support(obj, mask, boxes, "vote")[0] > 0.9
    assert model_with(flat).edge_support(obj, mask, boxes, "ratio")[0] > 0.9


def test_edge_support_statistic_is_checked() -> None:
    frame, background, mask, boxes = scene(np.random.default_rng(3))
    with pytest.raises(ValueError, match="statistic is 'median', expected 'ratio' or 'vote'"):
        model_with(background).edge_support(frame, mask, boxes, "median")
    with pytest.raises(ValueError, match="statistic is 'median'"):
        edge_support(frame, background, mask, boxes, "median")


@pytest.mark.parametrize("statistic", ["ratio", "vote"])
def test_edge_support_at_every_region_size(statistic: str) -> None:
    """Regions 3 to 42 px wide and tall, inside the frame and clipped at each of its sides: the
    band's and the blur's row loops (vectorised, with their ends) against the reference."""
    rng = np.random.default_rng(21)
    rows, cols = 70, 90
    frame = (rng.integers(0, 256, (rows, cols, 3), dtype=np.uint8) // 32 * 32).astype(np.uint8)
    background = rng.uniform(0, 255, (rows, cols, 3)).astype(np.float32)
    mask = np.where(rng.random((rows, cols)) < 0.7, 255, 0).astype(np.uint8)
    mask[20:50, 30:60] = 255  # a solid blob: a band only about its outline
    sizes = range(3, 43, 3)
    boxes = np.array(
        [[14, 16, s - 8, s - 8] for s in sizes]  # region [10, 10 + s) x [12, 12 + s)
        + [[-2, -2, s - 2, s - 2] for s in sizes]  # clipped at the near sides: [0, s)
        + [[cols - s + 4, rows - s + 4, s, s] for s in sizes]  # at the far sides
        + [[26, 16, 38, 38]],  # the solid blob's box
        np.float64,
    )
    got = model_with(background).edge_support(frame, mask, boxes, statistic)
    want = edge_support_reference(frame, background, mask, boxes, statistic)
    if statistic == "ratio":
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-5)
    else:  # float32 against float64 magnitudes: a near tie may go either way
        np.testing.assert_allclose(got, want, rtol=0, atol=0.05)
        assert np.mean(got == want) > 0.9
    assert not np.any(got == 0.5)  # every region has a band


def test_edge_support_of_every_small_region_shape() -> None:
    """Every region from 3 x 3 to 11 x 11 px, the band on its border rows and columns and inside:
    the blur and Sobel run as flat loops over rows of the padded width, whose values at the
    columns past each row's end and whose wrapped neighbours at its first and last column must
    never reach a magnitude (the border pixels are computed apart); held to the reference."""
    rng = np.random.default_rng(33)
    rows, cols = 60, 80
    frame = (rng.integers(0, 256, (rows, cols, 3), dtype=np.uint8) // 32 * 32).astype(np.uint8)
    background = rng.uniform(0, 255, (rows, cols, 3)).astype(np.float32)
    mask = np.where(rng.random((rows, cols)) < 0.6, 255, 0).astype(np.uint8)
    shapes = [(h, w) for h in range(3, 12) for w in range(3, 12)]
    corners = rng.integers(0, [rows - 11, cols - 11], (len(shapes), 2))
    # region [x, x + w) x [y, y + h): int(left) - 4 = x and int(left + width) + 4 = x + w
    boxes = np.array(
        [[x + 4, y + 4, w - 8, h - 8] for (h, w), (y, x) in zip(shapes, corners, strict=True)],
        np.float64,
    )
    model = model_with(background)
    got = model.edge_support(frame, mask, boxes)
    want = edge_support_reference(frame, background, mask, boxes)
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-5)
    assert np.all(got != 0.5)  # every region has a band
    vote = model.edge_support(frame, mask, boxes, "vote")
    want_vote = edge_support_reference(frame, background, mask, boxes, "vote")
    assert np.mean(vote == want_vote) > 0.9  # a float32 near tie may flip one pixel's vote
