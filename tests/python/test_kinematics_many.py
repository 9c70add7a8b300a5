"""The batched kinematics of a2ml.Robot (fk_many, jacobian_many, cpsa_many, ik_cpsa_many)
and the per-call outputs (out=, fk_jacobian): each equals the per-call method row by row,
writes where it is asked to, and refuses bad shapes, dtypes and values with a clear
exception."""

from __future__ import annotations

import os
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest
from numpy.typing import NDArray

from a2ml import Robot, SingularityError, UnreachableError

ROBOTS_DIR = Path(__file__).resolve().parents[2] / "robots"
NAMES = ["coman_right_arm", "centauro_right_arm", "iiwa14", "panda", "human_arm"]

_cache: dict[str, Robot] = {}


def robot(name: str) -> Robot:
    if name not in _cache:
        _cache[name] = Robot.from_urdf(ROBOTS_DIR / f"{name}.urdf")
    return _cache[name]


def configurations(r: Robot, count: int, seed: int = 3) -> NDArray[np.float64]:
    """Uniform in the middle 80 % of every range: regular, in limits."""
    rng = np.random.default_rng(seed)
    span = r.upper - r.lower
    return rng.uniform(r.lower + 0.1 * span, r.upper - 0.1 * span, size=(count, 7))


# The batched kernel runs several rows side by side, multiplies in another order than the
# per-call forward kinematics and takes its sines from fdlibm's polynomials rather than the
# platform's: a few ulps per joint, far below this on arms of about a metre.
AGREEMENT = 1e-12


@pytest.mark.parametrize("name", NAMES)
def test_batches_equal_the_per_call_methods(name: str) -> None:
    r = robot(name)
    qs = configurations(r, 41)
    frames, jacobians = r.fk_many(qs), r.jacobian_many(qs)
    pw, ow, swivel = r.cpsa_many(qs)
    assert frames.shape == (41, 4, 4) and jacobians.shape == (41, 6, 7)
    assert pw.shape == (41, 3) and ow.shape == (41, 3, 3) and swivel.shape == (41,)
    for i, q in enumerate(qs):
        np.testing.assert_allclose(frames[i], r.fk(q), rtol=0, atol=AGREEMENT)
        np.testing.assert_allclose(jacobians[i], r.jacobian(q), rtol=0, atol=AGREEMENT)
        p, o, s = r.cpsa(q)
        np.testing.assert_allclose(pw[i], p, rtol=0, atol=AGREEMENT)
        np.testing.assert_allclose(ow[i], o, rtol=0, atol=AGREEMENT)
        # Regular configurations (the middle of the ranges): the swivel is well conditioned.
        assert abs(np.angle(np.exp(1j * (swivel[i] - s)))) < 1e-10
        # The row's last column and bottom row of a frame are exact.
        np.testing.assert_array_equal(frames[i][3], [0.0, 0.0, 0.0, 1.0])
        np.testing.assert_array_equal(jacobians[i][:3, 6], 0.0)
    # fk_jacobian is the per-call path: exactly fk() and jacobian().
    frame, jacobian = r.fk_jacobian(qs[0])
    np.testing.assert_array_equal(frame, r.fk(qs[0]))
    np.testing.assert_array_equal(jacobian, r.jacobian(qs[0]))


@pytest.mark.parametrize("name", ["iiwa14", "panda"])
def test_a_row_gets_the_same_bits_however_the_batch_is_split(name: str) -> None:
    r = robot(name)
    qs = configurations(r, 23, seed=11)
    frames, jacobians = r.fk_many(qs), r.jacobian_many(qs)
    pw, ow, swivel = r.cpsa_many(qs)
    for start, stop in [(0, 1), (1, 4), (4, 9), (9, 10), (10, 23), (22, 23)]:
        np.testing.assert_array_equal(r.fk_many(qs[start:stop]), frames[start:stop])
        np.testing.assert_array_equal(r.jacobian_many(qs[start:stop]), jacobians[start:stop])
        p, o, s = r.cpsa_many(qs[start:stop])
        np.testing.assert_array_equal(p, pw[start:stop])
        np.testing.assert_array_equal(o, ow[start:stop])
        np.testing.assert_array_equal(s, swivel[start:stop])


@pytest.mark.parametrize("name", ["iiwa14", "panda", "centauro_right_arm", "human_arm"])
def test_ik_cpsa_many_equals_ik_cpsa_and_reaches_the_states(name: str) -> None:
    r = robot(name)
    qs = configurations(r, 12, seed=5)
    pw, ow, swivel = r.cpsa_many(qs)
    near = qs + 0.01
    solved = r.ik_cpsa_many(pw, ow, swivel, near)
    assert solved.shape == (12, 7)
    for i in range(12):
        np.testing.assert_array_equal(solved[i], r.ik_cpsa(pw[i], ow[i], float(swivel[i]), near[i]))
    # Each solution reaches its state.
    back_pw, back_ow, back_swivel = r.cpsa_many(solved)
    np.testing.assert_allclose(back_pw, pw, atol=1e-8)
    np.testing.assert_allclose(back_ow, ow, atol=1e-8)
    np.testing.assert_allclose(np.angle(np.exp(1j * (back_swivel - swivel))), 0.0, atol=1e-8)
    # One q_near for every row, and the default, agree with the per-call method too.
    one = r.ik_cpsa_many(pw, ow, swivel, qs[0])
    default = r.ik_cpsa_many(pw, ow, swivel)
    for i in range(12):
        np.testing.assert_array_equal(one[i], r.ik_cpsa(pw[i], ow[i], float(swivel[i]), qs[0]))
        np.testing.assert_array_equal(default[i], r.ik_cpsa(pw[i], ow[i], float(swivel[i])))


def test_out_arrays_are_filled_and_returned() -> None:
    r = robot("iiwa14")
    qs = configurations(r, 5)
    frame, jacobian = np.full((4, 4), np.nan), np.full((6, 7), np.nan)
    assert r.fk(qs[0], frame) is frame
    np.testing.assert_array_equal(frame, r.fk(qs[0]))
    assert r.jacobian(qs[1], out=jacobian) is jacobian
    np.testing.assert_array_equal(jacobian, r.jacobian(qs[1]))
    f, j = r.fk_jacobian(qs[2], frame, jacobian)
    assert f is frame and j is jacobian
    np.testing.assert_array_equal(frame, r.fk(qs[2]))
    np.testing.assert_array_equal(jacobian, r.jacobian(qs[2]))
    f, j = r.fk_jacobian(qs[3])
    np.testing.assert_array_equal(f, r.fk(qs[3]))
    np.testing.assert_array_equal(j, r.jacobian(qs[3]))
    frames, jacobians = np.empty((5, 4, 4)), np.empty((5, 6, 7))
    assert r.fk_many(qs, frames) is frames and r.jacobian_many(qs, out=jacobians) is jacobians
    np.testing.assert_array_equal(frames, r.fk_many(qs))
    np.testing.assert_array_equal(jacobians, r.jacobian_many(qs))
    pw, ow, swivel = r.cpsa_many(qs)
    outs = (np.full((5, 3), np.nan), np.full((5, 3, 3), np.nan), np.full(5, np.nan))
    got = r.cpsa_many(qs, out=outs)
    assert all(g is o for g, o in zip(got, outs))
    for g, expected in zip(got, (pw, ow, swivel)):
        np.testing.assert_array_equal(g, expected)
    solutions = np.empty((5, 7))
    assert r.ik_cpsa_many(pw, ow, swivel, qs, out=solutions) is solutions
    np.testing.assert_array_equal(solutions, r.ik_cpsa_many(pw, ow, swivel, qs))


def test_any_array_like_is_accepted() -> None:
    r = robot("iiwa14")
    qs = configurations(r, 6)
    expected = r.fk_many(qs)
    # A list, a Fortran-ordered copy, a strided view and float32 are converted.
    np.testing.assert_array_equal(r.fk_many(qs.tolist()), expected)
    np.testing.assert_array_equal(r.fk_many(np.asfortranarray(qs)), expected)
    doubled = np.repeat(qs, 2, axis=0)
    np.testing.assert_array_equal(r.fk_many(doubled[::2]), expected)
    np.testing.assert_allclose(r.fk_many(qs.astype(np.float32)), expected, atol=1e-6)
    # The per-call reader too (the per-call FK is its own reference: the batched kernel
    # agrees with it to 1e-12, not bit for bit).
    single = r.fk(qs[0])
    np.testing.assert_array_equal(r.fk(qs[0].tolist()), single)
    np.testing.assert_array_equal(r.fk(np.repeat(qs[0], 2)[::2]), single)
    np.testing.assert_allclose(single, expected[0], rtol=0, atol=1e-12)
    # An empty batch is an empty result.
    assert r.fk_many(np.empty((0, 7))).shape == (0, 4, 4)
    assert r.ik_cpsa_many(np.empty((0, 3)), np.empty((0, 3, 3)), np.empty(0)).shape == (0, 7)


def test_bad_shapes_and_values_raise_clear_errors() -> None:
    r = robot("iiwa14")
    qs = configurations(r, 4)
    with pytest.raises(ValueError, match=r"q must have shape \(N, 7\), got \(7,\)"):
        r.fk_many(qs[0])
    with pytest.raises(ValueError, match=r"q must have shape \(N, 7\), got \(4, 6\)"):
        r.jacobian_many(qs[:, :6])
    with pytest.raises(ValueError, match="q must be an array of numbers"):
        r.cpsa_many([["a"] * 7])
    bad = qs.copy()
    bad[2, 3] = np.nan
    with pytest.raises(ValueError, match=r"q\[2\] contains NaN or infinity"):
        r.fk_many(bad)
    with pytest.raises(ValueError, match="q contains NaN or infinity"):
        r.fk(bad[2])
    with pytest.raises(ValueError, match=r"out must have shape \(4, 4, 4\), got \(4, 4\)"):
        r.fk_many(qs, np.empty((4, 4)))
    with pytest.raises(TypeError, match="out must be a float64 numpy array"):
        r.fk(qs[0], np.empty((4, 4), dtype=np.float32))
    with pytest.raises(ValueError, match="out must be C-contiguous"):
        r.jacobian(qs[0], np.empty((7, 6)).T)
    frozen = np.empty((6, 7))
    frozen.flags.writeable = False
    with pytest.raises(ValueError, match="out cannot be written"):
        r.jacobian(qs[0], frozen)
    with pytest.raises(ValueError, match=r"jacobian_out must have shape \(6, 7\)"):
        r.fk_jacobian(qs[0], np.empty((4, 4)), np.empty((7, 6)))
    pw, ow, swivel = r.cpsa_many(qs)
    with pytest.raises(ValueError, match="ow has 3 rows, pw has 4"):
        r.ik_cpsa_many(pw, ow[:3], swivel)
    with pytest.raises(ValueError, match=r"ow must have shape \(N, 3, 3\)"):
        r.ik_cpsa_many(pw, ow[:, 0], swivel)
    with pytest.raises(ValueError, match="q_near has 2 rows, pw has 4"):
        r.ik_cpsa_many(pw, ow, swivel, qs[:2])
    reflected = ow.copy()
    reflected[1] = -reflected[1]
    with pytest.raises(ValueError, match=r"ow\[1\] is a reflection"):
        r.ik_cpsa_many(pw, reflected, swivel)
    with pytest.raises(ValueError, match='on_error must be "raise" or "nan"'):
        r.ik_cpsa_many(pw, ow, swivel, on_error="skip")  # type: ignore[arg-type]
    with pytest.raises(TypeError, match=r"out must be a tuple \(pw, ow, swivel\)"):
        r.cpsa_many(qs, out=np.empty((4, 3)))  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"out\[1\] \(ow\) must have shape \(4, 3, 3\), got \(4, 9\)"):
        r.cpsa_many(qs, out=(np.empty((4, 3)), np.empty((4, 9)), np.empty(4)))
    flat = np.empty(12)  # the swivel's array the last row of pw's: written twice at once
    with pytest.raises(ValueError, match=r"out\[2\] \(swivel\) cannot be written"):
        r.cpsa_many(qs, out=(flat.reshape(4, 3), np.empty((4, 3, 3)), flat[8:]))
    # The output must not be an input: q_near written while it is read.
    with pytest.raises(ValueError, match="out cannot be written"):
        r.ik_cpsa_many(pw, ow, swivel, qs, out=qs)


def test_failing_rows_raise_with_their_row_or_are_nan() -> None:
    r = robot("iiwa14")
    qs = configurations(r, 3)
    pw, ow, swivel = r.cpsa_many(qs)
    pw[1] *= 10.0  # far outside the reach
    with pytest.raises(UnreachableError, match="^row 1: "):
        r.ik_cpsa_many(pw, ow, swivel)
    solved = r.ik_cpsa_many(pw, ow, swivel, qs, on_error="nan")
    assert np.isnan(solved[1]).all()
    np.testing.assert_array_equal(solved[[0, 2]], r.ik_cpsa_many(pw[[0, 2]], ow[[0, 2]], swivel[[0, 2]], qs[[0, 2]]))
    straight = qs.copy()
    straight[2, 3] = 0.0  # iiwa: the elbow straight, the arm plane undefined
    with pytest.raises(SingularityError, match="^row 2: "):
        r.cpsa_many(straight)


def test_threads_share_a_batch() -> None:
    """The GIL is released around the rows: batches in threads give the same results."""
    r = robot("panda")
    qs = configurations(r, 2000)
    expected = r.jacobian_many(qs)
    results: list[NDArray[np.float64]] = [np.empty(0)] * 4

    def work(k: int) -> None:
        results[k] = r.jacobian_many(qs[k * 500 : (k + 1) * 500])

    threads = [threading.Thread(target=work, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    np.testing.assert_array_equal(np.concatenate(results), expected)


# A batch of 256 rows or more is shared out in chunks of 64 rows between two threads
# (src/batch.rs): 601 rows are ten chunks, the last a short one.
LARGE = 601


@pytest.mark.parametrize("name", ["iiwa14", "panda"])
def test_a_large_batch_split_over_threads_gives_the_bits_of_small_batches(name: str) -> None:
    r = robot(name)
    qs = configurations(r, LARGE, seed=5)
    frames, jacobians = r.fk_many(qs), r.jacobian_many(qs)
    pw, ow, swivel = r.cpsa_many(qs)
    solved = r.ik_cpsa_many(pw, ow, swivel, qs)
    for start in range(0, LARGE, 100):
        rows = slice(start, min(start + 100, LARGE))
        np.testing.assert_array_equal(r.fk_many(qs[rows]), frames[rows])
        np.testing.assert_array_equal(r.jacobian_many(qs[rows]), jacobians[rows])
        p, o, s = r.cpsa_many(qs[rows])
        np.testing.assert_array_equal(p, pw[rows])
        np.testing.assert_array_equal(o, ow[rows])
        np.testing.assert_array_equal(s, swivel[rows])
        np.testing.assert_array_equal(
            r.ik_cpsa_many(pw[rows], ow[rows], swivel[rows], qs[rows]), solved[rows]
        )
    # Every row is written, none left as the zeros of a new array.
    assert np.all(frames[:, 3, 3] == 1.0) and np.all(np.abs(jacobians[:, 3:]).sum(axis=1) > 0)


def test_a_large_batch_reports_its_first_failing_row_whichever_chunk_it_is_in() -> None:
    r = robot("iiwa14")
    qs = configurations(r, LARGE, seed=6)
    pw, ow, swivel = r.cpsa_many(qs)
    far = pw.copy()
    far[[450, 580]] *= 10.0  # in two later chunks
    with pytest.raises(UnreachableError, match="^row 450: "):
        r.ik_cpsa_many(far, ow, swivel, qs)
    far[17] *= 10.0  # and one in the first chunk
    with pytest.raises(UnreachableError, match="^row 17: "):
        r.ik_cpsa_many(far, ow, swivel, qs)
    solved = r.ik_cpsa_many(far, ow, swivel, qs, on_error="nan")
    assert np.isnan(solved[[17, 450, 580]]).all() and not np.isnan(np.delete(solved, [17, 450, 580], 0)).any()
    straight = qs.copy()
    straight[[400, 500], 3] = 0.0  # the elbow straight in two later chunks
    with pytest.raises(SingularityError, match="^row 400: "):
        r.cpsa_many(straight)
    straight[3, 3] = 0.0
    with pytest.raises(SingularityError, match="^row 3: "):
        r.cpsa_many(straight)


def test_per_call_writes_beside_a_batch_in_another_thread() -> None:
    """A per-call write into `out=` skips numpy's borrow table only while no batch of this
    module runs detached; beside one it takes the tracked path: the same bits either way."""
    r = robot("panda")
    qs = configurations(r, 4000, seed=11)
    expected_batch = r.jacobian_many(qs)
    singles = qs[:300]
    expected = [r.fk_jacobian(q) for q in singles]
    done = threading.Event()
    batches: list[NDArray[np.float64]] = []

    def work() -> None:
        while not done.is_set():
            batches.append(r.jacobian_many(qs))

    worker = threading.Thread(target=work)
    worker.start()
    frame_out, jacobian_out = np.empty((4, 4)), np.empty((6, 7))
    try:
        for _ in range(20):
            for q, (frame, jacobian) in zip(singles, expected):
                f, j = r.fk_jacobian(q, frame_out, jacobian_out)
                assert f is frame_out and j is jacobian_out
                np.testing.assert_array_equal(frame_out, frame)
                np.testing.assert_array_equal(jacobian_out, jacobian)
    finally:
        done.set()
        worker.join()
    assert batches
    for batch in batches:
        np.testing.assert_array_equal(batch, expected_batch)


def test_large_batches_at_once_and_after_the_helpers_sleep() -> None:
    """Large batches share out their chunks with the helper threads of the process (one
    caller at a time; the others run alone): from several threads at once, and after a pause
    long enough for the helpers to fall asleep (a second), every row has its bits."""
    r = robot("iiwa14")
    qs = configurations(r, 3000, seed=13)
    expected_frames = np.concatenate([r.fk_many(qs[k : k + 200]) for k in range(0, 3000, 200)])
    expected_swivel = np.concatenate([r.cpsa_many(qs[k : k + 200])[2] for k in range(0, 3000, 200)])
    failures: list[str] = []

    def work(k: int) -> None:
        frames = np.empty((3000, 4, 4))
        for _ in range(15):
            if not np.array_equal(r.fk_many(qs, frames), expected_frames):
                failures.append(f"thread {k}: fk_many")
            if not np.array_equal(r.cpsa_many(qs)[2], expected_swivel):
                failures.append(f"thread {k}: cpsa_many")

    threads = [threading.Thread(target=work, args=(k,)) for k in range(3)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert failures == []
    time.sleep(1.2)
    np.testing.assert_array_equal(r.fk_many(qs), expected_frames)
    time.sleep(1.2)
    np.testing.assert_array_equal(r.cpsa_many(qs[:1000])[2], expected_swivel[:1000])


def _batch_threads_after_a_large_batch(setting: str | None) -> int:
    """The threads a fresh interpreter's first large batch starts (its helpers)."""
    env = {k: v for k, v in os.environ.items() if k != "A2ML_BATCH_THREADS"}
    if setting is not None:
        env["A2ML_BATCH_THREADS"] = setting
    script = (
        "import os, numpy as np, a2ml\n"
        f"r = a2ml.Robot.from_urdf({str(ROBOTS_DIR / 'iiwa14.urdf')!r})\n"
        "q = np.tile(np.linspace(-0.5, 0.5, 7), (2000, 1))\n"
        "before = len(os.listdir('/proc/self/task'))\n"
        "assert np.array_equal(r.fk_many(q)[1999], r.fk(q[0]))\n"
        "print(len(os.listdir('/proc/self/task')) - before)\n"
    )
    done = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True, check=True)
    return int(done.stdout.strip())


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads the threads off /proc")
def test_a2ml_batch_threads_sets_the_helpers() -> None:
    cores = len(os.sched_getaffinity(0))
    assert _batch_threads_after_a_large_batch("1") == 0
    assert _batch_threads_after_a_large_batch("2") == 1
    assert _batch_threads_after_a_large_batch(None) == min(cores, 8) - 1
    assert _batch_threads_after_a_large_batch("lots") == min(cores, 8) - 1


@pytest.mark.skipif(not hasattr(os, "fork"), reason="needs os.fork")
def test_a_forked_child_computes_its_batches() -> None:
    """A child forked beside a running batch has none of its parent's helper threads (and one
    may have been inside that batch): its own batches still complete, with the same bits."""
    r = robot("panda")
    qs = configurations(r, 4000, seed=17)
    expected = r.jacobian_many(qs)
    stop = threading.Event()

    def busy() -> None:
        while not stop.is_set():
            r.jacobian_many(qs)

    worker = threading.Thread(target=busy)
    worker.start()
    try:
        for _ in range(5):
            read, write = os.pipe()
            pid = os.fork()
            if pid == 0:  # the child: one large batch, its verdict through the pipe, then out
                os.close(read)
                same = np.array_equal(r.jacobian_many(qs), expected)
                os.write(write, b"1" if same else b"0")
                os._exit(0)
            os.close(write)
            with os.fdopen(read, "rb") as pipe:
                verdict = pipe.read()
            os.waitpid(pid, 0)
            assert verdict == b"1"
    finally:
        stop.set()
        worker.join()
