#!/bin/sh
# Runs the fuzz harnesses of build/fuzz/ one after the other, each from its
# kept corpus (corpus/<harness>/, the boards' builds sharing one), new inputs
# going to a temporary copy, so the repository's corpus is never written.
#   run.sh short SECONDS harness...   each harness SECONDS seconds
#   run.sh long RUNS harness...       each harness RUNS executions (or at
#                                     most MAX_TIME seconds, if set)
# Prints one line per harness: executions, time, exec/s, coverage. A finding
# stops the run: the input is in build/fuzz/artifacts/, the log printed.
set -eu
cd "$(dirname "$0")"
mode=$1
amount=$2
shift 2
BUILD=../../build/fuzz
mkdir -p "$BUILD/artifacts" "$BUILD/logs"

for h in "$@"; do
	base=${h%-m32d}
	base=${base%-m128s}
	case $base in
	parse | exec) max_len=256 dict=gate.dict ;;
	regmap) max_len=256 dict="" ;;
	xact) max_len=384 dict="" ;;
	*) echo "run.sh: no harness $h" >&2; exit 2 ;;
	esac
	if [ "$mode" = short ]; then
		limit="-max_total_time=$amount"
	else
		limit="-runs=$amount${MAX_TIME:+ -max_total_time=$MAX_TIME}"
	fi
	tmp=$(mktemp -d)
	mkdir -p "$tmp/corpus"
	if [ -d "corpus/$base" ]; then
		cp "corpus/$base"/* "$tmp/corpus/" 2>/dev/null || true
	fi
	log="$BUILD/logs/$h-$mode.log"
	start=$(date +%s)
	status=0
	"$BUILD/fuzz-$h" $limit -max_len=$max_len ${dict:+-dict=$dict} -timeout=10 \
		-print_final_stats=1 -artifact_prefix="$BUILD/artifacts/$h-" \
		"$tmp/corpus" >"$log" 2>&1 || status=$?
	end=$(date +%s)
	rm -rf "$tmp"
	if [ $status -ne 0 ]; then
		tail -40 "$log"
		echo "fuzz-$h: FINDING (exit $status), log $log, input in $BUILD/artifacts/" >&2
		exit 1
	fi
	runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log")
	speed=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log")
	cov=$(sed -n 's/.*DONE *cov: \([0-9]*\) ft: \([0-9]*\).*/cov \1 ft \2/p' "$log" | tail -1)
	printf 'fuzz-%-13s %10s executions %5ss %7s exec/s  %s\n' "$h" "$runs" \
		$((end - start)) "$speed" "$cov"
done
