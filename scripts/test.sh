#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The README's test command: installs what is missing, builds, and runs every C++, Python and
# Blender test, then the C++ tests again under ASan+UBSan, each fuzz target for a bounded
# time, and a new user's path (scripts/new_user_test.sh: the demo in a fresh clone). Exits
# non-zero on the first failure.
# Environment: MPEG4FACE_FUZZ_SECONDS (default 20 per target).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
jobs=$(nproc)
export PYTHONDONTWRITEBYTECODE=1

step() { printf '\n=== %s (at %d min %02d s)\n' "$*" $((SECONDS / 60)) $((SECONDS % 60)); }

# Totals over every runner, for the closing line. A failure stops the script before it.
mkdir -p build/logs
passed=0
skipped=0
counted() {  # counted LOG COMMAND...: runs COMMAND, keeps its output in LOG for tally
  "${@:2}" 2>&1 | tee "build/logs/$1"
}
tally_ctest() {  # tally_ctest LOG BUILD_DIR
  local total skip
  # GoogleTest reports the tests of a suite whose SetUpTestSuite threw as skipped, and ctest
  # passes them: that is a failure.
  if grep -q 'SetUpTestSuite or TearDownTestSuite' "$2/Testing/Temporary/LastTest.log"; then
    echo "C++ tests: a test suite's set-up or tear-down failed, its tests skipped:" >&2
    grep -m5 -E 'thrown in (SetUp|TearDown)TestSuite|Failure' \
      "$2/Testing/Temporary/LastTest.log" >&2
    exit 1
  fi
  total=$(sed -n 's/.*tests passed, 0 tests failed out of \([0-9]*\).*/\1/p' "build/logs/$1")
  skip=$(grep -c '(Skipped)' "build/logs/$1" || true)
  passed=$((passed + total - skip)); skipped=$((skipped + skip))
}
tally_pytest() {
  local line
  line=$(grep -E '[0-9]+ passed' "build/logs/$1" | tail -n 1)
  passed=$((passed + $(grep -oE '[0-9]+ passed' <<<"$line" | cut -d' ' -f1)))
  skipped=$((skipped + $(grep -oE '[0-9]+ skipped' <<<"$line" | cut -d' ' -f1 || echo 0)))
}

step "setup"
scripts/setup.sh

step "build (release)"
scripts/build.sh build/release

export MPEG4FACE_GLTF_VALIDATOR="node $root/tests/tools/validate_gltf.mjs"

step "C++ tests"
# The python and blender labels are the steps below, run there with their own output.
counted ctest.log ctest --test-dir build/release --output-on-failure -j"$jobs" -LE "python|blender"
tally_ctest ctest.log build/release

step "Python tests"
PYTHONPATH="$root/build/release/python" \
  counted pytest.log /usr/bin/python3 -m pytest -q -p no:cacheprovider tests/python
tally_pytest pytest.log

# The same suite in every Blender this machine runs: Debian's (the window and GPU tests too)
# and Blender 4.5 LTS and 5.0 as Python modules (scripts/setup.sh's build/venv-bpy-*), where
# tests needing the blender program or a window skip with the reason.
blender_counts=()
blender_suite() {  # blender_suite NAME COMMAND...: the suite in one Blender (log blender-NAME.log)
  local log=blender-$1.log version
  version=$(MPEG4FACE_PYTHONPATH="$root/build/release/python" "${@:2}" --version 2>/dev/null |
    sed -n 's/^VERSION=//p')
  step "Blender tests: Blender $version ($1)"
  # The viewport test keeps its screenshots there (docs/images has copies for the user guide).
  MPEG4FACE_PYTHONPATH="$root/build/release/python" MPEG4FACE_SCREENSHOTS="$root/build/screenshots" \
    counted "$log" "${@:2}"
  tally_pytest "$log"
  blender_counts+=("Blender $version ($1): $(grep -E '[0-9]+ passed' "build/logs/$log" | tail -n 1 | tr -d '=')")
}
blender_suite debian blender -b --factory-startup --python-exit-code 1 --python tests/blender/run_in_blender.py --
for venv in build/venv-bpy-*; do
  blender_suite "${venv#build/venv-}" "$venv/bin/python" tests/blender/run_in_blender.py
done
printf '%s\n' "${blender_counts[@]}"

step "packages: the wheel, the Blender extension and the add-on zip, installed as an artist would"
# scripts/package.sh builds and checks dist/ (docs/packaging.md); the install test installs the
# zips into temporary user folders of bpy 4.5, 5.0 and Debian's Blender, with clean
# environments, and runs the workflow on the MakeHuman sample (samples/build.sh makes it).
scripts/package.sh
samples/build.sh
counted install.log tests/install/run_install_test.sh
passed=$((passed + $(grep -cE '^install-test: [^:]+: passed' build/logs/install.log)))

step "C++ tests under AddressSanitizer + UndefinedBehaviorSanitizer"
# One clang build serves the sanitised tests and the fuzz targets (everything instrumented
# with ASan, UBSan and libFuzzer's coverage), optimised (-O2 -g): the cloning and codec tests
# run tens of times slower unoptimised, and a second sanitised build cost CI a quarter hour.
CXX=clang++ scripts/build.sh build/sanitize -DMPEG4FACE_FUZZ=ON
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  counted ctest-sanitize.log ctest --test-dir build/sanitize --output-on-failure -j"$jobs"
tally_ctest ctest-sanitize.log build/sanitize

step "fuzz targets (${MPEG4FACE_FUZZ_SECONDS:-20} s each)"
mkdir -p build/sanitize/artifacts
for target in build/sanitize/fuzz/fuzz_*; do
  name=$(basename "$target")
  corpus=$(mktemp -d)
  cp -r "tests/fuzz_corpus/${name#fuzz_}/." "$corpus/"
  log=build/sanitize/$name.log
  # Inputs it once failed on (tests/fuzz_regressions/<name>/), replayed before it fuzzes.
  regressions=()
  if [[ -d tests/fuzz_regressions/${name#fuzz_} ]]; then
    mapfile -t regressions < <(find "tests/fuzz_regressions/${name#fuzz_}" -type f ! -name '*.md')
  fi
  if ((${#regressions[@]})) && ! "$target" -rss_limit_mb=2048 -timeout=10 "${regressions[@]}" \
      >"$log" 2>&1; then
    tail -n 60 "$log"
    echo "$name FAILED on a regression input of tests/fuzz_regressions/${name#fuzz_}/"
    exit 1
  fi
  if ! "$target" -max_total_time="${MPEG4FACE_FUZZ_SECONDS:-20}" -rss_limit_mb=2048 -timeout=10 \
      -print_final_stats=1 -artifact_prefix=build/sanitize/artifacts/ "$corpus" >"$log" 2>&1; then
    tail -n 60 "$log"
    echo "$name FAILED; the input is in build/sanitize/artifacts/"
    exit 1
  fi
  echo "$name: ${#regressions[@]} regression inputs and $(grep -E '^stat::number_of_executed_units' "$log" | tr -s ' ' | cut -d' ' -f2) inputs, no failure"
  passed=$((passed + 1))
  rm -rf "$corpus"
done

step "a new user's path: the README's demo command in a fresh clone, run twice, its output checked"
# This script is the README's other command, so the new-user test runs only the demo here.
MPEG4FACE_NEW_USER_STEPS=demo counted new-user.log scripts/new_user_test.sh
passed=$((passed + $(grep -c '^ok: ' build/logs/new-user.log)))

step "all tests passed"
printf '%s\n' "${blender_counts[@]}"
echo "tests: $passed passed, 0 failed, $skipped skipped"
