#!/bin/sh
# A stand-in external simulator for tests/test_external.cpp: reads the
# scenario on stdin (docs/external.md), then replays the trajectory in FILE,
# or breaks the protocol the way MODE says.
# usage: replay.sh FILE MODE [PATH]   (PATH: where `orphan` writes its child's pid, `input` its input)
file=$1
mode=$2
input=$(cat)
settings=$(printf '%s' "$input" | sed -n 's/.*"settings_file":"\([^"]*\)".*/\1/p')
case $mode in
  ok) cat "$file" ;;
  input) printf '%s' "$input" > "$3"; cat "$file" ;;
  pwd) pwd >&2; exit 4 ;;
  exit3) head -n 10 "$file"; echo "engine exploded at step 9" >&2; exit 3 ;;
  segv) head -n 10 "$file"; kill -SEGV $$ ;;
  badrow) head -n 5 "$file"; echo "0.12,0.5,0.9,0.5,abc,0.1,0.2" ;;
  nan) head -n 3 "$file"; echo "0.06,nan,0.9,0.5,0.3,0.1,0.2" ;;
  header) echo "t,x,y,z"; tail -n +2 "$file" ;;
  few) head -n 100 "$file" ;;
  many) cat "$file"; tail -n 1 "$file" ;;
  hang) head -n 10 "$file"; sleep 60 ;;
  orphan) sleep 60 & echo $! > "$3"; head -n 10 "$file"; sleep 60 ;;
  end) cat "$file"; echo '#end {"step_seconds": 1e-6, "from_a_later_version": [1, 2]}' ;;
  end-slow) cat "$file"; echo '#end {"step_seconds": 1000}' ;;
  end-early) head -n 10 "$file"; echo '#end' ;;
  settings-ok) cat "$file"; printf '[{"key":"engine","value":"replay 1","why":"a test"},{"key":"n","value":2}]' > "$settings" ;;
  settings-bad) cat "$file"; printf '{"engine":1}' > "$settings" ;;
  *) echo "replay.sh: unknown mode $mode" >&2; exit 2 ;;
esac
