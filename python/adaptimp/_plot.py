"""Figures of a run, of the kinds of the paper's Figs. 2–10, and a comparison of runs.

Each function returns a matplotlib ``Figure`` (made through pyplot, so that
``plt.show()`` and notebooks display it). When there is no display, the Agg
backend is selected before pyplot is first imported.

This module owns the registry of plot kinds: :data:`FIGURES` for
:meth:`adaptimp.Run.plot`, :data:`MUJOCO_FIGURES` for
``adaptimp.mujoco.MujocoResult.plot`` (with "contact"). It reads runs through
the :class:`Run` protocol and imports nothing of the result classes.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np
from numpy.typing import NDArray

from ._params import CASE_NAMES

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure


class Run(Protocol):
    """What the figures read of a run (:class:`adaptimp.Run` and its
    subclasses): arrays with one row per recorded step."""

    @property
    def case(self) -> str: ...
    @property
    def params(self) -> dict[str, Any]: ...
    @property
    def metrics(self) -> dict[str, Any]: ...
    @property
    def t(self) -> NDArray[np.float64]: ...
    @property
    def q(self) -> NDArray[np.float64]: ...
    @property
    def xc(self) -> NDArray[np.float64]: ...
    @property
    def xd(self) -> NDArray[np.float64]: ...
    @property
    def z1(self) -> NDArray[np.float64]: ...
    @property
    def tau(self) -> NDArray[np.float64]: ...
    @property
    def tau_sat(self) -> NDArray[np.float64]: ...
    @property
    def tau_e(self) -> NDArray[np.float64]: ...
    @property
    def n(self) -> int: ...
    @property
    def rows(self) -> int: ...


class MujocoRun(Run, Protocol):
    """A run on a MuJoCo plant (``adaptimp.mujoco.MujocoResult``)."""

    @property
    def wrench_ee(self) -> NDArray[np.float64] | None: ...


_SIZE = (8.0, 5.6)  # inches; 960 × 672 px at the default 120 dpi of savefig below
_COLORS = {"pd": "#d62728", "sf": "#1f77b4", "of": "#2ca02c"}


def _choose_backend() -> None:
    """Select Agg if pyplot is not imported yet, no backend was chosen and there is
    no display (call before importing pyplot)."""
    if "matplotlib.pyplot" not in sys.modules and not os.environ.get("MPLBACKEND"):
        headless = sys.platform.startswith("linux") and not (
            os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
        )
        if headless:
            import matplotlib

            matplotlib.use("Agg")


def _joint(i: int) -> str:
    return f"joint {i + 1}"


def _figure(title: str, rows: int = 2) -> tuple[Figure, Sequence[Axes]]:
    _choose_backend()
    import matplotlib.pyplot as plt

    size = (_SIZE[0], max(_SIZE[1], 2.2 * rows + 1.2))
    fig, axes = plt.subplots(
        rows, 1, sharex=True, figsize=size, layout="constrained", dpi=120, squeeze=False
    )
    axes = axes[:, 0]
    fig.suptitle(title, fontsize=12)
    for ax in axes:
        ax.grid(True, alpha=0.3)
    axes[-1].set_xlabel("time t (s)")
    return fig, list(axes)


def _legend(fig: Figure, ax: Axes, ncol: int) -> None:
    """One legend for the figure, below the axes, where it covers no data."""
    handles, labels = ax.get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside lower center", ncol=ncol, fontsize=9, frameon=False)


def _title(res: Run, what: str) -> str:
    return f"{CASE_NAMES.get(res.case, res.case)} ({res.case}): {what}"


def _settle_band(ax: Axes, res: Run) -> None:
    settle = float(res.params["settle"])
    if res.t.size and settle > res.t[0]:
        ax.axvspan(res.t[0], min(settle, res.t[-1]), color="0.85", alpha=0.5, lw=0)


def tracking(res: Run) -> Figure:
    """q against the commanded xc and the compliant reference xd, per joint, with
    the wall (the paper's Figs. 2, 5, 8)."""
    fig, axes = _figure(_title(res, "joint tracking"), res.n)
    wall = res.params["wall"]
    for i, ax in enumerate(axes):
        ax.plot(res.t, res.xc[:, i], color="k", lw=1.0, ls="--", label="xc, commanded")
        ax.plot(res.t, res.xd[:, i], color="tab:orange", lw=1.2, label="xd, compliant reference")
        ax.plot(res.t, res.q[:, i], color="tab:blue", lw=1.0, label="q, arm")
        if i == 0 and wall is not None:
            ax.axhline(wall, color="tab:red", lw=1.5, label=f"wall at {wall:g} rad")
            top = max(float(np.max(res.q[:, 0])), float(np.max(res.xc[:, 0])), wall) + 0.05
            ax.axhspan(wall, top, color="tab:red", alpha=0.08, lw=0)
            ax.set_ylim(top=top)
        ax.set_ylabel(f"{_joint(i)}: q{i + 1} (rad)")
    _legend(fig, axes[0], ncol=4)
    return fig


def errors(res: Run) -> Figure:
    """Tracking error z1 = xd − q per joint (the paper's Figs. 3, 6, 9): the settling
    transient (t < ``settle``, excluded from the 'after2' metrics) on the left, the
    rest of the run on its own scale on the right."""
    _choose_backend()
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(
        res.n,
        2,
        sharex="col",
        squeeze=False,
        figsize=(_SIZE[0], max(_SIZE[1], 2.2 * res.n + 1.2)),
        layout="constrained",
        dpi=120,
        width_ratios=(1, 3),
    )
    fig.suptitle(_title(res, "tracking error z1 = xd − q"), fontsize=12)
    rms = res.metrics["rms_z1_joint_after2"]
    settle = float(res.params["settle"])
    early = res.t < settle
    late = ~early
    for i in range(res.n):
        left, right = axes[i]
        for ax, rows in ((left, early), (right, late)):
            ax.grid(True, alpha=0.3)
            ax.axhline(0.0, color="0.4", lw=0.6)
            ax.plot(res.t[rows], res.z1[rows, i], color=_COLORS[res.case], lw=0.9)
        left.set_ylabel(f"{_joint(i)}: z1,{i + 1} (rad)")
        left.set_title(f"t < {settle:g} s (settling)", fontsize=10, loc="left")
        right.set_title(f"t ≥ {settle:g} s: RMS = {rms[i]:.3g} rad", fontsize=10, loc="left")
    for ax in axes[-1]:
        ax.set_xlabel("time t (s)")
    return fig


def torques(res: Run) -> Figure:
    """Commanded torque τ and applied torque sat(τ) per joint, with the limits ±τmax
    (the paper's Figs. 4, 7, 10). A commanded torque far beyond the limits (windup)
    is clipped to the view and its peak given in the panel title."""
    fig, axes = _figure(_title(res, "joint torques"), res.n)
    tau_max = res.params["tau_max"]
    for i, ax in enumerate(axes):
        m = float(tau_max[i])
        ax.plot(res.t, res.tau[:, i], color="tab:orange", lw=0.7, alpha=0.8, label="τ, commanded")
        ax.plot(res.t, res.tau_sat[:, i], color="tab:blue", lw=0.9, label="sat(τ), applied")
        ax.axhline(m, color="tab:red", lw=1.0, ls="--", label="±τmax, actuator limit")
        ax.axhline(-m, color="tab:red", lw=1.0, ls="--")
        peak = float(np.max(np.abs(res.tau[:, i]))) if res.rows else 0.0
        title = f"{_joint(i)}: τmax = {m:g} N m"
        if peak > 1.6 * m:
            ax.set_ylim(-1.6 * m, 1.6 * m)
            title += f"; commanded τ clipped to the view, peak |τ| = {peak:.4g} N m"
        ax.set_title(title, fontsize=10, loc="left")
        ax.set_ylabel(f"τ{i + 1} (N m)")
    _legend(fig, axes[0], ncol=3)
    return fig


FIGURES: dict[str, Callable[[Run], Figure]] = {
    "tracking": tracking,
    "errors": errors,
    "torques": torques,
}
"""The kinds of :meth:`adaptimp.SimResult.plot` (the kinds of the paper's Figs. 2–10)."""

PLOT_KINDS = tuple(FIGURES)


def _block_rms(t: np.ndarray, x: np.ndarray, width: float) -> tuple[np.ndarray, np.ndarray]:
    """RMS of ``x`` over consecutive windows of ``width`` seconds, at their centres."""
    if t.size < 2:
        return t, np.abs(x)
    per = max(1, round(width / float(t[1] - t[0])))
    blocks = x.size // per
    if blocks == 0:
        return t[:1], np.sqrt(np.mean(x**2, keepdims=True))
    sq = x[: blocks * per].reshape(blocks, per) ** 2
    centres = t[: blocks * per].reshape(blocks, per).mean(axis=1)
    return centres, np.sqrt(sq.mean(axis=1))


def compare(
    results: Sequence[Run],
    title: str = "tracking error of the three cases",
    window: float = 0.1,
) -> Figure:
    """RMS of z1 over ``window``-second windows (s), per joint, for several runs on
    shared logarithmic axes, so that PD's errors and the adaptive controllers'
    much smaller ones both show."""
    n = results[0].n if results else 2
    fig, axes = _figure(f"{title}: RMS of z1 over {window:g} s windows", n)
    for res in results:
        rms = res.metrics["rms_z1_joint_after2"]
        for i, ax in enumerate(axes):
            tc, r = _block_rms(res.t, res.z1[:, i], window)
            ax.semilogy(
                tc,
                r,
                color=_COLORS.get(res.case),
                lw=1.3,
                label=f"{CASE_NAMES.get(res.case, res.case)}: "
                + ", ".join(f"{r:.2g}" for r in rms)
                + " rad",
            )
    settle = float(results[0].params["settle"]) if results else 0.0
    for i, ax in enumerate(axes):
        _settle_band(ax, results[0])
        ax.set_ylabel(f"{_joint(i)}: RMS z1,{i + 1} (rad)")
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(
        handles,
        labels,
        loc="outside lower center",
        ncol=3,
        fontsize=9,
        frameon=False,
        title=f"RMS z1 per joint over t ≥ {settle:g} s",
        title_fontsize=9,
    )
    return fig


def _mujoco_title(res: Run, kind: str) -> str:
    return f"{res.params['controller']} on {res.params['model']}: {kind}"


def contact(res: MujocoRun) -> Figure:
    """The end-effector force F_e (N, world frame) and ‖τe‖ (N m) of a MuJoCo run."""
    if res.wrench_ee is None:
        raise ValueError("the run has no end-effector wrench (wrench_ee) to plot")
    fig, axes = _figure("end-effector force F_e (world frame) and ‖τe‖", rows=2)
    for i, axis in enumerate("xyz"):
        axes[0].plot(res.t, res.wrench_ee[:, i], lw=1.0, label=f"F_e,{axis}")
    axes[0].set_ylabel("force (N)")
    axes[1].plot(res.t, np.linalg.norm(res.tau_e, axis=1), color="k", lw=1.0, label="‖τe‖")
    axes[1].set_ylabel("‖τe‖ (N m)")
    _legend(fig, axes[0], ncol=3)
    return fig


def _coordinates(res: MujocoRun, width: int) -> list[tuple[str, str]]:
    """The name and unit of each of ``width`` coordinates of a MuJoCo run: the
    joints by their names in the model (rad) for a joint-space quantity, the
    world axes x, y, z (m) for a task-space one (a Cartesian controller's xc,
    xd, z1)."""
    joints = list(res.params.get("joints") or [])
    if width == res.q.shape[1]:
        names = joints if len(joints) == width else [f"joint {i + 1}" for i in range(width)]
        return [(name, "rad") for name in names]
    if width == 3:
        return [(axis, "m") for axis in "xyz"]
    return [(f"x{i + 1}", "") for i in range(width)]


def _unit(unit: str) -> str:
    return f" ({unit})" if unit else ""


def mujoco_tracking(res: MujocoRun) -> Figure:
    """xc and xd per coordinate, with q where the reference is in joint space
    (each joint by its name in the model, rad) and the tip's position where it
    is in task space (the world axes, m)."""
    n = res.z1.shape[1]
    fig, axes = _figure(_mujoco_title(res, "tracking"), rows=n)
    tip = getattr(res, "x_ee", None)
    for i, ((name, unit), ax) in enumerate(zip(_coordinates(res, n), axes)):
        ax.plot(res.t, res.xc[:, i], color="k", lw=1.0, ls="--", label="xc, commanded")
        ax.plot(res.t, res.xd[:, i], color="tab:orange", lw=1.2, label="xd, compliant reference")
        if res.q.shape[1] == n:
            ax.plot(res.t, res.q[:, i], color="tab:blue", lw=1.0, label="q, arm")
        elif n == 3 and tip is not None:
            ax.plot(res.t, tip[:, i], color="tab:blue", lw=1.0, label="p, the tip")
        ax.set_ylabel(f"{name}{_unit(unit)}")
    _legend(fig, axes[0], ncol=3)
    return fig


def mujoco_errors(res: MujocoRun) -> Figure:
    """The tracking error z1 = xd − x per coordinate (each joint by its name,
    rad; or the world axes, m)."""
    n = res.z1.shape[1]
    fig, axes = _figure(_mujoco_title(res, "errors"), rows=n)
    for i, ((name, unit), ax) in enumerate(zip(_coordinates(res, n), axes)):
        ax.plot(res.t, res.z1[:, i], color="tab:blue", lw=0.9, label="z1 = xd − x")
        ax.set_ylabel(f"z1, {name}{_unit(unit)}")
    _legend(fig, axes[0], ncol=3)
    return fig


def mujoco_torques(res: MujocoRun) -> Figure:
    """Commanded and applied torque per joint (by its name, N m), with ±τmax."""
    n = res.q.shape[1]
    fig, axes = _figure(_mujoco_title(res, "torques"), rows=n)
    for i, ((name, _), ax) in enumerate(zip(_coordinates(res, n), axes)):
        m = float(res.params["tau_max"][i])
        ax.plot(res.t, res.tau[:, i], color="tab:orange", lw=0.7, label="τ, commanded")
        ax.plot(res.t, res.tau_sat[:, i], color="tab:blue", lw=0.9, label="sat(τ), applied")
        ax.axhline(m, color="tab:red", lw=1.0, ls="--", label="±τmax")
        ax.axhline(-m, color="tab:red", lw=1.0, ls="--")
        ax.set_ylim(-1.6 * m, 1.6 * m)
        ax.set_ylabel(f"τ, {name} (N m)")
    _legend(fig, axes[0], ncol=3)
    return fig


MUJOCO_FIGURES: dict[str, Callable[[MujocoRun], Figure]] = {
    "tracking": mujoco_tracking,
    "errors": mujoco_errors,
    "torques": mujoco_torques,
    "contact": contact,
}
"""The kinds of ``adaptimp.mujoco.MujocoResult.plot``."""

MUJOCO_PLOT_KINDS = tuple(MUJOCO_FIGURES)


_QUANTITY = {"tracking": ("q", "rad"), "errors": ("z1", "rad"), "torques": ("tau_sat", "N m")}


def into(res: Run, kind: str, ax: Axes | Sequence[Axes]) -> Figure:
    """Draw ``kind`` of ``res`` into ``ax`` (one Axes per joint, or one for all),
    labelled with the case, so that several runs overlay; returns the figure."""
    from matplotlib.axes import Axes as _Axes

    name, unit = _QUANTITY[kind]
    data = getattr(res, name)
    axes = [ax] * res.n if isinstance(ax, _Axes) else list(ax)
    if len(axes) != res.n:
        raise ValueError(f"ax must be one Axes or {res.n} (one per joint), got {len(axes)}")
    single = isinstance(ax, _Axes)
    for i, a in enumerate(axes):
        joint = f", joint {i + 1}" if single and res.n > 1 else ""
        a.plot(
            res.t,
            data[:, i],
            lw=1.0,
            color=None if single else _COLORS.get(res.case),
            label=f"{CASE_NAMES.get(res.case, res.case)}: {name}{joint}",
        )
        if kind == "tracking" and not single:
            a.plot(res.t, res.xc[:, i], color="k", lw=0.8, ls="--")
        a.set_ylabel(f"{name} ({unit})")
        a.set_xlabel("time t (s)")
    fig = axes[0].get_figure()
    assert fig is not None
    return fig  # type: ignore[return-value]
