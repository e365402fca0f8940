#!/usr/bin/env bash
#! Writes the seeds of the `model_file` and `scxml_run` fuzz targets (seeds/model_file, seeds/scxml_run).
set -euo pipefail
cd "$(dirname "$0")"
out=seeds/model_file
mkdir -p "$out"
# The order of FILES in fuzz_targets/model_file.rs; 7 + k picks the same file under the
# tree's next semantics.
files=(plain/a.scxml plain/properties.xml robot/tree.xml robot/Grasp.scxml
    "" robot/main.xml robot/properties.xml)
for i in "${!files[@]}"; do
    f=${files[$i]}
    [ -n "$f" ] || f=../../examples/museum-guide/Plugins/ROS2Action.scxml
    for sem in 0 1 2; do
        { printf "\\$(printf '%03o' $((i + 7 * sem)))"; cat "templates/$f"; } >"$out/$i-$sem"
    done
done
echo "wrote $(ls "$out" | wc -l) seeds to fuzz/$out"
# scxml_run: machines joined by NUL bytes (the plain template, and groups of the museum's).
out=seeds/scxml_run
mkdir -p "$out"
{ cat templates/plain/a.scxml; printf '\0'; cat templates/plain/b.scxml; } >"$out/plain"
museum=(../examples/museum-scxml/*.scxml)
for ((i = 0; i < ${#museum[@]}; i += 3)); do
    {
        cat "${museum[$i]}"
        for f in "${museum[@]:i+1:2}"; do printf '\0'; cat "$f"; done
    } >"$out/museum-$i"
done
echo "wrote $(ls "$out" | wc -l) seeds to fuzz/$out"
