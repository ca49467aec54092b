#!/usr/bin/env bash
# Time-series benchmark (issue #15): pipelined vs --no-pipeline vs one process per frame.
# usage: bench_series.sh BIN SCENE ATOMS FRAMES SIZE PERFRAME   (PERFRAME: frames for the one-process-per-frame loop)
set -euo pipefail
B=$1; SC=$2; N=$3; F=$4; S=$5; P=$6
D=/tmp/bench_series; mkdir -p $D
[ -f $D/t.lammpstrj ] || /usr/bin/time -f "generate plain: %e s" $B generate $SC --atoms $N --frames $F -o $D/t.lammpstrj 2>&1 | tail -2
[ -f $D/t.lammpstrj.gz ] || /usr/bin/time -f "generate gz: %e s" $B generate $SC --atoms $N --frames $F -o $D/t.lammpstrj.gz 2>&1 | tail -2
ls -l $D/t.lammpstrj $D/t.lammpstrj.gz
echo "--- one frame alone (stage times):"
$B render $D/t.lammpstrj --frame 0 --size $S -v -o $D/one.png --force 2>&1 | grep -Ei "read|bonds|bvh|render|total" | head -12
for f in t.lammpstrj t.lammpstrj.gz; do
  for mode in pipe nopipe; do
    extra=""; [ $mode = nopipe ] && extra="--no-pipeline"
    rm -f $D/o_*.png
    /usr/bin/time -f "$f $mode: wall %e s, peak RSS %M KB" $B render $D/$f --frames all --size $S $extra -v -o "$D/o_%03d.png" 2>&1 | grep -E "series:|wall"
  done
  cam=$($B render $D/$f --frame 0 --size $S -v -o $D/c.png --force 2>&1 | sed -n 's/^camera:  --camera //p')
  start=$(date +%s.%N)
  for k in $(seq 0 $(( (F-1) / (P-1) )) $((F-1))); do $B render $D/$f --frame $k --camera "$cam" --size $S -o $D/s_$k.png --force 2>/dev/null; done
  end=$(date +%s.%N)
  echo "$f one process per frame, $P frames spread over 0..$((F-1)): wall $(echo "$end - $start" | bc) s ($(echo "scale=3; $P / ($end - $start)" | bc) frames/s)"
done
