#!/usr/bin/env bash
# Viewer benchmark (issue #16): frames per second of a scripted 100-frame orbit at full
# resolution (--no-preview), the time from a mode key to that mode's first frame, and the
# longest gap between presented frames while the next time step is built.
# usage: bench_view.sh BIN "ISAS" "SCENES" "SIZES"   e.g. bench_view.sh target/release/bnsview "avx512 avx2" "nanobowl ns740k" "1024 512"
# MODES="" leaves out the orbits (only the key latencies). Needs a display: DISPLAY set, else run it under `xvfb-run -a`.
set -euo pipefail
B=$1; ISAS=$2; SCENES=$3; SIZES=$4
D=/tmp/bench_view; mkdir -p $D
orbit=$D/orbit.txt; { echo wait-still; for i in $(seq 100); do echo "orbit 3.6 0"; echo "wait-frames 1"; done; echo quit; } > $orbit
key=$D/key.txt; { echo wait-still; for k in 3 1 3 1 3 1; do echo "key $k"; echo "wait-frames 1"; echo wait-still; done; echo quit; } > $key
fps() { python3 - "$1" <<'PY'
import json, sys
L = [json.loads(l) for l in open(sys.argv[1])]
p = [l for l in L if 'presented' in l][1:]          # the orbit's frames
print(f"{len(p)} frames {len(p) / (p[-1]['t'] - p[0]['t'] + p[0]['render_s']):.1f} fps (mean render {1e3 * sum(l['render_s'] for l in p) / len(p):.1f} ms)")
PY
}
latency() { python3 - "$1" <<'PY'
import json, sys
L = [json.loads(l) for l in open(sys.argv[1])]
out = []
for i, l in enumerate(L):
    if 'key' in l:
        nxt = next(m for m in L[i + 1:] if 'presented' in m)
        full = next(m for m in L[i + 1:] if 'presented' in m and m['scale'] == 1)
        out.append(f"{nxt['t'] - l['t']:.3f}/{full['t'] - l['t']:.3f}")
print("key to first frame / to full frame (s):", " ".join(out))
PY
}
for sc in $SCENES; do
  for isa in $ISAS; do
    for mode in ${MODES-bs vol+bs}; do
      for s in $SIZES; do
        $B --isa $isa view --scene $sc --mode $mode --size ${s}x${s} --no-preview --script $orbit --log $D/o.jsonl
        echo "$sc $isa $mode ${s}x${s}: $(fps $D/o.jsonl)"
      done
    done
    s=${SIZES%% *}
    $B --isa $isa view --scene $sc --size ${s}x${s} --script $key --log $D/k.jsonl
    echo "$sc $isa ${s}x${s} keys 3/1 (vol+bs/bs), previews on: $(latency $D/k.jsonl)"
  done
done
# PLAY=trajectory: play it while orbiting 300 frames at full resolution (each size), the
# longest gap between two of those frames while a time step was being built, beside the
# median render time; then the same orbit without playing (no build), to compare each frame
# with itself undisturbed. Also the time from start to the first frame (the first build).
if [ -n "${PLAY:-}" ]; then
  { echo wait-still; echo "key space"; for i in $(seq 300); do echo "orbit 1 0"; echo "wait-frames 1"; done; echo wait-still; echo quit; } > $D/play.txt
  grep -v "key space" $D/play.txt > $D/still.txt
  for s in $SIZES; do
    /usr/bin/time -f "peak RSS %M KB" $B view $PLAY --size ${s}x${s} --no-preview --script $D/play.txt --log $D/play.jsonl
    $B view $PLAY --size ${s}x${s} --no-preview --script $D/still.txt --log $D/still.jsonl
    python3 - $D/play.jsonl $D/still.jsonl $s <<'PY'
import json, sys
L = [json.loads(l) for l in open(sys.argv[1])]
S = [json.loads(l) for l in open(sys.argv[2])]
key = next(i for i, l in enumerate(L) if l.get('key') == 'PlayPause')
p = [l for l in L[key:] if 'presented' in l][:300]      # the orbit's frames
first = next(i for i, l in enumerate(S) if 'presented' in l)
q = [l for l in S[first + 1:] if 'presented' in l][:300]  # the same orbit, nothing loading
gaps = [b['t'] - a['t'] for a, b in zip(p, p[1:]) if b['loading']]
rs = sorted(l['render_s'] for l in p)
loads = [l for l in L if 'loaded' in l and not l.get('upgrade')]  # the first step's volume, built behind it, left out
gs = sorted(gaps)
wait = max(b['t'] - a['t'] - b['render_s'] for a, b in zip(p, p[1:]) if b['loading'])
still_gap = max(b['t'] - a['t'] for a, b in zip(q, q[1:]))
ratio = sorted((b['t'] - a['t']) / c['render_s'] for a, b, c in zip(p, p[1:], q[1:]) if b['loading'])
print(f"{sys.argv[3]}²: first frame after {loads[0]['t']:.2f} s (build {loads[0]['build_s']:.2f} s); {len(p)} orbit frames, {len(gaps)} during builds (median gap {gs[len(gs) // 2]:.3f} s); "
      f"builds {', '.join('%.2f' % l['build_s'] for l in loads[1:])} s; longest gap during a build {max(gaps):.3f} s, median render {rs[len(rs) // 2]:.3f} s, "
      f"longest wait beyond a frame's own render {1e3 * wait:.1f} ms; the same orbit without a build: longest gap {still_gap:.3f} s; "
      f"gap during a build / the same frame's undisturbed render: median {ratio[len(ratio) // 2]:.2f}, largest {ratio[-1]:.2f}")
PY
  done
fi
