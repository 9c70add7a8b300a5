"""Type stubs of the native module ``a2ml._a2ml`` (hand-written, checked by
``mypy.stubtest`` in ``make test``).

Conventions (DESIGN.md §2-3): metres, radians; every position and rotation is
in the base frame {b}, whose origin is the shoulder centre S and whose axes
are those of the URDF base link (z up). Array arguments accept any array-like
of the stated shape and are converted to float64; a wrong shape or a NaN or
infinite entry raises ``ValueError``. Rotation matrices must be orthonormal to
1e-6 with determinant +1, else ``ValueError``.
"""

import os
from typing import Any, final

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "__version__",
    "Robot",
    "A2mlError",
    "UrdfError",
    "UnreachableError",
    "JointLimitError",
    "SingularityError",
    "ConvergenceError",
]

__version__: str

class A2mlError(Exception):
    """Base class of every error raised by a2ml."""

class UrdfError(A2mlError):
    """The URDF is missing, unreadable, invalid, or holds no 7-revolute-joint arm."""

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

    def fk(self, q: ArrayLike) -> NDArray[np.float64]:
        """The hand frame {W} in {b} at joints ``q`` (shape (7,)), as a 4x4
        homogeneous matrix: origin the wrist centre W, rotation Ow with
        columns f (finger direction), p (palm normal), f x p."""

    def centers(self, q: ArrayLike) -> dict[str, NDArray[np.float64]]:
        """The arm's points at ``q``: keys ``"shoulder"`` (always the origin),
        ``"elbow"`` and ``"wrist"``, each shape (3,)."""

    def jacobian(self, q: ArrayLike) -> NDArray[np.float64]:
        """The geometric Jacobian J_ge, shape (6, 7): rows 0-2 the linear
        velocity of W, rows 3-5 the angular velocity of the hand, in {b}."""

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
