#!/usr/bin/env bash
# Benchmark session 2026-11-27 (second): per-ISA modalities on the four scenes not yet measured
# per ISA, and ns90k path tracing again (bounces now use the wide BVH).
set -u
B=/work/bench2/bnsview
cd /work/bench2
t() { local name=$1; shift; local s=$(date +%s); echo "=== $name start $(date -u +%H:%M:%S): $*" >> times.log; "$@" > "$name.out" 2> "$name.err"; echo "=== $name rc $? $(( $(date +%s) - s )) s" >> times.log; }
# (h) ns90k path per ISA, 3 frames (wide-BVH bounces)
t ns90k_path $B --isa all bench --table 3 --scenes ns90k --modes path --frames 3 --json ns90k_path.json -f
# (i) modalities per ISA on nanobowl, ns740k, sio2, anp3: 1 timed frame after 1 warm-up
t modal_isa4 $B --isa all bench --table 3 --scenes nanobowl,ns740k,sio2,anp3 --modes modalities,vol+bs-shadows --frames 1 --json modal_isa4.json -f
echo "=== all done $(date -u +%H:%M:%S)" >> times.log
# (j) afterwards: path per frame with avx2 on the five scenes, 3 frames
# /work/bench2/bnsview bench --table 3 --modes path --frames 3 --json path_avx2.json -f
