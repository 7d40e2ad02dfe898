#!/usr/bin/env bash
# Runs a bouncecheck stress or sweep run as N shards on a Slurm cluster, merges
# them, and exits as the unsharded command would have: one command that
# submits, waits and reports.
#
#   scripts/slurm/submit.sh --shards N --out OUT [--bouncecheck PATH]
#                           [--sbatch "EXTRA SBATCH OPTIONS"] -- stress [STRESS OPTIONS...]
#   scripts/slurm/submit.sh --shards N --out OUT ... -- sweep SCENARIO.toml [SWEEP OPTIONS...]
#
# What it submits (Slurm's own job array and dependency, no scheduler of ours):
#   - a job array, sbatch --array=1-N: task K runs
#       bouncecheck COMMAND ... --shard K/N --out OUT/shard-K
#     with --jobs $SLURM_CPUS_PER_TASK added when that is set and the options
#     give no --jobs (bouncecheck's default is every core of the node, not the
#     CPUs Slurm gave the task);
#   - a merge job, --dependency=afterany on the array, that runs
#       bouncecheck merge --out OUT OUT/shard-1 ... OUT/shard-N
#     ("afterany", not "afterok": after a failed task an afterok job would stay
#     pending forever on a cluster without DependencyParameters=kill_invalid_depend).
# It then polls squeue until the merge job has left the queue (sbatch --wait
# would return up to a minute late, and exits 0 for a cancelled job).
#
# OUT must not exist or be empty (old shard results must never be merged), and
# must be on a file system the compute nodes share with this one, as must the
# bouncecheck binary and any scenario file. Relative paths in the options are
# taken from the directory this is run in (the jobs start there). What OUT holds:
#   stress.json, stress.csv, stress-scenarios/   the merged result, the files the unsharded
#     or sweep.csv, sweep.json, sweep.html       command writes with --out OUT (bouncecheck merge)
#   merge.log, merge.status                      the merge job's output and exit status
#   shard-K/                                     shard K's own output (its partial results, shard.cbor)
#   shard-K.log, shard-K.status                  shard K's output and exit status
#
# Exit status: the merge's, which is the unsharded command's (0 every check
# held; 1 a stress invariant broke; 3 a simulator crashed or hung), or 2 when
# there is no merged result: a usage error, sbatch refused a job, a shard
# failed, or the merge failed or refused the shards. A shard fails when it ends
# without a result: bouncecheck exited 2 (bad options or input) or with a status
# outside its contract (0, 1, 3), was killed by a signal, or Slurm cancelled it,
# timed it out or lost its node. Each failed shard is named on stderr, e.g.
#   submit: shard 3/4 failed: exit 2 (see OUT/shard-3.log)
# Findings (1) and crashed simulators (3) are results, not failures: such a
# task still ends COMPLETED in Slurm. Ctrl-C (or SIGTERM) cancels both jobs.
#
# Options given with --sbatch go to both sbatch calls, split on whitespace (no
# quoting inside). The ones users typically change:
#   --partition=NAME           which partition (the cluster's default otherwise)
#   --time=HH:MM:SS            time limit of each shard, and of the merge
#   --cpus-per-task=C          CPUs per shard; bouncecheck then runs --jobs C
#   --mem=SIZE, --account=NAME, --qos=NAME, --constraint=FEATURE
#   e.g. --sbatch "--partition=batch --time=01:00:00 --cpus-per-task=4"
# Do not pass --array, --dependency, --output or --error: this script sets them.
#
# --bouncecheck defaults to the bouncecheck on PATH, else this checkout's
# build/bouncecheck. Slurm's client commands (sbatch, squeue, scontrol,
# scancel) must be on PATH; SLURM_CONF, when set, says which cluster.
set -euo pipefail

PROG="submit"
say() { echo "$PROG: $*" >&2; }
die() { say "$*"; exit 2; }

# The usage lines of the comment above; to stdout and exit 0 for --help, to
# stderr and exit 2 after a usage error.
usage() {
  local status="${1:-2}"
  {
    sed -n '/^#   scripts\/slurm\/submit.sh/,/^#   scripts\/slurm\/submit.sh.*sweep/p' "$0" | sed 's/^# \{0,1\}//'
    echo "The comment at the top of $0 says the rest."
  } >&$((status ? 2 : 1))
  exit "$status"
}

# bouncecheck's exit contract: 0, 1 and 3 are runs that ended with a result
# (3: a simulator crashed or hung, and the run reports it); 2 is bad input,
# and anything else (a signal, 127 command not found) is no run at all.
has_result() {
  case "$1" in 0 | 1 | 3) return 0 ;; *) return 1 ;; esac
}

describe_status() {
  local status="$1"
  if ((status > 128 && status < 160)); then
    echo "exit $status (killed by signal $((status - 128)), $(kill -l "$((status - 128))" 2>/dev/null || echo '?'))"
  else
    echo "exit $status"
  fi
}

# A status file is written last, renamed into place: a task killed before it
# leaves none, and none is read as a failure.
write_status() {
  printf '%s\n' "$2" > "$1.tmp" && mv -f "$1.tmp" "$1"
}

# --- Run by Slurm: one array task, shard $SLURM_ARRAY_TASK_ID of N ----------
run_shard() {
  local out="$1" shards="$2" bouncecheck="$3"
  shift 3
  local k="${SLURM_ARRAY_TASK_ID:?run_shard runs as a Slurm array task}"
  local jobs=() arg
  if [ -n "${SLURM_CPUS_PER_TASK:-}" ]; then
    jobs=(--jobs "$SLURM_CPUS_PER_TASK")
    for arg in "$@"; do
      case "$arg" in --jobs | --jobs=*) jobs=() ;; esac
    done
  fi
  echo "shard $k/$shards on $(uname -n), job ${SLURM_JOB_ID:-?}: $bouncecheck $* ${jobs[*]:+${jobs[*]} }--shard $k/$shards --out $out/shard-$k"
  local status=0
  "$bouncecheck" "$@" "${jobs[@]}" --shard "$k/$shards" --out "$out/shard-$k" || status=$?
  write_status "$out/shard-$k.status" "$status"
  echo "shard $k/$shards: bouncecheck exited $status"
  # Findings are a result: only a shard without one ends FAILED in Slurm.
  if has_result "$status"; then exit 0; fi
  exit "$status"
}

# The reason shard k has no result, or nothing when it has one.
shard_problem() {
  local out="$1" k="$2" shards="$3" array_job="${4:-}" status state
  if [ -f "$out/shard-$k.status" ]; then
    status="$(cat "$out/shard-$k.status")"
    has_result "$status" && return 0
    echo "shard $k/$shards failed: $(describe_status "$status") (see $out/shard-$k.log)"
    return 0
  fi
  state=""
  if [ -n "$array_job" ]; then
    # Slurm keeps a finished job's record for MinJobAge seconds (300 by default).
    state="$(scontrol -o show job "${array_job}_$k" 2>/dev/null |
      grep -oE '(JobState|Reason|ExitCode)=[^ ]+' | paste -sd' ' || true)"
  fi
  echo "shard $k/$shards failed: it ended without an exit status (cancelled, timed out or killed;" \
    "Slurm: ${state:-no record left}) (see $out/shard-$k.log)"
}

# --- Run by Slurm: the merge job, once every array task has ended -----------
run_merge() {
  local out="$1" shards="$2" bouncecheck="$3" k problem failed=0 dirs=()
  for ((k = 1; k <= shards; k++)); do
    problem="$(shard_problem "$out" "$k" "$shards")"
    if [ -n "$problem" ]; then
      echo "$problem"
      failed=1
    fi
    dirs+=("$out/shard-$k")
  done
  if ((failed)); then
    echo "not merging: a shard has no result"
    write_status "$out/merge.status" 2
    exit 2
  fi
  echo "merge on $(uname -n), job ${SLURM_JOB_ID:-?}: $bouncecheck merge --out $out ${dirs[*]}"
  local status=0
  "$bouncecheck" merge --out "$out" "${dirs[@]}" || status=$?
  write_status "$out/merge.status" "$status"
  if has_result "$status"; then exit 0; fi
  exit "$status"
}

case "${1:-}" in
  --run-shard) shift; run_shard "$@" ;;
  --run-merge) shift; run_merge "$@" ;;
esac

# --- Submission (on the login node) -------------------------------------------
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
SELF="$HERE/$(basename "${BASH_SOURCE[0]}")" # what the jobs run (sbatch copies it at submission)
ROOT="$(cd "$HERE/../.." && pwd)"
shards="" out="" bouncecheck="" sbatch_extra=""
while (($#)); do
  case "$1" in
    --shards) shards="${2:-}"; shift 2 || usage ;;
    --shards=*) shards="${1#*=}"; shift ;;
    --out) out="${2:-}"; shift 2 || usage ;;
    --out=*) out="${1#*=}"; shift ;;
    --bouncecheck) bouncecheck="${2:-}"; shift 2 || usage ;;
    --bouncecheck=*) bouncecheck="${1#*=}"; shift ;;
    --sbatch) sbatch_extra="${2:-}"; shift 2 || usage ;;
    --sbatch=*) sbatch_extra="${1#*=}"; shift ;;
    -h | --help) usage 0 ;;
    --) shift; break ;;
    stress | sweep) break ;;
    *) say "unknown option $1"; usage ;;
  esac
done
(($#)) || { say "no command: give -- stress ... or -- sweep SCENARIO.toml ..."; usage; }
command="$1"
case "$command" in
  stress | sweep) ;;
  *) die "the command must be stress or sweep, not '$command'" ;;
esac
for arg in "$@"; do
  case "$arg" in
    --out | --out=* | --shard | --shard=*) die "$arg is this script's to set (use --out OUT before --)" ;;
  esac
done
[[ "$shards" =~ ^[1-9][0-9]*$ ]] || die "--shards takes a whole number >= 1, not '$shards'"
[ -n "$out" ] || die "--out OUT is required"
# sbatch_extra is split on whitespace on purpose (documented above).
read -r -a sbatch_opts <<< "$sbatch_extra"

for tool in sbatch squeue scontrol scancel; do
  command -v "$tool" > /dev/null || die "$tool is not on PATH: this needs Slurm's client commands"
done

if [ -z "$bouncecheck" ]; then
  bouncecheck="$(command -v bouncecheck || true)"
  [ -n "$bouncecheck" ] || bouncecheck="$ROOT/build/bouncecheck"
elif [[ "$bouncecheck" != */* ]]; then
  bouncecheck="$(command -v "$bouncecheck" || true)"
fi
if [ -z "$bouncecheck" ] || [ ! -x "$bouncecheck" ]; then
  die "no bouncecheck binary at '${bouncecheck}' (give --bouncecheck PATH)"
fi
# The jobs may start elsewhere: every path they get is absolute.
bouncecheck="$(cd "$(dirname "$bouncecheck")" && pwd)/$(basename "$bouncecheck")"

if [ -e "$out" ] && [ -n "$(ls -A "$out" 2> /dev/null || echo x)" ]; then
  die "$out already exists and is not empty: give a new --out (old shard results must not be merged)"
fi
mkdir -p "$out"
out="$(cd "$out" && pwd)"
# sbatch expands %x in --output file names; a literal % is %%.
log_dir="${out//%/%%}"

jobs_submitted=()
cancel_jobs() {
  if ((${#jobs_submitted[@]})); then
    say "cancelling job(s) ${jobs_submitted[*]}"
    scancel "${jobs_submitted[@]}" 2> /dev/null || true
  fi
}
trap 'cancel_jobs; exit 130' INT
trap 'cancel_jobs; exit 143' TERM

# sbatch --parsable prints "JOBID" or "JOBID;CLUSTER".
array_job="$(sbatch --parsable "${sbatch_opts[@]}" --job-name="bouncecheck-$command" \
  --array="1-$shards" --output="$log_dir/shard-%a.log" \
  "$SELF" --run-shard "$out" "$shards" "$bouncecheck" "$@")" || die "sbatch refused the shards' job array"
array_job="${array_job%%;*}"
jobs_submitted+=("$array_job")
merge_job="$(sbatch --parsable "${sbatch_opts[@]}" --job-name="bouncecheck-$command-merge" \
  --dependency="afterany:$array_job" --output="$log_dir/merge.log" \
  "$SELF" --run-merge "$out" "$shards" "$bouncecheck")" || { cancel_jobs; die "sbatch refused the merge job"; }
merge_job="${merge_job%%;*}"
jobs_submitted+=("$merge_job")
say "$shards shard(s) of '$command': job array $array_job, merge job $merge_job; results in $out"

# Wait until the merge job has left the queue: it starts only after every
# task of the array has ended. Poll every second at first, less often as the
# wait grows (at most every 30 s).
started=$SECONDS
unreachable_since=""
while :; do
  if state="$(squeue -h -j "$merge_job" -t all -o %T 2> /dev/null)"; then
    unreachable_since=""
  elif error="$(squeue -h -j "$merge_job" -t all -o %T 2>&1 > /dev/null || true)" && [[ "$error" == *"Invalid job id"* ]]; then
    state="" # the record is already purged (MinJobAge): the job has ended
  else
    # The controller may be briefly unreachable (a restart): keep asking.
    state="UNREACHABLE"
    [ -n "$unreachable_since" ] || unreachable_since=$SECONDS
    if ((SECONDS - unreachable_since > 600)); then
      say "squeue has failed for 10 minutes ($error); jobs $array_job and $merge_job left as they are"
      exit 2
    fi
  fi
  case "$state" in
    "" | COMPLETED | FAILED | CANCELLED | TIMEOUT | NODE_FAIL | PREEMPTED | OUT_OF_MEMORY | BOOT_FAIL | DEADLINE | REVOKED) break ;;
  esac
  wait_s=$((1 + (SECONDS - started) / 20))
  # In the background and waited for: a signal is handled at once, not after the sleep.
  sleep "$((wait_s < 30 ? wait_s : 30))" &
  wait $!
done
jobs_submitted=()
say "done after $((SECONDS - started)) s (merge job $merge_job: ${state:-record purged})"

# Every failed shard, named, with the end of its log; then the merge's output.
failed=0
for ((k = 1; k <= shards; k++)); do
  problem="$(shard_problem "$out" "$k" "$shards" "$array_job")"
  if [ -n "$problem" ]; then
    say "$problem"
    tail -n 5 "$out/shard-$k.log" 2> /dev/null | sed 's/^/    /' >&2 || true
    failed=$((failed + 1))
  fi
done
((failed == 0)) || die "no merged result: $failed of $shards shard(s) failed"
[ -f "$out/merge.log" ] && cat "$out/merge.log"
if [ ! -f "$out/merge.status" ]; then
  merge_state="$(scontrol -o show job "$merge_job" 2> /dev/null |
    grep -oE '(JobState|Reason|ExitCode)=[^ ]+' | paste -sd' ' || true)"
  die "merge job $merge_job ended without an exit status (Slurm: ${merge_state:-no record left}) (see $out/merge.log)"
fi
status="$(cat "$out/merge.status")"
if ! has_result "$status"; then
  die "merge failed: $(describe_status "$status") (see $out/merge.log)"
fi
say "merged $shards shard(s) into $out: $(describe_status "$status")"
exit "$status"
