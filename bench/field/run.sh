#!/usr/bin/env bash
# The field side by side (issue 27 item 3): every table and picture of bench/field/RESULTS.md.
# Not for CI. Makes bench/field/.venv with setup.sh on first use. Writes bench/field/out/.
#
#   run.sh [--quick] [--part physics|mountain_car|cartpole|horizons|test]... [--env ID]
#          [--seeds N] [--hstl-seeds N]
#
# --part    only these parts (repeatable; default all of them, in the order above)
# --quick   short budgets (one SB3 seed, a few thousand steps, T = 50 and 200): checks the
#           pipeline end to end in a few minutes; its figures are not results
# --env     the long-horizon environment (default hstl/Plane-v0; field/StandinPlane-v0 is a
#           pure-Python stand-in, whose PPO figures are not the plane's)
# --seeds   SB3 seeds (default 10, as the issue asks), --hstl-seeds hstl's (default 10)
# The horizons part resumes where an earlier call with the same settings stopped (it takes
# hours; see horizons.py).
# SB3 runs under nice -n 10 on one torch thread (the machine is shared).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
py="$here/.venv/bin/python"
[ -x "$py" ] || "$here/setup.sh"
quick=0 parts=() env="hstl/Plane-v0" seeds=10 hseeds=10
while [ $# -gt 0 ]; do
    case "$1" in
        --quick) quick=1 ;;
        --part) parts+=("$2"); shift ;;
        --env) env="$2"; shift ;;
        --seeds) seeds="$2"; shift ;;
        --hstl-seeds) hseeds="$2"; shift ;;
        *) echo "run.sh: unknown argument \`$1\` (see the comment at the top of run.sh)" >&2; exit 2 ;;
    esac
    shift
done
[ ${#parts[@]} -gt 0 ] || parts=(physics mountain_car cartpole horizons)
list() { seq -s, 0 $(($1 - 1)); }
cd "$here"
run() { echo "+ $*" >&2; nice -n 10 "$py" "$@"; }
for part in "${parts[@]}"; do
    case "$part" in
    test)
        nice -n 10 "$here/.venv/bin/pytest" -q -p no:cacheprovider test_field.py ;;
    physics)
        if [ $quick = 1 ]; then run physics.py --steps 2000 --repeats 3; else run physics.py --steps 20000 --repeats 7; fi ;;
    mountain_car|cartpole)
        if [ $quick = 1 ]; then
            s=0 hs=0,1 ladder=1,2,preset ppo=8000 dqn=3000 runs=5 final=10 forms=4000
        else
            s=$(list "$seeds") hs=$(list "$hseeds") ladder=1,2,5,10,20,50,100,preset runs=20 final=100
            if [ "$part" = mountain_car ]; then ppo=1000000 dqn=30000 forms=40000; else ppo=100000 dqn=20000 forms=30000; fi
        fi
        rm -rf "out/patrol/$part"
        run patrol.py --part forms --task "$part" --methods ppo --seeds 0 --budget "$forms" --runs "$runs"
        if [ "$part" = mountain_car ]; then
            run patrol.py --part hstl --task "$part" --seeds "$hs" --ladder "$ladder"
        else
            run patrol.py --part hook --task "$part" --seeds "$s"
        fi
        run patrol.py --part sb3 --task "$part" --methods ppo --seeds "$s" --budget "$ppo" --runs "$runs" --final-runs "$final"
        run patrol.py --part sb3 --task "$part" --methods dqn --seeds "$s" --budget "$dqn" --runs "$runs" --final-runs "$final"
        run patrol.py --part plot --task "$part" ;;
    horizons)
        if [ $quick = 1 ]; then
            run horizons.py --env "$env" --horizons 50,200 --seeds 1 --seconds 10 --eval-runs 20 --fresh --out out/horizons-quick
        else
            run horizons.py --env "$env" --seeds "$seeds" --budget-factor 10
        fi ;;
    *) echo "run.sh: unknown part \`$part\` (physics, mountain_car, cartpole, horizons, test)" >&2; exit 2 ;;
    esac
done
