#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# An offline fuzzing campaign over the project's libFuzzer targets (core/fuzz/), one target
# at a time, each in libFuzzer's fork mode with one worker: it goes on past a crash, a
# timeout or an out-of-memory, keeping each input in the artifacts folder. Afterwards the
# inputs it found that reach code the committed corpus does not are merged into
# tests/fuzz_corpus/<name>/ (-merge=1 keeps only those, so the corpus stays small), and a
# summary line per target gives executions, coverage (cov: edges, ft: features), inputs added
# and findings. Before fuzzing, each target replays tests/fuzz_regressions/<name>/.
#
# Usage: scripts/fuzz.sh [--minutes N] [--runs N] [--jobs N] [--max-len N] [TARGET...]
#   --minutes N  time per target (default 10); the campaign stops a target at N minutes or
#                at --runs executions, whichever comes first
#   --runs N     executions per target (default: no bound but time)
#   --jobs N     fork-mode workers per target (default 1)
#   --max-len N  largest input libFuzzer makes (default: the table below, else libFuzzer's own,
#                the larger of 4096 and the largest seed)
#   TARGET       names as in core/fuzz/CMakeLists.txt (vrml, fap, ...); default all
# Output: build/sanitize/campaign/<name>.log, artifacts in
# build/sanitize/campaign/artifacts/<name>/, the summary also as a Markdown table in
# build/sanitize/campaign/summary.md. Exits non-zero if any target has a finding or a
# regression input fails.
set -euo pipefail
cd "$(dirname "$0")/.."

minutes=10
runs=-1
jobs=1
max_len=
targets=()
while (($#)); do
  case $1 in
    --minutes) minutes=$2; shift 2 ;;
    --runs) runs=$2; shift 2 ;;
    --jobs) jobs=$2; shift 2 ;;
    --max-len) max_len=$2; shift 2 ;;
    -h | --help) sed -n '3,21p' "$0" | cut -c3-; exit 0 ;;
    -*) echo "fuzz.sh: unknown option $1" >&2; exit 2 ;;
    *) targets+=("$1"); shift ;;
  esac
done
if ((${#targets[@]} == 0)); then
  # The target list of core/fuzz/CMakeLists.txt.
  mapfile -t targets < <(sed -n '/^set(MPEG4FACE_FUZZ_TARGETS/,/^)/p' core/fuzz/CMakeLists.txt |
    sed '1d;$d' | tr -d ' ')
fi

# Targets whose seeds are larger than the inputs worth mutating: libFuzzer would otherwise
# grow inputs to the largest seed. fap: the Xface seeds are 31 kB (each execution then parses,
# writes and parses ~150 frames); 4096 bytes hold 20 frames of all 68 FAPs, past every rule of
# the grammar. A longer seed is read truncated to its first max_len bytes.
declare -A default_max_len=([fap]=4096)

# The test command's sanitised build (scripts/test.sh), configured alike so the two share it.
build=build/sanitize
fuzz_targets=("${targets[@]/#/fuzz_}")
CXX=clang++ MPEG4FACE_BUILD_TARGETS="${fuzz_targets[*]}" \
  scripts/build.sh "$build" -DMPEG4FACE_FUZZ=ON

campaign=$build/campaign
mkdir -p "$campaign"
summary=$campaign/summary.md
{
  echo "| target | executions | cov | ft | inputs added | findings | time (s) |"
  echo "|---|---:|---:|---:|---:|---:|---:|"
} >"$summary"
status=0
for name in "${targets[@]}"; do
  fuzzer=$build/fuzz/fuzz_$name
  seeds=tests/fuzz_corpus/$name
  regressions=tests/fuzz_regressions/$name
  log=$campaign/$name.log
  artifacts=$campaign/artifacts/$name
  work=$campaign/corpus/$name
  rm -rf "$work" "$artifacts"
  mkdir -p "$work" "$artifacts" "$seeds"
  cp -r "$seeds/." "$work/"

  if [[ -d $regressions ]]; then
    mapfile -t inputs < <(find "$regressions" -type f ! -name '*.md' | sort)
    if ((${#inputs[@]})) && ! "$fuzzer" -rss_limit_mb=2048 -timeout=10 "${inputs[@]}" \
      >"$campaign/$name.regressions.log" 2>&1; then
      echo "$name: a regression input fails again (see $campaign/$name.regressions.log)"
      status=1
      continue
    fi
  fi

  bound="$minutes min"
  ((runs < 0)) || bound+=" or $runs executions"
  len=${max_len:-${default_max_len[$name]:-}}
  len_flag=()
  [[ -z $len ]] || len_flag=(-max_len="$len")
  echo "$name: fuzzing for up to $bound${len:+, inputs up to $len bytes} (log: $log)"
  # ASan's leak check at exit is off: fork mode's workers are killed at the time limit.
  "$fuzzer" -fork="$jobs" -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1 \
    -max_total_time=$((minutes * 60)) -runs="$runs" -rss_limit_mb=2048 -timeout=10 \
    "${len_flag[@]}" -artifact_prefix="$artifacts/" -print_final_stats=1 "$work" >"$log" 2>&1 ||
    true

  # Fork mode reports "#<executions>: cov: <edges> ft: <features> corp: ..." after each job.
  last=$(grep -E '^#[0-9]+: cov: ' "$log" | tail -n 1 || true)
  executions=$(sed -E 's/^#([0-9]+):.*/\1/' <<<"$last")
  cov=$(sed -E 's/.* cov: ([0-9]+) .*/\1/' <<<"$last")
  ft=$(sed -E 's/.* ft: ([0-9]+) .*/\1/' <<<"$last")
  seconds=$(sed -E 's/.* time: ([0-9]+)s .*/\1/' <<<"$last")
  findings=$(find "$artifacts" -type f | wc -l)

  before=$(find "$seeds" -type f | wc -l)
  # Edges only (no hit counters): an input is added for an edge the corpus does not reach,
  # not for every new loop count, which would add hundreds.
  "$fuzzer" -merge=1 -use_counters=0 -rss_limit_mb=2048 -timeout=10 "$seeds" "$work" \
    >"$campaign/$name.merge.log" 2>&1
  added=$(($(find "$seeds" -type f | wc -l) - before))

  line="$name: ${executions:-?} executions, cov ${cov:-?}, ft ${ft:-?}, $added inputs added to"
  echo "$line $seeds, $findings findings (in $artifacts), ${seconds:-?} s"
  echo "| $name | ${executions:-?} | ${cov:-?} | ${ft:-?} | $added | $findings | ${seconds:-?} |" \
    >>"$summary"
  ((findings == 0)) || status=1
done
echo
cat "$summary"
exit "$status"
