#!/usr/bin/env bash
# Build the Python package's wheel and sdist into dist/:
#
#   dist/adaptimp-<version>-cp39-abi3-manylinux_2_17_x86_64.whl   (CPython >= 3.9, one wheel
#                                                                   for every version: abi3)
#   dist/adaptimp-<version>.tar.gz                                 (the sdist: needs Rust)
#
# The wheel is built by maturin in release mode and linked by zig for glibc 2.17
# (manylinux2014), so it installs on any x86-64 Linux of the last decade without Rust.
# maturin and zig come from PyPI (the `maturin` and `ziglang` packages) into a build
# environment under target/ (override with ADAPTIMP_BUILD_VENV=DIR, the interpreter
# with PYTHON=...); nothing else is downloaded. Rust's build cache is target/
# (CARGO_TARGET_DIR). About 3 minutes on 2 cores from a cold target/.
#
#   bash scripts/wheel.sh            # both
#   bash scripts/wheel.sh --check    # also `auditwheel show` on the wheel
set -euo pipefail
cd "$(dirname "$0")/.."

venv="${ADAPTIMP_BUILD_VENV:-$PWD/target/build-venv}"
if [ ! -x "$venv/bin/maturin" ] || [ ! -x "$venv/bin/auditwheel" ] ||
    ! "$venv/bin/python" -c "import ziglang" 2>/dev/null; then
    "${PYTHON:-python3}" -m venv "$venv"
    "$venv/bin/python" -m pip install --quiet --disable-pip-version-check \
        "maturin>=1.9,<2" "ziglang>=0.13" "auditwheel>=6"
fi
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$PWD/target}"
# maturin finds zig as `python -m ziglang` of the interpreter on PATH.
export PATH="$venv/bin:$PATH"

version=$(sed -n 's/^version = "\(.*\)"/\1/p' Cargo.toml | head -n 1)
rm -f "dist/adaptimp-$version-"*.whl "dist/adaptimp-$version.tar.gz"
maturin build --release --zig --compatibility manylinux2014 --out dist --quiet
maturin sdist --out dist >/dev/null 2>&1 || maturin sdist --out dist

wheel=$(ls "dist/adaptimp-$version-"*.whl)
sdist="dist/adaptimp-$version.tar.gz"
printf '%s\n%s\n' "$wheel" "$sdist"
if [ "${1:-}" = "--check" ]; then
    auditwheel show "$wheel"
fi
