#!/usr/bin/env bash
# scripts/slurm/submit.sh against a real Slurm: starts a single-node cluster
# on this machine (munged, slurmctld, slurmd; as root, no systemd, on
# 127.0.0.1 only, every file in a temporary folder), then checks that
#   1. 4 shards of a reduced stress suite, merged, are the unsharded run apart
#      from timings, with the same exit status, and that each shard ran with
#      --jobs from --cpus-per-task;
#   2. the same for 3 shards of a small sweep;
#   3. a failing shard fails the whole submission (exit 2) and is named: one
#      shard exits 2, another's task is killed before it writes its status;
#   4. an OUT that holds results already is refused before anything is submitted;
#   5. submit.sh stopped by a signal (Ctrl-C, SIGTERM) cancels its jobs.
# The daemons are stopped by the pids their pid files gave, on every way out.
#
#   tests/slurm/slurm_test.sh BOUNCECHECK_BINARY
#
# Exits 77 (CTest's skip) when not root or when slurm-wlm, munge or python3
# is missing (WITH_TEST_TOOLS=1 scripts/setup.sh installs them).
# BOUNCECHECK_SLURM_KEEP=1 keeps the temporary folder, logs included.
#
# What this Slurm needs, found on Debian 12's slurm-wlm 22.05:
#   - munged as root with its own key, socket, pid, log and seed files (no
#     /run/munge, no /etc/munge/munge.key touched); the socket's folders must
#     be searchable by everyone, so the temporary folder is made 0755;
#     --origin=127.0.0.1 spares a host lookup of an unresolvable hostname;
#   - ProctrackType=proctrack/linuxproc and TaskPlugin=task/none: with the
#     cgroup plugins every job step failed while srun still exited 0;
#   - SchedulerParameters=batch_sched_delay=0: by default batch jobs (and each
#     next array task) start only every ~3 s; this makes a 4-task array of short
#     tasks plus the merge take about 5 s instead of 9;
#   - MinJobAge=5: a finished job's record goes soon (submit.sh keeps its own
#     exit status files and does not need the record);
#   - SlurmdParameters=config_overrides: the node has CPUs=2 even on a machine
#     with fewer cores, rather than being drained for it.
set -euo pipefail

say() { echo "slurm_test: $*"; }
skip() { say "SKIP: $*"; exit 77; }
fail() { say "FAIL: $*"; exit 1; }

(($# == 1)) || { echo "usage: $0 BOUNCECHECK_BINARY" >&2; exit 2; }
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
ROOT="$(cd "$HERE/../.." && pwd)"
SUBMIT="$ROOT/scripts/slurm/submit.sh"
SAME="$HERE/same_apart_from_timings.py"
[ -x "$1" ] || fail "no bouncecheck binary at $1"
BOUNCECHECK="$(cd "$(dirname "$1")" && pwd)/$(basename "$1")"
# The daemons live in /usr/sbin, which a non-login root shell may lack.
export PATH="$PATH:/usr/sbin:/sbin"

[ "$(id -u)" -eq 0 ] || skip "starts Slurm's daemons, so it runs as root"
for tool in munged slurmctld slurmd sbatch squeue scontrol scancel sinfo python3; do
  command -v "$tool" > /dev/null ||
    skip "$tool is not installed (WITH_TEST_TOOLS=1 scripts/setup.sh installs slurm-wlm, munge and python3)"
done
"$BOUNCECHECK" stress --help 2> /dev/null | grep -q -- '--shard' || fail "$BOUNCECHECK has no stress --shard"

started=$SECONDS
WORK="$(mktemp -d "${TMPDIR:-/tmp}/bouncecheck-slurm.XXXXXX")"
chmod 0755 "$WORK" # munged refuses a socket in a folder not everyone may search
mkdir -p "$WORK/munge" "$WORK/slurm/state" "$WORK/slurm/spool" "$WORK/runs"

# --- The daemons, and their end on every way out ------------------------------
CHILD_PID=""            # the command the test waits for (in the background, see run)
WATCHDOG_PID=""
DAEMONS=()              # names, in start order
declare -A DAEMON_PID=() # name -> pid read from its pid file
declare -A PID_FILE=()   # name -> pid file

# Runs a daemon (it forks into the background itself) and reads its pid file.
start_daemon() {
  local name="$1" pid_file="$2" i
  shift 2
  DAEMONS+=("$name")
  PID_FILE[$name]="$pid_file"
  "$@" || fail "$name did not start: $*"
  for ((i = 0; i < 100; i++)); do
    if [ -s "$pid_file" ]; then
      DAEMON_PID[$name]="$(cat "$pid_file")"
      kill -0 "${DAEMON_PID[$name]}" 2> /dev/null || fail "$name (pid ${DAEMON_PID[$name]}) exited at start"
      return 0
    fi
    sleep 0.1
  done
  fail "$name wrote no pid file $pid_file in 10 s"
}

# The pid of a daemon that still runs, or nothing. The pid is checked to
# still be that daemon (not a reused pid) before anything signals it.
running_pid() {
  local name="$1" pid="${DAEMON_PID[$1]:-}"
  if [ -z "$pid" ] && [ -s "${PID_FILE[$name]}" ]; then pid="$(cat "${PID_FILE[$name]}")"; fi
  [ -n "$pid" ] && [ "$(cat "/proc/$pid/comm" 2> /dev/null)" = "$name" ] && echo "$pid"
  return 0
}

# Stops the daemons by their pids: SIGTERM to all at once (each takes a second
# or two to exit), then SIGKILL to any still there after 10 s.
stop_daemons() {
  local name pid i
  declare -A stopping=()
  for name in "${DAEMONS[@]}"; do
    pid="$(running_pid "$name")"
    [ -n "$pid" ] || continue
    stopping[$name]="$pid"
    kill -TERM "$pid" 2> /dev/null || true
  done
  for ((i = 0; i < 100 && ${#stopping[@]}; i++)); do
    for name in "${!stopping[@]}"; do
      if ! kill -0 "${stopping[$name]}" 2> /dev/null; then
        say "stopped $name (pid ${stopping[$name]})"
        unset "stopping[$name]"
      fi
    done
    sleep 0.1
  done
  for name in "${!stopping[@]}"; do
    say "$name (pid ${stopping[$name]}) ignored SIGTERM for 10 s: SIGKILL"
    kill -KILL "${stopping[$name]}" 2> /dev/null || true
  done
}

cleanup() {
  local status=$? i name pid jobs
  set +e
  trap - EXIT INT TERM
  [ -z "$WATCHDOG_PID" ] || kill "$WATCHDOG_PID" 2> /dev/null
  # A command still running (the test was interrupted): a submit.sh then
  # cancels its jobs.
  if [ -n "$CHILD_PID" ] && kill -TERM "$CHILD_PID" 2> /dev/null; then
    wait "$CHILD_PID"
  fi
  if [ -n "${DAEMON_PID[slurmctld]:-}" ]; then
    # Jobs still queued or running (a failure half-way) are cancelled first, so
    # that no job step outlives slurmd.
    mapfile -t jobs < <(squeue -h -o %A 2> /dev/null)
    if ((${#jobs[@]})); then
      scancel "${jobs[@]}" 2> /dev/null
      for ((i = 0; i < 150; i++)); do
        [ -z "$(squeue -h -t PD,R,CG,CF,S -o %A 2> /dev/null)" ] && break
        sleep 0.1
      done
    fi
  fi
  stop_daemons
  if ((status != 0 && status != 77)); then
    for log in "$WORK/slurm/slurmctld.log" "$WORK/slurm/slurmd.log" "$WORK/munge/munged.log"; do
      [ -f "$log" ] && { say "last lines of $log:"; tail -n 15 "$log"; }
    done
  fi
  if [ "${BOUNCECHECK_SLURM_KEEP:-0}" = 1 ]; then
    say "kept $WORK"
  else
    rm -rf "$WORK"
  fi
  for name in "${DAEMONS[@]}"; do
    pid="$(running_pid "$name")"
    if [ -n "$pid" ]; then
      say "FAIL: $name (pid $pid) is still running"
      status=1
    fi
  done
  say "$( ((status == 0)) && echo PASS || echo "exit $status") after $((SECONDS - started)) s"
  exit "$status"
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

# The whole test takes about 20 s. Past 200 s it stops itself, so that its
# cleanup runs before CTest's TIMEOUT (300 s) kills it with a signal no trap
# sees, which would leave the daemons running. One-second sleeps: stopping
# the watchdog leaves at most one behind, for a second.
(
  for ((t = 0; t < 200; t++)); do sleep 1; done
  say "FAIL: still running after 200 s: stopping"
  kill -TERM $$
) &
WATCHDOG_PID=$!

# --- Slurm on this machine only -----------------------------------------------
# Nothing from an enclosing job or the user's sbatch defaults may leak in.
while read -r var; do unset "$var"; done < <(compgen -e | grep -E '^(SLURM|SBATCH|SQUEUE|SCONTROL)_' || true)

# slurmd must know itself by a NodeName in slurm.conf: the short host name,
# given to it with -N, reached at 127.0.0.1 (it need not resolve).
NODE="$(uname -n)"
NODE="${NODE%%.*}"
# Two free ports, so that a Slurm already on this machine is not disturbed.
read -r CTLD_PORT SLURMD_PORT < <(python3 -c '
import socket
socks = [socket.socket() for _ in range(2)]
for s in socks: s.bind(("127.0.0.1", 0))
print(*[s.getsockname()[1] for s in socks])')

head -c 1024 /dev/urandom > "$WORK/munge/munge.key"
chmod 0600 "$WORK/munge/munge.key"
MUNGE_SOCKET="$WORK/munge/munge.socket"
start_daemon munged "$WORK/munge/munged.pid" \
  munged --socket="$MUNGE_SOCKET" --key-file="$WORK/munge/munge.key" --pid-file="$WORK/munge/munged.pid" \
  --log-file="$WORK/munge/munged.log" --seed-file="$WORK/munge/munged.seed" --origin=127.0.0.1

export SLURM_CONF="$WORK/slurm/slurm.conf"
cat > "$SLURM_CONF" << EOF
ClusterName=bouncecheck-test
SlurmctldHost=$NODE(127.0.0.1)
SlurmctldPort=$CTLD_PORT
SlurmdPort=$SLURMD_PORT
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$MUNGE_SOCKET
StateSaveLocation=$WORK/slurm/state
SlurmdSpoolDir=$WORK/slurm/spool
SlurmctldPidFile=$WORK/slurm/slurmctld.pid
SlurmdPidFile=$WORK/slurm/slurmd.pid
SlurmctldLogFile=$WORK/slurm/slurmctld.log
SlurmdLogFile=$WORK/slurm/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
MailProg=/bin/true
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerParameters=batch_sched_delay=0,sched_min_interval=100000
MinJobAge=5
KillWait=2
DependencyParameters=kill_invalid_depend
ReturnToService=2
SlurmdParameters=config_overrides
NodeName=$NODE NodeAddr=127.0.0.1 CPUs=2 State=UNKNOWN
PartitionName=test Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
start_daemon slurmctld "$WORK/slurm/slurmctld.pid" slurmctld -c -f "$SLURM_CONF"
start_daemon slurmd "$WORK/slurm/slurmd.pid" slurmd -f "$SLURM_CONF" -N "$NODE"
for ((i = 0; i < 300; i++)); do
  [ "$(sinfo -h -n "$NODE" -o %T 2> /dev/null)" = idle ] && break
  sleep 0.1
done
[ "$(sinfo -h -n "$NODE" -o %T 2> /dev/null)" = idle ] || fail "node $NODE not idle after 30 s: $(sinfo 2>&1)"
say "Slurm up: node $NODE idle after $((SECONDS - started)) s (slurmctld port $CTLD_PORT, slurmd port $SLURMD_PORT)"
cd "$WORK/runs"

# --- Helpers --------------------------------------------------------------------
# run OUT_FILE COMMAND...: runs the command with its output in OUT_FILE; its
# exit status in $ran. In the background and waited for, so that a signal to
# the test is handled at once: cleanup then stops the command (a submit.sh
# cancels its jobs when stopped).
run() {
  local out_file="$1"
  shift
  ran=0
  "$@" > "$out_file" 2>&1 &
  CHILD_PID=$!
  wait "$CHILD_PID" || ran=$?
  CHILD_PID=""
}
# submit NAME ARGS...: runs submit.sh; its status in $submitted, its output in NAME.log.
submit() {
  local name="$1" t0=$SECONDS
  shift
  run "$name.log" "$SUBMIT" "$@"
  submitted=$ran
  say "$name: submit.sh exited $submitted after $((SECONDS - t0)) s"
}
show_log() {
  sed 's/^/    | /' "$1"
}
# sharded_matches_whole NAME SHARDS COMMAND...: the command sharded through
# Slurm (1 CPU a shard) against it run whole with --jobs 1.
sharded_matches_whole() {
  local name="$1" shards="$2" whole
  shift 2
  submit "$name-sharded" --shards "$shards" --out "$WORK/runs/$name-sharded" --bouncecheck "$BOUNCECHECK" \
    --sbatch "--cpus-per-task=1" -- "$@"
  run "$name-whole.log" "$BOUNCECHECK" "$@" --jobs 1 --out "$WORK/runs/$name-whole"
  whole=$ran
  case "$submitted" in
    0 | 1 | 3) ;;
    *) show_log "$name-sharded.log"; fail "$name: the sharded run failed (exit $submitted)" ;;
  esac
  [ "$submitted" = "$whole" ] || { show_log "$name-sharded.log"; fail "$name: sharded exit $submitted, whole exit $whole"; }
  python3 "$SAME" "$WORK/runs/$name-sharded" "$WORK/runs/$name-whole" || fail "$name: merged shards differ from the whole run"
  # Each shard ran with --jobs from --cpus-per-task=1 (its own report says so).
  python3 - "$WORK/runs/$name-sharded" "$shards" "$1" << 'EOF' || fail "$name: a shard did not run with --jobs 1"
import json, sys
out, shards, kind = sys.argv[1], int(sys.argv[2]), sys.argv[3]
for k in range(1, shards + 1):
    jobs = json.load(open(f"{out}/shard-{k}/{kind}.json"))["parameters"]["jobs"]
    if jobs != 1:
        sys.exit(f"shard {k}: --jobs {jobs}")
EOF
  say "$name: $shards shards merged = whole run apart from timings (exit $whole both)"
}

# --- 1, 2: sharded runs merged against whole ones ---------------------------------
# shellcheck disable=SC2054  # the commas are bouncecheck's list syntax
STRESS=(stress --only monte-carlo --monte-carlo 40 --engines reference,exact,ode,box2d --budget 30)
sharded_matches_whole stress 4 "${STRESS[@]}"
sharded_matches_whole sweep 3 sweep "$ROOT/scenarios/seed-2d.toml" --engines reference,ode --dt 0.02,0.01,0.005 --repeat 1

# --- 3: failing shards fail the submission, by name --------------------------------
# A stand-in bouncecheck for the array: shard 2 exits 2 (as bouncecheck does
# on bad options); shard 3 kills its task's batch shell, so the task ends with
# no exit status written; shards 1 and 4 run for real.
cat > "$WORK/failing-bouncecheck" << EOF
#!/bin/sh
case "\${SLURM_ARRAY_TASK_ID:-}" in
  2) echo "failing-bouncecheck: shard 2 refuses its options, on purpose" >&2; exit 2 ;;
  3) echo "failing-bouncecheck: killing shard 3's task, on purpose" >&2; kill -KILL "\$PPID"; exit 0 ;;
esac
exec "$BOUNCECHECK" "\$@"
EOF
chmod +x "$WORK/failing-bouncecheck"
FAILING_OUT="$WORK/runs/failing"
submit failing --shards 4 --out "$FAILING_OUT" --bouncecheck "$WORK/failing-bouncecheck" -- "${STRESS[@]}"
show_log failing.log
[ "$submitted" = 2 ] || fail "a submission with failing shards exited $submitted, not 2"
grep -qF "shard 2/4 failed: exit 2 (see $FAILING_OUT/shard-2.log)" failing.log || fail "shard 2/4 is not named as failed"
grep -qF "shard 3/4 failed: it ended without an exit status" failing.log || fail "shard 3/4 is not named as failed"
grep -qE "shard [14]/4 failed" failing.log && fail "a shard that succeeded is named as failed"
grep -qF "no merged result: 2 of 4 shard(s) failed" failing.log || fail "the submission does not say it has no result"
[ ! -e "$FAILING_OUT/stress.json" ] || fail "a merged stress.json was written despite failed shards"
say "failing shards: submission exited 2 and named shards 2/4 and 3/4"

# --- 4: old results are never merged -----------------------------------------------
submit reused --shards 2 --out "$WORK/runs/stress-sharded" --bouncecheck "$BOUNCECHECK" -- "${STRESS[@]}"
if [ "$submitted" != 2 ] || ! grep -q "already exists and is not empty" reused.log; then
  show_log reused.log
  fail "an OUT with results in it was not refused"
fi
say "an OUT holding results is refused"

# --- 5: a signal to submit.sh cancels its jobs ---------------------------------------
printf '#!/bin/sh\nexec sleep 60\n' > "$WORK/slow-bouncecheck"
chmod +x "$WORK/slow-bouncecheck"
"$SUBMIT" --shards 2 --out "$WORK/runs/interrupted" --bouncecheck "$WORK/slow-bouncecheck" -- "${STRESS[@]}" \
  > interrupted.log 2>&1 &
CHILD_PID=$!
for ((i = 0; i < 300; i++)); do
  [ "$(squeue -h -t R -o %A | wc -l)" = 2 ] && break
  sleep 0.1
done
[ "$(squeue -h -t R -o %A | wc -l)" = 2 ] || { show_log interrupted.log; fail "the slow shards never ran"; }
kill -TERM "$CHILD_PID"
interrupted=0
wait "$CHILD_PID" || interrupted=$?
CHILD_PID=""
for ((i = 0; i < 150; i++)); do
  [ -z "$(squeue -h -t PD,R,CG,CF,S -o %A)" ] && break
  sleep 0.1
done
show_log interrupted.log
[ "$interrupted" = 143 ] || fail "submit.sh stopped by SIGTERM exited $interrupted, not 143"
[ -z "$(squeue -h -t PD,R,CG,CF,S -o %A)" ] || fail "jobs left after submit.sh was stopped: $(squeue 2>&1)"
say "SIGTERM to submit.sh: it cancelled its shards and merge job, exit 143"
