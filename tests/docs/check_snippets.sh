#!/usr/bin/env bash
# The docs' commands run as printed: every snippet a page marks as checked
# is run, and its exit status compared with the one the page states.
#
#   check_snippets.sh SOURCE_DIR BUILD_DIR BOUNCECHECK [PAGE.md ...]
#
# Default pages: README.md, docs/*.md and examples/*/README.md. A checked
# snippet is a fenced block with info string `sh` right after the line
#   <!-- checked: exit N -->
# It runs with `bash -e` (so every command but the last must succeed; the
# last one's status must be N) in a fresh scratch folder holding symbolic
# links scenarios/ and examples/ to the source tree's and build/ to the build
# folder, with BOUNCECHECK first on PATH as `bouncecheck`: the commands read
# as a user in a clone types them. A marker not followed by such a block,
# and no checked snippet at all, are failures too.
set -uo pipefail

if (($# < 3)); then
  echo "usage: check_snippets.sh SOURCE_DIR BUILD_DIR BOUNCECHECK [PAGE.md ...]" >&2
  exit 2
fi
src="$(cd "$1" && pwd)" build="$(cd "$2" && pwd)" binary="$(cd "$(dirname "$3")" && pwd)/$(basename "$3")"
shift 3
pages=("$@")
if ((${#pages[@]} == 0)); then
  pages=("$src/README.md" "$src"/docs/*.md "$src"/examples/*/README.md)
fi

work="$(mktemp -d "${TMPDIR:-/tmp}/bouncecheck-snippets.XXXXXX")"
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/bin"
ln -s "$binary" "$work/bin/bouncecheck"

# Each page's snippets as work/snippet-N.sh, with work/snippet-N.where
# holding "PAGE:LINE EXPECTED".
n=0 failed=0
for page in "${pages[@]}"; do
  [ -f "$page" ] || { echo "$page: no such page"; failed=1; continue; }
  name="${page#"$src"/}"
  while IFS=$'\t' read -r line expected body_file; do
    if [ "$expected" = "orphan" ]; then
      echo "$name:$line: a checked marker not followed by a \`\`\`sh block"
      failed=1
      continue
    fi
    n=$((n + 1))
    mv "$body_file" "$work/snippet-$n.sh"
    echo "$name:$line $expected" > "$work/snippet-$n.where"
  done < <(awk -v out="$work/body-$RANDOM" '
    pending && /^```sh[ \t]*$/ { file = out "-" NR; inside = 1; pending = 0; start = NR; next }
    pending { print marker_line "\torphan\t-"; pending = 0 }
    inside && /^```[ \t]*$/ { close(file); print start "\t" expected "\t" file; inside = 0; next }
    inside { print > file; next }
    match($0, /^<!-- checked: exit [0-9]+ -->[ \t]*$/) {
      expected = $0; sub(/^<!-- checked: exit /, "", expected); sub(/ -->.*$/, "", expected)
      pending = 1; marker_line = NR
    }
    END { if (pending) print marker_line "\torphan\t-" }
  ' "$page")
done
if ((n == 0)); then
  echo "no checked snippet found in: ${pages[*]}"
  exit 1
fi

for ((i = 1; i <= n; i++)); do
  read -r where expected < "$work/snippet-$i.where"
  scratch="$work/run-$i"
  mkdir -p "$scratch"
  ln -s "$src/scenarios" "$scratch/scenarios"
  ln -s "$src/examples" "$scratch/examples"
  ln -s "$build" "$scratch/build"
  started=$SECONDS
  (cd "$scratch" && PATH="$work/bin:$PATH" timeout 600 bash -e "$work/snippet-$i.sh") > "$work/run-$i.log" 2>&1
  status=$?
  if [ "$status" = "$expected" ]; then
    echo "$where: exit $status as the docs say ($((SECONDS - started)) s)"
  else
    echo "$where: exited $status, the docs say $expected. The snippet:"
    sed 's/^/    /' "$work/snippet-$i.sh"
    echo "  its output (last 30 lines):"
    tail -n 30 "$work/run-$i.log" | sed 's/^/    /'
    failed=1
  fi
done
if ((failed)); then
  echo "FAILED: a snippet does not run as printed (above)"
  exit 1
fi
echo "all $n checked snippets run as printed"
