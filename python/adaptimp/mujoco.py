"""MuJoCo as the plant: real arms, contact from a physics engine (SPEC §13).

Needs the optional dependency MuJoCo (the extra ``mujoco``: ``pip install ".[mujoco]"``); the
rest of adaptimp never imports it.

- :class:`Plant` wraps a MuJoCo model of a serial arm with n ≤ 7 hinge joints,
  one torque actuator (``motor``) per joint: it reads τmax from the actuators'
  ``ctrlrange`` and says where the core's loop measures the force the arm
  exerts on its environment (mapped to joint space as τe = Jᵀ F_e); MuJoCo's
  constraint solver computes contact.
- :func:`simulate` closes the loop, the core's (SPEC §13.1): any controller
  with ``.step(m, **setpoint)`` (``m`` an :class:`adaptimp.Measurement`) and a period ``.Ts`` (s)
  (:class:`ControllerLike`, called back once a period), or one of the
  paper's cases by name, runs at Ts with the torque held over ``substeps``
  MuJoCo steps; returns a :class:`MujocoResult` with the SPEC §12 metrics.
- Models: :func:`two_link` (the paper's arm, packaged as ``models/two_link.xml``),
  :func:`panda` (the Franka Emika Panda of ``example-robot-data``, arm only, on a
  table), :func:`from_urdf` (any URDF arm, with motors from its effort limits).

The measured wrench. If the model has a ``force`` sensor, its site is the
end effector and F_e is read from it (with the ``torque`` sensor on the same
site, if any, for the moment; without one the moment is taken as zero).
MuJoCo's force/torque sensors measure the wrench between the site's body and
its parent, so the site should sit on a massless body welded to the last
link, holding the contact geometry: then the reading is exactly the contact
wrench (the packaged models do this). Without a force sensor, F_e is the net
force of the active contacts between the end-effector body's subtree and
anything outside it, with the moment about the end-effector point (the
plant's ``tip``, by default a site on the last arm joint's body, else its
origin): for a model :class:`Plant` loads from a file and in which no
contact can arise inside that subtree, from a contact sensor it adds (the
net contact wrench on the subtree, ``reduce="netforce"``; it changes no
dynamics); otherwise from the external forces MuJoCo sums from its contact
list on each body of the subtree (``cfrc_ext``: a contact inside the subtree
cancels). :attr:`Plant.wrench_source` says which is used.

Units: rad, rad/s, rad/s², N, N m, m, s. Vectors in the world frame.

The package's modules behind it, one responsibility each: the arms
(:mod:`adaptimp._plant_models`), the plant and its preparation
(:mod:`adaptimp._plant`, :mod:`adaptimp._mjcf`), tasks and postures
(:mod:`adaptimp._tasks`, :mod:`adaptimp._cartesian_task`), the run
(:mod:`adaptimp._run`: set-up; :mod:`adaptimp._loops`: dispatch;
:mod:`adaptimp._mujoco_result`, :mod:`adaptimp._run_checks`: results).
"""

from __future__ import annotations

from ._errors import needs_extra

try:
    import mujoco  # noqa: F401  (the extra, checked before the modules that need it)
except ImportError as e:  # pragma: no cover - depends on the environment
    raise needs_extra("adaptimp.mujoco", "mujoco>=3", "mujoco") from e

# Every name this module had, re-exported from where it now lives (explicitly:
# ``X as X``), so that nothing a user imports from adaptimp.mujoco moves.
# Names importable from this module before it was split (its own imports),
# kept so; EFFORT_ACCEL is the core's (SPEC §18, the effort estimate).
from ._adaptimp import EFFORT_ACCEL as EFFORT_ACCEL
from ._cartesian_task import (
    CartesianTask as CartesianTask,
)
from ._cartesian_task import (
    chain_of as chain_of,
)
from ._cartesian_task import (
    collision as collision,
)
from ._cartesian_task import (
    measure as measure,
)
from ._cartesian_task import (
    self_collision as self_collision,
)
from ._cartesian_task import (
    task_of as task_of,
)
from ._errors import ConfigError as ConfigError
from ._errors import (
    PlantWarning as PlantWarning,
)
from ._errors import no_file as no_file
from ._faults import Fault as Fault
from ._inputs import reals as reals
from ._loops import (
    DISTURBANCES as DISTURBANCES,
)
from ._mujoco_result import (
    ARRAYS as ARRAYS,
)
from ._mujoco_result import (
    PLOT_KINDS as PLOT_KINDS,
)
from ._mujoco_result import (
    MujocoResult as MujocoResult,
)
from ._params import loop_delay as loop_delay
from ._plant import (
    Plant as Plant,
)
from ._plant import (
    holding_controls as holding_controls,
)
from ._plant import (
    mocap_welds as mocap_welds,
)
from ._plant_models import (
    MAX_JOINTS as MAX_JOINTS,
)
from ._plant_models import (
    FloatArray as FloatArray,
)
from ._plant_models import (
    ModelSource as ModelSource,
)
from ._plant_models import (
    estimate_effort as estimate_effort,
)
from ._plant_models import (
    from_urdf as from_urdf,
)
from ._plant_models import (
    moving_mass as moving_mass,
)
from ._plant_models import (
    panda as panda,
)
from ._plant_models import (
    two_link as two_link,
)
from ._plant_models import (
    with_payload as with_payload,
)
from ._plot import MUJOCO_FIGURES as MUJOCO_FIGURES
from ._plot import MUJOCO_PLOT_KINDS as MUJOCO_PLOT_KINDS
from ._pose import call_shape as call_shape
from ._pose import task_space as task_space
from ._result import SimResult as SimResult
from ._run import (
    MAX_SUBSTEPS as MAX_SUBSTEPS,
)
from ._run import (
    ControllerLike as ControllerLike,
)
from ._run import (
    simulate as simulate,
)
from ._run_checks import (
    RUN_CONTACT_EVERY as RUN_CONTACT_EVERY,
)
from ._run_checks import (
    RUN_PEAK as RUN_PEAK,
)
from ._run_checks import (
    RUN_SATURATED as RUN_SATURATED,
)
from ._run_checks import (
    RUN_SETTLE as RUN_SETTLE,
)
from ._run_checks import (
    RUN_TRACKING as RUN_TRACKING,
)
from ._run_checks import (
    scene_contact_findings as scene_contact_findings,
)
from ._run_checks import (
    torque_findings as torque_findings,
)
from ._tasks import (
    HOME_CLEARANCE as HOME_CLEARANCE,
)
from ._tasks import (
    HOME_LOAD as HOME_LOAD,
)
from ._tasks import (
    HOME_SAMPLES as HOME_SAMPLES,
)
from ._tasks import (
    SWING_SAMPLES as SWING_SAMPLES,
)
from ._tasks import (
    TASK_AMPLITUDE as TASK_AMPLITUDE,
)
from ._tasks import (
    Task as Task,
)
from ._tasks import (
    cartesian_task as cartesian_task,
)
from ._tasks import (
    default_task as default_task,
)
from ._tasks import (
    home_posture as home_posture,
)
from ._tasks import (
    rule_coupled as rule_coupled,
)
from ._tasks import (
    rule_keywords as rule_keywords,
)
from ._tooling import add_table as add_table
from ._tooling import add_tool as add_tool
from ._trajectory import (
    Reference as Reference,
)
from ._trajectory import (
    paper_circle as paper_circle,
)
from ._trajectory import (
    sinusoid as sinusoid,
)

__all__ = [
    "MAX_JOINTS",
    "CartesianTask",
    "ControllerLike",
    "MujocoResult",
    "Plant",
    "Reference",
    "Task",
    "cartesian_task",
    "chain_of",
    "collision",
    "default_task",
    "estimate_effort",
    "from_urdf",
    "home_posture",
    "moving_mass",
    "panda",
    "paper_circle",
    "rule_coupled",
    "rule_keywords",
    "self_collision",
    "simulate",
    "sinusoid",
    "two_link",
    "with_payload",
]
