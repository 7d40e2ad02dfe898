#!/bin/sh
# A stand-in session program for tests/test_external_session.cpp
# (docs/external.md, Sessions): for each scenario line on stdin, replays the
# trajectory in FILE and ends the reply with #end, or breaks the session the
# way MODE says.
# usage: session.sh FILE MODE [PATH]   (PATH: where each reply appends the shell's pid)
file=$1
mode=$2
n=0
while IFS= read -r line; do
  n=$((n + 1))
  [ -n "$3" ] && echo $$ >> "$3"
  case $mode in
    ok) cat "$file"; echo '#end {"step_seconds": 1e-6}' ;;
    once) cat "$file"; echo '#end'; exit 0 ;;
    no-end) cat "$file" ;;
    second-hangs) if [ $n -ge 2 ]; then head -n 10 "$file"; sleep 60; fi; cat "$file"; echo '#end' ;;
    *) echo "session.sh: unknown mode $mode" >&2; exit 2 ;;
  esac
done
