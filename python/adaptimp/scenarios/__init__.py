"""Scenarios: users of adaptimp's public API, kept apart from it.

A scenario defines a task on an arm and the table of runs that measures it;
the API (:mod:`adaptimp`, :mod:`adaptimp.cartesian`, :mod:`adaptimp.mujoco`,
…) never imports one.

- :mod:`adaptimp.scenarios.panda_table`: the Panda drawing a circle on a table
  while pressing into it (``docs/panda.md``), its controllers and metrics;
- :mod:`adaptimp.scenarios.contact`: the same table for any arm, placed from
  the arm's reach at a posture, with the contact that holds a sliding tool
  (SPEC §19, ``docs/contact.md``).

MuJoCo and Pinocchio are imported when a function needs them.
"""

from __future__ import annotations

__all__ = ["contact", "panda_table"]
