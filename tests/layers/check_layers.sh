#!/usr/bin/env bash
# The include rule of the source tree (docs/internals.md): the top-level
# folders form layers, from the bottom
#
#   platform  scenarios  simulators  reference|exact|engines|external  registry
#   metrics  comparison  verdicts  reports  commands  cli
#
# and a file may include headers of its own folder or of a folder in a lower
# layer, never of a higher one nor of a sibling on its own layer (reference,
# exact and the engines know nothing of each other). The engines know nothing
# of each other either: engines/dart/ may include engines/*.h, never
# engines/ode/. Since every arrow points down, the folders' include graph has
# no cycle. The front ends (tests,
# bench, fuzz, examples) sit on top of everything and are not checked.
#
# Also fails when a top-level folder with C++ sources is in no layer (a new
# folder must be given its place), and when one folder holds more than a
# third of the layered source lines in files of its own (a subfolder counts
# for itself: engines/ grows by one folder per engine, each doing one job).
#
# usage: check_layers.sh ROOT     (exit 0 if the tree keeps the rule, 1 if not)
set -euo pipefail
ROOT="${1:?usage: check_layers.sh ROOT}"
cd "$ROOT"

LAYERS=(platform scenarios simulators "reference exact engines external" registry
        metrics comparison verdicts reports commands api cli)
FRONT_ENDS=" tests bench fuzz examples "

declare -A rank=()
for i in "${!LAYERS[@]}"; do
  for folder in ${LAYERS[i]}; do rank[$folder]=$i; done
done

status=0
sources=()
for dir in */; do
  folder="${dir%/}"
  [[ "$FRONT_ENDS" == *" $folder "* || "$folder" == build* ]] && continue
  mapfile -t found < <(find "$folder" -type f \( -name '*.h' -o -name '*.cpp' \) | sort)
  ((${#found[@]})) || continue
  if [[ -z "${rank[$folder]+x}" ]]; then
    echo "$folder/: holds C++ sources but is in no layer: give it its place in LAYERS (tests/layers/check_layers.sh) and in docs/internals.md"
    status=1
    continue
  fi
  sources+=("${found[@]}")
done

# Every quoted include of a top-level folder's header.
while IFS=: read -r file line text; do
  from="${file%%/*}"
  included="$(sed -E 's/^[[:space:]]*#[[:space:]]*include[[:space:]]*"([^"]+)".*/\1/' <<<"$text")"
  to="${included%%/*}"
  [[ "$included" == */* && -n "${rank[$to]+x}" ]] || continue
  if [[ "$to" == "$from" ]]; then
    # One engine's folder including another's.
    from_sub="$(cut -d/ -f2 <<<"$file")"; to_sub="$(cut -d/ -f2 <<<"$included")"
    if [[ "$from" == engines && "$file" == */*/* && "$included" == */*/* && "$from_sub" != "$to_sub" ]]; then
      echo "$file:$line: includes \"$included\": $to/$to_sub/ is a sibling of $from/$from_sub/"
      status=1
    fi
    continue
  fi
  if ((rank[$to] > rank[$from])); then
    echo "$file:$line: includes \"$included\": $to/ is above $from/, an include points up"
    status=1
  elif ((rank[$to] == rank[$from])); then
    echo "$file:$line: includes \"$included\": $to/ is a sibling of $from/ on the same layer"
    status=1
  fi
done < <(grep -nE '^[[:space:]]*#[[:space:]]*include[[:space:]]*"' "${sources[@]}" /dev/null || true)

# Source lines per folder (the folder a file sits in): none above a third of the whole.
total=0
declare -A lines=()
for file in "${sources[@]}"; do
  n=$(wc -l < "$file")
  folder="$(dirname "$file")"
  lines[$folder]=$(( ${lines[$folder]:-0} + n ))
  total=$((total + n))
done
for folder in "${!lines[@]}"; do
  if (( 3 * lines[$folder] > total )); then
    echo "$folder/: ${lines[$folder]} of $total source lines, more than a third: split it by what it does"
    status=1
  fi
done

if ((status == 0)); then
  echo "layers: ${#sources[@]} files in ${#lines[@]} folders; every include points down; largest folder:" \
       "$(for f in "${!lines[@]}"; do echo "${lines[$f]} $f"; done | sort -rn | head -n 1 | awk -v t="$total" '{ printf "%s/ %.0f%%", $2, 100 * $1 / t }')"
fi
exit "$status"
