"""Writes tests/data/mbm/<scene>.json from VAMP's MotionBenchMaker Panda problems.

Usage: python convert.py PATH/TO/problems.tar.bz2 [SCENE ...]   (needs PyYAML)

problems.tar.bz2 is KavrakiLab/vamp resources/panda/problems.tar.bz2 (in the vamp-planner
0.6.4 sdist): per scene a MoveIt scene YAML and a motion-plan request YAML per problem. They
are read as VAMP's resources/problem_tar_to_pkl_json.py reads them (the first primitive of
each collision object at its pose, the request's start state and its single joint-space
goal), with plain quaternion arithmetic instead of vamp.transformations. `valid_vamp` (whether
VAMP's own model finds the ends clear) is written only when given by an earlier conversion
that ran VAMP; a2ml's tests do not read it.
"""
import json
import math
import re
import sys
import tarfile
from collections import defaultdict
from pathlib import Path

import yaml

JOINTS = [f"panda_joint{i}" for i in range(1, 8)]
HERE = Path(__file__).parent


def multiply(a, b):
    """Hamilton product of quaternions x, y, z, w."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return [
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    ]


def rotate(q, v):
    p = multiply(multiply(q, [v[0], v[1], v[2], 0.0]), [-q[0], -q[1], -q[2], q[3]])
    return p[:3]


def normalised(q):
    n = math.sqrt(sum(c * c for c in q))
    q = [c / n for c in q]
    # One sign for each rotation: w >= 0.
    return [-c for c in q] if q[3] < 0 else q


def pose(tf):
    return [float(c) for c in tf["position"]], normalised([float(c) for c in tf["orientation"]])


def obstacles(scene):
    out = []
    for co in scene["world"]["collision_objects"]:
        position, orientation = pose(co["primitive_poses"][0])
        if "pose" in co:
            base_position, base_orientation = pose(co["pose"])
            shifted = rotate(base_orientation, position)
            position = [b + s for b, s in zip(base_position, shifted)]
            orientation = normalised(multiply(base_orientation, orientation))
        primitive = co["primitives"][0]
        kind, dims = primitive["type"], [float(d) for d in primitive["dimensions"]]
        obstacle = {"name": co["id"], "type": kind, "position": position,
                    "orientation_quat_xyzw": orientation}
        if kind == "sphere":
            obstacle["radius"] = dims[0]
        elif kind == "cylinder":
            obstacle["length"], obstacle["radius"] = dims[0], dims[1]
        elif kind == "box":
            obstacle["half_extents"] = [d / 2 for d in dims]
        else:
            raise SystemExit(f"unknown primitive {kind}")
        out.append(obstacle)
    return out


def request(data):
    js = data["start_state"]["joint_state"]
    start = [float(js["position"][js["name"].index(j)]) for j in JOINTS]
    goal_joints = {c["joint_name"]: float(c["position"])
                   for c in data["goal_constraints"][0]["joint_constraints"]}
    return start, [[goal_joints[j] for j in JOINTS]]


def main(tar_path, *wanted):
    scenes, requests = defaultdict(dict), defaultdict(dict)
    with tarfile.open(tar_path, "r:bz2") as tar:
        for member in tar.getmembers():
            if not member.isfile():
                continue
            _, problem, filename = member.name.split("/")
            name = problem.replace("_panda", "")
            if wanted and name not in wanted:
                continue
            data = yaml.load(tar.extractfile(member).read(), Loader=yaml.SafeLoader)
            index = int(re.findall(r"\d+", filename)[0])
            (scenes if "scene" in filename else requests)[name][index] = data
    for name in sorted(scenes):
        target = HERE / f"{name}.json"
        earlier = {}
        if target.exists():
            earlier = {p["index"]: p.get("valid_vamp")
                       for p in json.loads(target.read_text())["problems"]}
        problems = []
        for index in sorted(scenes[name]):
            start, goals = request(requests[name][index])
            problem = {"index": index, "start": start, "goals": goals,
                       "obstacles": obstacles(scenes[name][index])}
            if earlier.get(index) is not None:
                problem["valid_vamp"] = earlier[index]
            problems.append(problem)
        document = {
            "scene": name,
            "source": "VAMP (KavrakiLab/vamp) resources/panda/problems.tar.bz2, vamp-planner "
                      "0.6.4 sdist; MotionBenchMaker Panda problems, parsed as "
                      "resources/problem_tar_to_pkl_json.py does",
            "frame": "MoveIt world = panda_link0 (robot base at the origin); m, rad; "
                     "quaternions x, y, z, w; cylinder axis along its local z",
            "joints": JOINTS,
            "problems": problems,
        }
        target.write_text(json.dumps(document, indent=0) + "\n")
        print(f"{name}: {len(problems)} problems")


if __name__ == "__main__":
    main(*sys.argv[1:])
