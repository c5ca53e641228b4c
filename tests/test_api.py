"""``import pftrack`` exposes the public API, lazily."""

from __future__ import annotations

import ast
import importlib
import inspect
import os
import re
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import pftrack


@pytest.mark.parametrize("name", [n for n in pftrack.__all__ if n != "__version__"])
def test_every_public_name_resolves_to_its_home(name: str) -> None:
    obj = getattr(pftrack, name)
    home = importlib.import_module(pftrack._MODULE_OF[name])
    assert obj is getattr(home, name)
    if not isinstance(obj, tuple):  # METHODS, a tuple of names, has no __module__
        assert obj.__module__.startswith("pftrack.")
    assert name in dir(pftrack)


def test_the_recovery_names_the_readme_uses_are_top_level() -> None:
    """Regression (user trial): the README says public names are importable from the top
    level, but ``pftrack.filled_mask``, ``pftrack.FillReport`` and ``pftrack.METHODS`` (in
    ``pftrack.recovery.__all__``, used beside ``pftrack.fill_gaps``) were AttributeErrors."""
    for name in ("filled_mask", "FillReport", "METHODS"):
        assert name in pftrack.__all__
        assert getattr(pftrack, name) is getattr(pftrack.recovery, name)


def test_all_lists_exactly_the_lazy_names() -> None:
    assert sorted(pftrack.__all__) == sorted(["__version__", *pftrack._MODULE_OF])


def test_the_evaluation_entry_points_are_top_level() -> None:
    """``evaluate_sequence`` (what ``pftrack eval`` scores) and ``evaluate_hota`` were only in
    ``pftrack.eval``, beside the top-level ``evaluate_mot``."""
    for name in ("evaluate_sequence", "evaluate_hota", "evaluate_mot"):
        assert name in pftrack.__all__
        assert getattr(pftrack, name) is getattr(pftrack.eval, name)


def test_the_kernels_docs_api_lists_are_top_level() -> None:
    """docs/api.md says ``import pftrack`` gives every name it lists: the resamplers other than
    ``systematic_resample`` and the Bhattacharyya coefficient and distance were only in
    ``pftrack.particle_filter``."""
    names = (
        "stratified_resample", "multinomial_resample", "residual_resample",
        "bhattacharyya_coefficient", "bhattacharyya_distance",
    )  # fmt: skip
    for name in names:
        assert name in pftrack.__all__
        assert getattr(pftrack, name) is getattr(pftrack.particle_filter, name)


def _import_without_core(tmp_path: Path, installed: bool) -> str:
    """The error of ``import pftrack`` from a source checkout whose core is not built, with or
    without an installed pftrack (a dist-info and its package) after it on ``sys.path``.

    ``python -S``: site-packages, where CI installs pftrack, is not on the path.
    """
    checkout = tmp_path / "checkout" / "python" / "pftrack"
    checkout.mkdir(parents=True)
    package = Path(pftrack.__file__).parent
    for name in ("__init__.py", "_lazy.py"):
        (checkout / name).write_bytes((package / name).read_bytes())
    path = [str(checkout.parent)]
    if installed:
        site = tmp_path / "site"
        (site / "pftrack").mkdir(parents=True)
        (site / "pftrack" / "__init__.py").write_text("")
        info = site / "pftrack-0.1.0.dist-info"
        info.mkdir()
        (info / "METADATA").write_text("Metadata-Version: 2.1\nName: pftrack\nVersion: 0.1.0\n")
        path.append(str(site))
    run = subprocess.run([sys.executable, "-S", "-c", "import pftrack"], capture_output=True,
                         text=True, env={"PYTHONPATH": os.pathsep.join(path)}, cwd=tmp_path,
                         check=False)  # fmt: skip
    assert run.returncode == 1
    return run.stderr.strip().splitlines()[-1]


def test_a_source_checkout_shadowing_the_installed_package_says_so(tmp_path: Path) -> None:
    """Was: "compiled core is not built: install with `pip install .`" though it was."""
    checkout = tmp_path / "checkout" / "python" / "pftrack"
    assert _import_without_core(tmp_path, installed=True) == (
        f"ImportError: a source checkout at {checkout} is shadowing the installed pftrack "
        f"0.1.0 ({tmp_path / 'site' / 'pftrack'}), and its compiled core (pftrack._core) is "
        "not built: run from another folder (or take the checkout off PYTHONPATH)"
    )


def test_a_source_checkout_alone_says_to_build_it(tmp_path: Path) -> None:
    assert _import_without_core(tmp_path, installed=False) == (
        "ImportError: pftrack's compiled core (pftrack._core) is not built: install with "
        "`pip install .` or, for development, `pip install --no-build-isolation -ve .`"
    )


def test_unknown_name_is_an_attribute_error() -> None:
    with pytest.raises(AttributeError, match="no_such_thing"):
        pftrack.no_such_thing  # noqa: B018


def test_import_pftrack_loads_no_wing() -> None:
    """The top-level import stays light: the wings (and SciPy) load on first use."""
    code = (
        "import sys, pftrack; "
        "print(sorted(m for m in sys.modules if m.startswith(('pftrack.tracking', "
        "'pftrack.recovery', 'scipy', 'numpy', 'cv2', 'pftrack._core'))))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


ROOT = Path(__file__).resolve().parents[1]
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]


def _dotted_names() -> list[str]:
    """Every public ``pftrack.x.y`` the README and docs/*.md write (not a file name)."""
    found = set()
    for doc in DOCS:
        for m in re.finditer(r"(?<![\w/.])pftrack(\.[A-Za-z_]\w*)+", doc.read_text()):
            parts = m.group(0).split(".")
            if not any(p.startswith("_") and p != "__all__" for p in parts[1:]):
                found.add(m.group(0))
    return sorted(found - {"pftrack.yaml"})  # ~/.config/dask/pftrack.yaml


def test_documented_dotted_names_resolve_after_a_bare_import() -> None:
    """``pftrack.batch.track_many`` and ``pftrack.recovery.filled_mask`` were AttributeErrors.

    In a fresh interpreter: nothing but ``import pftrack`` before; Dask, SciPy and Matplotlib
    are not loaded by the import itself.
    """
    names = _dotted_names()
    assert {"pftrack.batch.track_many", "pftrack.recovery.filled_mask"} <= set(names)
    code = (
        "import functools, sys, pftrack\n"
        "heavy = [m for m in sys.modules if m.split('.')[0] in "
        "('dask', 'distributed', 'scipy', 'matplotlib')]\n"
        "print('heavy', sorted(heavy))\n"
        "for name in sys.argv[1:]:\n"
        "    try:\n"
        "        functools.reduce(getattr, name.split('.')[1:], pftrack)\n"
        "    except AttributeError as exc:\n"
        "        print('missing', name, exc)\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code, *names], capture_output=True, text=True, check=True
    )
    assert out.stdout.splitlines() == ["heavy []"]
    # each alone too (a name found only because an earlier one imported its module was not
    # caught above: pftrack.io.video and pftrack.detection.bootstrap were AttributeErrors)
    alone = {"pftrack.io.video.sequence_video", "pftrack.detection.bootstrap.bootstrap_frames"}
    for name in sorted(alone & set(names)):
        out = subprocess.run(
            [sys.executable, "-c", code, name], capture_output=True, text=True, check=True
        )
        assert out.stdout.splitlines() == ["heavy []"], name


def test_subpackages_load_on_first_use_only() -> None:
    code = (
        "import sys, pftrack; before = 'pftrack.batch' in sys.modules; "
        "pftrack.batch.track_many; "
        "print(before, 'batch' in dir(pftrack), "
        "sorted(m for m in sys.modules if m.split('.')[0] in ('dask', 'distributed')))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False True []"  # Dask itself waits for a batch to run
    with pytest.raises(AttributeError, match="no_such_module"):
        pftrack.no_such_module  # noqa: B018
    with pytest.raises(AttributeError, match="_private"):
        pftrack._private  # noqa: B018


def test_cli_parser_loads_no_scipy() -> None:
    """``pftrack --help`` builds every sub-command's parser without loading a method.

    Not even NumPy or OpenCV: ``pftrack --help`` then takes about 0.1 s more than Python
    itself (0.19 s against 0.11 s, measured while the machine was busy).
    """
    code = (
        "import sys; from pftrack.cli import build_parser; build_parser(); "
        "print(sorted(m for m in sys.modules if m.startswith(('scipy', 'numpy', 'cv2', "
        "'pftrack.recovery.'))))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "['pftrack.recovery.names']"


def test_recover_loads_no_tracker(tmp_path: Path) -> None:
    """``pftrack recover`` runs without importing the tracker (about 0.14 s of imports).

    Nor OpenCV and the video module without ``--video`` (they took 64 ms of a 500-track file's
    1.1 s: ``from pftrack.io.video import source_files`` ran for every file).
    """
    tracks = tmp_path / "t.txt"
    tracks.write_text("1,1,10,10,5,5,1,-1,-1,-1\n4,1,13,10,5,5,1,-1,-1,-1\n")
    code = (
        "import sys; from pftrack.cli import main; "
        f"status = main(['-q', 'recover', {str(tracks)!r}, '--out', {str(tmp_path / 'o.txt')!r}]); "
        "print(status, sorted(m for m in sys.modules if m.startswith(('pftrack.tracking', "
        "'pftrack.detection', 'pftrack.io.video', 'cv2'))))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip().splitlines()[-1] == "0 []"
    assert (tmp_path / "o.txt").read_text().count("\n") == 4  # frames 2 and 3 filled


#: The scripts mypy checks, in one run for the tests below (a cold ``mypy --strict`` through
#: pftrack's imports took 100 s of each test's 110 s on a busy 2-core machine: one run, not two).
TYPED_SCRIPTS = {
    "use.py": (
        "import pftrack\n"
        "reveal_type(pftrack.read_mot)\n"
        "reveal_type(pftrack.FrameSource('x').fps)\n"
        "pftrack.fill_gaps(1, method=2)\n"
        "pftrack.batch.track_many(1)\n"
        "reveal_type(pftrack.recovery.filled_mask)\n"
        "pftrack.Tracker(detector='mog3', camera_motion='of')\n"
        "pftrack.recover_gap([], [], method='lineer')\n"
        "pftrack.Tracker(detector='mog2', sampler='mh', dynamics='ar2-mean', fill='pf')\n"
        "pftrack.Tracker(fill='cubic')\n"
        "pftrack.TrackerConfig(detector='mog3', sampler='gibbs', camera_motion='yes')\n"
        "pftrack.evaluate_sequence([], [], benchmark='MOT18')\n"
        "pftrack.track_frames([], bootstrap='sprad')\n"
        "from pftrack.integrations.supervision import SupervisionTracker\n"
        "SupervisionTracker(frame_rate=25.0, sed=1, detector='mog3')\n"
    ),
    "rates.py": (
        "from fractions import Fraction\n"
        "import numpy as np\n"
        "import pftrack\n"
        "from pftrack.integrations.supervision import SupervisionTracker\n"
        "from pftrack.detection.bootstrap import bootstrap_frames\n"
        "rate = Fraction(30000, 1001)\n"
        "pftrack.Tracker(frame_rate=rate, max_coast=Fraction(1, 2), prime=np.float32(1))\n"
        "pftrack.Tracker(frame_rate=np.float32(25))\n"
        "pftrack.Tracker.from_config(frame_rate=rate, prime_frames=np.int64(3))\n"
        "SupervisionTracker(frame_rate=rate, max_coast=rate, prime=np.float64(1))\n"
        "pftrack.VideoWriter('a.mp4', rate)\n"
        "pftrack.TrackRenderer('a.mp4', np.float32(25))\n"
        "pftrack.FrameSource('a.mp4', fps=rate)\n"
        "pftrack.make_scene(fps=rate)\n"
        "pftrack.write_annotated_video('a.mp4', [], np.zeros((0, 10)), fps=rate)\n"
        "pftrack.fill_gaps(np.zeros((0, 10)), max_gap=np.int64(3))\n"
        "pftrack.smooth_tracks(np.zeros((0, 10)), max_gap=np.int64(3))\n"
        "pftrack.track_frames('a.mp4', prime_frames=np.int64(3))\n"
        "bootstrap_frames([], np.int64(3))\n"
        "pftrack.Tracker(frame_rate='25')\n"
    ),
}


@pytest.fixture(scope="module")
def mypy_says(tmp_path_factory: pytest.TempPathFactory) -> dict[str, str]:
    """``mypy --strict`` on :data:`TYPED_SCRIPTS`, once: each script's lines of its report."""
    api = pytest.importorskip("mypy.api")
    folder = tmp_path_factory.mktemp("typed")
    for name, code in TYPED_SCRIPTS.items():
        (folder / name).write_text(code)
    root = Path(pftrack.__file__).parents[1]
    with pytest.MonkeyPatch.context() as monkeypatch:
        if root.name not in ("site-packages", "dist-packages"):
            # a source checkout (PYTHONPATH=python): mypy finds installed packages by itself and
            # refuses site-packages on MYPYPATH
            monkeypatch.setenv("MYPYPATH", str(root))
        files = [str(folder / name) for name in TYPED_SCRIPTS]
        out, _, _ = api.run(["--strict", "--no-incremental", "--follow-imports=silent", *files])
    lines = out.splitlines()
    return {
        n: "\n".join(x for x in lines if x.startswith(str(folder / n) + ":")) for n in TYPED_SCRIPTS
    }


def test_the_api_is_typed(mypy_says: dict[str, str]) -> None:
    """mypy sees the real signatures through the lazy re-exports (and the package's py.typed)."""
    out = mypy_says["use.py"]
    assert ": error:" in out, out  # the bad call is caught, so the names are not Any
    assert 'Revealed type is "def (path: ' in out
    assert 'Revealed type is "float"' in out or 'Revealed type is "builtins.float"' in out
    assert 'Argument "method" to "fill_gaps" has incompatible type "Literal[2]"' in out
    # the subpackages too (pftrack.batch.track_many was Any)
    assert 'Argument 1 to "track_many" has incompatible type "int"' in out
    assert 'Revealed type is "def (rows: ' in out, out
    # names from a fixed set are Literal types: a typo is caught before the run
    assert 'Argument "detector" to "Tracker" has incompatible type "Literal[\'mog3\']"' in out
    assert 'Argument "camera_motion" to "Tracker" has incompatible type' in out
    assert 'Argument "method" to "recover_gap" has incompatible type "Literal[\'lineer\']"' in out
    assert "use.py:9:" not in out, out  # every valid name is accepted (line 9)
    assert 'Argument "fill" to "Tracker" has incompatible type "Literal[\'cubic\']"' in out
    for arg in ("detector", "sampler", "camera_motion"):
        assert f'Argument "{arg}" to "TrackerConfig" has incompatible type' in out, arg
    assert 'Argument "benchmark" to "evaluate_sequence" has incompatible type' in out
    assert 'Argument "bootstrap" to "track_frames" has incompatible type' in out
    # the supervision adapter's **options are the Tracker's (they were Any)
    assert 'Unexpected keyword argument "sed" for "SupervisionTracker"' in out
    assert 'Argument "detector" to "SupervisionTracker" has incompatible type' in out


def test_what_docs_api_says_rates_seconds_and_counts_take_type_checks(
    mypy_says: dict[str, str],
) -> None:
    """docs/api.md: every frame rate and time in seconds takes any real number (a Fraction,
    PyAV's ``stream.average_rate``; a NumPy scalar), and frame counts NumPy's ints; the
    annotations said ``float`` and ``int``, so mypy --strict refused each call below, which
    runs."""
    out = mypy_says["rates.py"]
    errors = [line for line in out.splitlines() if ": error:" in line]
    # only the str, which the runtime refuses too: the rest type-checks
    assert [e.split(":")[1] for e in errors] == ["20"], out


def test_the_literal_types_list_the_names_the_runtime_takes() -> None:
    from typing import get_args

    from pftrack import _typing
    from pftrack.detection import DETECTORS
    from pftrack.recovery import METHODS
    from pftrack.tracking.config import CAMERA_MOTION, SAMPLERS

    assert get_args(_typing.RecoveryMethod) == METHODS
    assert get_args(_typing.DetectorName) == DETECTORS
    assert get_args(_typing.SamplerName) == SAMPLERS
    assert get_args(_typing.CameraMotion) == CAMERA_MOTION
    with pytest.raises(ValueError, match="dynamics is 'ar3', expected 'ar2' or 'ar2-mean'"):
        pftrack.Tracker(dynamics="ar3")  # type: ignore[arg-type]
    assert get_args(_typing.DynamicsName) == ("ar2", "ar2-mean")
    from pftrack.detection.bootstrap import BOOTSTRAPS
    from pftrack.eval.rows import BENCHMARKS

    assert get_args(_typing.BootstrapMode) == ("auto", *BOOTSTRAPS)
    assert get_args(_typing.BenchmarkName) == ("auto", *BENCHMARKS)
    with pytest.raises(ValueError, match="fill is 'cubic', expected 'linear' or 'pf'"):
        pftrack.Tracker(fill="cubic")  # type: ignore[arg-type]
    assert get_args(_typing.FillMode) == ("linear", "pf")


API_DOC = Path(__file__).resolve().parents[1] / "docs" / "api.md"


def _calls(cell: str) -> list[tuple[str, list[str]]]:
    """Every ``name(arg, arg, ...)`` of a table cell, its arguments split at top-level commas."""
    found: list[tuple[str, list[str]]] = []
    for m in re.finditer(r"(\w+)\(", cell):
        depth, start = 1, m.end()
        args: list[str] = []
        for i in range(m.end(), len(cell)):
            if cell[i] in "([":
                depth += 1
            elif cell[i] in ")]":
                depth -= 1
            if depth == 0 or (depth == 1 and cell[i] == ","):
                args.append(cell[start:i].strip())
                start = i + 1
            if depth == 0:
                break
        found.append((m.group(1), [a for a in args if a]))
    return found


def _documented() -> list[tuple[str, list[str]]]:
    """The calls of pftrack's top-level names in the first column of docs/api.md's tables."""
    rows = [line[2:].split(" | ")[0] for line in API_DOC.read_text().splitlines()]
    return [
        (name, args)
        for cell in rows
        for name, args in _calls(cell)
        if name in pftrack.__all__ and cell.startswith("`")
    ]


def test_docs_api_names_every_public_name() -> None:
    """pftrack.Tracker, the drop-in API, was missing from the Tracking table."""
    spans = " ".join(re.findall(r"`([^`]*)`", API_DOC.read_text()))
    missing = [
        n for n in pftrack.__all__ if n != "__version__" and not re.search(rf"\b{n}\b", spans)
    ]
    assert not missing


@pytest.mark.parametrize(("name", "args"), _documented(), ids=lambda x: str(x)[:40])
def test_docs_api_signatures_are_the_real_ones(name: str, args: list[str]) -> None:
    """Each ``x=default`` shown is the real parameter at that place, keyword-only after ``*``.

    docs/api.md showed ``recover_gap(segment_a, segment_b, method="auto")``: the third
    parameter is ``frames``.
    """
    params = list(inspect.signature(getattr(pftrack, name)).parameters.values())
    positional = [p for p in params if p.kind is not p.KEYWORD_ONLY]
    keyword_only, skipped = False, False
    for i, arg in enumerate(args):
        if arg == "*":
            keyword_only = True
            continue
        if arg == "...":
            skipped = True  # parameters left out: the next ones' places are unknown
            continue
        if "=" not in arg or "(" in arg.split("=", 1)[0]:
            assert not keyword_only and i < len(positional), f"{name}: {arg} has no place"
            if arg.isidentifier() and not skipped:  # fill_gaps(rows, ...) was fill_gaps(tracks)
                assert positional[i].name == arg, (
                    f"{name}: parameter {i + 1} is {positional[i].name}"
                )
            continue
        key, default = (t.strip() for t in arg.split("=", 1))
        real = {p.name: p for p in params}
        assert key in real, f"{name} has no parameter {key}"
        assert (real[key].kind is real[key].KEYWORD_ONLY) == keyword_only, f"{name}: {key}"
        if not keyword_only and not skipped:
            assert positional[i].name == key, f"{name}: parameter {i + 1} is {positional[i].name}"
        try:
            value = ast.literal_eval(default)
        except (ValueError, SyntaxError):  # not a literal: LinkConfig(), a name
            continue
        assert real[key].default == value, f"{name}: {key} defaults to {real[key].default!r}"


#: The README's Python blocks, in order.
README_BLOCKS = re.findall(r"```python\n(.*?)```", (ROOT / "README.md").read_text(), re.S)


def _readme_detector(scene: Any, supervised: bool) -> Any:
    """The README's ``my_detector``: the next frame's true boxes as (N, 5) x1, y1, x2, y2,
    conf, or as ``sv.Detections`` for the supervision block."""
    frame_no = iter(range(1, len(scene.frames) + 1))

    def my_detector(frame: np.ndarray) -> Any:
        r = scene.truth[scene.truth[:, 0] == next(frame_no)]
        xyxy = np.column_stack([r[:, 2:4], r[:, 2:4] + r[:, 4:6]])
        if supervised:
            sv = pytest.importorskip("supervision")
            return sv.Detections(xyxy=xyxy, confidence=np.full(len(r), 0.95))
        return np.column_stack([xyxy, np.full(len(r), 0.95)])

    return my_detector


@pytest.mark.parametrize("k", range(len(README_BLOCKS)))
def test_every_readme_python_block_runs_as_written(
    k: int, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Each of the README's Python blocks runs in a fresh namespace, given only what its text
    leaves to the reader (``video.avi``, ``frames``, ``first_frames``, ``my_detector``: a
    synthetic scene and its truth), and gives what its comments say. The recovery block ran
    only with names it never defined; the supervision block called ``finalize()`` after one
    frame (a warning, no row) with ``detections`` and ``frame`` undefined."""
    block = README_BLOCKS[k]
    scene = pftrack.make_scene(n_frames=80, width=320, height=240, n_walkers=4, rng=1)
    monkeypatch.chdir(tmp_path)
    scene.write_video("video.avi")
    namespace: dict[str, Any] = {
        "frames": scene.frames,
        "first_frames": scene.frames[:30],
        "my_detector": _readme_detector(scene, "SupervisionTracker" in block),
    }
    exec(block, namespace)  # noqa: S102 - the README's own code
    if "recover_gap(" in block:
        assert namespace["path"].shape == (4, 2)
        assert namespace["filled"].shape[1] == 10 and namespace["report"].n_filled_rows > 0
        assert namespace["hists"].shape == (2, 110) and np.isclose(namespace["w"].sum(), 1.0)
        return
    assert namespace["rows"].shape[1] == 10 and len(namespace["rows"]) > 0  # every tracker's
    if "tracks = tracker.update(dets, frame)" in block:
        assert namespace["tracks"].shape[1] == 8
    if "SupervisionTracker" in block:
        assert namespace["detections"].tracker_id is not None


def test_printing_a_report_shows_its_readable_form(tmp_path: Path) -> None:
    """A user trial: ``print(report)`` of what fill_gaps, track_frames, evaluate_* and
    track_many return printed the whole dataclass on one line (a FillReport its nested
    calibrations, a HotaMetrics seven (19,) arrays); ``describe()`` / ``table()`` were the
    readable forms. ``str`` is now that form; ``repr`` still names every field."""
    from pftrack.batch.engine import BatchSummary
    from pftrack.eval import format_metrics, format_scores

    scene = pftrack.make_scene(n_frames=30, rng=1)
    rows = scene.truth[scene.truth[:, 0] % 7 != 3]  # a hole in every track
    _, report = pftrack.fill_gaps(rows, max_gap=3)
    assert str(report).splitlines()[0] == (
        f"fill_gaps (auto): {report.n_gaps} gaps filled, {report.n_filled_rows} rows added"
    )
    assert str(report).endswith(report.describe()) and report.n_gaps > 1
    assert repr(report).startswith("FillReport(n_gaps=")
    assert report.calibration is not None
    assert str(report.calibration) == report.calibration.describe()
    _, long = pftrack.fill_gaps(rows[rows[:, 0] % 7 != 4], "linear", max_gap=1)
    unfilled = f"{long.n_long_holes} holes longer than max_gap left unfilled (the longest 2 frames)"
    assert str(long).splitlines()[0].endswith(f"; {unfilled}")
    mot = pftrack.evaluate_mot(scene.truth, rows)
    assert str(mot) == format_metrics(mot) and repr(mot).startswith("MotMetrics(mota=")
    scores = pftrack.evaluate_sequence(scene.truth, rows)
    assert str(scores) == format_scores({"result": scores})
    hota = scores.hota
    head, values, note = str(hota).splitlines()
    assert head.split() == ["HOTA", "DetA", "AssA", "DetRe", "DetPr", "AssRe", "AssPr", "LocA"]
    assert values.split()[0] == f"{100 * hota.hota:.1f}" and "array(" not in str(hota)
    run = pftrack.track_frames(scene.frames[:12], show_progress=False)
    assert str(run).startswith(f"TrackingRun: 12 frames, {len(np.unique(run.rows[:, 1]))} track")
    summary = BatchSummary("track", tmp_path, [{"name": "a", "status": "done"}])
    assert str(summary) == summary.table()


def test_the_classes_top_level_functions_return_are_top_level() -> None:
    """A typed user annotates what ``pftrack.evaluate_sequence`` returns as
    ``pftrack.SequenceScores``: docs/api.md names that class and ``HotaMetrics`` beside their
    functions, but they, ``GdtSolution``, ``Scene`` and ``BinnedImage`` (``hsv_bins``) were
    only in their subpackages, while ``TrackingRun``, ``FillReport`` and ``MotMetrics`` were
    top-level."""
    import inspect
    import typing

    missing = []
    for name in pftrack.__all__:
        obj = getattr(pftrack, name)
        if not inspect.isfunction(obj):
            continue
        returned = typing.get_type_hints(obj).get("return")
        for cls in (returned, *typing.get_args(returned)):
            if inspect.isclass(cls) and cls.__module__.startswith("pftrack"):
                if getattr(pftrack, cls.__name__, None) is not cls:
                    missing.append(f"{name} -> {cls.__name__}")
    assert not missing


def test_tracking_modules_load_no_numpy_ma() -> None:
    """``numpy.ma`` is not imported to refuse masked arrays: none can exist without it.

    ``pftrack._check.refuse_masked`` read ``np.ma.MaskedArray``, which imported ``numpy.ma``
    (10-25 ms) at every ``pftrack track``'s start (a recovery dataclass checks its defaults at
    import); a masked array is still refused (tests/core/test_errors.py).
    """
    code = (
        "import sys, pftrack.cli.track, pftrack.tracking.run, pftrack.recovery.fill; "
        "print('numpy.ma' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"
