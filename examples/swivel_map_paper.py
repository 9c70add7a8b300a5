"""The scenario of the swivel obstacle-map paper (§4; METHODS.md §1.5): its arm
(upper arm 72.7 mm, forearm 68.0 mm: robots/swivel_map_arm.urdf), the wrist
from S (0, 60, 0) mm through the via points V1 and V2 to G (70, 100, 30) mm in
T = 5 s along a clamped cubic spline with chord-length knots, the hand's
orientation held, and the two spheres. The wrist path is given by points in
Python (the language has no `path Pw through [...]`: a segment's Pw path is a
line or an arc there). Prints where each sphere forbids swivel angles and the
profile the map plans; run from the repository root after `make python`."""

from pathlib import Path

import numpy as np

import a2ml

ROOT = Path(__file__).resolve().parent.parent
robot = a2ml.Robot.from_urdf(ROOT / "robots" / "swivel_map_arm.urdf")
points = [[0.0129, 0.0834, 0.0198], [0.0469, 0.0757, 0.0313], [0.070, 0.100, 0.030]]
spheres = [("sphere1", [0.033, 0.063, 0.0], 0.020), ("sphere2", [0.045, 0.095, 0.010], 0.015)]

# The palm normal (joint 7's axis) along the shoulder-wrist line keeps the wrist
# away from its singularity for every swivel angle.
p = np.array([0.3, 0.93, 0.12]) / np.linalg.norm([0.3, 0.93, 0.12])
f = np.array([0.0, 0.0, 1.0]) - p * p[2]
f /= np.linalg.norm(f)
ow = np.column_stack([f, p, np.cross(f, p)])
start = robot.ik_cpsa([0.0, 0.06, 0.0], ow, -1.57)

m = a2ml.swivel_map(robot, start=start, points=points, duration=5.0, spheres=spheres,
                    safety_distance=0.0)
for k, name in enumerate(m["obstacles"]):
    hit = (m["labels"] == 3 + k).any(axis=1)
    print(f"{name}: forbids swivel angles from t = {m['t'][hit].min():.2f} s to {m['t'][hit].max():.2f} s")
if m["profile"] is None:
    print("no profile:", m["error"])
else:
    prof = m["profile"]
    print(f"profile: θsw {np.degrees(prof['swivel'][0]):.1f}° → {np.degrees(prof['swivel'][-1]):.1f}°, "
          f"clearance {prof['clearance'] * 1e3:.1f} mm, {len(prof['t'])} samples at 1 kHz")
