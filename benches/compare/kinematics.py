"""a2ml against pinocchio from Python: forward kinematics and the 6x7 Jacobian,
per call and over a batch, on the shipped iiwa14 and Panda.

Both libraries run in this one process on the same configurations. A round
times every problem once for each library, in an order that alternates from
round to round; the figure of a problem is the median over rounds of each
library's time per configuration, and the median of the per-round ratios
(paired: both sides of a ratio ran in the same round, under the same load).

The peer's route is its cheapest for the same result, found by trying the
documented ones (see README.md): ``computeFrameJacobian`` (which runs the
forward kinematics of every joint itself) then ``updateFramePlacement`` for
the tip frame's pose. a2ml's hand frame {W} sits at the wrist centre and
pinocchio's tip frame at the flange, so the linear rows differ by the
offset between them; the angular rows are the same joint axes, and the
script checks that they agree before it times anything.

    python benches/compare/kinematics.py [--rounds 15] [--batch 1000]

Run by ``make compare`` in ``.venv-compare`` (benches/compare/requirements.txt).
"""

from __future__ import annotations

import argparse
import datetime
import os
import platform
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pinocchio as pin

import a2ml

ROOT = Path(__file__).resolve().parents[2]
ROBOTS = ("iiwa14", "panda")


def load(name: str) -> tuple[a2ml.Robot, pin.Model, int]:
    """a2ml's robot, pinocchio's model of the same URDF and its tip frame's id."""
    urdf = ROOT / "robots" / f"{name}.urdf"
    robot = a2ml.Robot.from_urdf(urdf)
    model = pin.buildModelFromUrdf(str(urdf))
    if model.nq != 7:
        sys.exit(f"{name}: pinocchio reads {model.nq} joints, a2ml 7; not the same chain")
    return robot, model, model.getFrameId(robot.tip_link)


def configurations(robot: a2ml.Robot, count: int, seed: int) -> np.ndarray:
    """Uniform joint values within the limits, C-contiguous (count, 7)."""
    rng = np.random.default_rng(seed)
    return np.ascontiguousarray(rng.uniform(robot.lower, robot.upper, size=(count, 7)))


def check_same_axes(robot: a2ml.Robot, model: pin.Model, frame: int, qs: np.ndarray) -> None:
    """The angular rows of both Jacobians are the joint axes in the base frame."""
    data = model.createData()
    world = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
    for q in qs[:50]:
        theirs = pin.computeFrameJacobian(model, data, q, frame, world)[3:]
        ours = robot.jacobian(q)[3:]
        error = float(np.abs(theirs - ours).max())
        if error > 1e-9:
            sys.exit(f"{robot.name}: joint axes differ by {error:.2e}; not the same chain")


def per_call_problems(
    robot: a2ml.Robot, model: pin.Model, frame: int, qs: np.ndarray
) -> dict[str, tuple[Callable[[], None], Callable[[], None]]]:
    """Name -> (a2ml, pinocchio), each running over every row of `qs`, one call at a time."""
    data = model.createData()
    world = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
    rows = list(qs)
    frame_out = np.empty((4, 4))
    jacobian_out = np.empty((6, 7))

    def ours_out() -> None:
        for q in rows:
            robot.fk_jacobian(q, frame_out, jacobian_out)

    def ours_alloc() -> None:
        for q in rows:
            robot.fk_jacobian(q)

    def ours_two_calls() -> None:
        for q in rows:
            robot.fk(q)
            robot.jacobian(q)

    def theirs() -> None:
        for q in rows:
            pin.computeFrameJacobian(model, data, q, frame, world)
            pin.updateFramePlacement(model, data, frame)

    def ours_fk() -> None:
        for q in rows:
            robot.fk(q, frame_out)

    def theirs_fk() -> None:
        for q in rows:
            pin.forwardKinematics(model, data, q)
            pin.updateFramePlacement(model, data, frame)

    return {
        "FK + J, per call (out=)": (ours_out, theirs),
        "FK + J, per call (new arrays)": (ours_alloc, theirs),
        "fk() then jacobian(), per call": (ours_two_calls, theirs),
        "FK only, per call (out=)": (ours_fk, theirs_fk),
    }


def batch_problems(
    robot: a2ml.Robot, model: pin.Model, frame: int, qs: np.ndarray
) -> dict[str, tuple[Callable[[], None], Callable[[], None]]]:
    """Name -> (a2ml batched over `qs`, pinocchio called in a loop over it)."""
    data = model.createData()
    world = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
    rows = list(qs)
    frames = np.empty((len(qs), 4, 4))
    jacobians = np.empty((len(qs), 6, 7))
    states = (np.empty((len(qs), 3)), np.empty((len(qs), 3, 3)), np.empty(len(qs)))

    def theirs_fk() -> None:
        for q in rows:
            pin.forwardKinematics(model, data, q)
            pin.updateFramePlacement(model, data, frame)

    def theirs_jacobian() -> None:
        for q in rows:
            pin.computeFrameJacobian(model, data, q, frame, world)

    def theirs_both() -> None:
        for q in rows:
            pin.computeFrameJacobian(model, data, q, frame, world)
            pin.updateFramePlacement(model, data, frame)

    def ours_both() -> None:
        robot.fk_many(qs, frames)
        robot.jacobian_many(qs, jacobians)

    return {
        "fk_many vs FK loop": (lambda: robot.fk_many(qs, frames), theirs_fk),
        "jacobian_many vs frame-Jacobian loop": (
            lambda: robot.jacobian_many(qs, jacobians),
            theirs_jacobian,
        ),
        "fk_many + jacobian_many vs FK + J loop": (ours_both, theirs_both),
        "cpsa_many (out=) vs FK loop": (lambda: robot.cpsa_many(qs, out=states), theirs_fk),
        "cpsa_many (new arrays) vs FK loop": (lambda: robot.cpsa_many(qs), theirs_fk),
    }


def ik_problem(robot: a2ml.Robot, qs: np.ndarray) -> tuple[Callable[[], None], Callable[[], None]]:
    """(ik_cpsa_many, ik_cpsa in a loop) over the CPSA states of `qs`; no peer has CPSA IK."""
    pw, ow, swivel = robot.cpsa_many(qs)
    rows = list(zip(pw, ow, swivel.tolist(), qs))

    def batched() -> None:
        robot.ik_cpsa_many(pw, ow, swivel, qs, on_error="nan")

    def looped() -> None:
        for p, o, s, q in rows:
            robot.ik_cpsa(p, o, s, q)

    return batched, looped


def timed(run: Callable[[], None]) -> float:
    started = time.perf_counter()
    run()
    return time.perf_counter() - started


def measure(
    problems: dict[str, tuple[Callable[[], None], Callable[[], None]]], rounds: int, per: int
) -> dict[str, tuple[float, float, float]]:
    """Name -> (median a2ml s/config, median peer s/config, median paired ratio)."""
    times: dict[str, list[tuple[float, float]]] = {name: [] for name in problems}
    for ours, theirs in problems.values():  # warm both up: caches, lazy imports
        ours()
        theirs()
    for r in range(rounds):
        for name, (ours, theirs) in problems.items():
            if r % 2 == 0:
                a, b = timed(ours), timed(theirs)
            else:
                b, a = timed(theirs), timed(ours)
            times[name].append((a / per, b / per))
    return {
        name: (
            statistics.median(a for a, _ in pairs),
            statistics.median(b for _, b in pairs),
            statistics.median(a / b for a, b in pairs),
        )
        for name, pairs in times.items()
    }


def microseconds(seconds: float) -> str:
    return f"{seconds * 1e6:.3f} µs" if seconds < 1e-6 else f"{seconds * 1e6:.2f} µs"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=15, help="interleaved rounds")
    parser.add_argument("--calls", type=int, default=2000, help="per-call problems: calls a round")
    parser.add_argument("--batch", type=int, default=1000, help="configurations per batch")
    parser.add_argument("--seed", type=int, default=7)
    args = parser.parse_args()

    load_average = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(
        f"# a2ml {a2ml.__version__} vs pinocchio {pin.__version__}, "
        f"{datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC, "
        f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
        f"load average {load_average:.2f}, Python {platform.python_version()}"
    )
    print(f"# {args.rounds} interleaved rounds; times per configuration, medians; ratio a2ml/peer")
    print("| robot | problem | a2ml | pinocchio | ratio |")
    print("|---|---|---|---|---|")
    for name in ROBOTS:
        robot, model, frame = load(name)
        calls = configurations(robot, args.calls, args.seed)
        batch = configurations(robot, args.batch, args.seed + 1)
        check_same_axes(robot, model, frame, calls)
        results = measure(per_call_problems(robot, model, frame, calls), args.rounds, args.calls)
        results |= measure(batch_problems(robot, model, frame, batch), args.rounds, args.batch)
        for problem, (ours, theirs, ratio) in results.items():
            print(f"| {name} | {problem} | {microseconds(ours)} | {microseconds(theirs)} | {ratio:.3f} |")
        if robot.has_analytic_ik:
            # Paired against a2ml's own per-call loop: pinocchio has no CPSA IK.
            ik = measure({"ik": ik_problem(robot, batch)}, max(3, args.rounds // 3), args.batch)
            batched, looped, ratio = ik["ik"]
            print(
                f"| {name} | ik_cpsa_many (nearest solution) vs ik_cpsa loop (a2ml) | "
                f"{microseconds(batched)} | {microseconds(looped)} (a2ml loop) | {ratio:.3f} |"
            )


if __name__ == "__main__":
    main()
