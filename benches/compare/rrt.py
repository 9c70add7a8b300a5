"""a2ml's joint-space RRT-Connect against VAMP's RRTC on the MotionBenchMaker Panda scenes of
tests/data/mbm, in one process.

Models: a2ml plans with robots/panda.urdf (capsules, with the hand and fingers) and with
tests/data/panda_spheres/panda_spheres.urdf (VAMP's 59 spheres); VAMP with its own spherised
Panda. A round runs every planner once on a problem, in an order that alternates from round
to round; a problem's figure per planner is the median over rounds, and a2ml/VAMP is the median
over problems of the per-problem ratio of medians (paired: the same problems, the same rounds,
the same load). Solve rates count problems solved in every round.

VAMP counts a configuration free when no sphere overlaps an obstacle (touching is free); a2ml's
default keeps 1 cm. So a2ml with the spheres runs twice: at its default 0.01 m and at 0 m, the
latter being VAMP's criterion and the like-for-like ratio.

The models differ, so each path is also checked in the other's: a2ml's paths by VAMP's
`validate` at VAMP's own resolution along each edge, and VAMP's paths by a2ml's exact clearance
(`a2ml.scene_clearance`, ≥ 0) at 1 mm of arm motion along each edge.

    python benches/compare/rrt.py [--scenes cage,box] [--problems 100] [--rounds 3]

Run in .venv-compare (benches/compare/requirements.txt); a peer that does not import is
reported as missing, never replaced. The VAMP calls follow vamp-planner 0.6.4's Python API
(configure_robot_and_planner_with_kwargs, halton, simplify, validate); benches/compare/README.md
says how it was built offline here. OMPL (the `ompl` wheel's RRTConnect) checks states with
a2ml's clearance of the 59 spheres from Python, as a user of OMPL's Python bindings would.
"""

from __future__ import annotations

import argparse
import datetime
import json
import math
import platform
import statistics
import time
from pathlib import Path

import numpy as np

import a2ml

ROOT = Path(__file__).resolve().parents[2]
SCENES = ("bookshelf_small", "bookshelf_tall", "bookshelf_thin", "box", "cage", "table_pick",
          "table_under_pick")
MODELS = {"capsules": ROOT / "robots" / "panda.urdf",
          "spheres": ROOT / "tests" / "data" / "panda_spheres" / "panda_spheres.urdf"}

try:
    import vamp
except ImportError:
    vamp = None

try:
    from ompl import base as ompl_base
    from ompl import geometric as ompl_geometric
    from ompl import util as ompl_util
except ImportError:
    ompl_base = None


def euler_xyz(q: list[float]) -> list[float]:
    """Static-axes x-y-z Euler angles (VAMP's `orientation_euler_xyz`) of a quaternion x, y, z, w."""
    x, y, z, w = q
    roll = math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2 * (w * y - z * x))))
    yaw = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    return [roll, pitch, yaw]


def vamp_environment(problem: dict, scene: str):
    """VAMP's environment as its own `vamp.problem_dict_to_vamp` builds it for its MBM
    evaluation: a cylinder becomes a capsule (VAMP has no cylinder primitive), except in the
    box scene, where it becomes its bounding box (VAMP's comment: the top-down grasp of that
    scene's cylinder would not fit a capsule's rounded ends). Both over-approximate the
    cylinder that a2ml checks exactly, which is why paths are cross-checked."""
    env = vamp.Environment()
    for o in problem["obstacles"]:
        euler = euler_xyz(o["orientation_quat_xyzw"])
        if o["type"] == "sphere":
            env.add_sphere(vamp.Sphere(o["position"], o["radius"]))
        elif o["type"] == "box":
            env.add_cuboid(vamp.Cuboid(o["position"], euler, o["half_extents"]))
        elif scene == "box":
            env.add_cuboid(vamp.Cuboid(o["position"], euler,
                                       [o["radius"], o["radius"], o["length"] / 2]))
        else:
            env.add_capsule(vamp.Cylinder(o["position"], euler, o["radius"], o["length"]))
    return env


class Vamp:
    name = "vamp"

    def __init__(self):
        (self.module, self.planner, self.settings,
         self.simplify_settings) = vamp.configure_robot_and_planner_with_kwargs("panda", "rrtc")
        self.resolution = self.module.resolution()

    def prepare(self, problem, scene):
        return vamp_environment(problem, scene)

    def plan(self, problem, env):
        sampler = self.module.halton()
        start = time.perf_counter()
        result = self.planner(problem["start"], problem["goals"], env, self.settings, sampler)
        if not result.solved:
            return time.perf_counter() - start, None
        path = self.module.simplify(result.path, env, self.simplify_settings, sampler).path
        elapsed = time.perf_counter() - start
        # `Path.numpy()`: (waypoints, 7). Iterating a Path by index does not stop at its end.
        return elapsed, np.asarray(path.numpy(), dtype=float)

    def valid_path(self, problem, env, waypoints) -> bool:
        """Every configuration at VAMP's resolution along every edge passes `validate`."""
        for a, b in zip(waypoints[:-1], waypoints[1:]):
            steps = max(1, math.ceil(np.linalg.norm(b - a) * self.resolution))
            for k in range(steps + 1):
                if not self.module.validate(list(a + (b - a) * k / steps), env):
                    return False
        return True


class A2ml:
    def __init__(self, model: str, clearance: float = 0.01):
        self.name = f"a2ml/{model}" + ("" if clearance == 0.01 else f"@{clearance * 1e3:g}mm")
        self.robot = a2ml.Robot.from_urdf(MODELS[model])
        self.clearance = clearance

    def prepare(self, problem, scene):
        # Converted and checked once, as VAMP's environment is built once per problem; the
        # robot builds its arm's collision model at its first call (the untimed warm-up).
        return a2ml.Obstacles(self.robot, problem["obstacles"])

    def plan(self, problem, obstacles):
        start = time.perf_counter()
        try:
            result = a2ml.rrt_connect(self.robot, obstacles, problem["start"], problem["goals"],
                                      clearance=self.clearance)
        except a2ml.A2mlError:
            return time.perf_counter() - start, None
        return time.perf_counter() - start, result["waypoints"]

    def valid_path(self, problem, obstacles, waypoints) -> bool:
        return a2ml_valid_path(self.robot, obstacles, waypoints)


class Ompl:
    """OMPL's RRTConnect with the state validity checker a Python user would write: a2ml's
    clearance of the 59-sphere Panda (`a2ml.scene_clearance`, ≥ 0: VAMP's criterion) at each
    state OMPL asks about, OMPL's own discrete motion check along edges (its default
    resolution) and `simplifySolution`; a wall-clock limit per problem (OMPL has no sample
    budget), a problem not solved within it counting as unsolved."""

    name = "ompl"

    def __init__(self, time_limit: float):
        ompl_util.setLogLevel(ompl_util.LogLevel.LOG_ERROR)
        self.robot = a2ml.Robot.from_urdf(MODELS["spheres"])
        self.time_limit = time_limit
        self.space = ompl_base.RealVectorStateSpace(7)
        bounds = ompl_base.RealVectorBounds(7)
        for i, (low, high) in enumerate(zip(self.robot.lower, self.robot.upper)):
            bounds.setLow(i, float(low))
            bounds.setHigh(i, float(high))
        self.space.setBounds(bounds)

    def prepare(self, problem, scene):
        return a2ml.Obstacles(self.robot, problem["obstacles"])

    def plan(self, problem, obstacles):
        robot = self.robot
        setup = ompl_geometric.SimpleSetup(self.space)
        setup.setStateValidityChecker(
            lambda s: a2ml.scene_clearance(robot, obstacles, [s[i] for i in range(7)]) >= 0)
        goals = ompl_base.GoalStates(setup.getSpaceInformation())
        for g in problem["goals"]:
            state = self.space.allocState()
            for i in range(7):
                state[i] = g[i]
            goals.addState(state)
        start = self.space.allocState()
        for i in range(7):
            start[i] = problem["start"][i]
        setup.setStartState(start)
        setup.setGoal(goals)
        setup.setPlanner(ompl_geometric.RRTConnect(setup.getSpaceInformation()))
        began = time.perf_counter()
        setup.solve(self.time_limit)
        if not setup.haveExactSolutionPath():
            return time.perf_counter() - began, None
        setup.simplifySolution()
        elapsed = time.perf_counter() - began
        path = setup.getSolutionPath()
        waypoints = [[path.getState(k)[i] for i in range(7)] for k in range(path.getStateCount())]
        return elapsed, np.asarray(waypoints, dtype=float)

    def valid_path(self, problem, obstacles, waypoints) -> bool:
        return a2ml_valid_path(self.robot, obstacles, waypoints)


def a2ml_valid_path(robot, obstacles, waypoints) -> bool:
    """a2ml's exact clearance stays ≥ 0 at 1 mm of arm motion (1.5 m of lever per rad)."""
    for a, b in zip(waypoints[:-1], waypoints[1:]):
        steps = max(1, math.ceil(np.abs(b - a).sum() * 1.5 / 1e-3))
        for k in range(steps + 1):
            if a2ml.scene_clearance(robot, obstacles, a + (b - a) * k / steps) < 0:
                return False
    return True


def run_scene(name, planners, count, rounds):
    problems = json.loads((ROOT / "tests" / "data" / "mbm" / f"{name}.json").read_text())
    problems = problems["problems"][:count]
    times = {p.name: [[] for _ in problems] for p in planners}
    paths = {p.name: [None] * len(problems) for p in planners}
    prepared = [[p.prepare(problem, name) for p in planners] for problem in problems]
    # One untimed call each first: what a planner builds once per robot, and the caches.
    for k, p in enumerate(planners):
        p.plan(problems[0], prepared[0][k])
    for r in range(rounds):
        for i, problem in enumerate(problems):
            order = list(range(len(planners)))
            if (r + i) % 2:
                order.reverse()
            for k in order:
                elapsed, path = planners[k].plan(problem, prepared[i][k])
                times[planners[k].name][i].append(elapsed if path is not None else None)
                if path is not None and paths[planners[k].name][i] is None:
                    paths[planners[k].name][i] = path
    rows = {}
    for p in planners:
        solved = [i for i, t in enumerate(times[p.name]) if all(x is not None for x in t)]
        medians = {i: statistics.median(times[p.name][i]) for i in solved}
        rows[p.name] = {"solved": len(solved), "medians": medians,
                        "median": statistics.median(medians.values()) if medians else math.nan}
    # Cross-validity: each planner's paths in every other planner's model.
    for p in planners:
        rows[p.name]["valid_in"] = {}
        for k, other in enumerate(planners):
            if other is p:
                continue
            found = [(i, path) for i, path in enumerate(paths[p.name]) if path is not None]
            valid = sum(other.valid_path(problems[i], prepared[i][k], path) for i, path in found)
            rows[p.name]["valid_in"][other.name] = (valid, len(found))
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--scenes", default=",".join(SCENES))
    parser.add_argument("--problems", type=int, default=100)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--ompl-time", type=float, default=5.0,
                        help="OMPL's wall-clock limit per problem (s); 0 leaves OMPL out")
    args = parser.parse_args()
    planners = [A2ml("capsules"), A2ml("spheres"), A2ml("spheres", clearance=0.0)]
    compared = [p.name for p in planners if p.name.startswith("a2ml/spheres")]
    if vamp is None:
        print("vamp-planner does not import here: a2ml alone, no ratio")
    else:
        planners.append(Vamp())
    if ompl_base is None:
        print("ompl does not import here: no OMPL column")
    elif args.ompl_time > 0:
        planners.append(Ompl(args.ompl_time))
    print(f"{datetime.date.today()} {platform.machine()} {platform.processor() or ''} "
          f"{len(planners)} planners, {args.rounds} rounds, paired medians")
    names = [p.name for p in planners]
    pairs = [(a, peer) for peer in ("vamp", "ompl") if peer in names for a in compared]
    header = "| scene | " + " | ".join(f"{p.name} median, solved" for p in planners)
    header += "".join(f" | {a} ÷ {peer}" for a, peer in pairs)
    print(header + " |")
    for name in args.scenes.split(","):
        rows = run_scene(name, planners, args.problems, args.rounds)
        cells = [f"{rows[p.name]['median'] * 1e3:.3f} ms, {rows[p.name]['solved']}"
                 for p in planners]
        for a_name, peer in pairs:
            a, v = rows[a_name]["medians"], rows[peer]["medians"]
            ratios = [a[i] / v[i] for i in a if i in v]
            cells.append(f"{statistics.median(ratios):.2f}" if ratios else "-")
        print(f"| {name} | " + " | ".join(cells) + " |", flush=True)
        for p in planners:
            for other, (valid, found) in rows[p.name]["valid_in"].items():
                print(f"    {name}: {p.name} paths valid in {other}'s model: {valid} of {found}")


if __name__ == "__main__":
    main()
