#!/usr/bin/env bash
# Run every check and test of the project: Rust (format, lints, no_std builds,
# docs, tests, fuzzing), the wheel (built once, tested in a Rust-free
# environment) and Python (ruff, stubs, mypy, the docs site, pytest).
# Works on a fresh machine with Rust (stable and nightly) and Python 3.9+.
#
# What it installs, and where (README "Tests"):
#   apt     cmake, valgrind, g++, libeigen3-dev  (if missing; as root)
#   cargo   cargo-fuzz into ~/.cargo/bin         (if missing)
#   pip     target/build-venv: maturin, ziglang (zig, the wheel's linker), auditwheel
#           target/py-venv:    the wheel with its `test` extra (pytest, hypothesis, ruff,
#                              mypy, pandas, xarray, tqdm, MkDocs, MuJoCo, Pinocchio,
#                              example-robot-data, Dask, pylibfranka, franky-sim)
#           target/wheel-test: the wheel with its `mujoco` extra, without Rust on PATH
#           target/robosuite-venv: the wheel with its `robosuite` extra (robosuite 1.5 on
#                              MuJoCo 3.3, which robosuite runs on), pytest, hypothesis
# Disk it leaves: target/ (Rust builds and the venvs), fuzz/target/, dist/.
#
# ADAPTIMP_VENV=DIR overrides the test environment, PYTHON=... the interpreter,
# ADAPTIMP_FUZZ_SECONDS the time of each fuzz target (default 10).
set -euo pipefail
cd "$(dirname "$0")/.."

step() { printf '\n==> %s  [%d s]\n' "$*" "$SECONDS"; }

# One build cache for everything, no incremental compilation (a test run
# builds once; incremental state only costs time and disk here).
export CARGO_TARGET_DIR="$PWD/target"
export CARGO_INCREMENTAL=0

step "System tools: CMake and valgrind for the C ABI's examples, g++ and Eigen for the Pinocchio peer"
need=()
command -v cmake >/dev/null || need+=(cmake)
command -v valgrind >/dev/null || need+=(valgrind)
command -v g++ >/dev/null || need+=(g++)
[ -e /usr/include/eigen3/Eigen/Core ] || need+=(libeigen3-dev)
if [ ${#need[@]} -gt 0 ]; then
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
        apt-get update -qq && apt-get install -y -qq "${need[@]}" >/dev/null
    else
        echo "please install: ${need[*]}" >&2
        exit 1
    fi
fi
if ! cargo +nightly --version >/dev/null 2>&1; then
    echo "the nightly toolchain is needed for cargo-fuzz (rustup toolchain install nightly)" >&2
    exit 1
fi

step "Rust: format, lints"
cargo fmt --all --check
cargo fmt --manifest-path fuzz/Cargo.toml --check
cargo clippy --quiet --workspace --all-targets -- -D warnings
# The core's dependency tree holds no Python: the bindings are a crate of their own.
if cargo tree --quiet -p adaptimp -e normal,build | grep -E "^.*(pyo3|numpy) v"; then
    echo "the core crate depends on pyo3 or numpy" >&2
    exit 1
fi

step "Rust: no_std builds of the core (firmware: without and with alloc; the simulator), docs"
cargo build --quiet --no-default-features
cargo build --quiet --no-default-features --features alloc
cargo build --quiet --no-default-features --features sim
RUSTDOCFLAGS="-D warnings" cargo doc --workspace --no-deps --quiet

step "Rust: tests (the core, and the C ABI with its header check)"
if command -v cargo-nextest >/dev/null; then
    # Every test in its own process, the binaries in parallel; then the doctests.
    cargo nextest run --workspace --no-fail-fast --status-level fail --final-status-level slow
    cargo test --workspace --doc --quiet
else
    cargo test --workspace --quiet
fi
# The examples under the harness's own arguments (-q, a filter): they must not read them.
cargo test --quiet --examples runs

step "Fuzzing: a short run of each cargo-fuzz target (nightly)"
command -v cargo-fuzz >/dev/null || cargo install --locked --quiet cargo-fuzz
for target in config steps abi urdf; do
    (cd fuzz && CARGO_TARGET_DIR="$PWD/target" cargo +nightly fuzz run -O "$target" -- \
        -max_total_time="${ADAPTIMP_FUZZ_SECONDS:-10}" -timeout=5 -rss_limit_mb=2048 2>&1 |
        grep -E "^Done|ERROR|panicked|SUMMARY")
done

step "Python: the wheel and the sdist (scripts/wheel.sh: maturin, zig for manylinux_2_17)"
bash scripts/wheel.sh
wheel=$(ls dist/adaptimp-*-cp39-abi3-*.whl)
# The sdist holds what a build needs: its crate, unpacked outside this workspace,
# resolves and compiles (check) offline.
# Its own target dir, and the files' times made new: cargo names a path crate's
# artifacts without its path and judges them fresh by the files' times, so the
# tarball's old times beside the workspace's newer build of the same crates
# would check that build, not the sdist's files.
sdist_dir=$(mktemp -d)
tar xzf dist/adaptimp-*.tar.gz -C "$sdist_dir"
find "$sdist_dir" -type f -exec touch {} +
(cd "$sdist_dir"/adaptimp-* &&
    CARGO_TARGET_DIR="$CARGO_TARGET_DIR/sdist-check" cargo check --quiet --offline -p adaptimp-python)
rm -rf "$sdist_dir"

step "Python: the test environment (the wheel with its test extra)"
venv="${ADAPTIMP_VENV:-$PWD/target/py-venv}"
if [ ! -x "$venv/bin/python" ]; then
    "${PYTHON:-python3}" -m venv "$venv"
fi
py="$venv/bin/python"
"$py" -m pip install --quiet --disable-pip-version-check --force-reinstall --no-deps "$wheel"
"$py" -m pip install --quiet --disable-pip-version-check "$wheel[test]"
# adaptimp.franka's tests drive franky-sim's FR3 through pylibfranka: both must be here
# from Python 3.10 on (below it they have no wheels, and those tests skip).
if "$py" -c "import sys; sys.exit(sys.version_info < (3, 10))"; then
    "$py" -c "import pylibfranka, franky_sim"
fi

step "Python: ruff, type stubs, mypy"
"$py" -m ruff check python tests examples benches scripts
"$py" -m ruff format --check python tests examples benches scripts
"$py" -m mypy.stubtest adaptimp._adaptimp
"$py" -m mypy

step "Docs: the site, warnings as errors (MkDocs + mkdocstrings)"
NO_MKDOCS_2_WARNING=1 "$py" -m mkdocs build --strict --quiet

step "The wheel without Rust: installed with its mujoco extra, reproduce and a MuJoCo run"
bash scripts/test_wheel.sh

step "Python: tests"
"$py" -m pytest

step "Python: ADAPTIMP in robosuite (the extra robosuite: robosuite 1.5 on its MuJoCo 3.3, an environment of its own)"
rsvenv="$PWD/target/robosuite-venv"
if [ ! -x "$rsvenv/bin/python" ]; then
    "${PYTHON:-python3}" -m venv "$rsvenv"
fi
"$rsvenv/bin/python" -m pip install --quiet --disable-pip-version-check --force-reinstall --no-deps "$wheel"
"$rsvenv/bin/python" -m pip install --quiet --disable-pip-version-check "$wheel[robosuite]" \
    "pytest>=7" "hypothesis>=6"
"$rsvenv/bin/python" -m pytest tests/test_robosuite.py

step "The core against Pinocchio: benches/peers/peers.cpp built against the pin wheel, every row to 1e-12 (the bench's three arms and three more, the Kinova's joints continuous)"
"$py" benches/peers.py --check --urdf kinova_description/robots/kinova.urdf \
    --urdf z1_description/urdf/z1.urdf --urdf so_arm_description/urdf/so100.urdf
step "done"
