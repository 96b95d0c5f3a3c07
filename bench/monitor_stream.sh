#!/usr/bin/env bash
# The streaming monitor on long streams: rows per second and peak memory of
# `hstlc monitor --online` for 10^5 to 10^7 rows piped in, against `--signal` on the same
# rows read from a file. Usage: bench/monitor_stream.sh [path/to/hstlc]
set -euo pipefail
cd "$(dirname "$0")/.."
hstlc=${1:-target/release/hstlc}
[[ -x $hstlc ]] || cargo build --release --locked -p hstlc
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cat > "$tmp/s.hstl" <<'SPEC'
spec Stream {
    state { x: int in 0..=14, y: int in 0..=14 }
    let A = x > 3 && x < 9 && y > 10 && y < 14;
    let B = x > 1 && x < 5 && y > 1 && y < 5;
    let C = 9 < x < 13 && 1 < y < 7;
    let Window = eventually[0..40] A && eventually[0..40] B && eventually[0..40] C;
    task always[0..] Window;
}
SPEC
# A repeating walk through the three regions, written in blocks (the generator is not
# what is measured: it writes well over 10^7 rows per second).
rows() {
    python3 - "$1" <<'PY'
import sys
n = int(sys.argv[1])
cells = [(x, 12) for x in range(4, 9)] + [(3, y) for y in range(12, 1, -1)] + \
        [(x, 4) for x in range(3, 12)] + [(11, y) for y in range(4, 13)]
block = "".join(f"{x},{y}\n" for x, y in cells * 50)
per = len(cells) * 50
out = sys.stdout
out.write("x,y\n")
full, rest = divmod(n, per)
for _ in range(full):
    out.write(block)
out.write("".join(f"{x},{y}\n" for x, y in (cells * 50)[:rest]))
PY
}
printf '%-10s %-8s %12s %14s %12s\n' rows mode seconds rows/s "max RSS MB"
for n in 100000 1000000 10000000; do
    rows "$n" > "$tmp/t.csv"
    for mode in online signal; do
        if [[ $mode = online ]]; then
            /usr/bin/time -f "%e %M" -o "$tmp/time" "$hstlc" monitor "$tmp/s.hstl" --formula Window \
                --trace - --online < "$tmp/t.csv" > /dev/null
        else
            /usr/bin/time -f "%e %M" -o "$tmp/time" "$hstlc" monitor "$tmp/s.hstl" --formula Window \
                --trace "$tmp/t.csv" --signal > /dev/null
        fi
        read -r secs kb < "$tmp/time"
        python3 -c "import sys; n,s,kb=int(sys.argv[1]),float(sys.argv[2]),int(sys.argv[3]); print(f'{n:<10} {sys.argv[4]:<8} {s:12.2f} {n/max(s,1e-9):14,.0f} {kb/1024:12.1f}')" \
            "$n" "$secs" "$kb" "$mode"
    done
done
