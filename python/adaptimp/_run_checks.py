"""The checks after a run of :func:`adaptimp.mujoco.simulate` (SPEC §18.10):
tracking, delay, refused steps, saturation and peaks, contacts with the
scene and of the arm with itself, each a warning naming what it found.

Units: rad, N m, s."""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence

import mujoco
import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _contacts
from ._errors import PlantWarning
from ._faults import Fault
from ._loops import Run
from ._mujoco_result import MujocoResult
from ._plant import Plant, uses_rule
from ._pose import task_space

FloatArray = NDArray[np.float64]

RUN_TRACKING = 0.5
"""A joint-space run whose RMS tracking error over t ≥ settle exceeds this share
of the reference's own RMS motion there says so (:func:`simulate`'s check)."""


def check_tracking(run: Run, res: MujocoResult) -> None:
    """A joint-space run on an arm whose arm did not follow its task says so
    (a :class:`adaptimp.PlantWarning`, also in ``res.params["warnings"]``):
    the RMS ‖z1‖ over t ≥ settle beyond :data:`RUN_TRACKING` of the RMS of the
    reference's motion about its mean over the same rows (an arm that sags
    or rings through its task, whatever the reason: gains too low for its
    load, a delay that leaves little bandwidth, SPEC (18.11))."""
    if not uses_rule(run.plant) or task_space(run.ctrl) or res.rows == 0:
        return
    rows = res.t >= run.settle - 1e-12
    if not np.any(rows) or res.xc.shape != res.q.shape:
        return
    xc = res.xc[rows]
    motion = float(np.sqrt(np.mean(np.sum((xc - xc.mean(axis=0)) ** 2, axis=1))))
    error = float(res.metrics.get("rms_z1_after2", math.nan))
    if not (motion > 0 and error > RUN_TRACKING * motion):
        return
    text = (
        f"the arm did not follow its task: RMS tracking error {error:.3g} rad over "
        f"t ≥ {run.settle:g} s, more than {RUN_TRACKING:g} of the reference's own RMS motion "
        f"{motion:.3g} rad (gains too low for the load or the loop's delay, SPEC (18.11))"
    )
    res.params.setdefault("warnings", []).append(text)
    warnings.warn(text, PlantWarning, stacklevel=3)


def check_delay(res: MujocoResult) -> None:
    """SPEC (18.11): a controller made for a shorter delay than the plant's
    says so (a :class:`adaptimp.PlantWarning`, also in
    ``res.params["warnings"]``): its velocity loop's gains are sized for a
    loop that answers sooner than this one does, and may ring."""
    made, plant = res.params.get("delay"), int(res.params.get("plant_delay", 0))
    if made is None or made >= plant:
        return
    text = (
        f"the controller was made for a loop delay of {made} period(s), the plant's is "
        f"{plant}: its velocity loop may ring (SPEC (18.11)); build it with delay={plant}, "
        f"or give simulate delay={plant} and a case name"
    )
    res.params.setdefault("warnings", []).append(text)
    warnings.warn(text, PlantWarning, stacklevel=3)


def check_refused(res: MujocoResult, fault: Fault | None) -> None:
    """Steps refused where no fault was injected, said (a
    :class:`adaptimp.PlantWarning`, in ``res.params["warnings"]``): with a
    fault configured a refused step applies the fallback and the run goes
    on, and a controller whose every torque was refused (a step that returned
    NaN) ran 200 of 200 rows at zero torque with no word."""
    if res.refused is None or not res.refused.any():
        return
    t = res.t
    outside = res.refused.copy()
    if fault is not None:
        start = float(fault.start)
        end = start + float(fault.duration or 0.0)
        outside &= (t < start - 1e-12) | (t >= end - 1e-12)
    if not outside.any():
        return
    first = float(t[np.flatnonzero(outside)[0]])
    text = (
        f"{int(outside.sum())} of {res.rows} recorded steps were refused"
        f"{' outside the fault' if fault is not None else ''} (the first at t = {first:.3f} s): "
        "the controller's step failed there (a torque or a measurement that was not finite, "
        "or beyond its limits) and its fallback was applied"
    )
    res.params.setdefault("warnings", []).append(text)
    warnings.warn(text, PlantWarning, stacklevel=3)


RUN_PEAK = 2.0
"""A run whose commanded |τ_i| exceeds this many τmax_i after :data:`RUN_SETTLE`
says so (:func:`simulate`'s check)."""

RUN_SETTLE = 0.1
"""The start (s) of the peak-torque check."""

RUN_SATURATED = 0.01
"""A run whose torque is at a limit in more than this share of its steps says so."""

RUN_CONTACT_EVERY = 0.01
"""The spacing (s) of the recorded rows at which a run's self-contact is checked."""


def check_run(run: Run, res: MujocoResult) -> None:
    """What a run found that its numbers alone do not say (SPEC §18, §18.10),
    as :class:`adaptimp.PlantWarning` and in ``res.params["warnings"]``: the
    arm touching itself (rows every :data:`RUN_CONTACT_EVERY` s replayed
    through MuJoCo's collision detection); the arm touching the rest of the
    scene (another arm, a pedestal, the table, a free body: the plant's
    watched contacts, at the end of every period; a contact task's own
    surface is not watched); a commanded torque beyond :data:`RUN_PEAK` τmax
    after :data:`RUN_SETTLE` s; the torque at a limit in more than
    :data:`RUN_SATURATED` of the steps. Every run is checked, in contact or
    not, joint or Cartesian. ``res.params["plant"]`` is what the plant made
    of the model (:attr:`Plant.notes`). Not for the paper's arm, whose
    scenario saturates by design."""
    plant = run.plant
    res.params["plant"] = dict(plant.notes)
    found: list[str] = []
    if uses_rule(plant) and res.rows > 0:
        found += _self_contact(plant, res)
    if plant.watch is not None and uses_rule(plant):
        found += _scene_contact(plant, int(res.metrics.get("rows", run.steps)), run.Ts)
    if uses_rule(plant) and res.rows > 0:
        found += torque_findings(res.t, res.tau, plant.tau_max, plant.joint_names,
                                 float(res.metrics.get("sat_duty", math.nan)))  # fmt: skip
    res.params["warnings"] = found
    for text in found:
        warnings.warn(text, PlantWarning, stacklevel=3)


def torque_findings(
    t: FloatArray,
    tau: FloatArray,
    tau_max: ArrayLike,
    joints: Sequence[str],
    sat_duty: float,
) -> list[str]:
    """The torque checks of every run (SPEC §18): the commanded |τ_i| (N m,
    rows ``tau`` at times ``t``, s) beyond :data:`RUN_PEAK` τmax_i after
    :data:`RUN_SETTLE` s, and the torque at a limit in more than
    :data:`RUN_SATURATED` of the steps (``sat_duty``, the run's metric)."""
    found: list[str] = []
    limit = np.asarray(tau_max, dtype=np.float64)
    late = np.flatnonzero(np.asarray(t) >= RUN_SETTLE - 1e-12)
    if late.size:
        ratio = np.abs(np.asarray(tau)[late]) / limit
        k, i = np.unravel_index(int(np.argmax(ratio)), ratio.shape)
        if ratio[k, i] > RUN_PEAK:
            found.append(
                f"the commanded torque reached {ratio[k, i]:.3g} τmax after {RUN_SETTLE:g} s "
                f"(joint {joints[int(i)]!r} at t = {t[late[k]]:.3f} s), beyond "
                f"{RUN_PEAK:g} τmax: the controller asks far more than the actuators give"
            )
    if sat_duty > RUN_SATURATED:
        found.append(
            f"the torque was at a limit in {100 * sat_duty:.1f} % of the steps (more than "
            f"{100 * RUN_SATURATED:g} %): the actuators saturate, so the tracking measured is "
            "theirs as much as the controller's"
        )
    return found


def _scene_contact(plant: Plant, rows: int, Ts: float) -> list[str]:
    """The warning of a run in which the arm touched the rest of the scene
    (the plant's watched contacts, SPEC §18.10), if it did."""
    assert plant.watch is not None
    return scene_contact_findings(plant.watch.found(plant.data), rows, Ts)


def scene_contact_findings(
    found: Sequence[tuple[str, str, int, float, int]], rows: int, Ts: float
) -> list[str]:
    """The warning for watched contacts ``found`` ((arm body, other body,
    periods in contact, peak force N, its row), :class:`adaptimp._contacts.Watch`)
    over a run of ``rows`` periods of ``Ts`` s: the pairs by name, most
    steps first, each with its share of the steps, its peak force and when."""
    if not found or rows <= 0:
        return []
    pairs: dict[tuple[str, str], list[float]] = {}
    for a, b, count, peak, row in found:
        key = (a, b)
        old = pairs.get(key)
        if old is None:
            pairs[key] = [count, peak, row]
        else:  # one pair watched twice (a body and a subtree): the larger
            old[0] = max(old[0], count)
            if peak > old[1]:
                old[1], old[2] = peak, row
    order = sorted(pairs.items(), key=lambda kv: (-kv[1][0], -kv[1][1]))
    said = "; ".join(
        f"{a!r}–{b!r} in {100 * c / rows:.1f} % of the steps, up to {f:.3g} N "
        f"(t = {(r + 1) * Ts:.3f} s)"
        for (a, b), (c, f, r) in order[:3]
    )
    more = f"; and {len(order) - 3} more pairs" if len(order) > 3 else ""
    return [
        f"the arm touched the rest of the scene: {said}{more}: the task runs into what is "
        "around the arm, so the tracking measured is the contact's as much as the "
        "controller's; give another home= or reference, or move what is in the way"
    ]


def _self_contact(plant: Plant, res: MujocoResult) -> list[str]:
    """The warning of a run in which the arm touched itself, if it did."""
    m = plant.model
    if m.opt.disableflags & int(mujoco.mjtDisableBit.mjDSBL_CONTACT):
        return []
    contacts = _contacts.Contacts(m, plant.data.qpos, plant.joint_ids, self_only=True)
    if not contacts.possible:
        return []
    dt = float(res.t[1] - res.t[0]) if res.rows > 1 else 1.0
    stride = max(1, round(RUN_CONTACT_EVERY / dt))
    rows = range(0, res.rows, stride)
    touched: list[tuple[str, str, float]] = []
    first, hits = math.nan, 0
    for k in rows:
        found = contacts.at(res.q[k])
        if found:
            hits += 1
            touched += found
            if math.isnan(first):
                first = float(res.t[k])
    if not hits:
        return []
    return [
        f"the arm touched itself in {100 * hits / len(rows):.1f} % of the rows checked "
        f"({_contacts.pairs(touched)}; first at t = {first:.3f} s): its own links collide along "
        "this task; give another home= or reference (or contact=False)"
    ]
