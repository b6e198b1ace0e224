"""Robot descriptions shipped with, or found by, adaptimp (standard library only).

- ``two_link.xml`` (packaged): the paper's 2-link arm as MJCF, SPEC §1.
- The Franka Emika Panda of the ``example-robot-data`` package (installed data,
  no download): its URDF path, joints, limits and reference posture.

Nothing here reads a file or imports MuJoCo or Pinocchio: the core reads
descriptions (:mod:`adaptimp._description`, SPEC §21); :mod:`adaptimp.mujoco`
and :mod:`adaptimp.baselines` build their models from what it reads.
"""

from __future__ import annotations

import importlib.metadata
import os
from pathlib import Path

from ._errors import needs_extra

MODELS_DIR = Path(__file__).resolve().parent / "models"
"""The packaged model files."""

TWO_LINK_XML = MODELS_DIR / "two_link.xml"
"""MJCF of the paper's 2-link arm in a vertical plane (SPEC §1), with a ceiling wall."""

PANDA_JOINTS = tuple(f"panda_joint{i}" for i in range(1, 8))
"""The Panda's seven arm joints, base to flange."""

PANDA_FINGERS = ("panda_finger_joint1", "panda_finger_joint2")
"""The Panda's two prismatic finger joints (locked closed, at 0 m, in every adaptimp model)."""

PANDA_EFFORT = (87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0)
"""The Panda's joint torque limits (N m), the URDF's ``<limit effort>``."""

PANDA_HOME = (0.0, -0.785398, 0.0, -2.35619, 0.0, 1.5707, 0.785398)
"""The Panda's reference posture (rad): the ``default`` state of example-robot-data's SRDF."""

PANDA_EE = "panda_hand_tcp"
"""The Panda's end-effector frame: the tool centre point, 0.1034 m beyond the hand
along its z axis (the SRDF's ``end_effector``)."""

_ERD = "example-robot-data"
_PANDA_URDF = "cmeel.prefix/share/example-robot-data/robots/panda_description/urdf/panda.urdf"


def panda_urdf_path() -> Path:
    """Path of the Panda's URDF in the installed ``example-robot-data`` package.

    The package (data only since its version 4.4; the Python loaders are the
    separate ``example-robot-data-loaders``) installs its robots under its
    ``cmeel.prefix``. ``$ADAPTIMP_PANDA_URDF`` overrides the lookup.

    Raises
    ------
    ImportError
        ``example-robot-data`` is not installed (the extra ``pinocchio``).
    """
    override = os.environ.get("ADAPTIMP_PANDA_URDF")
    if override:
        return Path(override)
    try:
        dist = importlib.metadata.distribution(_ERD)
    except importlib.metadata.PackageNotFoundError as e:
        raise needs_extra("the Panda model", "example-robot-data>=4", "pinocchio") from e
    path = Path(str(dist.locate_file(_PANDA_URDF)))
    if not path.is_file():
        raise ImportError(f"example-robot-data {dist.version} has no Panda URDF at {path}")
    return path
