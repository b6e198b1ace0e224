"""State that travels: save what a controller learned, continue it elsewhere,
warm-start a new run with it.

1. A controller is stepped in your loop, pickled mid-run and unpickled (as a
   process pool or Dask would); both continue bit-identically.
2. ``state_dict()`` is saved with ``np.savez``; a new controller loads it and
   continues exactly where the first stopped.
3. A new simulation starts from the learned weights (``weights=``): the first
   seconds of tracking are better than from zero weights.

    python examples/09_state.py

``ADAPTIMP_QUICK=1`` shortens it.
"""

from __future__ import annotations

import argparse
import os
import pickle
import tempfile
import textwrap
from pathlib import Path

import numpy as np

import adaptimp


def main() -> None:
    T = 3.0 if os.environ.get("ADAPTIMP_QUICK") else 20.0
    # 1. Pickle mid-run.
    ctrl = adaptimp.Controller("sf", "robot")
    meas = adaptimp.Measurement([0.3, -0.1], [0.1, 0.2], tau_e=[0.0, 0.0])
    for _ in range(500):
        ctrl.step(meas)
    twin = pickle.loads(pickle.dumps(ctrl))
    same = all(np.array_equal(ctrl.step(meas), twin.step(meas)) for _ in range(500))
    print(f"pickled after 500 steps; the next 500 torques are identical: {same}")

    # 2. state_dict through a file.
    learned = adaptimp.simulate("sf", "robot", T=T)
    ctrl = adaptimp.Controller("sf", "robot")
    ctrl.replay(learned.q, learned.tau_e, learned.dq)  # learn from the run's log
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "learned.npz"
        np.savez(path, **ctrl.state_dict())
        state = dict(np.load(path))
    again = adaptimp.Controller("sf", "robot")
    again.load_state_dict(state)
    print(f"restored at t = {again.t:g} s, ‖Ŵ_G‖ = {np.linalg.norm(again.weights['G']):.4f} N m")

    # 3. A warm start.
    cold = adaptimp.simulate("sf", "robot", T=2.0)
    warm = adaptimp.simulate("sf", "robot", T=2.0, weights=state)
    print(
        f"RMS ‖z1‖ over the first 2 s: from zero weights {cold.metrics['rms_z1']:.5f} rad, "
        f"warm-started {warm.metrics['rms_z1']:.5f} rad"
    )


if __name__ == "__main__":
    # --help: what the example does and how to run it (it takes no arguments).
    doc = (__doc__ or "").split("\n\n")
    argparse.ArgumentParser(
        description=textwrap.fill(" ".join(doc[0].split()), 79),
        epilog="\n\n".join(p for p in doc[1:]),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    ).parse_args()
    main()
