"""The tool and the table added to a MuJoCo model (an ``MjSpec``): one builder
for :func:`adaptimp.mujoco.panda` and the table scenario
(:mod:`adaptimp.scenarios.contact`).

- :func:`add_tool`: a sphere (the arm's contact geometry) with the site ``ee``
  and the force/torque sensors ``ee_force``, ``ee_torque`` at the origin of a
  body, on it or on a massless body of its own (whose force sensor then reads
  the contact alone);
- :func:`add_table`: a 0.7 × 1.0 m box whose top is at a height, static or on
  a vertical spring.

Settings left at None keep MuJoCo's defaults. Units: m, kg, N/m, s.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import mujoco

__all__ = ["GRAVITY", "TABLE_SIZE", "TABLE_THICKNESS", "add_table", "add_tool", "unused_body"]

TABLE_SIZE = (0.35, 0.5)
"""Half the table's depth and width (m): 0.7 × 1.0 m."""

TABLE_THICKNESS = 0.05
"""The table's thickness (m)."""

GRAVITY = 9.81
"""MuJoCo's default gravity (m/s²): a spring table's preload carries its weight."""


def unused_body(spec: Any, name: str) -> str:
    """``name``, or ``name_1``, ``name_2``, … if the model already has a body of
    that name (a URDF link called "tool" or "table")."""
    return _unused(spec.body, name)


def _unused(find: Any, name: str) -> str:
    """``name``, or ``name_1``, ``name_2``, … the first that ``find`` (an
    ``MjSpec``'s lookup by name: ``spec.site``, ``spec.sensor``, …) does not find."""
    i, candidate = 0, name
    while find(candidate) is not None:
        i += 1
        candidate = f"{name}_{i}"
    return candidate


def add_tool(
    spec: Any,
    body: str,
    *,
    radius: float,
    own_body: bool,
    friction: Sequence[float] | None = None,
    solref: Sequence[float] | None = None,
) -> tuple[str, str]:
    """The tool at the origin of ``body``: a sphere ``tool`` of ``radius`` (m),
    massless, that collides; the site ``ee`` and its sensors ``ee_force``,
    ``ee_torque`` (each name with ``_1``, ``_2``, … if the model has it
    already). ``own_body``: on a massless body ``tool`` of its own (the force
    sensor then reads the contact alone; on a body with mass it would add the
    weight). ``friction``, ``solref``: the sphere's (None: MuJoCo's). Returns
    the names of the site and of the sphere."""
    parent = spec.body(body)
    if parent is None:
        raise ValueError(f"the model has no body {body!r} for the tool")
    holder = parent.add_body(name=unused_body(spec, "tool")) if own_body else parent
    site = _unused(spec.site, "ee")
    sphere = _unused(spec.geom, "tool")
    holder.add_site(name=site, size=[0.01, 0, 0])
    geom = holder.add_geom(
        name=sphere,
        type=mujoco.mjtGeom.mjGEOM_SPHERE,
        size=[radius, 0, 0],
        contype=1,
        conaffinity=1,
        mass=0.0,
        density=0.0,
    )
    if friction is not None:
        geom.friction = list(friction)
    if solref is not None:
        geom.solref = list(solref)
    for name, kind in (("ee_force", "mjSENS_FORCE"), ("ee_torque", "mjSENS_TORQUE")):
        spec.add_sensor(
            name=_unused(spec.sensor, name),
            type=getattr(mujoco.mjtSensor, kind),
            objtype=mujoco.mjtObj.mjOBJ_SITE,
            objname=site,
        )
    return site, sphere


def add_table(
    spec: Any,
    *,
    top: float,
    centre: Sequence[float],
    friction: Sequence[float] | None = None,
    solref: Sequence[float] | None = None,
    mass: float | None = None,
    spring: float | None = None,
    yaw: float = 0.0,
) -> tuple[str, str]:
    """A table (a box of :data:`TABLE_SIZE` and :data:`TABLE_THICKNESS`, geom
    ``table``) whose top is at height ``top`` (m), centred at ``centre`` (x,
    y), turned by ``yaw`` (rad) about the vertical (its first side along the
    direction ``yaw`` from the world's x axis); static, or with ``spring``
    (N/m) on a vertical slide joint ``table_spring``, critically damped for
    its ``mass`` (kg) and preloaded by its weight (at rest the top is at
    ``top``). Returns the names of its body
    and its geom."""
    name = unused_body(spec, "table")
    body = spec.worldbody.add_body(
        name=name, pos=[float(centre[0]), float(centre[1]), top - TABLE_THICKNESS / 2]
    )
    if yaw != 0.0:
        body.quat = [math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)]
    if spring is not None:
        m = 1.0 if mass is None else mass
        body.add_joint(
            name="table_spring",
            type=mujoco.mjtJoint.mjJNT_SLIDE,
            axis=[0, 0, 1],
            stiffness=spring,
            damping=2.0 * math.sqrt(spring * m),
            springref=m * GRAVITY / spring,
        )
    box = _unused(spec.geom, "table")
    geom = body.add_geom(
        name=box,
        type=mujoco.mjtGeom.mjGEOM_BOX,
        size=[TABLE_SIZE[0], TABLE_SIZE[1], TABLE_THICKNESS / 2],
        contype=1,
        conaffinity=1,
        rgba=[0.6, 0.5, 0.4, 1.0],
    )
    if friction is not None:
        geom.friction = list(friction)
    if solref is not None:
        geom.solref = list(solref)
    if mass is not None:
        geom.mass = mass
    return name, box
