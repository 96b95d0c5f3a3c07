#!/usr/bin/env bash
# The Python package's benchmark (not for CI): builds the wheel, installs it with rtamt
# into a throwaway venv (.venv-bench-python), runs the facade's criterion bench of the same
# calls, writes the benchmark walk, and prints the tables of bench.py (extra arguments go
# to it, e.g. --repeats 3 --rtamt-steps 20000), then those of gym_bench.py (GridWorldEnv and
# STLReward steps per second, hstl.train against a release `hstlc train`), and those of
# continuous_bench.py (PlaneEnv and MountainCarEnv, hstl.train on continuous worlds).
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
venv="$root/.venv-bench-python"
cd "$root"
if [ ! -x "$venv/bin/python" ]; then
    python3.11 -m venv "$venv"
    "$venv/bin/pip" install --quiet --disable-pip-version-check maturin==1.16.0 numpy==2.4.6 rtamt==0.4.10
fi
"$venv/bin/python" -c "import gymnasium" 2>/dev/null ||
    "$venv/bin/pip" install --quiet --disable-pip-version-check gymnasium==1.4.0
rm -f target/wheels/hstl-*.whl
(cd python && "$venv/bin/maturin" build --release --locked --quiet --out ../target/wheels)
"$venv/bin/pip" install --quiet --disable-pip-version-check --no-deps --force-reinstall target/wheels/hstl-*.whl
cargo bench --locked -q -p hstl --bench monitor -- --warm-up-time 1 --measurement-time 3
cargo run --release --locked -q -p hstl-robustness --example walk -- target/walk.csv
"$venv/bin/python" bench/python/bench.py target/walk.csv "$@"
cargo build --release --locked -q -p hstlc
"$venv/bin/python" bench/python/gym_bench.py target/release/hstlc
"$venv/bin/python" bench/python/continuous_bench.py target/release/hstlc
