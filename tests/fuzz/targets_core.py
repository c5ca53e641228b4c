"""Fuzz targets: every public function and class of ``pftrack._core``."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import numpy as np
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from pftrack import _core
from tests.fuzz.harness import Target, call, fl, floats_array, garbage, ints, layout, maybe

N = st.integers(0, 12)  # particles, boxes, steps: small, 0 included
# a person-size model's lines [[h_slope, h_intercept], [w_slope, w_intercept]]
SIZE_LINES = floats_array((2, 2), -5, 50)


@st.composite
def frames(draw: st.DrawFn) -> np.ndarray:
    h, w = draw(st.integers(1, 24)), draw(st.integers(1, 24))
    a = draw(hnp.arrays(np.uint8, (h, w, 3)))
    out: np.ndarray = draw(layout(a))
    return out


@st.composite
def binned(draw: st.DrawFn) -> Any:
    return _core.hsv_bins(np.ascontiguousarray(draw(frames())), None, 4, 4, 4)


@st.composite
def masks(draw: st.DrawFn) -> np.ndarray:
    h, w = draw(st.integers(1, 24)), draw(st.integers(1, 24))
    out: np.ndarray = draw(hnp.arrays(st.sampled_from([np.uint8, np.bool_]), (h, w)))
    return out


def boxes(n: st.SearchStrategy[int] = N) -> st.SearchStrategy[np.ndarray]:
    return n.flatmap(lambda k: floats_array((k, 4), -30, 60))


def weights(n: int) -> st.SearchStrategy[np.ndarray]:
    return floats_array((n,), 0, 10)


def vec3(lo: float = -2, hi: float = 2) -> st.SearchStrategy[np.ndarray]:
    return floats_array((3,), lo, hi)


def particles(n: int) -> st.SearchStrategy[np.ndarray]:
    return floats_array((n, 6), 0, 20)


def hist_pair() -> st.SearchStrategy[tuple[np.ndarray, np.ndarray]]:
    return st.tuples(N, st.integers(1, 8)).flatmap(
        lambda kb: st.tuples(floats_array(kb, 0, 1), floats_array((kb[1],), 0, 1))
    )


def _hist_call(fn: Any, lam: bool) -> st.SearchStrategy[Any]:
    extra = (maybe(fl(0, 100)),) if lam else ()
    return hist_pair().flatmap(lambda hr: call(fn, maybe(st.just(hr[0])), maybe(st.just(hr[1])),
                                               *extra))  # fmt: skip


def _resample(name: str) -> Target:
    fn = getattr(_core, name)
    if name == "systematic_resample":
        calls = N.flatmap(lambda n: call(fn, maybe(weights(n)), maybe(fl(0, 0.999))))
    else:
        calls = N.flatmap(
            lambda n: call(fn, maybe(weights(n)), maybe(floats_array((n,), 0, 0.999)))
        )
    return Target(name, calls)


# colour bins of the step targets' images: hsv_bins 4 x 4 x 4 gives 4 * 4 colour + 4 grey bins
# (was 64, so every step call was refused for its reference's length before its kernel ran)
B = 20


def _object_kwargs(n: int) -> dict[str, st.SearchStrategy[Any]]:
    """One filter's state: particles, weights, means."""
    return {
        "particles": maybe(particles(n)),
        "weights": maybe(weights(n)),
        "means": maybe(floats_array((2, 3), 0, 20)),
    }


def _model_kwargs() -> dict[str, st.SearchStrategy[Any]]:
    """The motion model and likelihood settings sis_step and sis_step_batch share."""
    return {
        "a": maybe(vec3()),
        "b": maybe(vec3()),
        "sigma": maybe(vec3(0, 3)),
        "s_min": maybe(fl(0.1, 1)),
        "s_max": maybe(fl(1, 5)),
        "use_means": st.booleans(),
        "lam": maybe(fl(0, 50)),
        "kernel": maybe(st.sampled_from(["uniform", "epanechnikov", "gaussian"])),
        "resample": st.booleans(),
        "min_samples": maybe(fl(0, 50)),
    }


def _step_kwargs(n: int) -> dict[str, st.SearchStrategy[Any]]:
    return {
        **_object_kwargs(n),
        "image": maybe(binned()),
        "ref": maybe(floats_array((B,), 0, 1)),
        "w0": maybe(fl(0.5, 20)),
        "h0": maybe(fl(0.5, 20)),
        **_model_kwargs(),
        "seed": maybe(ints(0, 2**63 - 1)),
        "step": maybe(ints(0, 1000)),
    }


def _sis() -> st.SearchStrategy[Any]:
    return N.flatmap(lambda n: call(_core.sis_step, **_step_kwargs(n)))


def _sis_batch() -> st.SearchStrategy[Any]:
    def kw(ns: list[int]) -> dict[str, st.SearchStrategy[Any]]:
        k = len(ns)
        per = [_object_kwargs(n) for n in ns]
        return {
            **{
                key: maybe(st.tuples(*[p[key] for p in per]).map(list))
                for key in ("particles", "weights", "means")
            },
            "image": maybe(binned()),
            "refs": maybe(st.lists(floats_array((B,), 0, 1), min_size=k, max_size=k)),
            "w0": maybe(floats_array((k,), 0.5, 20)),
            "h0": maybe(floats_array((k,), 0.5, 20)),
            **_model_kwargs(),
            "seeds": maybe(st.lists(ints(0, 2**63 - 1), min_size=k, max_size=k)),
            "steps": maybe(st.lists(ints(0, 1000), min_size=k, max_size=k)),
        }

    return st.lists(st.integers(0, 6), max_size=3).flatmap(
        lambda ns: call(_core.sis_step_batch, **kw(ns))
    )


def _reseed_batch() -> st.SearchStrategy[Any]:
    def kw(ns: list[int]) -> dict[str, st.SearchStrategy[Any]]:
        k = len(ns)
        per = [_object_kwargs(n) for n in ns]
        return {
            **{
                key: maybe(st.tuples(*[p[key] for p in per]).map(list))
                for key in ("particles", "weights", "means")
            },
            "boxes": maybe(floats_array((k, 4), 0.5, 20)),
            "velocities": maybe(floats_array((k, 2), -3, 3)),
            "w0": maybe(floats_array((k,), 0.5, 20)),
            "h0": maybe(floats_array((k,), 0.5, 20)),
            "noise": maybe(floats_array((sum(ns), 3), -3, 3)),
            "pos_sd": maybe(fl(0, 5)),
            "s_sd": maybe(fl(0, 1)),
            "s_min": maybe(fl(0.1, 1)),
            "s_max": maybe(fl(1, 5)),
        }

    return st.lists(st.integers(0, 6), max_size=3).flatmap(
        lambda ns: call(_core.reseed_batch, **kw(ns))
    )


def _centre_tracks(k: int) -> st.SearchStrategy[list[Any]]:
    """`k` objects with a LiveTrack's centre-filter attributes, some of them garbage."""
    motion = st.builds(
        SimpleNamespace,
        p=maybe(floats_array((2,), -50, 500)),
        v=maybe(floats_array((2,), -5, 5)),
        cov=maybe(st.tuples(fl(0, 50), fl(-5, 5), fl(0, 50))),
        accel=maybe(fl(0, 1)),
    )
    track = st.builds(
        SimpleNamespace, motion=motion, size=maybe(floats_array((2,), 0.5, 300)),
        box=st.none(), flat=st.just(False), measured=st.none(), rho=st.just(1.0),
        age=maybe(ints(1, 100)),
    )  # fmt: skip
    return st.lists(track, min_size=k, max_size=k)


def _centre_predict() -> st.SearchStrategy[Any]:
    return st.integers(0, 6).flatmap(
        lambda k: call(
            _core.centre_predict_tracks,
            maybe(_centre_tracks(k)),
            maybe(floats_array((k, 4), -50, 500)),
            maybe(st.lists(fl(0, 5), min_size=k, max_size=k)),
            maybe(fl(0, 2)),
            maybe(fl(0, 1e-6)),
        )
    )


def _centre_follow() -> st.SearchStrategy[Any]:
    return st.integers(0, 6).flatmap(
        lambda k: call(
            _core.centre_follow_tracks,
            maybe(_centre_tracks(k)),
            maybe(floats_array((k, 4), 0.5, 300)),
            maybe(fl(0, 2)),
            maybe(st.booleans()),
        )
    )


def _association_cost() -> st.SearchStrategy[Any]:
    return st.tuples(N, N).flatmap(
        lambda td: call(
            _core.association_cost,
            maybe(floats_array((td[0], 4), 0, 50)),
            maybe(floats_array((td[0],), 1, 50)),
            maybe(floats_array((td[0],), 0, 20)),
            maybe(floats_array(td, 0, 1)),
            maybe(floats_array((td[1], 4), 0, 50)),
            maybe(fl(0.1, 3)),
            maybe(fl(0, 2)),
            maybe(fl(0, 1)),
            maybe(fl(0, 1e6)),
        )
    )


def _assignment() -> st.SearchStrategy[Any]:
    return st.tuples(N, N).flatmap(
        lambda rc: call(_core.linear_sum_assignment, maybe(floats_array(rc, -10, 10)))
    )


@st.composite
def _sparse_assignment(draw: st.DrawFn) -> Any:
    """Pairs of ends and starts, some out of range; costs, some special; the counts."""
    n_ends, n_starts, k = draw(N), draw(N), draw(st.integers(0, 20))
    r = np.array(draw(st.lists(st.integers(-1, n_ends), min_size=k, max_size=k)), np.int64)
    c = np.array(draw(st.lists(st.integers(-1, n_starts), min_size=k, max_size=k)), np.int64)
    return draw(
        call(
            _core.sparse_assignment,
            maybe(st.just(r)),
            maybe(st.just(c)),
            maybe(floats_array((k,), -10, 10)),
            maybe(st.just(n_ends)),
            maybe(st.just(n_starts)),
            maybe(fl(-1e6, 1e6)),
        )
    )


def _overlap_pairs() -> st.SearchStrategy[Any]:
    return call(_core.overlap_pairs, maybe(boxes()), maybe(boxes()))


def _still_flow() -> st.SearchStrategy[Any]:
    def grey(h: int, w: int) -> st.SearchStrategy[Any]:
        return hnp.arrays(np.uint8, (h, w)).flatmap(layout)

    return st.tuples(st.integers(1, 24), st.integers(1, 24), N).flatmap(
        lambda hwn: call(
            _core.still_flow,
            maybe(grey(hwn[0], hwn[1])),
            maybe(grey(hwn[0], hwn[1])),
            maybe(floats_array((hwn[2], 2), -30, 60)),
        )
    )


def _similarity_fit() -> st.SearchStrategy[Any]:
    return N.flatmap(
        lambda n: call(
            _core.similarity_fit,
            maybe(floats_array((n, 2), -1e3, 1e3)),
            maybe(floats_array((n, 2), -1e3, 1e3)),
        )
    )


def _padded_assignment() -> st.SearchStrategy[Any]:
    return st.tuples(N, N).flatmap(
        lambda td: call(
            _core.padded_assignment,
            maybe(floats_array(td, -10, 1e6)),
            maybe(fl(-1e6, 1e6)),
            maybe(fl(0, 1e6)),
        )
    )


def _mh() -> st.SearchStrategy[Any]:
    def kw(n: int) -> dict[str, st.SearchStrategy[Any]]:
        k = _step_kwargs(n)
        k.update(n_iter=maybe(ints(1, 3)), burn_in=maybe(ints(0, 2)),
                 proposal=maybe(st.sampled_from(["dynamics", "random_walk"])),
                 rw_sigma=maybe(vec3(0, 2)))  # fmt: skip
        return k

    return N.flatmap(lambda n: call(_core.mh_step, **kw(n)))


def _propagate(p: np.ndarray, noise: Any, *rest: Any) -> Any:
    """propagate writes in place: check the particles it leaves behind as its result."""
    p = p if isinstance(p, np.ndarray) else p
    _core.propagate(p, noise, *rest)
    return p


def _propagate_calls() -> st.SearchStrategy[Any]:
    return N.flatmap(lambda n: call(
        _propagate, maybe(particles(n)), maybe(floats_array((n, 3), -3, 3)), maybe(vec3()),
        maybe(vec3()), maybe(vec3(0, 3)), maybe(fl(0.1, 1)), maybe(fl(1, 5)), st.booleans(),
        maybe(vec3(0, 20)), maybe(vec3(0, 20)),
    ))  # fmt: skip


@st.composite
def lti(draw: st.DrawFn, stable: bool = False) -> dict[str, Any]:
    """A small linear-Gaussian problem: A, Q, H, Pi_T, m0, Pi_0, y, T (sometimes unstable)."""
    n = draw(st.integers(1, 4))
    m = draw(st.integers(1, n))
    scale = 1.0 if stable else draw(st.sampled_from([0.5, 1.0, 1.5, 5.0]))
    L = draw(floats_array((n, n), -1, 1))
    with np.errstate(all="ignore"):  # a special value in A or L makes a special A or Q
        A = draw(floats_array((n, n), -1, 1)) * scale
        spd = np.ascontiguousarray(L @ L.T) + np.eye(n)
    return {
        "A": maybe(st.just(A)), "Q": maybe(st.just(spd)),
        "H": maybe(st.just(np.eye(m, n))), "Pi_T": maybe(st.just(np.eye(m))),
        "m0": maybe(floats_array((n,), -10, 10)), "Pi_0": maybe(st.just(np.eye(n))),
        "y": maybe(floats_array((m,), -10, 10)),
        "T": maybe(st.one_of(ints(1, 40), st.sampled_from([500, 5000]))),
    }  # fmt: skip


def _gdt_solve() -> st.SearchStrategy[Any]:
    return lti().flatmap(lambda p: call(
        _core.gdt_solve, *p.values(), form=maybe(st.sampled_from(["general", "information"])),
        start_conditioned=st.booleans(),
    ))  # fmt: skip


def _gdt_sample() -> st.SearchStrategy[Any]:
    return lti().flatmap(lambda p: call(
        _core.gdt_sample, *p.values(), maybe(ints(0, 5)), maybe(ints(0, 2**63 - 1)),
    ))  # fmt: skip


def _gdt_batch() -> st.SearchStrategy[Any]:
    problem = lti().flatmap(lambda p: st.tuples(*p.values()))
    return call(_core.gdt_solve_batch, maybe(st.lists(maybe(problem), max_size=3)),
                paths_only=st.booleans())  # fmt: skip


@st.composite
def _recover_batch(draw: st.DrawFn) -> Any:
    g = draw(st.integers(0, 3))
    a_len = np.asarray(draw(st.lists(st.integers(1, 6), min_size=g, max_size=g)), np.int32)
    b_len = np.asarray(draw(st.lists(st.integers(1, 6), min_size=g, max_size=g)), np.int32)
    seg_a, seg_b = [], []
    for la, lb in zip(a_len, b_len, strict=True):
        fa = np.arange(1, la + 1, dtype=float)
        fb = fa[-1] + draw(st.integers(1, 50)) + np.arange(lb, dtype=float)
        seg_a.append(np.column_stack([fa, draw(floats_array((int(la), 2), 0, 500))]))
        seg_b.append(np.column_stack([fb, draw(floats_array((int(lb), 2), 0, 500))]))
    sa = np.vstack(seg_a) if seg_a else np.zeros((0, 3))
    sb = np.vstack(seg_b) if seg_b else np.zeros((0, 3))
    F = np.array([[1, 0, 1, 0], [0, 1, 0, 1], [0, 0, 1, 0], [0, 0, 0, 1]], float)
    return draw(call(
        _core.gdt_recover_batch, maybe(st.just(sa)), maybe(st.just(a_len)), maybe(st.just(sb)),
        maybe(st.just(b_len)), maybe(st.just(F)), maybe(st.just(np.eye(4))),
        maybe(st.just(np.eye(2, 4))), maybe(st.just(np.eye(2))), maybe(fl(0, 100)),
        maybe(st.sampled_from(["first_point", "backward_state"])), maybe(ints(0, 10)),
        st.booleans(),
    ))  # fmt: skip


@st.composite
def _runs(draw: st.DrawFn) -> tuple[np.ndarray, np.ndarray]:
    lengths = np.asarray(draw(st.lists(st.integers(1, 8), max_size=4)), np.int32)
    return draw(floats_array((int(lengths.sum()),), -50, 50)), lengths


def _noise_grid() -> st.SearchStrategy[Any]:
    return st.tuples(_runs(), st.integers(0, 4)).flatmap(lambda rg: call(
        _core.noise_loglik_grid, maybe(st.just(rg[0][0])), maybe(st.just(rg[0][1])),
        maybe(floats_array((rg[1],), 1e-6, 10)), maybe(floats_array((rg[1],), 1e-6, 10)),
    ))  # fmt: skip


def _state_loglik() -> st.SearchStrategy[Any]:
    F = np.array([[1.0, 1.0], [0.0, 1.0]])
    return st.tuples(_runs(), st.integers(1, 3)).flatmap(lambda rk: call(
        _core.state_loglik_batch, maybe(st.just(rk[0][0])), maybe(st.just(rk[0][1])),
        maybe(st.just(np.vstack([F] * rk[1]))), maybe(st.just(np.vstack([np.eye(2)] * rk[1]))),
        maybe(floats_array((rk[1],), 1e-3, 10)), maybe(fl(1, 1e6)), maybe(st.integers(1, 4)),
    ))  # fmt: skip


@st.composite
def _gap_mixture_many(draw: st.DrawFn) -> Any:
    jobs = []
    for _ in range(draw(st.integers(0, 4))):
        (_, (z, fa, fb, *_rest, t1, t2, _v2), _kw) = draw(_gap_mixture())
        jobs.append(
            draw(
                maybe(
                    st.tuples(
                        st.just(z),
                        st.just(fa),
                        st.just(fb),
                        st.integers(-1, 2),
                        st.just(t1),
                        st.just(t2),
                    )
                )
            )
        )
    k = draw(st.integers(0, 2))
    F = np.array([[1.0, 1.0], [0.0, 1.0]])
    return draw(call(
        _core.gap_mixture_many, maybe(st.just(jobs)), maybe(st.just([F] * k)),
        maybe(st.just([np.eye(2)] * k)), maybe(st.lists(fl(1e-3, 10), min_size=k, max_size=k)),
        maybe(st.lists(floats_array((2,), 1e-3, 100), min_size=k, max_size=k)),
        maybe(st.lists(fl(0, 10), min_size=k, max_size=k)), maybe(st.integers(0, 4)),
    ))  # fmt: skip


@st.composite
def _rts_gaps(draw: st.DrawFn) -> Any:
    g = draw(st.integers(0, 4))
    pts, offsets, n_before = [np.zeros((0, 3))], [0], []
    for _ in range(g):
        na, nb = draw(st.integers(1, 6)), draw(st.integers(1, 6))
        steps = draw(st.lists(st.integers(1, 4), min_size=na + nb - 1, max_size=na + nb - 1))
        fr = draw(st.integers(-5, 50)) + np.r_[0, np.cumsum(steps)]
        pts.append(np.column_stack([fr, draw(floats_array((na + nb, 2), -500, 500))]))
        offsets.append(offsets[-1] + na + nb)
        n_before.append(na)
    return draw(call(
        _core.rts_gaps_batch, maybe(st.just(np.vstack(pts))),
        maybe(st.just(np.asarray(offsets, np.int32))),
        maybe(st.just(np.asarray(n_before, np.int32))),
        maybe(fl(1e-3, 100)), maybe(fl(1e-3, 100)), maybe(fl(1e-3, 1e4)),
    ))  # fmt: skip


@st.composite
def _rts_smooth(draw: st.DrawFn) -> Any:
    steps, n = draw(st.integers(0, 30)), draw(st.integers(0, 4))
    per_axis = draw(st.booleans())
    has = draw(floats_array((steps, n) if per_axis else (steps,), 0, 1)) > 0.4
    return draw(call(
        _core.rts_smooth, maybe(floats_array((steps, n), -1e4, 1e4)), maybe(st.just(has)),
        maybe(floats_array((n,), 1e-6, 1e3)), maybe(floats_array((n,), 1e-6, 1e3)),
        maybe(fl(0.0, 1e3)), st.booleans(),
    ))  # fmt: skip


@st.composite
def _gap_mixture(draw: st.DrawFn) -> Any:
    n = draw(st.integers(2, 30))
    fa = draw(st.integers(0, n - 2))
    fb = draw(st.integers(fa + 1, n - 1))
    z = draw(floats_array((n,), -50, 50))
    z[fa + 1 : fb] = np.nan
    F = np.array([[1.0, 1.0], [0.0, 1.0]])
    h = draw(st.integers(0, 3))
    t1 = np.asarray(draw(st.lists(st.integers(-1, n), min_size=h, max_size=h)), np.int32)
    t2 = np.asarray(draw(st.lists(st.integers(-1, n), min_size=h, max_size=h)), np.int32)
    return draw(call(
        _core.gap_mixture, maybe(st.just(z)), maybe(st.just(fa)), maybe(st.just(fb)),
        maybe(st.just(F)), maybe(st.just(np.eye(2))), maybe(fl(1e-3, 10)),
        maybe(floats_array((2,), 1e-3, 100)), maybe(st.just(t1)), maybe(st.just(t2)),
        maybe(fl(0, 10)),
    ))  # fmt: skip


@st.composite
def _mot_lines(draw: st.DrawFn) -> Any:
    k = draw(N)
    ids = np.round(draw(floats_array((k, 2), -1e6, 1e6)))  # sometimes a special value
    codes = np.asarray(draw(hnp.arrays(np.int64, (k, 8), elements=st.integers(-2, 33))))
    return draw(call(
        _core.mot_lines, maybe(st.just(ids)), maybe(floats_array((k, 8), -1e300, 1e300)),
        maybe(layout(codes)),
    ))  # fmt: skip


@st.composite
def _region_blocks(draw: st.DrawFn) -> Any:
    sizes = draw(st.lists(st.integers(0, 6), max_size=6))
    n = sum(sizes)
    return draw(call(
        _core.region_blocks, maybe(floats_array((n, 2), -20, 20)),
        maybe(st.just(np.array(sizes, dtype=np.int64))),
        maybe(N.flatmap(lambda k: floats_array((k, 2), -20, 20))), maybe(fl(0, 50)),
        maybe(ints(0, 100)), maybe(st.integers(0, 22)),
    ))  # fmt: skip


def _mot_bytes() -> st.SearchStrategy[bytes]:
    """Bytes that are mostly MOT text: numbers, separators and line ends, sometimes anything."""
    line = st.lists(st.sampled_from(["1", "-2.5", "+.5", "3e2", "1e400", "nan", ""]), max_size=11)
    sep = st.sampled_from([",", " ", ", ", "\t"])
    end = st.sampled_from(["\n", "\r\n", "\r", ""])
    text = st.lists(st.tuples(line, sep, end), max_size=5).map(
        lambda ls: "".join(s.join(f) + e for f, s, e in ls).encode()
    )
    return st.one_of(text, st.binary(max_size=40))


def _kalman() -> st.SearchStrategy[Any]:
    F = np.array([[1.0, 1.0], [0.0, 1.0]])
    return N.flatmap(lambda k: call(
        _core.kalman_filter, maybe(floats_array((k, 1), -50, 50)), maybe(st.just(F)),
        maybe(st.just(np.eye(2))), maybe(st.just(np.eye(1, 2))), maybe(st.just(np.eye(1))),
        maybe(floats_array((2,), -5, 5)), maybe(st.just(np.eye(2))),
    ))  # fmt: skip


def _mask_pass(fn: Any) -> st.SearchStrategy[Any]:
    """Calls of a morphology pass (close_mask, open_mask): a mask and a small element."""
    element = hnp.arrays(st.sampled_from([np.uint8, np.bool_]), st.tuples(ints(1, 7), ints(1, 7)))
    return call(fn, maybe(masks().flatmap(layout)), maybe(element))


def _clean_mask() -> st.SearchStrategy[Any]:
    """Calls of clean_mask: a mask (any levels, or 0/255 and 0/127/255: the bit planes) and two
    small elements."""
    element = hnp.arrays(st.sampled_from([np.uint8, np.bool_]), st.tuples(ints(1, 7), ints(1, 7)))
    levels = st.sampled_from([(0, 255), (0, 127, 255), (0, 1)])
    planes = st.tuples(levels, ints(1, 70), ints(1, 70), st.integers(0, 2**32 - 1)).map(
        lambda a: np.random.default_rng(a[3]).choice(np.array(a[0], np.uint8), (a[1], a[2]))
    )
    mask = st.one_of(masks().flatmap(layout), planes)
    return call(_core.clean_mask, maybe(mask), maybe(element), maybe(element))


def _background(
    params: dict[str, Any], frames_: list[Any], mask: Any, rate: Any, boxes: Any
) -> Any:
    model = _core.BackgroundModel(**params)
    out = None
    for f in frames_:
        out = model.apply(f)
    support = None
    if frames_:
        out = model.apply(frames_[-1], hold=mask)  # a tracked object's pixels not learnt
        model.blend(frames_[-1], mask, rate)  # ghosts learnt faster (after the last frame)
        support = model.edge_support(frames_[-1], mask, boxes)  # the ghost test
        support = (support, model.mean_and_gain(frames_[-1]))  # the light's two measures
    return None if out is None else (out[0].bins, out[1], model.threshold, support)


def _background_calls() -> st.SearchStrategy[Any]:
    params = st.fixed_dictionaries({}, optional={
        "alpha": maybe(fl(0, 1)), "alpha_fg": maybe(fl(0, 1)), "n_learn": maybe(ints(1, 3)),
        "k_noise": maybe(fl(0, 10)), "t_min": maybe(fl(0, 50)), "t_max": maybe(fl(50, 255)),
        "low_ratio": maybe(fl(0, 1)), "n_h": maybe(ints(1, 64)), "s_min": maybe(fl(0, 1)),
    })  # fmt: skip
    return call(_background, params, st.lists(maybe(frames()), max_size=4), maybe(masks()),
                maybe(fl(0, 1)), maybe(boxes()))  # fmt: skip


def _rjmcmc(params: dict[str, Any], image: Any, mask: Any, cands: Any, hists: Any, seed: Any,
            step: Any, affine: Any, restore: Any) -> Any:  # fmt: skip
    tracker = _core.RJMCMCTracker(**params)
    out = tracker.step(image, mask, cands, hists, seed=seed, step=step)
    tracker.warp(affine)  # camera-motion compensation of the kept identities
    kept = tracker.tracks
    fresh = _core.RJMCMCTracker(**params)
    fresh.restore(kept if restore is None else restore, tracker.next_id)  # a checkpoint's resume
    return out, [t for t in fresh.tracks]


def _rjmcmc_calls() -> st.SearchStrategy[Any]:
    params = st.fixed_dictionaries({}, optional={
        "burn_in": maybe(ints(0, 5)), "n_samples": maybe(ints(1, 10)),
        "p_birth": maybe(fl(0, 1)), "lam": maybe(fl(0, 50)), "s_min": maybe(fl(0.1, 1)),
        "sigma": maybe(vec3(0, 3)), "kernel": maybe(st.sampled_from(["uniform", "gaussian"])),
        "min_samples": maybe(fl(-1, 100)),
    })  # fmt: skip
    return st.tuples(frames(), N).flatmap(lambda fk: call(
        _rjmcmc, params, maybe(st.just(_core.hsv_bins(np.ascontiguousarray(fk[0]), None, 4, 4, 4))),
        maybe(st.just(np.ones(fk[0].shape[:2], np.uint8))), maybe(boxes(st.just(fk[1]))),
        st.none(), maybe(ints(0, 2**63 - 1)), maybe(ints(0, 100)),
        maybe(floats_array((2, 3), -10.0, 10.0)), st.one_of(st.none(), garbage()),
    ))  # fmt: skip


def _binned_image(bins: Any, n_bins: Any) -> Any:
    img = _core.BinnedImage(bins, n_bins)
    return img.bins.copy(), img.shape, img.n_bins


TARGETS: list[Target] = [
    Target(
        "hsv_bins",
        st.one_of(frames(), garbage()).flatmap(
            lambda f: call(
                _core.hsv_bins,
                st.just(f),
                st.one_of(st.none(), masks(), garbage()),
                maybe(ints(1, 64)),
                maybe(ints(1, 64)),
                maybe(ints(1, 64)),
                maybe(fl(0, 1)),
                maybe(fl(0, 1)),
            )
        ),
    ),  # fmt: skip
    Target("mask_bins", call(_core.mask_bins, maybe(binned()), maybe(masks()))),
    Target("sampled_mean", call(_core.sampled_mean, maybe(frames()), maybe(ints(-2, 64)))),
    Target("close_mask", _mask_pass(_core.close_mask)),
    Target("open_mask", _mask_pass(_core.open_mask)),
    Target("clean_mask", _clean_mask()),
    Target(
        "median_frames",
        call(
            _core.median_frames,
            maybe(st.lists(maybe(frames()), max_size=4)),
            maybe(st.integers(1, 5)),
        ),
    ),
    Target(
        "BinnedImage",
        call(
            _binned_image,
            maybe(hnp.arrays(np.int16, (3, 4), elements=st.integers(-2, 70)).flatmap(layout)),
            maybe(ints(1, 64)),
        ),
    ),  # fmt: skip
    Target(
        "box_histograms",
        call(
            _core.box_histograms,
            maybe(binned()),
            maybe(boxes()),
            maybe(st.sampled_from(["uniform", "epanechnikov"])),
            maybe(st.sampled_from(["auto", "direct", "integral"])),
        ),
    ),  # fmt: skip
    Target(
        "box_weights",
        N.flatmap(
            lambda k: call(
                _core.box_weights,
                maybe(binned()),
                maybe(boxes(st.just(k))),
                maybe(floats_array((64,), 0, 1)),
                maybe(fl(0, 100)),
                maybe(st.sampled_from(["uniform", "epanechnikov"])),
                maybe(st.sampled_from(["auto", "direct", "integral"])),
                maybe(ints(1, 8)),
            )
        ),
    ),  # fmt: skip
    Target("bhattacharyya_coefficient", _hist_call(_core.bhattacharyya_coefficient, False)),
    Target("bhattacharyya_distance", _hist_call(_core.bhattacharyya_distance, False)),
    Target("bhattacharyya_weights", _hist_call(_core.bhattacharyya_weights, True)),
    *[
        _resample(n)
        for n in (
            "systematic_resample",
            "stratified_resample",
            "multinomial_resample",
            "residual_resample",
        )
    ],  # fmt: skip
    Target("propagate", _propagate_calls()),
    Target(
        "estimate",
        N.flatmap(lambda n: call(_core.estimate, maybe(particles(n)), maybe(weights(n)))),
    ),  # fmt: skip
    Target("sis_step", _sis()),
    Target("mh_step", _mh()),
    Target("sis_step_batch", _sis_batch()),
    Target("reseed_batch", _reseed_batch()),
    Target("centre_predict_tracks", _centre_predict()),
    Target("centre_follow_tracks", _centre_follow()),
    Target("linear_sum_assignment", _assignment()),
    Target("association_cost", _association_cost()),
    Target("sparse_assignment", _sparse_assignment()),
    Target("overlap_pairs", _overlap_pairs()),
    Target("padded_assignment", _padded_assignment()),
    Target("still_flow", _still_flow()),
    Target("similarity_fit", _similarity_fit()),
    Target("grey_halved", call(_core.grey_halved, st.one_of(frames(), garbage()))),
    Target(
        "refine_boxes",
        call(
            _core.refine_boxes,
            maybe(boxes()),
            st.one_of(masks(), masks().flatmap(layout), garbage()),
            maybe(fl(-1, 2)),
            maybe(fl(-1, 2)),
        ),
    ),  # fmt: skip
    Target(
        "blob_boxes",
        call(
            _core.blob_boxes,
            st.one_of(
                masks().map(lambda m: (np.asarray(m) > 0).astype(np.uint8) * 255),
                masks().flatmap(layout),
                garbage(),
            ),
            maybe(fl(0, 0.01)),
            maybe(fl(0.01, 1)),
            maybe(fl(1e-3, 1)),
            maybe(fl(1, 1e3)),
            maybe(fl(0, 1)),
            maybe(fl(0, 10)),
            st.one_of(st.none(), SIZE_LINES, garbage()),
            maybe(fl(1, 3)),
            maybe(fl(0.5, 3)),
            maybe(fl(1, 3)),
        ),
    ),  # fmt: skip
    Target(
        "extend_legs",
        call(
            _core.extend_legs,
            st.one_of(
                masks().map(lambda m: (np.asarray(m, np.uint8) % 3) * 127),  # 0, 127, 254
                masks().flatmap(layout),
                garbage(),
            ),
            maybe(boxes()),
            st.one_of(SIZE_LINES, garbage()),
            maybe(fl(0, 3)),
            maybe(fl(0, 1)),
        ),
    ),  # fmt: skip
    Target(
        "split_count",
        call(
            _core.split_count,
            maybe(boxes()),
            maybe(SIZE_LINES),
            maybe(fl(1, 3)),
            maybe(fl(0.5, 3)),
        ),
    ),  # fmt: skip
    Target(
        "merge_fragments",
        call(
            _core.merge_fragments,
            maybe(boxes()),
            maybe(SIZE_LINES),
            maybe(fl(1, 3)),
        ),
    ),  # fmt: skip
    Target(
        "size_fit",
        N.flatmap(lambda n: call(_core.size_fit, maybe(floats_array((n, 3), 0, 500)))),
    ),  # fmt: skip
    Target(
        "theil_sen",
        N.flatmap(
            lambda n: call(_core.theil_sen, maybe(floats_array((n,))), maybe(floats_array((n,))))
        ),
    ),  # fmt: skip
    Target(
        "counter_normals",
        call(
            _core.counter_normals,
            maybe(ints(0, 2**64 - 1)),
            maybe(ints(0, 2**64 - 1)),
            st.one_of(ints(0, 50), garbage()),
        ),
    ),  # fmt: skip
    Target(
        "counter_uniforms",
        call(
            _core.counter_uniforms,
            maybe(ints(0, 2**64 - 1)),
            maybe(ints(0, 2**64 - 1)),
            maybe(ints(0, 2**64 - 1)),
            st.one_of(ints(0, 50), garbage()),
        ),
    ),  # fmt: skip
    Target("gdt_solve", _gdt_solve()),
    Target("gdt_sample", _gdt_sample()),
    Target("gdt_solve_batch", _gdt_batch()),
    Target("gdt_recover_batch", _recover_batch()),
    Target("kalman_filter", _kalman()),
    Target("noise_loglik_grid", _noise_grid()),
    Target("state_loglik_batch", _state_loglik()),
    Target("gap_mixture", _gap_mixture()),
    Target("gap_mixture_many", _gap_mixture_many()),
    Target(
        "fewest_decimals",
        call(
            _core.fewest_decimals,
            maybe(N.flatmap(lambda n: floats_array((n,), -1e20, 1e20))),
            maybe(fl(1e-3, 2.0**53)),
            maybe(st.integers(0, 22)),
        ),
    ),  # fmt: skip
    Target("mot_lines", _mot_lines()),
    Target("parse_mot_text", call(_core.parse_mot_text, maybe(_mot_bytes()))),
    Target("region_blocks", _region_blocks()),
    Target("rts_gaps_batch", _rts_gaps()),
    Target("rts_smooth", _rts_smooth()),
    Target("BackgroundModel", _background_calls()),
    Target("RJMCMCTracker", _rjmcmc_calls()),
]
