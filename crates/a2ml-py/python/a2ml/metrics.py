"""Human-likeness, measured and planned (METHODS.md §3; docs/metrics.md).

:func:`analyze` scores a :class:`a2ml.Plan` or a plan file (``.mcap`` with its
attached URDF, or ``.csv`` with ``robot=``): per-frame float64 arrays under
``"frames"`` (element speeds, swivel angle, RULA scores and angles, NaN where
a frame cannot be scored) and the summaries ``"whole"`` and ``"segments"``, the
same dicts ``a2ml analyze --json`` prints. Patterns are strings of primitives
joined by ``-`` such as ``"ΦPO-PO"`` (Φ swivel, P wrist position, O hand
orientation; ``phi`` is accepted for Φ). :func:`plan_handover` is the HAMP
planner for a pick-up or a delivery.

>>> import a2ml.metrics
>>> a2ml.metrics.similarity("ΦPO-PO", "P-ΦPO-PO")
0.8
>>> round(a2ml.metrics.fitts_duration(0.1), 4)
0.8027
"""

import os
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

from numpy.typing import ArrayLike

from a2ml import _a2ml
from a2ml._a2ml import Plan, Robot

__all__ = [
    "analyze",
    "connection_similarity",
    "fitts_duration",
    "levenshtein",
    "mpcsi",
    "plan_handover",
    "rula_table_a",
    "similarity",
]


def analyze(
    plan_or_path: Union[Plan, str, "os.PathLike[str]"], robot: Optional[Robot] = None
) -> Dict[str, Any]:
    """The measures of a plan or a plan file; ``robot`` overrides the plan's
    (required for CSV). Releases the GIL.

    Raises:
        TypeError: ``plan_or_path`` is neither a Plan nor a path.
        OSError: the file cannot be read.
        ValueError: the file is not a plan, has no URDF and no ``robot`` was
            given, or its joints are not the robot's.
        UrdfError: the attached URDF cannot be loaded.
    """
    return _a2ml._metrics_analyze(plan_or_path, robot)


def similarity(h: str, s: str) -> float:
    """sim(h, s) = (n + m - Levenshtein(h, s)) / (n + m) (HAMP eq. 3).

    Raises:
        ValueError: a pattern is not primitives joined by ``-``.
    """
    return _a2ml._metrics_similarity(h, s)


def levenshtein(h: str, s: str) -> int:
    """The edit distance between two patterns over primitive tokens."""
    return _a2ml._metrics_levenshtein(h, s)


def connection_similarity(
    h: str, s: str, target_share: float, population: Sequence[Tuple[str, float]]
) -> float:
    """simc(h, s) (HAMP eq. 4): ``target_share`` is f_h, ``population`` the
    patterns with their shares of all samples, from which f_L is taken."""
    return _a2ml._metrics_connection_similarity(h, s, target_share, list(population))


def mpcsi(
    candidates: Sequence[str], samples: Sequence[str], population: Sequence[Tuple[str, float]]
) -> List[float]:
    """MPCSI (HAMP eqs. 5-6): each candidate's mean simc over the samples."""
    return _a2ml._metrics_mpcsi(list(candidates), list(samples), list(population))


def fitts_duration(amplitude: float) -> float:
    """Fitts' T = 0.3625 + 0.1325 log2(2A / 20 mm) (s) for a travel of
    ``amplitude`` metres (at least 0.3625 s).

    Raises:
        ValueError: ``amplitude`` is negative or not finite.
    """
    return _a2ml._metrics_fitts_duration(amplitude)


def rula_table_a(upper_arm: int, lower_arm: int, wrist: int, wrist_twist: int) -> int:
    """RULA Table A (McAtamney & Corlett 1993).

    Raises:
        ValueError: a score is outside the table (1-6, 1-3, 1-4, 1-2).
    """
    return _a2ml._metrics_rula_table_a(upper_arm, lower_arm, wrist, wrist_twist)


def plan_handover(
    robot: Robot,
    start: ArrayLike,
    pw: ArrayLike,
    ow: ArrayLike,
    swivel: Optional[float] = None,
    handover: str = "pick_up",
    seed: int = 0,
    rate: float = 120.0,
) -> Dict[str, Any]:
    """The HAMP planner (METHODS.md §3.4): from joint configuration ``start``
    (7,) to the hand pose ``pw`` (3,), ``ow`` (3, 3) and, if given, the swivel
    angle; ``handover`` is ``"pick_up"`` or ``"delivery"``. Returns ``t``,
    ``q``, ``qd``, the planned ``phase1`` / ``phase2`` patterns, the timing
    (``duration`` = Fitts' T, ``peak_time``, ``swivel_window``,
    ``swivel_ratios``, ``duration_ratio`` R_d), ``limit_violations``,
    ``clearance`` (self-collision only) and the plan's ``metrics``.

    Raises:
        ValueError: an argument has the wrong shape or value.
        PlanError: the motion cannot be planned (IK fails on the way).
    """
    return _a2ml._metrics_plan_handover(robot, start, pw, ow, swivel, handover, seed, rate)
