#!/usr/bin/env bash
# The slow tier, outside CI (about 12 minutes on 2 cores): a 1 h soak of the
# robot scenario, and a short fuzzing session of each target (needs the
# nightly toolchain; installs cargo-fuzz if missing).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo run --release --example soak -- "${SOAK_HOURS:-1}"
# The default route of docs/your_arm.md for 600 s on the UR5 and the Panda:
# tracking error and weight norms over time (about a minute each).
py="${ADAPTIMP_VENV:-target/py-venv}/bin/python"
"$py" examples/15_your_arm.py --long 600
"$py" examples/15_your_arm.py "$("$py" -c 'from adaptimp._models import panda_urdf_path as p; print(p())')" --long 600
