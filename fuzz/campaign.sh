#!/usr/bin/env bash
# A fuzzing campaign (issue #33, item 7), outside CI (CI keeps its
# fixed-seed minute in .ci/run): every target of the fuzzer, one after
# another, each on both cores (`--jobs 2`) for its share of the time, with
# a fresh seed each, printing each target's inputs, inputs/s and totals and
# the seeds to replay from. Failing inputs are saved in fuzz/crashes/.
# With --lensc, one in 50 `.lens` inputs of check and build also runs
# through the release `lensc` binary end to end (exit codes, output files).
#
#   fuzz/campaign.sh [SECONDS]     # default 3600: an hour in all
#   PLAN="check:100" fuzz/campaign.sh 900   # one target, a quarter hour
#
# A run that aborts (exit 134: an allocation that fails, a stack overflow;
# a panic is caught and saved, an abort cannot be) is started again with
# a new seed for the rest of its target's time; what it had reached is its
# last progress line, and the abort's backtrace is in the log.
#
# The share of each target is set below (check and build, the issue's
# goals of 10 M and 100 k inputs, take most of the hour).
set -u
cd "$(dirname "$0")/.."
total=${1:-3600}
cargo build --release -p fuzz -p lensc || exit 2
lensc=target/release/lensc
fuzz=target/release/fuzz
# target:percent of the time
plan=${PLAN:-"check:45 build:33 verify:7 import:5 lsp:5 measure:5"}
status=0
summary=""
for entry in $plan; do
    target=${entry%%:*}
    share=${entry##*:}
    seconds=$(( total * share / 100 ))
    [ "$seconds" -lt 1 ] && seconds=1
    left=$seconds
    while [ "$left" -gt 0 ]; do
        seed=$(date +%s%N)
        began=$(date +%s)
        echo "== $target: $left s, seed $seed"
        log=$(mktemp)
        "$fuzz" --target "$target" --seconds "$left" --seed "$seed" --jobs 2 \
            --lensc "$lensc" 2>&1 | tee "$log"
        rc=${PIPESTATUS[0]}
        [ "$rc" -ne 0 ] && status=1
        summary+="$target (seed $seed, exit $rc, $(( $(date +%s) - began )) s):"$'\n'"$(grep -E '^  (inputs|through|end to end|an hour|panics)' "$log")"$'\n'
        if [ "$rc" -gt 1 ]; then
            summary+="  aborted at $(grep 'fuzz: progress' "$log" | tail -1 | sed 's/^fuzz: progress //')"$'\n'
        fi
        rm -f "$log"
        [ "$rc" -le 1 ] && break
        left=$(( left - ($(date +%s) - began) ))
    done
done
echo
echo "== campaign of $total s"
printf '%s' "$summary"
exit $status
