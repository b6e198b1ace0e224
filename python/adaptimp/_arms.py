"""The arms of the rigid plant (SPEC §1): :class:`TwoLinkArm` (the paper's)
and :class:`PlanarArm` (n revolute joints in a vertical plane), fronts over the
compiled core's models."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _adaptimp
from ._errors import ConfigError
from ._params import check_n, resolve

FloatArray = NDArray[np.float64]


class TwoLinkArm:
    """The paper's 2-link arm in a vertical plane, (55)–(63), SPEC §1.

    ``D(q) q̈ + C(q, q̇) q̇ + G(q) = τ − τe``, with τ the applied (saturated)
    torque and τe the force the arm exerts on the environment.

    Parameters
    ----------
    **params
        ``m1``, ``m2`` (kg), ``l1``, ``l2`` (m), ``lc1``, ``lc2`` (m; default
        half the given lengths), ``I1``, ``I2`` (kg m²; default m l²/4 of the
        given masses and lengths), ``g`` (m/s²). Defaults: SPEC §1.

    Examples
    --------
    >>> import adaptimp
    >>> arm = adaptimp.TwoLinkArm(m2=1.0)
    >>> arm.D([0.0, 0.0]).shape
    (2, 2)
    """

    __slots__ = ("_core", "_params")

    n = 2
    """Joints."""

    def __init__(self, **params: Any) -> None:
        self._params = resolve(params, groups=("arm",), caller="TwoLinkArm()")
        self._core = _adaptimp.TwoLinkArm(self._params)
        self._params.update(self._core.params)

    def __reduce__(self) -> tuple[Any, ...]:
        return (_two_link_arm, (self._params,))

    @property
    def core(self) -> Any:
        """The compiled arm (``adaptimp._adaptimp.TwoLinkArm``) the core's runs simulate."""
        return self._core

    @property
    def params(self) -> dict[str, Any]:
        """The arm's parameters (a copy), derived ones included."""
        return dict(self._params)

    @property
    def lumped(self) -> tuple[float, float, float, float, float]:
        """p1 … p5 of (59)–(63) (kg m², kg m², kg m², kg m, kg m), p4 with the erratum."""
        p1, p2, p3, p4, p5 = self._core.lumped
        return (p1, p2, p3, p4, p5)

    def D(self, q: ArrayLike) -> FloatArray:
        """Inertia matrix D(q) (kg m²), (2, 2), at joint positions ``q`` (rad), (56)."""
        return self._core.D(q)

    def C(self, q: ArrayLike, dq: ArrayLike) -> FloatArray:
        """Coriolis and centripetal matrix C(q, q̇) (kg m²/s), (2, 2), (57)."""
        return self._core.C(q, dq)

    def G(self, q: ArrayLike) -> FloatArray:
        """Gravity torque G(q) (N m), (2,), (58)."""
        return self._core.G(q)

    def forward_dynamics(
        self, q: ArrayLike, dq: ArrayLike, tau: ArrayLike, tau_e: ArrayLike
    ) -> FloatArray:
        """Joint acceleration q̈ (rad/s²), (2,), from (4).

        Parameters
        ----------
        q, dq : array_like, shape (2,)
            Joint positions (rad) and velocities (rad/s).
        tau : array_like, shape (2,)
            Applied (already saturated) torque (N m).
        tau_e : array_like, shape (2,)
            Force the arm exerts on the environment (N m).
        """
        return self._core.forward_dynamics(q, dq, tau, tau_e)

    def fk(self, q: ArrayLike) -> FloatArray:
        """End-effector position (m), (3,), in the arm's plane (z = 0), SPEC §16."""
        return self._core.fk(q)

    def jacobian(self, q: ArrayLike) -> FloatArray:
        """Position Jacobian J(q) = ∂fk/∂q (m/rad), (3, 2), SPEC §16."""
        return self._core.jacobian(q)

    def __repr__(self) -> str:
        p = self._params
        return (
            f"adaptimp.TwoLinkArm(m1={p['m1']:g}, m2={p['m2']:g}, l1={p['l1']:g}, "
            f"l2={p['l2']:g}, lc1={p['lc1']:g}, lc2={p['lc2']:g}, I1={p['I1']:g}, "
            f"I2={p['I2']:g}, g={p['g']:g})"
        )


def _two_link_arm(params: dict[str, Any]) -> TwoLinkArm:
    return TwoLinkArm(**params)


def _per_link(name: str, value: ArrayLike, n: int, positive: bool) -> list[float]:
    arr = np.asarray(value)
    if arr.dtype.kind not in "iuf":
        raise TypeError(f"{name} must be a number or {n} numbers, got {type(value).__name__}")
    if arr.shape not in ((), (n,)):
        raise ConfigError(f"{name} must be a number or have shape ({n},), got shape {arr.shape}")
    out = np.broadcast_to(arr.astype(np.float64), (n,))
    for i, x in enumerate(out):
        if not math.isfinite(x) or (x <= 0 if positive else x < 0):
            rel = "> 0" if positive else "≥ 0"
            raise ConfigError(f"{name}[{i}] must be finite and {rel}, got {x}")
    return [float(x) for x in out]


class PlanarArm:
    """An arm of n revolute joints (1 ≤ n ≤ 7) in a vertical plane.

    Joint angles are relative (q_i is link i's angle to link i−1); link 1's
    angle is measured from the horizontal, and gravity acts along −y. D is
    assembled from the centre-of-mass Jacobians and C from the Christoffel
    symbols of D, so Ḋ − 2C is skew-symmetric. For n = 2 it equals
    :class:`TwoLinkArm` with the same links to rounding.

    Parameters
    ----------
    n : int
        Links (joints), 1 … 7.
    masses : float or array_like, shape (n,)
        Link masses (kg), > 0. Default 1 kg each.
    lengths : float or array_like, shape (n,)
        Joint-to-joint lengths (m), > 0. Default 0.3 m each.
    coms : float or array_like, shape (n,), optional
        Distances from each link's proximal joint to its centre of mass (m).
        Default half the lengths.
    inertias : float or array_like, shape (n,), optional
        Moments of inertia about the centres of mass, normal to the plane
        (kg m²). Default m l²/12 (uniform rods).
    g : float
        Gravity (m/s²).

    Examples
    --------
    >>> import adaptimp
    >>> arm = adaptimp.PlanarArm(3, masses=[2.0, 1.5, 1.0], lengths=0.4)
    >>> arm.D([0.0, 0.1, 0.2]).shape
    (3, 3)
    """

    __slots__ = ("_core", "_params")

    def __init__(
        self,
        n: int,
        masses: ArrayLike = 1.0,
        lengths: ArrayLike = 0.3,
        coms: ArrayLike | None = None,
        inertias: ArrayLike | None = None,
        g: float = 9.81,
    ) -> None:
        n = check_n(n)
        m = _per_link("masses", masses, n, positive=True)
        length = _per_link("lengths", lengths, n, positive=True)
        c = [x / 2 for x in length] if coms is None else _per_link("coms", coms, n, False)
        if inertias is None:
            inertia = [mi * li * li / 12 for mi, li in zip(m, length)]
        else:
            inertia = _per_link("inertias", inertias, n, positive=False)
        if isinstance(g, bool) or not isinstance(g, (int, float, np.floating, np.integer)):
            raise TypeError(f"g must be a number (m/s²), got {type(g).__name__}")
        if not math.isfinite(float(g)):
            raise ConfigError(f"g must be finite, got {g}")
        self._params: dict[str, Any] = {
            "n": n,
            "masses": m,
            "lengths": length,
            "coms": c,
            "inertias": inertia,
            "g": float(g),
        }
        self._core = _adaptimp.PlanarArm(m, length, c, inertia, float(g))

    def __reduce__(self) -> tuple[Any, ...]:
        p = self._params
        return (PlanarArm, (p["n"], p["masses"], p["lengths"], p["coms"], p["inertias"], p["g"]))

    @property
    def core(self) -> Any:
        """The compiled arm (``adaptimp._adaptimp.PlanarArm``) the core's runs simulate."""
        return self._core

    @property
    def n(self) -> int:
        """Joints."""
        return int(self._params["n"])

    @property
    def params(self) -> dict[str, Any]:
        """The arm's parameters (a copy): n, masses, lengths, coms, inertias, g."""
        return {k: list(v) if isinstance(v, list) else v for k, v in self._params.items()}

    def D(self, q: ArrayLike) -> FloatArray:
        """Inertia matrix D(q) (kg m²), (n, n), at joint positions ``q`` (rad)."""
        return self._core.D(q)

    def C(self, q: ArrayLike, dq: ArrayLike) -> FloatArray:
        """Coriolis and centripetal matrix C(q, q̇) (kg m²/s), (n, n)."""
        return self._core.C(q, dq)

    def G(self, q: ArrayLike) -> FloatArray:
        """Gravity torque G(q) (N m), (n,)."""
        return self._core.G(q)

    def forward_dynamics(
        self, q: ArrayLike, dq: ArrayLike, tau: ArrayLike, tau_e: ArrayLike
    ) -> FloatArray:
        """Joint acceleration q̈ (rad/s²), (n,): D q̈ = τ − τe − C q̇ − G, with τ the
        applied torque and τe the force on the environment (N m)."""
        return self._core.forward_dynamics(q, dq, tau, tau_e)

    def fk(self, q: ArrayLike) -> FloatArray:
        """End-effector position (m), (3,): the tip of the last link, in the arm's
        x–y plane (z = 0; x horizontal, y up), SPEC §16."""
        return self._core.fk(q)

    def jacobian(self, q: ArrayLike) -> FloatArray:
        """Position Jacobian J(q) = ∂fk/∂q (m/rad), (3, n): ṗ = J q̇ (the z row is zero)."""
        return self._core.jacobian(q)

    def __repr__(self) -> str:
        p = self._params
        return (
            f"adaptimp.PlanarArm({p['n']}, masses={p['masses']}, lengths={p['lengths']}, "
            f"coms={p['coms']}, inertias={p['inertias']}, g={p['g']:g})"
        )
