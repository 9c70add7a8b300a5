"""a2ml: human-like motion for 7-DoF anthropomorphic arms (Fang & Ding 2019).

Everything is implemented in Rust (the ``a2ml-core`` crate) and exposed by the
native module ``a2ml._a2ml``; this package re-exports it. Positions are in
metres, angles in radians, all in the base frame {b} whose origin is the
shoulder centre. Arrays are float64 numpy arrays.

>>> import a2ml
>>> robot = a2ml.Robot.from_urdf("robots/iiwa14.urdf")  # doctest: +SKIP
>>> pw, ow, swivel = robot.cpsa([0.1, 0.5, 0.0, -1.2, 0.0, 0.4, 0.0])  # doctest: +SKIP
>>> task = a2ml.load("push.a2ml")  # doctest: +SKIP
>>> task.actions[0]["goal"]["primary"]["pw"]  # doctest: +SKIP
>>> d = a2ml.decompose(task)  # doctest: +SKIP
>>> d["actions"][0]["type"], d["actions"][0]["segments"][0]["end"]  # doctest: +SKIP
>>> plan = a2ml.plan("push.a2ml")  # doctest: +SKIP
>>> plan.t.shape, plan.q.shape, plan.reached  # doctest: +SKIP
>>> plan.write_mcap("push.mcap")  # doctest: +SKIP
>>> tasks = [task.with_goal("push_a", pw=[0.3, y, -0.2]) for y in (-0.1, 0.0)]  # doctest: +SKIP
>>> plans = a2ml.plan_many(tasks)  # doctest: +SKIP
>>> m = a2ml.swivel_map("push.a2ml", action="push_a")  # doctest: +SKIP
>>> m["labels"].shape, m["profile"]["q"].shape  # doctest: +SKIP

Invalid task text raises :class:`ParseError`, located by ``line`` and
``column`` and rendered in full by ``str()``; a task that cannot be
decomposed raises :class:`DecomposeError`, one that cannot be solved
:class:`PlanError`. :class:`Decomposition` and the other ``TypedDict``
classes describe what :func:`decompose` returns; :class:`VariableError`,
:class:`Clearance`, :class:`QpStats` and :class:`RrtStats` are the records of a
:class:`SegmentReport`, :class:`PlanWarning` those of :attr:`Plan.warnings`.
"""

from a2ml._a2ml import (
    A2mlError,
    ConvergenceError,
    DecomposeError,
    JointLimitError,
    Obstacles,
    ParseError,
    Plan,
    PlanError,
    Robot,
    SegmentReport,
    SingularityError,
    Task,
    UnreachableError,
    UrdfError,
    __version__,
    compare,
    decompose,
    load,
    parse,
    plan,
    plan_many,
    rrt_connect,
    scene_clearance,
    swivel_map,
)
from a2ml._types import (
    Clearance,
    Decomposition,
    OptReport,
    PlanWarning,
    PlannedAction,
    PlannedSegment,
    QpStats,
    RrtStats,
    VariableError,
)

__all__ = [
    "A2mlError",
    "Clearance",
    "ConvergenceError",
    "DecomposeError",
    "Decomposition",
    "JointLimitError",
    "Obstacles",
    "OptReport",
    "ParseError",
    "Plan",
    "PlanError",
    "PlanWarning",
    "PlannedAction",
    "PlannedSegment",
    "QpStats",
    "Robot",
    "RrtStats",
    "SegmentReport",
    "SingularityError",
    "Task",
    "UnreachableError",
    "UrdfError",
    "VariableError",
    "__version__",
    "compare",
    "decompose",
    "load",
    "parse",
    "plan",
    "plan_many",
    "rrt_connect",
    "scene_clearance",
    "swivel_map",
]
