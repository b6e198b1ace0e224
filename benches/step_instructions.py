"""Instructions a ``Controller.step`` call from Python costs over the same step in
Rust, counted by callgrind (repeatable where timings on a shared machine are not).

Runs of this script under ``valgrind --tool=callgrind`` share the setup of
``benches/python_step.py`` (a logged robot-scenario run, its controller, the
K measurements made from its rows) and then replay the K rows in one
``Controller.replay`` call (``replay``), or take the same K steps one Python
call each on the measurements made (``step``: ``step(m)`` alone), or make
each measurement from the rows' NumPy arrays of shape (n,) in the loop and
step (``measure``: ``step(Measurement(q, dq, tau_e=tau_e))``, as a user's
loop does); the difference of two totals over K is the cost of a Python call
over the Rust step::

    for mode in replay step measure; do
      valgrind --tool=callgrind --callgrind-out-file=/tmp/cg.$mode \\
        target/py-venv/bin/python benches/step_instructions.py $mode --n 2
    done
    callgrind_annotate /tmp/cg.replay | head -3; callgrind_annotate /tmp/cg.step | head -3

(the totals are on the line "PROGRAM TOTALS"; divide their difference by K).
"""

from __future__ import annotations

import argparse

from python_step import setup

import adaptimp
from adaptimp import Measurement


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("mode", choices=["replay", "step", "measure"])
    ap.add_argument("--rows", type=int, default=2000, help="K (default 2000)")
    ap.add_argument("--n", type=int, default=2)
    args = ap.parse_args()
    log, kw = setup(args.rows, args.n)
    q, tau_e, dq = log.q[: args.rows], log.tau_e[: args.rows], log.dq[: args.rows]
    rows = list(zip(q, tau_e, dq))
    made = [Measurement(a, c, tau_e=b) for a, b, c in rows]
    ctrl = adaptimp.Controller("sf", "robot", **kw)
    step, measurement = ctrl.step, Measurement
    if args.mode == "replay":
        ctrl.replay(q, tau_e, dq)
    elif args.mode == "step":
        for m in made:
            step(m)
    else:
        for a, b, c in rows:
            step(measurement(a, c, tau_e=b))


if __name__ == "__main__":
    main()
