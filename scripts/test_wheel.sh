#!/usr/bin/env bash
# The wheel as a user without Rust gets it: install dist/adaptimp-*.whl with its
# mujoco extra into a fresh virtual environment whose PATH has no cargo and no
# rustc (and pip may take wheels only: nothing is built), then run
# `adaptimp reproduce` (the paper's digits) and a MuJoCo run from it, and check
# that `auditwheel show` gives the wheel a manylinux tag.
#
#   bash scripts/wheel.sh && bash scripts/test_wheel.sh     # about 1 minute (warm pip cache)
#
# Run by scripts/test.sh after it built the wheel. The environment is
# target/wheel-test (made anew each run).
set -euo pipefail
cd "$(dirname "$0")/.."

fail() { echo "test_wheel: FAILED: $*" >&2; exit 1; }

shopt -s nullglob
wheels=(dist/adaptimp-*-cp39-abi3-*.whl)
[ ${#wheels[@]} -eq 1 ] || fail "expected one wheel in dist/ (bash scripts/wheel.sh), found ${#wheels[@]}"
wheel="$PWD/${wheels[0]}"
auditwheel="${ADAPTIMP_BUILD_VENV:-$PWD/target/build-venv}/bin/auditwheel"

# 1. The platform tag, from the wheel's own symbol versions.
tag=$("$auditwheel" show "$wheel")
grep -q '"manylinux_2_17_x86_64"' <<<"$tag" || fail "auditwheel show: $tag"
echo "auditwheel show: consistent with manylinux_2_17_x86_64"

# 2. A fresh environment without Rust.
dir="$PWD/target/wheel-test"
rm -rf "$dir"
mkdir -p "$dir"
interpreter=$("${PYTHON:-python3}" -c 'import sys; print(sys.executable)')
"$interpreter" -m venv "$dir/venv"
# Only the venv and the system's directories: no ~/.cargo/bin, no rustup.
clean_path="$dir/venv/bin:/usr/local/bin:/usr/bin:/bin"
run() { env -u CARGO_HOME -u RUSTUP_HOME -u CARGO_TARGET_DIR PATH="$clean_path" "$@"; }
for tool in cargo rustc; do
    if run sh -c "command -v $tool" >/dev/null; then
        fail "$tool is on the clean PATH ($clean_path)"
    fi
done
echo "PATH without cargo and rustc: $clean_path"

run "$dir/venv/bin/python" -m pip install --quiet --disable-pip-version-check \
    --only-binary=:all: "$wheel[mujoco]"

# 3. The paper's three cases, from the installed command, to the printed digits.
cd "$dir"
run adaptimp reproduce --out reproduce >reproduce.log
run python - <<'EOF'
import json

metrics = json.load(open("reproduce/metrics.json"))["metrics"]
got = {case: round(m["rms_z1_after2"], 5) for case, m in metrics.items()}
want = {"pd": 0.12802, "sf": 0.00686, "of": 0.00640}
assert got == want, f"RMS ‖z1‖ (t ≥ 2 s): {got}, the paper's digits are {want}"
print(f"adaptimp reproduce: RMS ‖z1‖ (t ≥ 2 s) {got}")
EOF

# 4. MuJoCo as the plant, from the installed package and its extra.
run python - <<'EOF'
import math

import adaptimp
from adaptimp import mujoco as amj

assert "site-packages" in adaptimp.__file__, adaptimp.__file__
res = amj.simulate("sf", "two_link", T=3.0)  # robot scenario, 1 kHz, the ceiling on
rms = res.metrics["rms_z1_after2"]
assert math.isfinite(rms) and rms < 0.05, res.metrics
assert res.metrics["steps_in_contact"] > 0, res.metrics
print(f"MuJoCo (mujoco {amj.mujoco.__version__}), state feedback on two_link, 3 s: "
      f"RMS ‖z1‖ (t ≥ 2 s) = {rms:.4g} rad, {res.metrics['steps_in_contact']} steps in contact")
EOF
echo "test_wheel: passed"
