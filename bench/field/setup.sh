#!/usr/bin/env bash
# Creates the field's venv at bench/field/.venv (gitignored, never used by CI) and fills it:
# torch (CPU), stable-baselines3, gymnasium with MuJoCo (mujoco from PyPI), rtamt (the
# reference monitor), matplotlib (the pictures), and the hstl package built from this
# repository (maturin, release), as scripts/test-python builds it.
#
# `setup.sh --hstl` only rebuilds and reinstalls the hstl package (after a change or a merge).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
venv="$here/.venv"
pip() { "$venv/bin/pip" --disable-pip-version-check "$@"; }
if [ "${1:-}" != "--hstl" ]; then
    python=$(command -v python3.11 || command -v python3)
    [ -x "$venv/bin/python" ] || "$python" -m venv "$venv"
    pip install --quiet --upgrade pip wheel setuptools
    # The CPU-only build where its index is reachable; PyPI's build otherwise (it brings the
    # CUDA libraries, several GB, which the CPU never loads).
    pip install --quiet torch==2.15.0 --index-url https://download.pytorch.org/whl/cpu --timeout 15 \
        2>/dev/null || pip install --quiet torch==2.15.0
    pip install --quiet -r "$here/requirements.txt"
fi
rm -f "$root"/target/wheels-field/hstl-*.whl
(cd "$root/python" && "$venv/bin/maturin" build --release --locked --quiet \
    --out "$root/target/wheels-field" 2>&1 |
    sed '/`build-backend` in pyproject.toml is not set to `maturin`/d')
pip install --quiet --no-deps --force-reinstall "$root"/target/wheels-field/hstl-*.whl
"$venv/bin/python" -c "import hstl, torch, stable_baselines3, gymnasium, mujoco, rtamt, matplotlib; print('bench/field/.venv: hstl', hstl.__version__, 'torch', torch.__version__, 'sb3', stable_baselines3.__version__, 'gymnasium', gymnasium.__version__, 'mujoco', mujoco.__version__)"
