#!/usr/bin/env bash
# The slow tier, outside CI (about 1 h 30 min on 2 cores): a 1 h soak of the
# robot scenario (SOAK_HOURS=24 for a day); the default route of
# docs/your_arm.md for 600 s on the UR5 and the Panda (tracking error and
# weight norms over time, about a minute each; needs the test venv, made by
# scripts/test.sh, or ADAPTIMP_VENV); then a longer fuzzing session of each
# target (ADAPTIMP_FUZZ_SECONDS each, default 300; needs the nightly
# toolchain, installs cargo-fuzz into ~/.cargo/bin if missing).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo run --release --example soak -- "${SOAK_HOURS:-1}"

py="${ADAPTIMP_VENV:-target/py-venv}/bin/python"
"$py" examples/15_your_arm.py --long 600
"$py" examples/15_your_arm.py "$("$py" -c 'from adaptimp._models import panda_urdf_path as p; print(p())')" --long 600

command -v cargo-fuzz >/dev/null || cargo install --locked --quiet cargo-fuzz
for target in config steps abi; do
    (cd fuzz && cargo +nightly fuzz run -O "$target" -- \
        -max_total_time="${ADAPTIMP_FUZZ_SECONDS:-300}" -timeout=5 -rss_limit_mb=2048 2>&1 |
        grep -E "^Done|ERROR|panicked|SUMMARY")
done
