"""One filter in one thread at a time: a second thread gets RuntimeError, never a mixed state.

The steps run in the core without the GIL and update the filter's arrays in place; two threads
inside one filter mixed the two steps' particles and reused a step number (a wrong result and no
error), where :class:`pftrack.Tracker` refused the second thread.
"""

from __future__ import annotations

import copy
import pickle
import re
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np
import pytest

from pftrack.particle_filter import (
    ColourParticleFilter,
    FilterConfig,
    MHColourParticleFilter,
    RJMCMCFilter,
    box_histograms,
    hsv_bins,
)
from pftrack.particle_filter import filter as filter_module
from pftrack.particle_filter import mh as mh_module
from pftrack.particle_filter.filter import reinitialise_filters, step_filters
from pftrack.synthetic import make_scene

BOX = np.array([112.0, 201.0, 22.0, 98.0])


@pytest.fixture(scope="module")
def image():
    return hsv_bins(make_scene(n_frames=1, rng=0).frames[0])


@pytest.fixture(scope="module")
def reference(image):
    return box_histograms(image, BOX)[0]


def _message(cls: str, method: str) -> str:
    return (
        f"{method}: this {cls} is in use by another thread (use one {cls} per thread, or a lock "
        "around it)"
    )


@contextmanager
def _held_inside(module: Any, name: str) -> Iterator[Callable[[Callable[[], object]], None]]:
    """Makes ``module.name`` (a core kernel) wait inside until released; yields ``start(call)``.

    ``start(call)`` runs `call` in a thread and returns once it is inside the kernel; leaving
    the ``with`` lets it finish and joins it.
    """
    real = getattr(module, name)
    inside, leave = threading.Event(), threading.Event()
    threads: list[threading.Thread] = []

    def held(*args: Any, **kwargs: Any) -> Any:
        inside.set()
        assert leave.wait(10)
        return real(*args, **kwargs)

    def start(call: Callable[[], object]) -> None:
        t = threading.Thread(target=call)
        threads.append(t)
        t.start()
        assert inside.wait(10)

    setattr(module, name, held)
    try:
        yield start
    finally:
        leave.set()
        for t in threads:
            t.join()
        setattr(module, name, real)


SAMPLERS = [
    (ColourParticleFilter, filter_module._core, "sis_step"),
    (MHColourParticleFilter, mh_module._core, "mh_step"),
]


@pytest.mark.parametrize(("cls", "core", "kernel"), SAMPLERS, ids=["sis", "mh"])
def test_a_second_thread_is_refused_while_one_steps(image, reference, cls, core, kernel):
    f = cls(BOX, reference, rng=0)
    serial = cls(BOX, reference, rng=0)
    name = cls.__name__
    with _held_inside(core, kernel) as start:
        start(lambda: f.step(image))
        with pytest.raises(RuntimeError, match=f"^{re.escape(_message(name, f'{name}.step'))}$"):
            f.step(image)
        with pytest.raises(RuntimeError, match=rf"^{name}\.reinitialise: this {name} is in use"):
            f.reinitialise(BOX)
        with pytest.raises(RuntimeError, match=rf"^{name}\.__getstate__: this {name} is in use"):
            copy.deepcopy(f)
    # the first thread's step went in, the refused calls changed nothing
    serial.step(image)
    np.testing.assert_array_equal(f.particles, serial.particles)
    assert f._step == 1
    f.step(image)  # free again
    serial.step(image)
    np.testing.assert_array_equal(f.particles, serial.particles)


def test_step_filters_refuses_a_filter_in_use_and_steps_none(image, reference):
    a, b = (ColourParticleFilter(BOX, reference, rng=k) for k in range(2))
    before = a.particles.copy()
    with _held_inside(filter_module._core, "sis_step") as start:
        start(lambda: b.step(image))
        with pytest.raises(RuntimeError, match=r"^step_filters: filters\[1\] is in use by "):
            step_filters([a, b], image)
        with pytest.raises(RuntimeError, match=r"^reinitialise_filters: filters\[1\] is in use"):
            reinitialise_filters([a, b], [BOX, BOX], [[0, 0], [0, 0]])
    np.testing.assert_array_equal(a.particles, before)  # a was not stepped nor re-seeded
    assert a._step == 0
    step_filters([a, b], image)  # free again
    assert (a._step, b._step) == (1, 2)


def test_step_filters_refuses_the_same_filter_twice(image, reference):
    # was: one step of the core on the same arrays twice, the filter's counter advanced by two
    f = ColourParticleFilter(BOX, reference, rng=0)
    with pytest.raises(ValueError, match=r"^step_filters: filters\[2\] is filters\[0\], the same"):
        step_filters([f, ColourParticleFilter(BOX, reference, rng=1), f], image)
    assert f._step == 0


@pytest.mark.parametrize("cls", [ColourParticleFilter, MHColourParticleFilter], ids=["sis", "mh"])
def test_two_threads_raise_or_equal_serial_never_mix(image, reference, cls):
    """Two threads step one filter 60 times each: every step either raises or is a whole step."""
    config = FilterConfig(n_particles=2000)  # long steps: the threads do meet
    f = cls(BOX, reference, config, rng=0)
    done: list[int] = []
    errors: list[str] = []

    def work() -> None:
        for _ in range(60):
            try:
                f.step(image)
                done.append(1)
            except RuntimeError as e:
                errors.append(str(e))

    threads = [threading.Thread(target=work) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert set(errors) <= {_message(cls.__name__, f"{cls.__name__}.step")}
    assert len(done) + len(errors) == 120 and f._step == len(done)
    serial = cls(BOX, reference, config, rng=0)
    for _ in range(len(done)):
        serial.step(image)
    np.testing.assert_array_equal(f.particles, serial.particles)  # was: a mix of two runs
    np.testing.assert_array_equal(f.means, serial.means)


@pytest.mark.parametrize("cls", [ColourParticleFilter, MHColourParticleFilter], ids=["sis", "mh"])
def test_two_threads_with_a_lock_equal_serial(image, reference, cls):
    f = cls(BOX, reference, rng=0)
    lock = threading.Lock()

    def work() -> None:
        for _ in range(50):
            with lock:
                f.step(image)

    threads = [threading.Thread(target=work) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    serial = cls(BOX, reference, rng=0)
    for _ in range(100):
        serial.step(image)
    np.testing.assert_array_equal(f.particles, serial.particles)


@pytest.mark.parametrize("cls", [ColourParticleFilter, MHColourParticleFilter], ids=["sis", "mh"])
def test_a_filter_still_copies_and_pickles(image, reference, cls):
    f = cls(BOX, reference, rng=0)
    f.step(image)
    for clone in (copy.deepcopy, lambda g: pickle.loads(pickle.dumps(g))):
        g = clone(f)
        assert g._busy is not f._busy
        np.testing.assert_array_equal(g.step(image).box_cxcywh, clone(f).step(image).box_cxcywh)
    assert "_busy" not in f.__getstate__()  # a lock is not copied: the copy is free


def test_rjmcmc_refuses_a_second_thread_until_its_step_is_counted(image):
    # the core refused a second thread only while inside; between its return and n_steps += 1 a
    # second step ran with the same step number
    rj = RJMCMCFilter(rng=0)
    mask = np.ones(image.shape, np.uint8)
    real = rj._core
    inside, leave = threading.Event(), threading.Event()

    class Held:
        def step(self, *args: Any, **kwargs: Any) -> Any:
            inside.set()
            assert leave.wait(10)
            return real.step(*args, **kwargs)

    rj._core = Held()
    first = threading.Thread(target=rj.step, args=(image, mask, BOX))
    first.start()
    assert inside.wait(10)
    message = _message("RJMCMCFilter", "RJMCMCFilter.step")
    with pytest.raises(RuntimeError, match=f"^{re.escape(message)}$"):
        rj.step(image, mask, BOX)
    leave.set()
    first.join()
    rj._core = real
    assert rj.n_steps == 1
    rj.step(image, mask, BOX)
    assert rj.n_steps == 2
