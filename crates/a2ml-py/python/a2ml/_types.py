"""The shapes of the plain data :func:`a2ml.decompose` returns, as
``TypedDict`` classes, and the small records of :class:`a2ml.SegmentReport`,
as ``NamedTuple`` classes (all re-exported by :mod:`a2ml`).

At run time the decomposition's values are ordinary ``dict`` objects; the
``TypedDict`` classes only describe their keys. Joint vectors are float64 arrays of shape (7,) (rad),
spaces are ``"cpsa"`` or ``"hat"``, variables ``"pw"``, ``"ow"``, ``"swivel"``,
``"shoulder_frame"``, ``"elbow"``: every enum value is spelled once, as every
output spells it (docs/cli.md lists them). The records are built by field
name from the core's serialisation.
"""

# Annotations stay evaluable on Python 3.9 (no ``X | None``), so
# ``typing.get_type_hints`` works on every supported version.
from typing import Any, Dict, List, Literal, NamedTuple, Optional, TypedDict

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "Clearance",
    "Decomposition",
    "OptReport",
    "PlanWarning",
    "PlannedAction",
    "PlannedSegment",
    "QpStats",
    "RrtStats",
    "VariableError",
]

# A space is ``"cpsa"`` (Pw, Ow, swivel) or ``"hat"`` (Os, elbow, Ow); spelled
# out below rather than as an alias, which stubtest cannot compare.


class OptReport(TypedDict):
    """An optimisation that filled in goals or path sizes of an action.

    ``solver`` is ``"Opt1"`` or ``"Opt2"``; ``residual`` the error of the goals
    it could not meet exactly (m / rad); ``sizes`` the path sizes it chose
    (Opt2; m for a line, rad for an angle), in the order of the path's items;
    ``evaluations`` the candidates it evaluated.
    """

    solver: Literal["Opt1", "Opt2"]
    residual: float
    sizes: List[float]
    evaluations: int


class PlannedSegment(TypedDict):
    """A movement segment with every value known.

    ``space``; ``pattern`` ``"path"`` (1: every primitive a path or hold),
    ``"goal"`` (2: every primitive a goal) or ``"mixed"`` (3: both); ``duration`` (s) and ``duration_raised``
    (whether it was raised to respect the joint velocity limits); ``solver``
    (``"auto"``, ``"qp"``, ``"rrt"``, ...); ``relaxed``, the variables the
    table held that had to move for the end to be within the joint limits;
    ``start`` and ``end``, the joints it starts from and is expected to end
    in; ``primitives`` in parallel, shaped as an explicit segment's in
    :attr:`a2ml.Task.actions`, with goals and path sizes filled in.
    """

    space: Literal["cpsa", "hat"]
    pattern: Literal["path", "goal", "mixed"]
    duration: float
    duration_raised: bool
    solver: Literal["auto", "qp", "rrt", "map", "gpm", "clik", "pmp", "hamp"]
    relaxed: List[str]
    start: NDArray[np.float64]
    end: NDArray[np.float64]
    primitives: List[Dict[str, Any]]


class PlannedAction(TypedDict):
    """One action, decomposed.

    ``index`` in :attr:`a2ml.Task.actions` and ``name``; the classification:
    ``type`` (the paper's I to VII in lower case, ``"i"`` ... ``"vii"``),
    ``type_number`` (1-7), ``description``
    (what characterises the type), ``goal_space`` (of G, or of G1 when two
    goals are prioritised), ``secondary_goal_space`` (of G2) and
    ``path_space``, every one None for an explicit action and a space None
    where the action has no such constraint; ``segments`` (joined by +Tr) and
    ``optimisations`` that parameterised them, in order.
    """

    index: int
    name: str
    type: Optional[Literal["i", "ii", "iii", "iv", "v", "vi", "vii"]]
    type_number: Optional[int]
    description: Optional[str]
    goal_space: Optional[Literal["cpsa", "hat"]]
    secondary_goal_space: Optional[Literal["cpsa", "hat"]]
    path_space: Optional[Literal["cpsa", "hat"]]
    segments: List[PlannedSegment]
    optimisations: List[OptReport]


class Decomposition(TypedDict):
    """A decomposed task: its name ``task``, the ``start`` joints and the
    ``actions`` in execution order (the STRIPS plan, or the written order)."""

    task: str
    start: NDArray[np.float64]
    actions: List[PlannedAction]


class VariableError(NamedTuple):
    """The error of one state ``variable`` at a segment's end, or its largest
    deviation from its path: distance (m) for ``pw``, geodesic angle (rad)
    for ``ow`` and ``shoulder_frame``, absolute difference (rad) for
    ``swivel`` and ``elbow``; ``within`` the tolerance (1 mm, 1 degree)."""

    variable: Literal["pw", "ow", "swivel", "shoulder_frame", "elbow"]
    error: float
    within: bool


class Clearance(NamedTuple):
    """The smallest clearance over a segment: signed ``distance`` (m; negative
    is a penetration depth) at ``time`` (s, plan time) between the arm's
    ``link`` capsule and ``obstacle`` (or another link, for self-collision)."""

    distance: float
    time: float
    link: str
    obstacle: str


class RrtStats(NamedTuple):
    """Counters of the RRT over a segment it solved: random ``samples``
    drawn, ``nodes`` in both trees, configurations checked for
    ``collision_checks``, and the wall ``time`` (s)."""

    samples: int
    nodes: int
    collision_checks: int
    time: float


class QpStats(NamedTuple):
    """Counters and timings of the velocity QP over a segment: control
    ``steps``, the ``clarabel_steps`` where a bound or collision row was
    binding (``clarabel_almost_solved`` of them solved to Clarabel's reduced
    accuracy), the mean and longest step (s), and the median time of the
    steps solved by weighted least squares and by Clarabel (s; 0 when none)."""

    steps: int
    clarabel_steps: int
    clarabel_almost_solved: int
    mean_step_time: float
    worst_step_time: float
    median_fast_time: float
    median_clarabel_time: float


class PlanWarning(NamedTuple):
    """Something a plan did that its user should know: its ``kind``, the
    ``action`` and ``segment`` (0-based, as :attr:`a2ml.SegmentReport.segment`)
    it names, if any, and the ``message`` the CLI prints (also ``str()``)."""

    kind: Literal[
        "close_start",
        "collision_geometry",
        "rrt_failed",
        "rrt_no_better",
        "hamp_over_speed",
        "rrt_slowed",
        "slowed_down",
        "blend_shortened",
        "too_close",
        "missed_goal",
        "left_path",
        "over_limits",
    ]
    action: Optional[str]
    segment: Optional[int]
    message: str

    def __str__(self) -> str:
        return self.message
