#!/usr/bin/env bash
# Builds the libFuzzer targets (clang, ASan + UBSan) in build-fuzz/ and runs each of them for
# SECONDS (default 600). Not part of the default build, the tests or .ci/run. docs/fuzzing.md.
#
#   fuzz/run.sh [SECONDS] [problem_file|expression]...
#
# New inputs go to build-fuzz/corpus/<target>/, crashes, timeouts and OOMs to
# build-fuzz/findings/<target>/; keep each fixed reproducer in tests/bad_input/fuzz/<target>/.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-600}
shift || true
targets=("$@")
((${#targets[@]})) || targets=(problem_file expression)

missing=()
for p in clang libclang-rt-14-dev; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  sudo_cmd=""
  [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
  $sudo_cmd env DEBIAN_FRONTEND=noninteractive apt-get update -qq
  $sudo_cmd env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

cmake -S . -B build-fuzz -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DFESD_BUILD_FUZZ=ON -DFESD_BUILD_TESTS=OFF -DFESD_BUILD_BENCH=OFF >/dev/null
cmake --build build-fuzz -j2 --target fuzz_problem_file fuzz_expression

# Seeds for the expression target: every quoted string of the examples and bad-input files.
seeds=build-fuzz/seeds/expression
mkdir -p "$seeds"
i=0
grep -ohE '"[^"]+"' examples/*.toml tests/bad_input/files/*.toml | sort -u | while read -r q; do
  printf '%s' "${q:1:${#q}-2}" >"$seeds/example_$i"
  i=$((i + 1))
done

for t in "${targets[@]}"; do
  mkdir -p "build-fuzz/corpus/$t" "build-fuzz/findings/$t"
  case $t in
    problem_file) extra=(examples tests/bad_input/files tests/bad_input/fuzz/problem_file) ;;
    expression) extra=("$seeds" tests/bad_input/fuzz/expression) ;;
    *) echo "unknown target $t" >&2; exit 2 ;;
  esac
  "./build-fuzz/fuzz/fuzz_$t" -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=10 \
    -dict="fuzz/$t.dict" -artifact_prefix="build-fuzz/findings/$t/" -print_final_stats=1 \
    "build-fuzz/corpus/$t" "${extra[@]}" 2>&1 | tee "build-fuzz/fuzz_$t.log" | grep -E "^#|ERROR|SUMMARY|stat::|==" | tail -40
done
