#!/usr/bin/env bash
# A fuzzing campaign (issue #33, item 7), outside CI (CI keeps its
# fixed-seed minute in .ci/run): targets of the fuzzer one after another,
# each on both cores (`--jobs 2`: two worker processes), with a fresh seed
# each, printing each target's inputs, inputs/s, totals, projection and the
# seeds to replay from. Failing inputs are saved in fuzz/crashes/. One in
# 50 `.lens` inputs of build, and one in 1,000 of check (a process
# started each time would be a tenth of check's time at 1 in 50), also runs
# through the release `lensc` binary end to end (exit codes, output files).
#
#   fuzz/campaign.sh [SECONDS]            # default 3600: every target its share
#   PLAN="check:100" fuzz/campaign.sh 900 # one target, a quarter hour
#   fuzz/campaign.sh --until-goals [CAP]  # the issue's goals, see below
#
# --until-goals runs `check` until 10,000,000 inputs have gone through it
# (or half of CAP has passed), then `build` until 100,000 jobs are built
# (or CAP has passed), then each other target for OTHERS seconds (default
# 300). CAP defaults to 8 hours; the fuzzer's summary projects, at the
# rates it measures, how long each goal takes on the cores it is given.
# A campaign run in legs (a session is shorter than the goals take) states
# what is left: CHECK_GOAL and BUILD_GOAL (default the issue's), ORDER
# (default "check build"). TIMEOUT (default 10 s) is the hang limit of one
# input; on a machine shared with other work a worker may be starved for
# longer than a quiet machine's 10 s without hanging.
#
# Each lane is a worker process: an abort (exit 134: an allocation that
# fails, a stack overflow) loses the one input it was on, which is saved
# and reported, and the lane starts again past it. Should the fuzzer itself
# die, the run is started again with a new seed for what is left, the
# counts it had reached (its last progress line) taken off the goal.
set -u
cd "$(dirname "$0")/.."
goals=0
if [ "${1:-}" = "--until-goals" ]; then
    goals=1
    shift
fi
total=${1:-3600}
cargo build --release -p fuzz -p lensc || exit 2
lensc=target/release/lensc
fuzz=target/release/fuzz
status=0
summary=""

# run TARGET SECONDS [INPUT-GOAL] [BUILD-GOAL]: the fuzzer on TARGET until
# the time is up or the goal reached, started again with a new seed if it
# dies, the reached counts taken off the goals.
run() {
    local target=$1 left=$2 inputs=${3:-} builds=${4:-}
    while [ "$left" -gt 0 ]; do
        local seed began log rc flags=()
        seed=$(date +%s%N)
        began=$(date +%s)
        [ -n "$inputs" ] && flags+=(--inputs "$inputs")
        [ -n "$builds" ] && flags+=(--until-built "$builds")
        [ "$target" = check ] && flags+=(--end-to-end-every 1000)
        echo "== $target: $left s, seed $seed ${flags[*]}"
        log=$(mktemp)
        "$fuzz" --target "$target" --seconds "$left" --seed "$seed" --jobs 2 \
            --timeout "${TIMEOUT:-10}" --lensc "$lensc" "${flags[@]}" 2>&1 | tee "$log"
        rc=${PIPESTATUS[0]}
        [ "$rc" -ne 0 ] && status=1
        summary+="$target (seed $seed, exit $rc, $(( $(date +%s) - began )) s):"$'\n'"$(grep -E '^  (inputs|through|end to end|time by|an hour|projection|CPU|panics)' "$log")"$'\n'
        if [ "$rc" -gt 1 ]; then
            local last
            last=$(grep 'fuzz: progress' "$log" | tail -1 | sed 's/^fuzz: progress //')
            summary+="  died at $last"$'\n'
            # "30 s: 12345 inputs, 67 built"
            local got_inputs got_built
            got_inputs=$(echo "$last" | sed -n 's/.*: \([0-9]*\) inputs.*/\1/p')
            got_built=$(echo "$last" | sed -n 's/.* \([0-9]*\) built.*/\1/p')
            [ -n "$inputs" ] && inputs=$(( inputs - ${got_inputs:-0} ))
            [ -n "$builds" ] && builds=$(( builds - ${got_built:-0} ))
        fi
        rm -f "$log"
        [ "$rc" -le 1 ] && break
        left=$(( left - ($(date +%s) - began) ))
    done
}

if [ "$goals" -eq 1 ]; then
    cap=${1:-28800}
    began=$(date +%s)
    for target in ${ORDER:-check build}; do
        case $target in
            check) [ "${CHECK_GOAL:-10000000}" -gt 0 ] &&
                run check $(( cap / 2 )) "${CHECK_GOAL:-10000000}" ;;
            build) [ "${BUILD_GOAL:-100000}" -gt 0 ] &&
                run build $(( cap - ($(date +%s) - began) )) "" "${BUILD_GOAL:-100000}" ;;
        esac
    done
    for target in verify import lsp measure; do
        run "$target" "${OTHERS:-300}"
    done
else
    # target:percent of the time (check and build, the issue's goals of
    # 10 M and 100 k inputs, take most of it).
    plan=${PLAN:-"check:45 build:33 verify:7 import:5 lsp:5 measure:5"}
    for entry in $plan; do
        target=${entry%%:*}
        share=${entry##*:}
        seconds=$(( total * share / 100 ))
        [ "$seconds" -lt 1 ] && seconds=1
        run "$target" "$seconds"
    done
fi
echo
echo "== campaign"
printf '%s' "$summary"
exit $status
