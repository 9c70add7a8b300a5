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

Invalid task text raises :class:`ParseError`, located by ``line`` and
``column`` and rendered in full by ``str()``.
"""

from a2ml._a2ml import (
    A2mlError,
    ConvergenceError,
    JointLimitError,
    ParseError,
    Robot,
    SingularityError,
    Task,
    UnreachableError,
    UrdfError,
    __version__,
    load,
    parse,
)

__all__ = [
    "A2mlError",
    "ConvergenceError",
    "JointLimitError",
    "ParseError",
    "Robot",
    "SingularityError",
    "Task",
    "UnreachableError",
    "UrdfError",
    "__version__",
    "load",
    "parse",
]
