#!/usr/bin/env bash
# Renders nanobowl and ns90k at 256x256 in ten modes with every backend this CPU has, into
# OUTDIR (80 PNGs on an AVX-512 machine), so two binaries' pictures can be compared with
# `cmp`:   scripts/compare-images.sh OLD_BIN old/ && scripts/compare-images.sh NEW_BIN new/ &&
#          for f in old/*.png; do cmp -s "$f" "new/${f#old/}" || echo "differs: $f"; done
# (BENCHMARKS.md, "The library split", used it against a81d852.)
set -euo pipefail
if [ $# -ne 2 ]; then
    echo "usage: $0 BNSVIEW_BINARY OUTDIR" >&2
    exit 2
fi
bin=$1
out=$2
mkdir -p "$out"
modes=(
    "bs|"
    "volume|--mode volume"
    "volbs|--mode vol+bs"
    "volbslit|--mode vol+bs --lit"
    "volumelit|--mode volume --lit"
    "shadows|--shadows"
    "ao|--ao 4"
    "path|--mode path --spp 2"
    "volshadows|--mode volume --volume-shadows"
    "volbsshadows|--mode vol+bs --shadows --volume-shadows"
)
status=0
for scene in nanobowl ns90k; do
    for isa in $("$bin" isa | awk 'NR > 1 && $3 == "yes" {print $1}'); do
        for m in "${modes[@]}"; do
            name=${m%%|*}
            flags=${m#*|}
            png="$out/${scene}_${name}_${isa}.png"
            # shellcheck disable=SC2086
            if ! "$bin" render --scene "$scene" --size 256x256 --isa "$isa" $flags -o "$png" -f \
                >/dev/null 2>"${png%.png}.err"; then
                echo "failed: $scene $name $isa (see ${png%.png}.err)" >&2
                status=1
            fi
        done
    done
done
exit $status
