"""The Python API of a2ml.Robot on every shipped arm: properties, FK,
Jacobians against finite differences, CPSA/HAT round trips through IK,
swivel feasibility, pickling and every exception class."""

from __future__ import annotations

import copy
import pickle
from pathlib import Path
from typing import Callable

import numpy as np
import pytest

import a2ml
from a2ml import (
    A2mlError,
    ConvergenceError,
    JointLimitError,
    Robot,
    SingularityError,
    UnreachableError,
    UrdfError,
)

ROBOTS_DIR = Path(__file__).resolve().parents[2] / "robots"
NAMES = ["coman_right_arm", "centauro_right_arm", "iiwa14", "panda", "human_arm"]
ANALYTIC = [n for n in NAMES if n != "human_arm"]

# Upper-arm and forearm lengths (m) from the robots' reference table.
LENGTHS = {
    "coman_right_arm": (0.180624, 0.195257),
    "centauro_right_arm": (0.295595, 0.251448),
    "iiwa14": (0.42, 0.40),
    "panda": (0.326592, 0.392762),
}

_cache: dict[str, Robot] = {}


def load(name: str) -> Robot:
    if name not in _cache:
        _cache[name] = Robot.from_urdf(ROBOTS_DIR / f"{name}.urdf")
    return _cache[name]


@pytest.fixture(params=NAMES)
def robot(request: pytest.FixtureRequest) -> Robot:
    return load(request.param)


@pytest.fixture(params=ANALYTIC)
def analytic_robot(request: pytest.FixtureRequest) -> Robot:
    return load(request.param)


def random_q(robot: Robot, rng: np.random.Generator) -> np.ndarray:
    return rng.uniform(robot.lower, robot.upper)


def regular_configs(robot: Robot, seed: int, count: int) -> list[np.ndarray]:
    """In-limit configurations away from both representation singularities:
    the elbow angle's sine and the wrist's angle from the vertical above 0.1."""
    rng = np.random.default_rng(seed)
    configs: list[np.ndarray] = []
    while len(configs) < count:
        q = random_q(robot, rng)
        pw = robot.centers(q)["wrist"]
        _, elbow, _ = robot.hat(q)
        if np.sin(elbow) < 0.1 or np.linalg.norm(np.cross(pw / np.linalg.norm(pw), [0, 0, 1])) < 0.1:
            continue
        configs.append(q)
    return configs


def angular_rate(r_plus: np.ndarray, r_minus: np.ndarray, r: np.ndarray, h: float) -> np.ndarray:
    """ω from central differences of a rotation: Ṙ Rᵀ = [ω]×."""
    s = (r_plus - r_minus) / (2 * h) @ r.T
    s = 0.5 * (s - s.T)
    return np.array([s[2, 1], s[0, 2], s[1, 0]])


def wrap(a: float) -> float:
    return (a + np.pi) % (2 * np.pi) - np.pi


# --- package ---------------------------------------------------------------


def test_package_exports() -> None:
    assert set(a2ml.__all__) >= {"Robot", "A2mlError", "UrdfError", "UnreachableError",
                                 "JointLimitError", "SingularityError", "ConvergenceError"}
    assert isinstance(a2ml.__version__, str) and a2ml.__version__.count(".") == 2
    for cls in (UrdfError, UnreachableError, JointLimitError, SingularityError, ConvergenceError):
        assert issubclass(cls, A2mlError) and issubclass(A2mlError, Exception)
    with pytest.raises(TypeError):
        Robot()


# --- properties ------------------------------------------------------------


def test_properties(robot: Robot) -> None:
    assert robot.dof == 7
    assert len(robot.joint_names) == 7 and len(set(robot.joint_names)) == 7
    for limits in (robot.lower, robot.upper, robot.velocity_limits):
        assert isinstance(limits, np.ndarray) and limits.dtype == np.float64 and limits.shape == (7,)
    assert np.all(robot.lower < robot.upper)
    assert np.all(robot.velocity_limits > 0)
    assert robot.is_srs == (robot is load("iiwa14"))
    assert robot.has_analytic_ik == (robot is not load("human_arm"))
    assert robot.upper_arm_length > 0.1 and robot.forearm_length > 0.1
    assert robot.tip_link == "hand"
    assert isinstance(robot.base_link, str) and robot.base_link
    assert isinstance(robot.name, str) and robot.name
    assert repr(robot) == (
        f"Robot(name={robot.name!r}, base_link={robot.base_link!r}, tip_link={robot.tip_link!r})"
    )


@pytest.mark.parametrize("name", list(LENGTHS))
def test_limb_lengths_match_reference(name: str) -> None:
    lu, lf = LENGTHS[name]
    assert load(name).upper_arm_length == pytest.approx(lu, abs=1e-6)
    assert load(name).forearm_length == pytest.approx(lf, abs=1e-6)


def test_iiwa_names_and_links() -> None:
    iiwa = load("iiwa14")
    assert iiwa.joint_names == [f"lbr_A{i}" for i in range(1, 8)]
    assert iiwa.base_link == "lbr_link_0"
    assert iiwa.is_srs and iiwa.has_analytic_ik
    assert not load("panda").is_srs and load("panda").has_analytic_ik


def test_from_urdf_string_matches_file(robot: Robot) -> None:
    path = ROBOTS_DIR / f"{robot.name}.urdf"
    text = Path(path).read_text()
    again = Robot.from_urdf_string(text)
    q = 0.5 * (robot.lower + robot.upper)
    assert again.joint_names == robot.joint_names
    np.testing.assert_array_equal(again.fk(q), robot.fk(q))


def test_from_urdf_accepts_str_paths_and_chain_ends() -> None:
    iiwa = Robot.from_urdf(str(ROBOTS_DIR / "iiwa14.urdf"), base="lbr_link_0", tip="hand")
    assert (iiwa.base_link, iiwa.tip_link) == ("lbr_link_0", "hand")


# --- forward kinematics -----------------------------------------------------


def test_fk_and_centers(robot: Robot) -> None:
    rng = np.random.default_rng(1)
    for _ in range(10):
        q = random_q(robot, rng)
        frame = robot.fk(q)
        centers = robot.centers(q)
        assert frame.shape == (4, 4) and frame.dtype == np.float64
        np.testing.assert_array_equal(frame[3], [0, 0, 0, 1])
        rotation = frame[:3, :3]
        np.testing.assert_allclose(rotation.T @ rotation, np.eye(3), atol=1e-12)
        assert np.linalg.det(rotation) == pytest.approx(1.0, abs=1e-12)
        assert set(centers) == {"shoulder", "elbow", "wrist"}
        assert all(v.shape == (3,) for v in centers.values())
        np.testing.assert_allclose(frame[:3, 3], centers["wrist"], atol=1e-12)
        np.testing.assert_allclose(centers["shoulder"], 0, atol=1e-12)
        s, e, w = centers["shoulder"], centers["elbow"], centers["wrist"]
        assert np.linalg.norm(e - s) == pytest.approx(robot.upper_arm_length, abs=1e-9)
        if robot.has_analytic_ik:
            # Joints 5-7 do not move W, so |W - E| keeps its zero-configuration value.
            assert np.linalg.norm(w - e) == pytest.approx(robot.forearm_length, abs=1e-9)


def test_inputs_are_array_like(robot: Robot) -> None:
    q = 0.5 * (robot.lower + robot.upper)
    expected = robot.fk(q)
    np.testing.assert_array_equal(robot.fk(list(q)), expected)
    np.testing.assert_array_equal(robot.fk(tuple(q)), expected)
    # A strided view and a float32 array are converted too.
    wide = np.zeros(14)
    wide[::2] = q
    np.testing.assert_array_equal(robot.fk(wide[::2]), expected)
    np.testing.assert_allclose(robot.fk(q.astype(np.float32)), expected, atol=1e-5)


def test_jacobian_matches_finite_differences(robot: Robot) -> None:
    h = 1e-6
    for q in regular_configs(robot, seed=2, count=4):
        j = robot.jacobian(q)
        assert j.shape == (6, 7)
        r = robot.fk(q)[:3, :3]
        numeric = np.zeros((6, 7))
        for i in range(7):
            dq = np.zeros(7)
            dq[i] = h
            plus, minus = robot.fk(q + dq), robot.fk(q - dq)
            numeric[:3, i] = (plus[:3, 3] - minus[:3, 3]) / (2 * h)
            numeric[3:, i] = angular_rate(plus[:3, :3], minus[:3, :3], r, h)
        np.testing.assert_allclose(j, numeric, atol=1e-7)


# --- representation spaces --------------------------------------------------


def test_cpsa_and_hat_states(robot: Robot) -> None:
    for q in regular_configs(robot, seed=3, count=5):
        pw, ow, swivel = robot.cpsa(q)
        os_, elbow, ow2 = robot.hat(q)
        frame = robot.fk(q)
        assert pw.shape == (3,) and ow.shape == (3, 3) and os_.shape == (3, 3)
        assert isinstance(swivel, float) and -np.pi < swivel <= np.pi
        assert isinstance(elbow, float) and 0 <= elbow <= np.pi
        np.testing.assert_allclose(pw, frame[:3, 3], atol=1e-12)
        np.testing.assert_allclose(ow, frame[:3, :3], atol=1e-12)
        np.testing.assert_allclose(ow2, ow, atol=1e-12)
        np.testing.assert_allclose(os_.T @ os_, np.eye(3), atol=1e-12)
        # The elbow angle closes the S-E-W triangle (law of cosines).
        e = robot.centers(q)["elbow"]
        lu, lf = np.linalg.norm(e), np.linalg.norm(pw - e)
        assert np.linalg.norm(pw) ** 2 == pytest.approx(lu**2 + lf**2 - 2 * lu * lf * np.cos(elbow), abs=1e-9)
        # r, the first column of Os, points from S to E.
        np.testing.assert_allclose(os_[:, 0], e / np.linalg.norm(e), atol=1e-12)


def test_cpsa_jacobian_matches_finite_differences(robot: Robot) -> None:
    h = 1e-6
    for q in regular_configs(robot, seed=4, count=3):
        j = robot.cpsa_jacobian(q)
        assert j.shape == (7, 7)
        _, ow, _ = robot.cpsa(q)
        numeric = np.zeros((7, 7))
        for i in range(7):
            dq = np.zeros(7)
            dq[i] = h
            pw_p, ow_p, sw_p = robot.cpsa(q + dq)
            pw_m, ow_m, sw_m = robot.cpsa(q - dq)
            numeric[:3, i] = (pw_p - pw_m) / (2 * h)
            numeric[3:6, i] = angular_rate(ow_p, ow_m, ow, h)
            numeric[6, i] = wrap(sw_p - sw_m) / (2 * h)
        np.testing.assert_allclose(j, numeric, atol=1e-6)
        np.testing.assert_allclose(j[:6], robot.jacobian(q), atol=1e-12)


def test_hat_jacobian_matches_finite_differences(robot: Robot) -> None:
    h = 1e-6
    for q in regular_configs(robot, seed=5, count=3):
        j = robot.hat_jacobian(q)
        assert j.shape == (7, 7)
        os_, _, ow = robot.hat(q)
        numeric = np.zeros((7, 7))
        for i in range(7):
            dq = np.zeros(7)
            dq[i] = h
            os_p, el_p, ow_p = robot.hat(q + dq)
            os_m, el_m, ow_m = robot.hat(q - dq)
            numeric[:3, i] = angular_rate(os_p, os_m, os_, h)
            numeric[3, i] = (el_p - el_m) / (2 * h)
            numeric[4:, i] = angular_rate(ow_p, ow_m, ow, h)
        np.testing.assert_allclose(j, numeric, atol=1e-6)


# --- inverse kinematics -----------------------------------------------------


def test_ik_cpsa_round_trip(robot: Robot) -> None:
    for q in regular_configs(robot, seed=6, count=8):
        pw, ow, swivel = robot.cpsa(q)
        solution = robot.ik_cpsa(pw, ow, swivel, q_near=q)
        assert solution.shape == (7,) and solution.dtype == np.float64
        assert np.all(solution >= robot.lower - 1e-9) and np.all(solution <= robot.upper + 1e-9)
        pw2, ow2, swivel2 = robot.cpsa(solution)
        np.testing.assert_allclose(pw2, pw, atol=1e-9)
        np.testing.assert_allclose(ow2, ow, atol=1e-9)
        assert abs(wrap(swivel2 - swivel)) < 1e-9
        # Near q, the solution nearest q is q itself.
        np.testing.assert_allclose(solution, q, atol=1e-6)


def test_ik_hat_round_trip(robot: Robot) -> None:
    for q in regular_configs(robot, seed=7, count=8):
        os_, elbow, ow = robot.hat(q)
        solution = robot.ik_hat(os_, elbow, ow, q_near=q)
        assert solution.shape == (7,)
        os2, elbow2, ow2 = robot.hat(solution)
        np.testing.assert_allclose(os2, os_, atol=1e-9)
        assert elbow2 == pytest.approx(elbow, abs=1e-9)
        np.testing.assert_allclose(ow2, ow, atol=1e-9)
        np.testing.assert_allclose(solution, q, atol=1e-6)


def test_ik_without_q_near(analytic_robot: Robot) -> None:
    robot = analytic_robot
    for q in regular_configs(robot, seed=8, count=3):
        pw, ow, swivel = robot.cpsa(q)
        solution = robot.ik_cpsa(pw, ow, swivel)
        np.testing.assert_allclose(robot.fk(solution), robot.fk(q), atol=1e-9)


def test_all_branches(robot: Robot) -> None:
    for q in regular_configs(robot, seed=9, count=3):
        pw, ow, swivel = robot.cpsa(q)
        nearest = robot.ik_cpsa(pw, ow, swivel, q_near=q)
        branches = robot.ik_cpsa(pw, ow, swivel, q_near=q, all_branches=True)
        assert branches.ndim == 2 and branches.shape[1] == 7 and branches.dtype == np.float64
        assert 1 <= branches.shape[0] <= (8 if robot.has_analytic_ik else 1)
        np.testing.assert_array_equal(branches[0], nearest)
        distances = np.linalg.norm(branches - q, axis=1)
        assert np.all(np.diff(distances) >= 0)
        for b in branches:
            np.testing.assert_allclose(robot.fk(b), robot.fk(q), atol=1e-9)
            assert abs(wrap(robot.cpsa(b)[2] - swivel)) < 1e-9
        os_, elbow, ow = robot.hat(q)
        hat_branches = robot.ik_hat(os_, elbow, ow, q_near=q, all_branches=True)
        assert hat_branches.ndim == 2 and hat_branches.shape[1] == 7


def test_iiwa_has_several_branches() -> None:
    iiwa = load("iiwa14")
    q = np.array([0.3, 0.6, -0.4, -1.1, 0.5, 0.7, -0.2])
    branches = iiwa.ik_cpsa(*iiwa.cpsa(q), q_near=q, all_branches=True)
    assert branches.shape[0] >= 2


def test_swivel_intervals_contain_own_swivel(analytic_robot: Robot) -> None:
    robot = analytic_robot
    for q in regular_configs(robot, seed=10, count=5):
        pw, ow, swivel = robot.cpsa(q)
        intervals = robot.swivel_intervals(pw, ow)
        assert isinstance(intervals, list) and intervals
        for lower, upper in intervals:
            assert isinstance(lower, float) and isinstance(upper, float)
            assert -np.pi - 1e-12 <= lower <= upper <= np.pi + 1e-12
        assert any(lower - 1e-9 <= swivel <= upper + 1e-9 for lower, upper in intervals), (swivel, intervals)
        assert all(a[1] <= b[0] for a, b in zip(intervals, intervals[1:]))


def test_ik_runs_in_threads() -> None:
    # The IK releases the GIL; concurrent calls must agree with serial ones.
    from concurrent.futures import ThreadPoolExecutor

    robot = load("human_arm")
    targets = [robot.cpsa(q) for q in regular_configs(robot, seed=11, count=4)]
    serial = [robot.ik_cpsa(*t) for t in targets]
    with ThreadPoolExecutor(4) as pool:
        parallel = list(pool.map(lambda t: robot.ik_cpsa(*t), targets))
    for a, b in zip(serial, parallel):
        np.testing.assert_array_equal(a, b)


# --- pickling ---------------------------------------------------------------


@pytest.mark.parametrize("protocol", range(pickle.HIGHEST_PROTOCOL + 1))
def test_pickle_round_trip(robot: Robot, protocol: int) -> None:
    again = pickle.loads(pickle.dumps(robot, protocol=protocol))
    assert type(again) is Robot
    assert repr(again) == repr(robot)
    assert again.joint_names == robot.joint_names
    q = 0.5 * (robot.lower + robot.upper) + 0.1
    np.testing.assert_array_equal(again.fk(q), robot.fk(q))
    np.testing.assert_array_equal(again.lower, robot.lower)


def test_pickle_keeps_options_and_needs_no_file(tmp_path: Path) -> None:
    path = tmp_path / "arm.urdf"
    path.write_text((ROBOTS_DIR / "iiwa14.urdf").read_text())
    robot = Robot.from_urdf(path, base="lbr_link_0", tip="hand")
    data = pickle.dumps(robot)
    path.unlink()
    again = pickle.loads(data)
    assert (again.base_link, again.tip_link) == ("lbr_link_0", "hand")
    assert copy.deepcopy(robot).name == robot.name
    assert robot.__reduce__()[1][1:] == ("lbr_link_0", "hand")


# --- errors -----------------------------------------------------------------


def chain_urdf(joints: int) -> str:
    """A serial chain of `joints` revolute joints with alternating axes."""
    parts = ["<robot name='chain'><link name='l0'/>"]
    for i in range(1, joints + 1):
        axis = ["0 0 1", "0 1 0"][i % 2]
        parts.append(
            f"<link name='l{i}'/><joint name='j{i}' type='revolute'><parent link='l{i - 1}'/>"
            f"<child link='l{i}'/><origin xyz='0 0 0.1'/><axis xyz='{axis}'/>"
            "<limit lower='-1' upper='1' velocity='1' effort='1'/></joint>"
        )
    return "".join(parts) + "</robot>"


def test_missing_file_is_urdf_error() -> None:
    with pytest.raises(UrdfError, match="no_such_arm.urdf") as info:
        Robot.from_urdf(ROBOTS_DIR / "no_such_arm.urdf")
    assert isinstance(info.value, A2mlError)


def test_six_joint_chain_is_urdf_error() -> None:
    with pytest.raises(UrdfError, match="7") as info:
        Robot.from_urdf_string(chain_urdf(6))
    assert isinstance(info.value, A2mlError)


def test_broken_urdf_and_unknown_link_are_urdf_errors() -> None:
    with pytest.raises(UrdfError, match="invalid URDF"):
        Robot.from_urdf_string("<robot name='x'><link name='a'></robot>")
    with pytest.raises(UrdfError, match="did you mean"):
        Robot.from_urdf(ROBOTS_DIR / "iiwa14.urdf", tip="hnad")


def test_unreachable_wrist() -> None:
    iiwa = load("iiwa14")
    with pytest.raises(UnreachableError, match="unreachable") as info:
        iiwa.ik_cpsa([1.0, 0.2, 0.1], np.eye(3), 0.3)
    assert isinstance(info.value, A2mlError)
    with pytest.raises(UnreachableError):
        iiwa.swivel_intervals([1.0, 0.2, 0.1], np.eye(3))


def test_wrist_above_shoulder_is_singular() -> None:
    iiwa = load("iiwa14")
    with pytest.raises(SingularityError, match="vertical") as info:
        iiwa.ik_cpsa([0.0, 0.0, 0.6], np.eye(3), 0.0)
    assert isinstance(info.value, A2mlError)
    with pytest.raises(SingularityError):
        iiwa.swivel_intervals([0.0, 0.0, 0.6], np.eye(3))


def test_straight_arm_is_singular() -> None:
    iiwa = load("iiwa14")
    q = np.zeros(7)
    q[1] = 0.7
    for query in (iiwa.cpsa, iiwa.hat, iiwa.cpsa_jacobian, iiwa.hat_jacobian):
        with pytest.raises(SingularityError, match="straight"):
            query(q)
    # FK and J_ge are defined there.
    assert iiwa.fk(q).shape == (4, 4) and iiwa.jacobian(q).shape == (6, 7)


def test_target_outside_limits_names_the_joint() -> None:
    coman = load("coman_right_arm")
    lu, lf = coman.upper_arm_length, coman.forearm_length
    direction = np.array([0.2, -0.3, -0.1])
    pw = direction / np.linalg.norm(direction) * (abs(lu - lf) + 0.01)
    with pytest.raises(JointLimitError) as info:
        coman.ik_cpsa(pw, np.eye(3), 0.0)
    assert isinstance(info.value, A2mlError)
    assert any(f"`{name}`" in str(info.value) for name in coman.joint_names)


def test_no_closed_form_is_convergence_error() -> None:
    human = load("human_arm")
    pw, ow, _ = human.cpsa(0.5 * (human.lower + human.upper))
    with pytest.raises(ConvergenceError, match="spherical") as info:
        human.swivel_intervals(pw, ow)
    assert isinstance(info.value, A2mlError)


@pytest.mark.parametrize(
    "call",
    [
        lambda r: r.fk(np.zeros(6)),
        lambda r: r.fk(np.zeros((7, 1))),
        lambda r: r.fk(3.0),
        lambda r: r.centers([0.0] * 8),
        lambda r: r.jacobian(np.zeros((1, 7))),
        lambda r: r.cpsa(np.zeros(6)),
        lambda r: r.hat(np.zeros(6)),
        lambda r: r.cpsa_jacobian([]),
        lambda r: r.hat_jacobian(np.zeros(7 * 7)),
        lambda r: r.ik_cpsa([0.3, 0.2], np.eye(3), 0.0),
        lambda r: r.ik_cpsa([0.3, 0.2, 0.1], np.eye(4), 0.0),
        lambda r: r.ik_cpsa([0.3, 0.2, 0.1], np.eye(3), 0.0, q_near=np.zeros(6)),
        lambda r: r.ik_hat(np.eye(3).ravel(), 1.0, np.eye(3)),
        lambda r: r.swivel_intervals([0.3, 0.2, 0.1], np.eye(3)[:2]),
        lambda r: r.fk("seven"),
    ],
)
def test_bad_shapes_are_value_errors(call: Callable[[Robot], object]) -> None:
    with pytest.raises(ValueError, match="shape"):
        call(load("iiwa14"))


def test_non_finite_inputs_are_value_errors() -> None:
    iiwa = load("iiwa14")
    q = np.full(7, 0.3)
    q[2] = np.nan
    with pytest.raises(ValueError, match="q contains NaN"):
        iiwa.fk(q)
    with pytest.raises(ValueError, match="pw contains NaN"):
        iiwa.ik_cpsa([np.inf, 0.2, 0.1], np.eye(3), 0.0)
    with pytest.raises(ValueError, match="swivel must be finite"):
        iiwa.ik_cpsa([0.3, 0.2, 0.1], np.eye(3), np.nan)
    with pytest.raises(ValueError, match="elbow must be finite"):
        iiwa.ik_hat(np.eye(3), np.inf, np.eye(3))
    with pytest.raises(ValueError, match="q_near contains NaN"):
        iiwa.ik_cpsa([0.3, 0.2, 0.1], np.eye(3), 0.0, q_near=q)


def test_non_rotations_are_value_errors() -> None:
    iiwa = load("iiwa14")
    pw = [0.3, 0.2, 0.1]
    with pytest.raises(ValueError, match="ow is not a rotation"):
        iiwa.ik_cpsa(pw, 2 * np.eye(3), 0.0)
    with pytest.raises(ValueError, match="ow is not a rotation"):
        iiwa.ik_cpsa(pw, np.eye(3) + 1e-4, 0.0)
    with pytest.raises(ValueError, match="reflection"):
        iiwa.ik_cpsa(pw, np.diag([1.0, 1.0, -1.0]), 0.0)
    with pytest.raises(ValueError, match="os is not a rotation"):
        iiwa.ik_hat(np.ones((3, 3)), 1.0, np.eye(3))
    with pytest.raises(ValueError, match="ow is not a rotation"):
        iiwa.swivel_intervals(pw, np.zeros((3, 3)))


def test_type_errors_stay_type_errors() -> None:
    with pytest.raises(TypeError):
        load("iiwa14").fk({"q": 1})  # type: ignore[arg-type]
