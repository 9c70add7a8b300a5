"""Type stubs of the native module ``a2ml._a2ml`` (hand-written, checked by
``mypy.stubtest`` in ``make test``).

Conventions (docs/design.md §2-3): metres, radians; every position and rotation is
in the base frame {b}, whose origin is the shoulder centre S and whose axes
are those of the URDF base link (z up). Array arguments accept any array-like
of the stated shape and are converted to float64; a wrong shape or a NaN or
infinite entry raises ``ValueError``. Rotation matrices must be orthonormal to
1e-6 with determinant +1, else ``ValueError``.

A task (:func:`parse`, :func:`load`) comes back as plain Python data in SI
units: state variables are spelled once, as every output spells them (``"pw"``,
``"ow"``, ``"swivel"``, ``"shoulder_frame"``, ``"elbow"``), positions are arrays of shape
(3,), rotations (3, 3), angles floats. :func:`decompose` turns a task into
movement segments, returned in the same spelling (keys as in
:class:`a2ml.Decomposition`). :func:`plan` solves them into a :class:`Plan`:
the joint trajectory at the output rate, one :class:`SegmentReport` per
segment, and the MCAP, CSV and JSON writers (docs/design.md §6).
"""

import os
from collections.abc import Iterable
from typing import Any, ClassVar, Literal, final

import numpy as np
from numpy.typing import ArrayLike, NDArray

from a2ml._types import Clearance, Decomposition, PlanWarning, QpStats, RrtStats, VariableError

# The one spelling of each enum's values (docs/cli.md, "Enum values"); private, so that
# stubtest does not look for them at run time.
_Space = Literal["cpsa", "hat"]
_Variable = Literal["pw", "ow", "swivel", "shoulder_frame", "elbow"]
_ActionType = Literal["i", "ii", "iii", "iv", "v", "vi", "vii"]
_Pattern = Literal["path", "goal", "mixed"]
_Solver = Literal["auto", "qp", "rrt", "map", "gpm", "clik", "pmp", "hamp"]
_Fallback = Literal["qp_stalled", "qp_missed_goal", "qp_left_path"]

__all__ = [
    "__version__",
    "Robot",
    "Task",
    "parse",
    "load",
    "compare",
    "swivel_map",
    "decompose",
    "plan",
    "plan_many",
    "Obstacles",
    "rrt_connect",
    "scene_clearance",
    "Plan",
    "SegmentReport",
    "A2mlError",
    "UrdfError",
    "ParseError",
    "UnreachableError",
    "JointLimitError",
    "SingularityError",
    "ConvergenceError",
    "DecomposeError",
    "PlanError",
    "_metrics_analyze",
    "_metrics_connection_similarity",
    "_metrics_fitts_duration",
    "_metrics_levenshtein",
    "_metrics_mpcsi",
    "_metrics_plan_handover",
    "_metrics_rula_table_a",
    "_metrics_similarity",
]

__version__: str

class A2mlError(Exception):
    """Base class of every error raised by a2ml."""

class UrdfError(A2mlError):
    """The URDF is missing, unreadable, invalid, or holds no 7-revolute-joint arm."""

class ParseError(A2mlError):
    """The text is not a valid A2ML task.

    ``str(e)`` renders every problem with its location, the source line and a
    caret, as the command line does. The attributes locate the first problem;
    ``errors`` lists them all, in source order.
    """

    line: int
    """Line of the first problem, 1-based."""
    column: int
    """Column of the first problem, 1-based, in characters."""
    message: str
    """What is wrong at the first problem, without location."""
    errors: list[tuple[int, int, str]]
    """``(line, column, message)`` of every problem."""
    path: str | None
    """The file, or None for text parsed without a path."""

class UnreachableError(A2mlError):
    """The wrist target is outside the reachable annulus ``|lu - lf| <= |pw| <= lu + lf``."""

class JointLimitError(A2mlError):
    """Every IK solution leaves the joint limits; the message names the joint and by how much."""

class SingularityError(A2mlError):
    """The configuration or target is singular for the representation: a
    straight (or folded) arm, or the wrist on the vertical through the shoulder."""

class ConvergenceError(A2mlError):
    """Numerical IK did not converge, or the query needs a spherical shoulder
    and wrist (closed-form IK) that this arm lacks."""

class DecomposeError(A2mlError):
    """The task cannot be decomposed into actions and movement segments: it
    has no ``start``, no order of the actions reaches its STRIPS goal, an
    action's constraints fit none of the seven types, a path leaves out a
    size nothing chooses, or a segment's goal is out of reach within the
    joint limits. ``str(e)`` names the task or action (and segment)."""

class PlanError(A2mlError):
    """A decomposed task cannot be solved: the solver asked for is not
    available yet, a segment's references cannot be built, the QP fails on a
    segment (e.g. a singular configuration), or the segments cannot be
    joined. ``str(e)`` names the action and segment. A goal missed beyond
    tolerance is not an error: see :attr:`Plan.reached` and
    :attr:`Plan.warnings`."""

@final
class Robot:
    """A 7-DoF anthropomorphic arm read from a URDF; immutable.

    Create one with :meth:`from_urdf` or :meth:`from_urdf_string`. A robot
    pickles (it keeps its URDF text), so it can be sent to worker processes.
    """

    @classmethod
    def from_urdf(cls, path: str | os.PathLike[str], base: str | None = None, tip: str | None = None) -> Robot:
        """Read a URDF file.

        ``base`` and ``tip`` name the first and last link of the chain; by
        default the unique chain of 7 revolute joints is used.

        Raises:
            UrdfError: the file is missing or unreadable, is not valid URDF,
                names an unknown link, or holds no unique 7-joint arm.
        """

    @classmethod
    def from_urdf_string(cls, text: str, base: str | None = None, tip: str | None = None) -> Robot:
        """Read a URDF document given as a string; as :meth:`from_urdf`."""

    def __reduce__(self) -> tuple[Any, tuple[str, str | None, str | None]]:
        """Pickle as ``Robot.from_urdf_string(urdf_text, base, tip)``."""

    @property
    def name(self) -> str:
        """The URDF robot name."""

    @property
    def dof(self) -> int:
        """Number of joints: always 7."""

    @property
    def joint_names(self) -> list[str]:
        """Joint names, base to tip."""

    @property
    def lower(self) -> NDArray[np.float64]:
        """Lower position limits (rad), shape (7,)."""

    @property
    def upper(self) -> NDArray[np.float64]:
        """Upper position limits (rad), shape (7,)."""

    @property
    def velocity_limits(self) -> NDArray[np.float64]:
        """Velocity limits (rad/s), shape (7,)."""

    @property
    def is_srs(self) -> bool:
        """Spherical shoulder, spherical wrist and no elbow offset (e.g. the iiwa)."""

    @property
    def has_analytic_ik(self) -> bool:
        """Whether IK is closed-form (shoulder axes meet in a point and joints
        5-7 do not move the wrist centre); otherwise IK uses damped Newton."""

    @property
    def upper_arm_length(self) -> float:
        """lu = |E - S| (m)."""

    @property
    def forearm_length(self) -> float:
        """lf = |W - E| at the zero configuration (m); constant unless the
        wrist joints move W (the human arm)."""

    @property
    def base_link(self) -> str:
        """Base link of the chain."""

    @property
    def tip_link(self) -> str:
        """Tip link of the chain (the tool frame)."""

    def fk(self, q: ArrayLike, out: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
        """The hand frame {W} in {b} at joints ``q`` (shape (7,)), as a 4x4
        homogeneous matrix: origin the wrist centre W, rotation Ow with
        columns f (finger direction), p (palm normal), f x p.

        ``out``, a writeable C-contiguous float64 array of shape (4, 4), is
        filled and returned instead of a new array (no allocation per call).

        Raises:
            TypeError: ``out`` is not a float64 numpy array.
            ValueError: ``q`` or ``out`` has the wrong shape, or ``out`` is
                not C-contiguous or not writeable.
        """

    def centers(self, q: ArrayLike) -> dict[str, NDArray[np.float64]]:
        """The arm's points at ``q``: keys ``"shoulder"`` (always the origin),
        ``"elbow"`` and ``"wrist"``, each shape (3,)."""

    def jacobian(self, q: ArrayLike, out: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
        """The geometric Jacobian J_ge, shape (6, 7): rows 0-2 the linear
        velocity of W, rows 3-5 the angular velocity of the hand, in {b}.

        ``out`` (6, 7) is filled and returned when given, as in :meth:`fk`."""

    def fk_jacobian(
        self,
        q: ArrayLike,
        frame_out: NDArray[np.float64] | None = None,
        jacobian_out: NDArray[np.float64] | None = None,
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``(fk(q), jacobian(q))`` from one forward kinematics: the hand
        frame (4, 4) and J_ge (6, 7), written into ``frame_out`` and
        ``jacobian_out`` when given (as ``out`` of :meth:`fk`).

        Raises:
            TypeError, ValueError: as :meth:`fk`, for either output.
        """

    def fk_many(self, q: ArrayLike, out: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
        """:meth:`fk` at every row of ``q`` (shape (N, 7)): shape (N, 4, 4).

        A C-contiguous float64 ``q`` is read in place; the rows run with the
        GIL released, so threads may share a batch. ``out`` (N, 4, 4), if
        given, is filled and returned. A batch of 256 rows or more shares its
        rows with helper threads (one fewer than the cores, at most seven),
        which watch for the next batch for a few milliseconds after one; the
        environment variable ``A2ML_BATCH_THREADS`` (read at the first large
        batch) sets the threads a batch may use, its caller included: ``1``
        for none, as a process among one per core wants.

        Raises:
            TypeError: ``q`` is not numeric, or ``out`` not a float64 array.
            ValueError: ``q`` is not (N, 7) or holds NaN or infinity (the
                message names the row); ``out`` has the wrong shape, is not
                C-contiguous or writeable, or shares memory with ``q``.
        """

    def jacobian_many(self, q: ArrayLike, out: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
        """:meth:`jacobian` at every row of ``q`` (N, 7): shape (N, 6, 7);
        as :meth:`fk_many`."""

    def cpsa_many(
        self,
        q: ArrayLike,
        out: tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]] | None = None,
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """:meth:`cpsa` at every row of ``q`` (N, 7): ``(pw (N, 3), ow (N, 3, 3),
        swivel (N,))``; as :meth:`fk_many`. ``out``, a tuple of three float64
        arrays of those shapes, if given, is filled and returned.

        Raises:
            SingularityError: at a singular row, named in the message.
            TypeError: as :meth:`fk_many`, or ``out`` is not a tuple of three
                arrays.
            ValueError: as :meth:`fk_many`, for each array of ``out``.
        """

    def ik_cpsa_many(
        self,
        pw: ArrayLike,
        ow: ArrayLike,
        swivel: ArrayLike,
        q_near: ArrayLike | None = None,
        out: NDArray[np.float64] | None = None,
        on_error: Literal["raise", "nan"] = "raise",
    ) -> NDArray[np.float64]:
        """:meth:`ik_cpsa` (nearest solution) for every row of ``pw`` (N, 3),
        ``ow`` (N, 3, 3) and ``swivel`` (N,): shape (N, 7).

        ``q_near`` is one (7,) for every row or (N, 7), one per row; by
        default the middle of the joint ranges. A row without a solution
        raises the exception :meth:`ik_cpsa` would, its message led by the
        row (``on_error="raise"``), or is NaN (``"nan"``). Runs with the GIL
        released; ``out`` (N, 7) as in :meth:`fk_many`.

        Raises:
            UnreachableError, JointLimitError, SingularityError,
                ConvergenceError: as :meth:`ik_cpsa`, with ``on_error="raise"``.
            TypeError, ValueError: wrong shapes, row counts that differ, a
                non-finite entry, a matrix of ``ow`` that is not a rotation
                (named ``ow[i]``), or an unknown ``on_error``.
        """

    def cpsa(self, q: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64], float]:
        """The CPSA state ``(pw, ow, swivel)`` at ``q``: wrist position (3,),
        hand rotation (3, 3) and swivel angle in (-pi, pi].

        Raises:
            SingularityError: the arm is straight, or the wrist is on the
                vertical through the shoulder.
        """

    def hat(self, q: ArrayLike) -> tuple[NDArray[np.float64], float, NDArray[np.float64]]:
        """The HAT state ``(os, elbow, ow)`` at ``q``: shoulder frame
        [r, l, r x l] (3, 3), elbow angle in [0, pi] (pi = straight) and hand
        rotation (3, 3).

        Raises:
            SingularityError: the arm is straight.
        """

    def cpsa_jacobian(self, q: ArrayLike) -> NDArray[np.float64]:
        """J_cs, shape (7, 7): maps joint velocities to [pw', omega_w, swivel'].

        Raises:
            SingularityError: as :meth:`cpsa`.
        """

    def hat_jacobian(self, q: ArrayLike) -> NDArray[np.float64]:
        """J_tr, shape (7, 7): maps joint velocities to [omega_s, elbow', omega_w].

        Raises:
            SingularityError: as :meth:`hat`.
        """

    def ik_cpsa(
        self,
        pw: ArrayLike,
        ow: ArrayLike,
        swivel: float,
        q_near: ArrayLike | None = None,
        all_branches: bool = False,
    ) -> NDArray[np.float64]:
        """Joints reaching the CPSA state (pw (3,), ow (3, 3), swivel).

        Returns the in-limit solution nearest ``q_near`` (default: the middle
        of the joint ranges), shape (7,); with ``all_branches`` every distinct
        in-limit solution, nearest first, shape (n, 7). Arms without
        closed-form IK return the one Newton solution. Releases the GIL.

        Raises:
            UnreachableError: ``|pw|`` is outside the reachable annulus.
            SingularityError: e.g. the wrist on the vertical through the shoulder.
            JointLimitError: no solution within the joint limits.
            ConvergenceError: Newton IK did not converge.
        """

    def ik_hat(
        self,
        os: ArrayLike,
        elbow: float,
        ow: ArrayLike,
        q_near: ArrayLike | None = None,
        all_branches: bool = False,
    ) -> NDArray[np.float64]:
        """Joints reaching the HAT state (os (3, 3), elbow, ow (3, 3)); as
        :meth:`ik_cpsa`."""

    def swivel_intervals(self, pw: ArrayLike, ow: ArrayLike) -> list[tuple[float, float]]:
        """The swivel angles at which the wrist pose (pw, ow) is reachable
        within the joint limits, as sorted disjoint ``(lower, upper)``
        intervals of [-pi, pi] (an interval through pi appears as two).
        Releases the GIL.

        Raises:
            ConvergenceError: the arm has no closed-form IK.
            UnreachableError, SingularityError: as :meth:`ik_cpsa`.
        """

@final
class Task:
    """A validated A2ML task, immutable; create one with :func:`parse` or
    :func:`load`.

    Every property builds fresh Python data (arrays included), so changing it
    does not change the task. A task keeps its source text and path and
    pickles as ``parse(source, path)``. Tasks compare equal when they say the
    same thing, whatever their layout and comments.
    """

    __hash__: ClassVar[None]  # type: ignore[assignment]

    def __reduce__(self) -> tuple[Any, tuple[str, str | None]]:
        """Pickle as ``parse(source, path)``."""

    def __eq__(self, value: object, /) -> bool:
        """Equal when both say the same thing; layout and comments aside."""

    @property
    def name(self) -> str:
        """The task's name."""

    @property
    def robot(self) -> str:
        """The robot URDF path, resolved relative to the task file (or the
        working directory when parsed without a path)."""

    @property
    def start(self) -> dict[str, Any] | None:
        """None, ``{"joints": q}`` with ``q`` of shape (7,) (rad), or
        ``{"state": {variable: value}}`` with a complete state of one space."""

    @property
    def scene(self) -> list[dict[str, Any]]:
        """The obstacles, each a dict with ``"name"``, ``"shape"`` and the
        shape's fields: ``box`` (``center``, ``size``: full edge lengths
        along its own axes, ``rotation``), ``sphere`` (``center``,
        ``radius``), ``capsule`` (``a``, ``b``, ``radius``), ``cylinder``
        (``center``, ``radius``, ``height``, ``rotation``: its own z is the
        axis); points are arrays of shape (3,), rotations (3, 3) arrays (the
        shape's axes as columns), lengths floats (m)."""

    @property
    def settings(self) -> dict[str, Any]:
        """``rate`` (Hz), ``solver`` (``"auto"``, ``"qp"``, ``"rrt"``, ...),
        ``seed`` (int), ``transition`` (fraction of the shorter segment) and
        ``frame`` (``"base"`` or ``"root"``), defaults filled in."""

    @property
    def init(self) -> list[str] | None:
        """STRIPS initial facts, or None when the actions run in written order."""

    @property
    def goal(self) -> list[str] | None:
        """STRIPS goal facts, or None."""

    @property
    def actions(self) -> list[dict[str, Any]]:
        """The actions in written order. Each dict has ``name``,
        ``description`` (str or None), ``pre``, ``add``, ``del`` (lists of
        facts), ``contact`` (names of the obstacles it may touch), ``solver``
        (str or None) and ``kind``:

        - ``"constraints"``: ``goal`` (None or ``{"primary": {variable:
          value}, "secondary": {variable: value} | None}``), ``path`` (None or
          ``{"items": [{"variables": [...], "feature": feature}], "space":
          "cpsa" | "hat" | None, "hard": bool}``) and ``duration`` (s or None);
        - ``"explicit"``: ``segments``, each ``{"space": "cpsa" | "hat",
          "duration": float | None, "primitives": [...]}``; a primitive is
          ``{"variables": [...], "kind": "goal" | "path" | "hold"}`` plus
          ``goal`` (``{variable: value}``) or ``feature``.

        A feature is ``{"kind": "line", "direction": (3,), "length": float |
        None}``, ``{"kind": "about", "axis": (3,) array or body axis ("r",
        "-l", "f", "p", ...), "angle": float | None}``, ``{"kind": "by",
        "angle": float}`` or ``{"kind": "hold"}``."""

    @property
    def source(self) -> str:
        """The text the task was parsed from."""

    @property
    def path(self) -> str | None:
        """The file the task was read from or named with, or None."""

    def to_dict(self) -> dict[str, Any]:
        """``name``, ``robot``, ``start``, ``scene``, ``settings``, ``init``,
        ``goal`` and ``actions`` in one dict."""

    def with_goal(
        self,
        action: str,
        *,
        pw: ArrayLike | None = ...,
        ow: ArrayLike | None = ...,
        swivel: float | None = ...,
        shoulder_frame: ArrayLike | None = ...,
        elbow: float | None = ...,
    ) -> Task:
        """A new task: this one with the goal values of ``action`` replaced
        (``pw``: a (3,) position in m; ``ow``, ``shoulder_frame``: (3, 3) rotations;
        ``swivel``, ``elbow``: angles in rad), in the task's frame. Only a
        goal the action states can change, in its primary or secondary term.
        The new task is this task's text with those values, printed in
        canonical form (comments kept) and validated: it pickles, and is
        attached to outputs, as any parsed task. For sweeps without string
        templating: ``[task.with_goal("reach", pw=p) for p in grid]``.

        Raises:
            TypeError: a keyword that is not a variable.
            ValueError: no such action, no goal on a variable, a value of
                the wrong shape.
            ParseError: the new values make the task invalid (out of reach
                of the workspace bound, say).
        """

def parse(text: str, path: str | os.PathLike[str] | None = None) -> Task:
    """Parse and validate an A2ML task.

    ``path`` names the file in messages and anchors a relative robot path;
    without it the robot path is taken relative to the working directory.
    Releases the GIL.

    Raises:
        ParseError: the text is not a valid task (every problem is listed).
    """

def load(path: str | os.PathLike[str]) -> Task:
    """Read, parse and validate an A2ML task file; a relative robot path is
    taken relative to the file's folder. Releases the GIL.

    Raises:
        FileNotFoundError, PermissionError, OSError: the file cannot be read.
        ParseError: the text is not a valid task.
    """

def decompose(task: Task, robot: Robot | None = None) -> Decomposition:
    """Decompose a task into movement segments (docs/design.md §4).

    The actions run in execution order (the STRIPS plan from ``init`` to
    ``goal``, or the written order) from the task's start configuration; each
    is classified (types I-VII) and split into segments whose open goals and
    path sizes Opt1 and Opt2 fill in. ``robot`` defaults to the task's robot
    file (:attr:`Task.robot`). Deterministic; releases the GIL.

    Returns a dict (shape :class:`a2ml.Decomposition`): ``"task"`` (name),
    ``"start"`` (joints, (7,)) and ``"actions"``, each with ``"index"`` (in
    :attr:`Task.actions`), ``"name"``, ``"type"`` (``"i"`` ... ``"vii"``),
    ``"type_number"`` (1-7), ``"description"`` (of the type),
    ``"goal_space"``, ``"secondary_goal_space"``, ``"path_space"``
    (``"cpsa"``, ``"hat"`` or None; the classification is all None for an
    explicit action), ``"segments"`` and ``"optimisations"`` (``{"solver":
    "Opt1" | "Opt2", "residual", "sizes", "evaluations"}``). A segment is
    ``{"space", "pattern" ("path", "goal" or "mixed"), "duration" (s), "duration_raised",
    "solver", "relaxed" ([variable]), "start", "end" ((7,) joints),
    "primitives"}`` with primitives as in an explicit segment of
    :attr:`Task.actions`.

    Raises:
        DecomposeError: the task cannot be decomposed (the message says why).
        UrdfError: ``robot`` is None and the task's robot file cannot be
            loaded as a 7-DoF arm.
    """

@final
class SegmentReport:
    """What one movement segment did, as solved; immutable.

    Spelled as every output spells them (docs/cli.md): spaces ``"cpsa"`` or
    ``"hat"``, variables ``"pw"``, ``"ow"``, ``"swivel"``, ``"shoulder_frame"``,
    ``"elbow"``. Reports compare equal when every field is equal and pickle
    through the core's serialisation.
    """

    __hash__: ClassVar[None]  # type: ignore[assignment]

    def __reduce__(self) -> tuple[Any, tuple[str, tuple[float, float, float, float, float | None]]]:
        """Pickle as its JSON and its wall-clock timings."""

    def __eq__(self, value: object, /) -> bool:
        """Equal when every field is equal."""

    @property
    def action(self) -> str:
        """The action's name."""

    @property
    def action_index(self) -> int:
        """The action's index in :attr:`Task.actions`."""

    @property
    def segment(self) -> int:
        """The segment's index within its action, 0-based."""

    @property
    def action_type(self) -> _ActionType | None:
        """The action's type (the paper's I to VII, in lower case), or None for
        an action written as explicit segments."""

    @property
    def space(self) -> _Space:
        """The segment's representation space."""

    @property
    def pattern(self) -> _Pattern:
        """The paper's pattern: ``"path"`` (1: every primitive a path or hold),
        ``"goal"`` (2: every primitive a goal) or ``"mixed"`` (3: both)."""

    @property
    def solver(self) -> _Solver:
        """The solver that produced the motion (``"qp"``; never ``"auto"``)."""

    @property
    def focus(self) -> list[_Variable]:
        """The focus of interest: the variables of the segment's featured primitive."""

    @property
    def start(self) -> float:
        """Start in the plan's time (s)."""

    @property
    def end(self) -> float:
        """End in the plan's time (s), settling included."""

    @property
    def duration(self) -> float:
        """The segment's own duration before joining (s)."""

    @property
    def settle(self) -> float:
        """Time the solver ran past the reference's end to settle on the goal (s)."""

    @property
    def errors(self) -> dict[str, VariableError]:
        """The final error of every variable of the segment's space, in the
        space's order (``pw``, ``ow``, ``swivel`` or ``shoulder_frame``, ``elbow``, ``ow``)."""

    @property
    def path_errors(self) -> dict[str, VariableError]:
        """The largest distance of each path or held variable from its path (the
        path's locus, whatever the timing along it)."""

    @property
    def hard_path(self) -> bool:
        """Whether the segment's path is a hard constraint (action type IV or VI)."""

    @property
    def path_kept(self) -> bool:
        """Whether the path was kept within tolerance throughout (always True
        for a soft path, which may give way)."""

    @property
    def clearance(self) -> Clearance | None:
        """The smallest clearance over the segment's samples, or None when
        there is no pair to measure."""

    @property
    def limit_margin(self) -> float:
        """The smallest distance of any joint to its position limits over the segment (rad)."""

    @property
    def stalled(self) -> bool:
        """Whether the solver stopped making progress short of the goal."""

    @property
    def reached(self) -> bool:
        """Whether every variable is within tolerance at the end."""

    @property
    def qp(self) -> QpStats:
        """The velocity QP's counters and timings over the segment."""

    @property
    def rrt(self) -> RrtStats | None:
        """The RRT's counters when the RRT solved the segment, else None."""

    @property
    def fallback(self) -> _Fallback | None:
        """Why ``auto`` went on from the QP to the solver named, else None."""

    @property
    def peak_velocity_ratio(self) -> float:
        """The largest |q'| / velocity limit of any joint over the segment's time in the output."""

    @property
    def peak_acceleration_ratio(self) -> float:
        """The largest |q''| / acceleration limit of any joint over the segment's time in the output."""

    @property
    def limits_kept(self) -> bool:
        """Whether the output holds every position, velocity and acceleration limit over the segment."""

    @property
    def slowed_down(self) -> float:
        """The factor the segment was slowed down by to keep the limits (1: as solved)."""

    @property
    def joint_jerk(self) -> float:
        """The normalised jerk of the joints over the segment (dimensionless)."""

    @property
    def wrist_jerk(self) -> float:
        """The normalised jerk of the wrist path over the segment (dimensionless)."""

    @property
    def speed_peaks(self) -> int:
        """The number of peaks of the featured variable's speed (1: one bell)."""

    def to_dict(self) -> dict[str, Any]:
        """Every field above in one dict (records as their NamedTuples), e.g.
        for ``pandas.DataFrame([s.to_dict() for s in plan.segments])``."""

@final
class Plan:
    """A planned task: the joint trajectory at the output rate and what each
    segment did; immutable. Create one with :func:`plan`.

    Every array property builds a fresh float64 array. A plan keeps the
    :class:`Robot` and :class:`Task` it was planned from (the task's source is
    attached to the MCAP file) and pickles as its data (the core's JSON), without
    planning again.
    """

    def __reduce__(
        self,
    ) -> tuple[Any, tuple[Robot, Task, str, list[tuple[float, float, float, float, float | None]]]]:
        """Pickle as the robot, the task, the plan's JSON and each segment's
        wall-clock timings (which plan files leave out)."""

    @property
    def t(self) -> NDArray[np.float64]:
        """Sample times (s), shape (N,): every 1 / :attr:`rate` from 0, and the
        plan's end as the last sample (so the last step may be shorter)."""

    @property
    def q(self) -> NDArray[np.float64]:
        """Joint positions (rad), shape (N, 7), columns in :attr:`joint_names` order."""

    @property
    def qd(self) -> NDArray[np.float64]:
        """Joint velocities (rad/s), shape (N, 7)."""

    @property
    def joint_names(self) -> list[str]:
        """Joint names, base to tip: the columns of :attr:`q` and :attr:`qd`."""

    @property
    def rate(self) -> float:
        """Output rate (Hz)."""

    @property
    def segments(self) -> list[SegmentReport]:
        """One report per movement segment, in time order."""

    @property
    def warnings(self) -> list[PlanWarning]:
        """Goals missed beyond tolerance, fallbacks and repairs: each with its
        ``kind``, the ``action`` and ``segment`` (0-based) it names and its
        ``message``, in the order the CLI prints them."""

    @property
    def reached(self) -> bool:
        """Whether every segment reached its goals within tolerance."""

    @property
    def wrist_reference(self) -> NDArray[np.float64]:
        """The wrist path Pw the segments were asked to follow, shape (M, 4):
        rows ``(t, x, y, z)`` in s and m, in {b}, at :attr:`rate`."""

    @property
    def references(self) -> dict[str, NDArray[Any]]:
        """What the running segment asked for at each sample: ``segment`` (N,)
        its index in :attr:`segments`, ``pw`` (N, 3) in m, ``ow`` and
        ``shoulder_frame`` (N, 4) as quaternions ``(x, y, z, w)``, ``swivel``
        and ``elbow_angle`` (N,) in rad, all in {b}: the segment's own space
        from its references, the other mapped from them; NaN where
        undefined."""

    @property
    def distances(self) -> dict[tuple[str, str], NDArray[np.float64]]:
        """Each moving arm capsule's signed distance to each obstacle at every
        sample (m), keyed by ``(capsule, obstacle)``; NaN while the running
        action touches the obstacle on purpose (``contact``)."""

    @property
    def safety_distance(self) -> float:
        """The distance the solvers kept from obstacles (m)."""

    @property
    def task(self) -> Task:
        """The task that was planned."""

    @property
    def robot(self) -> Robot:
        """The robot it was planned on."""

    def write_mcap(self, path: str | os.PathLike[str]) -> None:
        """Write an MCAP file for Foxglove: ``/robot_description``,
        ``/joint_states``, ``/tf``, ``/scene``, ``/arm_capsules``,
        ``/wrist_path``, ``/a2ml/state`` and ``/a2ml/segments``, JSON-encoded
        with JSON schemas in zstd chunks, with the task source and the URDF
        attached; no wall-clock time, so the same plan gives the same bytes. Written to a temporary file and renamed,
        so a failure leaves no partial file. Releases the GIL.

        Raises:
            OSError: the file cannot be written.
        """

    def to_csv(self, path: str | os.PathLike[str]) -> None:
        """Write the joint trajectory as CSV: a header ``t``,
        ``<joint>_pos``..., ``<joint>_vel``... and one row per sample (s, rad,
        rad/s). Atomic as :meth:`write_mcap`; releases the GIL.

        Raises:
            OSError: the file cannot be written.
        """

    def to_parquet(self, path: str | os.PathLike[str], task_id: str | None = None) -> None:
        """Write one row per sample as a Parquet table (zstd): ``task``
        (``task_id``, default the task's name), ``action``, ``action_index``,
        ``segment`` (within its action), ``t``, ``q1``..``q7``,
        ``qd1``..``qd7``, the wrist state ``pw_x``..``pw_z``,
        ``ow_w``..``ow_z`` (unit quaternion) and ``swivel`` (null where
        singular), and ``clearance`` (m, null without obstacles); the same
        columns for every robot, so the files of a batch load as one table
        (``pandas.read_parquet(folder)``). Atomic as :meth:`write_mcap`;
        releases the GIL.

        Raises:
            OSError: the file cannot be written.
        """

    def to_arrow(self, task_id: str | None = None) -> Any:
        """The table of :meth:`to_parquet` as a ``pyarrow.Table``, for
        ``.to_pandas()`` or ``polars.from_arrow``.

        Raises:
            ImportError: pyarrow is not installed.
        """

    def metrics(self) -> dict[str, Any]:
        """The human-likeness measures of the plan, as
        :func:`a2ml.metrics.analyze` returns them: ``frames`` (float64 arrays
        per sample), ``whole`` and ``segments`` (summaries as ``a2ml analyze
        --json`` prints them) and ``singular_frames``."""

    def to_json(self, path: str | os.PathLike[str]) -> None:
        """Write the plan as JSON: joint names, rate, trajectory, segment
        reports, wrist reference and warnings, with the a2ml version, robot
        name and URDF path. Atomic as :meth:`write_mcap`; releases the GIL.

        Raises:
            OSError: the file cannot be written.
        """

    def to_svg(self, kind: Literal["joints", "velocities", "featured", "distances", "wrist", "all"] = "all") -> str:
        """The plan drawn as an SVG document (no matplotlib, no fonts loaded):
        ``joints`` (positions, limits shaded, segment boundaries numbered),
        ``velocities`` (and accelerations, against the speed limits),
        ``featured`` (each segment's featured variables against their
        reference and goal), ``distances`` (each arm capsule to each obstacle,
        with the safety distance), ``wrist`` (three orthographic views) or
        ``all`` on one page; what ``a2ml plot --kind`` draws. Releases the GIL.

        Raises:
            ValueError: an unknown kind.
        """

    def plot(self, path: str | os.PathLike[str], kind: Literal["joints", "velocities", "featured", "distances", "wrist", "all"] = "all", width: int | None = None) -> None:
        """Write :meth:`to_svg` of ``kind`` to an SVG file, or for a path
        ending in ``.png`` a PNG image rendered from it (its text in the font
        the library embeds: no system font is read), ``width`` pixels wide
        (as drawn when None; the height in proportion). Atomic as
        :meth:`write_mcap`; releases the GIL.

        Raises:
            ValueError: an unknown kind, or a width outside 1 to 16384.
            OSError: the file cannot be written.
        """

    def to_html(self) -> str:
        """One self-contained HTML page (nothing fetched): summary and
        warnings, the segment table, the motion in a front and a top view with
        a play button and a time slider, every plot, and the task's text.
        Releases the GIL."""

    def write_report(self, path: str | os.PathLike[str]) -> None:
        """Write :meth:`to_html` to a file. Atomic as :meth:`write_mcap`.

        Raises:
            OSError: the file cannot be written.
        """

    def _repr_html_(self) -> str:
        """A notebook's view: the caption, the segment table and the joint plot."""

def plan(
    task_or_path: Task | str | os.PathLike[str],
    solver: Literal["auto", "qp", "rrt", "map", "gpm", "clik", "pmp", "hamp"] | None = None,
    rate: float | None = None,
    seed: int | None = None,
    robot: Robot | None = None,
    acceleration_scale: float | None = None,
    time_limit: float | None = None,
) -> Plan:
    """Plan a task (docs/design.md §4-5): decompose it, solve every segment from
    where the last one really ended and join them (+Tr within an action, +Se
    between actions), resampled at ``rate``.

    ``task_or_path`` is a :class:`Task` or the path of a task file (read as
    :func:`load` does). ``solver`` overrides the solver of the task and of
    every action (default: theirs; ``"map"`` is the swivel obstacle map; ``"gpm"``,
    ``"clik"`` and ``"pmp"`` are the baselines). ``rate`` (Hz) overrides the task's
    ``settings { rate }`` (default 100 Hz); ``seed`` its ``seed``. ``robot``
    defaults to the task's robot file (:attr:`Task.robot`).
    ``acceleration_scale`` multiplies the robot's acceleration limits
    (overriding ``settings { acceleration }``); ``time_limit`` (s, default
    none) makes the plan fail with a timeout once it passes. Every joint
    holds its position, velocity and acceleration limits at every instant of
    the output; a segment that cannot is named in :attr:`Plan.warnings`
    and is not reached. A goal missed
    beyond tolerance is not an error: :attr:`Plan.reached` is False and
    :attr:`Plan.warnings` say which. Deterministic; releases the GIL.

    Raises:
        TypeError: ``task_or_path`` is neither a Task nor a path.
        ValueError: ``solver`` is not a solver's name, or ``rate`` is not
            positive and finite.
        FileNotFoundError, OSError, ParseError: as :func:`load`.
        UrdfError: the task's robot file cannot be loaded as a 7-DoF arm.
        DecomposeError: the task cannot be decomposed.
        PlanError: the solver is not available yet, or a segment cannot be solved.
    """

def plan_many(
    tasks: Iterable[Task | str | os.PathLike[str]],
    robot: Robot | None = None,
    jobs: int | None = None,
    solver: Literal["auto", "qp", "rrt", "map", "gpm", "clik", "pmp", "hamp"] | None = None,
    rate: float | None = None,
    seed: int | None = None,
    acceleration_scale: float | None = None,
    time_limit: float | None = None,
) -> list[Plan | Exception]:
    """Plan many tasks (Tasks or paths) at once on ``jobs`` threads (default:
    one per core), without the GIL: one entry per task in input order, the
    :class:`Plan` that :func:`plan` would return or the exception it would
    raise (a :class:`ParseError`, ``OSError``, :class:`UrdfError`,
    :class:`PlanError`, ...), so one failure does not stop the others. Each
    plan equals :func:`plan` of its task with the same options. ``robot``
    defaults to each task's own, loaded once per file, base and tip.

    Raises:
        ValueError: ``jobs`` is 0, or ``solver`` is not a solver's name.
        TypeError: ``tasks`` is not iterable.
    """

def compare(
    task_or_path: Task | str | os.PathLike[str],
    solvers: list[Literal["auto", "qp", "rrt", "map", "gpm", "clik", "pmp", "hamp"]] | None = None,
    robot: Robot | None = None,
) -> list[dict[str, Any]]:
    """Plan one task with each of ``solvers`` (default ``auto``, ``gpm``,
    ``clik``, ``pmp``) and return flat records, ``pandas.DataFrame``-ready:
    one per solver and segment with ``solver``, ``solved_by``, ``action``,
    ``segment``, ``reached``, ``path_kept``, ``error_<var>`` and
    ``path_error_<var>`` (m or rad; var Pw, Ow, sw, Os, e), ``limit_margin``
    (rad, negative = outside) and ``limit_joint``, ``clearance`` (m) and
    ``clearance_link``, ``peak_speed_ratio``, ``duration`` and
    ``planning_time`` (s); a solver that produced no plan gives one record
    whose ``error`` says why. Releases the GIL.

    Raises:
        TypeError: ``task_or_path`` is neither a Task nor a path.
        ValueError: a solver is not a solver's name.
        FileNotFoundError, OSError, ParseError: as :func:`load`.
        UrdfError: the task's robot file cannot be loaded as a 7-DoF arm.
    """


@final
class Obstacles:
    """Obstacle dicts converted into the robot's base frame and checked once, for many
    ``rrt_connect`` and ``scene_clearance`` calls on one scene.

    Each dict as ``rrt_connect`` takes them. Usable with any robot whose URDF root is where
    ``robot``'s is relative to its base frame (ValueError otherwise).
    """

    def __new__(cls, robot: Robot, obstacles: Iterable[dict[str, Any]]) -> Obstacles: ...
    def __len__(self) -> int: ...

def rrt_connect(
    robot: Robot,
    obstacles: Obstacles | Iterable[dict[str, Any]],
    start: ArrayLike,
    goals: Iterable[ArrayLike],
    *,
    seed: int = 0,
    clearance: float = 0.01,
    max_samples: int = 20000,
    step: float = 2.0,
    resolution: float = 0.005,
    shortcuts: int = 200,
) -> dict[str, Any]:
    """Joint-space RRT-Connect among obstacle dicts in the URDF root frame.

    Each obstacle: ``type`` (box, sphere, cylinder), ``position``, optional
    ``orientation_quat_xyzw``, and ``half_extents``, ``radius``, ``length``.
    Returns ``waypoints`` ((N, 7) array), ``goal``, ``samples``, ``nodes``,
    ``collision_checks``; raises PlanError when no path is found. ``Obstacles`` converts a
    scene once for many calls; the robot builds its arm's collision model (shapes, self
    pairs) at its first call and keeps it.
    """

def scene_clearance(
    robot: Robot, obstacles: Obstacles | Iterable[dict[str, Any]], q: ArrayLike
) -> float:
    """Smallest signed distance (m) of the arm at q to the obstacles or between its self pairs."""

def swivel_map(
    task_or_robot: Task | Robot | str | os.PathLike[str],
    action: str | None = None,
    segment: int = 1,
    *,
    start: ArrayLike | None = None,
    points: ArrayLike | None = None,
    duration: float | None = None,
    spheres: list[tuple[str, list[float], float]] | None = None,
    time_steps: int = 200,
    angle_steps: int = 360,
    safety_distance: float = 0.01,
) -> dict[str, Any]:
    """The time × swivel obstacle map (METHODS.md §1) and its planned profile.

    For a task (a :class:`Task` or a path): segment ``segment`` (from 1) of
    ``action``, from the decomposition's start of that segment. For a
    :class:`Robot`: the wrist path from ``start``'s wrist through ``points``
    ((K, 3), m in {b}) as a clamped cubic spline with chord-length knots over
    ``duration`` s, the hand orientation held, among ``spheres``
    (``(name, [x, y, z], radius)``, m).

    Returns a dict: ``t`` (N_t,) s; ``swivel`` (N_θ,) cell-centre angles in
    rad over [-π, π); ``labels`` (N_t, N_θ) int8 (0 free, 1 joint limits,
    2 self-collision, 3 + k obstacle k); ``obstacles`` (names); ``faults``
    (per column None, or why the wrist pose rules it out); ``profile`` (None,
    or a dict of ``t``, ``swivel``, ``q`` (N, 7), ``qd`` (N, 7) at 1 kHz and
    ``clearance`` in m); ``error`` (None, or why there is no profile, naming
    the time the free region is cut). Releases the GIL.

    Raises:
        TypeError: ``task_or_robot`` or ``points`` has the wrong type.
        ValueError: a missing or invalid argument, an unknown action or
            segment, a task that does not decompose, a HAT segment or an arm
            without analytic IK.
    """



def _metrics_analyze(plan_or_path: Plan | str | os.PathLike[str], robot: Robot | None = None) -> dict[str, Any]:
    """Backs :func:`a2ml.metrics.analyze`."""

def _metrics_similarity(h: str, s: str) -> float:
    """Backs :func:`a2ml.metrics.similarity`."""

def _metrics_levenshtein(h: str, s: str) -> int:
    """Backs :func:`a2ml.metrics.levenshtein`."""

def _metrics_connection_similarity(
    h: str, s: str, target_share: float, population_shares: list[tuple[str, float]]
) -> float:
    """Backs :func:`a2ml.metrics.connection_similarity`."""

def _metrics_mpcsi(
    candidates: list[str], samples: list[str], population_shares: list[tuple[str, float]]
) -> list[float]:
    """Backs :func:`a2ml.metrics.mpcsi`."""

def _metrics_fitts_duration(amplitude: float) -> float:
    """Backs :func:`a2ml.metrics.fitts_duration`."""

def _metrics_rula_table_a(upper_arm: int, lower_arm: int, wrist: int, wrist_twist: int) -> int:
    """Backs :func:`a2ml.metrics.rula_table_a`."""

def _metrics_plan_handover(
    robot: Robot,
    start: ArrayLike,
    pw: ArrayLike,
    ow: ArrayLike,
    swivel: float | None = None,
    handover: str = "pick_up",
    seed: int = 0,
    rate: float = 120.0,
) -> dict[str, Any]:
    """Backs :func:`a2ml.metrics.plan_handover`."""
