#!/usr/bin/env bash
# Fuzzes trm's file readers with cargo-fuzz (libFuzzer; needs the nightly toolchain).
#
#   fuzz/run.sh TARGET [libFuzzer flags…]   one target, e.g. `fuzz/run.sh map -runs=10000000`
#   fuzz/run.sh --all [libFuzzer flags…]    every target in turn with the same flags
#   fuzz/run.sh --smoke                     every target for 3 s, no sanitizer, unoptimised;
#                                           skips with a message where nightly is missing
#   fuzz/run.sh --list                      the targets
#
# Each target's corpus (fuzz/corpus/TARGET, not committed) is seeded from the files seeds.txt
# names (specs/, models/…) and from fuzz/seeds/TARGET; crashes land in fuzz/artifacts/TARGET.
# What each target checks is a function of fuzz/checks, which the quick test suite also runs on
# the seeds and mutations of them (stable). Targets run under AddressSanitizer; SANITIZER=none runs them about twice as fast (long runs).
set -euo pipefail
cd "$(dirname "$0")"
root=..

targets=(urdf model_description task_spec world motion_spec taskmap_spec map checkpoint taskmap scene
         configurations posture trajectory_csv trajectory_json srdf mesh moveit points)

# The seed files of a target, one per line: its globs in seeds.txt and the files in seeds/TARGET.
seeds() {
  local glob
  awk -v t="$1" '$1 == t { print $2 }' seeds.txt | while read -r glob; do
    # shellcheck disable=SC2086
    ls "$root"/$glob
  done
  if [ -d "seeds/$1" ]; then ls "seeds/$1"/*; fi
}

# libFuzzer flags of a target: the iCub model descriptions and URDFs (50–110 kB) and scenes
# (30 kB) would make every mutated input that large; smaller inputs (small seeds in seeds/)
# explore faster.
flags() {
  case "$1" in
    model_description | scene | urdf | srdf | mesh | moveit | points) echo -max_len=8192 ;;
  esac
}

prepare() {
  mkdir -p "corpus/$1"
  seeds "$1" | while read -r f; do cp "$f" "corpus/$1/"; done
}

run() {
  local target=$1
  shift
  prepare "$target"
  # shellcheck disable=SC2046
  cargo +nightly fuzz run "${FUZZ_PROFILE:---release}" -s "${SANITIZER:-address}" "$target" "corpus/$target" -- $(flags "$target") "$@"
}

case "${1:-}" in
  --list) printf '%s\n' "${targets[@]}" ;;
  --all)
    shift
    for t in "${targets[@]}"; do run "$t" "$@"; done ;;
  --smoke)
    if ! cargo +nightly --version >/dev/null 2>&1; then
      echo "fuzz smoke run skipped: no nightly toolchain (rustup toolchain install nightly)"
      exit 0
    fi
    if ! cargo fuzz --version >/dev/null 2>&1; then
      cargo install cargo-fuzz --locked --version 0.13.2
    fi
    # no sanitizer: trm's code has no `unsafe`, and the build and the runs are faster; an
    # unoptimised build: it compiles in about half the time, and 3 s still runs each target's
    # seeds and thousands of mutations
    export SANITIZER=none FUZZ_PROFILE=--dev
    cargo +nightly fuzz build --dev -s none
    for t in "${targets[@]}"; do
      runs=$(run "$t" -max_total_time=3 -print_final_stats=1 2>&1 |
        grep -E "stat::number_of_executed_units|ERROR|panicked" || true)
      echo "fuzz smoke $t: ${runs//stat::number_of_executed_units: /} executions in 3 s"
      if [ -n "$(ls "artifacts/$t" 2>/dev/null)" ]; then
        echo "fuzz target $t crashed: see fuzz/artifacts/$t"; exit 1
      fi
    done ;;
  ""|-h|--help) sed -n 2,12p "$0" | sed 's/^# \{0,1\}//' ;;
  *) run "$@" ;;
esac
