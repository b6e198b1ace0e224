"""Write the reference fixtures the Rust integration tests compare against.

The fixtures come from the independent Python implementations in this folder
(never from the crate), so the Rust tests check the crate against a second
implementation of SPEC.md:

- ``tests/data/pd_paper_2s.csv``: PD, paper scenario, first 2 s, every 400th row
  (PD is not chaotic: trajectories must agree to ~1e-12).
- ``tests/data/steps_sf.csv``, ``steps_of.csv``: the first 400 rows (20 ms) of the
  adaptive cases, before the chaotic closed loops part.
- ``tests/data/paper_metrics.csv``: the SPEC §12 metrics of the full paper
  scenario (numba), to compare the chaotic cases by metrics.

Run from the repository root::

    python benches/reference/make_fixtures.py
"""

from __future__ import annotations

import pathlib
import sys

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import spec_numba  # noqa: E402
import spec_numpy  # noqa: E402

OUT = HERE.parent.parent / "tests" / "data"
COLUMNS = ("q", "dq", "tau", "tau_sat", "tau_e", "zeta", "z1", "xd", "dq_hat")


def _write_rows(path: pathlib.Path, run: dict, rows: np.ndarray) -> None:
    header = ["t"]
    cols = [run["t"][rows][:, None]]
    for name in COLUMNS:
        header += [f"{name}{i + 1}" for i in range(run[name].shape[1])]
        cols.append(run[name][rows])
    header += ["wD", "wC", "wG"]
    cols.append(run["w_norms"][rows])
    np.savetxt(
        path, np.hstack(cols), delimiter=",", header=",".join(header), comments="", fmt="%.17e"
    )


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    pd = spec_numpy.simulate("pd", T=2.0)
    _write_rows(OUT / "pd_paper_2s.csv", pd, np.arange(0, len(pd["t"]), 400))
    for case in ("sf", "of"):
        run = spec_numpy.simulate(case, T=0.02)
        _write_rows(OUT / f"steps_{case}.csv", run, np.arange(len(run["t"])))
    with open(OUT / "paper_metrics.csv", "w") as f:
        f.write("case,metric,value\n")
        for case in ("pd", "sf", "of"):
            metrics = spec_numba.simulate(case)["metrics"]
            for key, value in metrics.items():
                for i, v in enumerate(np.atleast_1d(value)):
                    name = key if np.ndim(value) == 0 else f"{key}[{i}]"
                    f.write(f"{case},{name},{float(v):.17e}\n")
    print(f"fixtures written to {OUT}")


if __name__ == "__main__":
    main()
