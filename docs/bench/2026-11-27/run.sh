#!/usr/bin/env bash
# Benchmark session 2026-11-27: run in priority order, each step's wall time logged.
set -u
B=/work/bench/bnsview
cd /work/bench
t() { local name=$1; shift; local s=$(date +%s); echo "=== $name start $(date -u +%H:%M:%S): $*" >> times.log; "$@" > "$name.out" 2> "$name.err"; echo "=== $name rc $? $(( $(date +%s) - s )) s" >> times.log; }
# (a) the full default run (issue 7): five scenes at full size, Tables 1-3, widest ISA
t full $B bench --json full.json -f
# (b) b&s per ISA, five scenes, 10 frames (issue 4)
t bs_isa $B --isa all bench --table 3 --modes bs --json bs_isa.json -f
# (c) the modalities on the five scenes, widest ISA, 3 frames (issue 6)
t modal $B bench --table 3 --modes bs-shadows,bs-ao,path,volume-lit,volume-shadows,volume-lit-shadows,vol+bs-shadows --frames 3 --json modal.json -f
# (d) macrocells off on ns740k (issue 5)
t nocells $B bench --table 3 --scenes ns740k --modes volume --no-macrocells --frames 3 --json nocells.json -f
# (e) volume and vol+bs per ISA, five scenes, 3 frames (issue 5)
t vol_isa $B --isa all bench --table 3 --modes volume,vol+bs --frames 3 --json vol_isa.json -f
# (f) modalities per ISA on ns90k, 3 frames (issue 6)
t modal_isa $B --isa all bench --table 3 --scenes ns90k --modes modalities,vol+bs-shadows --frames 3 --json modal_isa.json -f
echo "=== all done $(date -u +%H:%M:%S)" >> times.log
# (g) afterwards: the quick run
# $B bench --quick --json quick.json -f
