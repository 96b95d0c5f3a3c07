#!/usr/bin/env bash
# Side-by-side timing of the peer STL monitors on the benchmark walk (not for CI).
# Installs them into the repository root's .venv-bench (see setup.sh), writes the walk CSV
# with the hstl-robustness example, and prints a table of samples/s. Extra arguments go to
# peers.py (e.g. --steps 100000 --repeats 1).
#
# `run.sh --dense [ARGS]`: dense time instead. Builds hstl's Python package (maturin) into
# the venv and hstlc (release), writes the dense walk (stamped rows) and runs dense.py:
# hstl's command line and package against rtamt's dense-time monitor and tidystl, D1 to D4.
# Extra arguments go to dense.py (e.g. --steps 20000 --repeats 1).
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
here="$root/bench/peers"
[ -x "$root/.venv-bench/bin/python" ] || "$here/setup.sh"
if [ "${1:-}" = "--dense" ]; then
    shift
    rm -f "$root"/target/wheels/hstl-*.whl
    (cd "$root/python" && "$root/.venv-bench/bin/maturin" build --release --locked --quiet \
        --out "$root/target/wheels")
    "$root/.venv-bench/bin/pip" install --quiet --disable-pip-version-check --no-deps \
        --force-reinstall "$root"/target/wheels/hstl-*.whl
    (cd "$root" && cargo build --release --locked -q -p hstlc)
    walk="$root/target/dense_walk.csv"
    (cd "$root" && cargo run --release -q -p hstl-robustness --example dense_walk -- "$walk")
    "$root/.venv-bench/bin/python" "$here/dense.py" "$walk" "$root/target/release/hstlc" "$@"
    exit
fi
walk="$root/target/walk.csv"
(cd "$root" && cargo run --release -q -p hstl-robustness --example walk -- "$walk")
"$root/.venv-bench/bin/python" "$here/peers.py" "$walk" "$@"
